// cdbench: what the contact dynamics costs. Google Benchmark runs
// over prepared piles of disks (pile.hpp); every timed solve runs a fixed
// number of sweeps (eps_f = 0, max_iter = kSweeps) unless the name says
// "converged", so that two runs compare the cost of the same work.
//
//   nlgs/N              kSweeps sweeps on a frozen contact problem, 1 thread:
//                       contact updates per second per core
//   nlgs_shuffled/N     the same problem with the bodies numbered at random:
//                       what memory locality is worth
//   nlgs_poly/S/N       nlgs/N on a settled pile of regular S-gons (S = 4, 6):
//                       updates/s per core, and the cost per contact update
//                       against disks at the same N (summary)
//   step/N              one time step (detect, build, kSweeps sweeps,
//                       integrate), 1 thread: ms/step against N, and its slope
//   step_converged/N    one time step at the default eps_f: ms and sweeps a step
//   threads/{nlgs,step}/N/T   the same with T OpenMP threads, wall time:
//                       the speedup from 1 to 2 threads
//   effect/<name>:<on|off>    one step, N = 1e4, 1 thread: what an effect
//                       costs when on, and that it costs nothing when off
//                       (periodicity: the pile made periodic in x over its
//                       box width plus one diameter; the side walls stay, so
//                       the same rows, and the difference is the periodic
//                       cell list, images and wrapping)
//
// Scenes: N = 1e3 is a deposited, settled square pile (45 d deep); larger N
// are side by side mirrored copies of it (a layer of the same depth), so
// that preparing 1e5 disks takes seconds, and the work a sweep does per
// contact is the same at every N. Polygon piles: 1e3 polygons collapsed from
// a loose lattice under gravity (cdbench::polygon_pile, a few seconds), 1e4
// tiled from it. Preparation runs on one thread.
//
// Besides Google Benchmark's own output, --csv_dir=DIR writes
//   runs.csv     one line per benchmark (time and counters)
//   summary.csv  the ratios measured in this run (speedups, effect on/off,
//                updates/s per core, ms/step slope against N)
//   machine.csv  CPU model, cores, compiler, flags, load average
//   plots.gp     gnuplot script (with plot_step.dat, plot_nlgs.dat), run if
//                gnuplot is installed: step_ms_vs_N.png (log-log, slope-1
//                guide) and nlgs_updates_disk_vs_polygon.png
// and the summary is printed at the end.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "machine.hpp"
#include "nlgs.hpp"
#include "pile.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr int kBase = 1000;   // disks in the base pile; larger N are copies of it
constexpr int kSweeps = 50;   // sweeps a solve in every fixed-work benchmark
constexpr double kWork = 2e7; // contact updates a benchmark aims at (~1-2 s a run)

struct Threads {  // OpenMP threads for one scope
  int saved;
  explicit Threads(int t) : saved(omp_get_max_threads()) { omp_set_num_threads(t); }
  ~Threads() { omp_set_num_threads(saved); }
};

cd::WorldParams fixed_sweeps(cd::WorldParams p, int k) {
  p.solver.tol = 0.0;  // never met: exactly k sweeps
  p.solver.max_iter = k;
  return p;
}

// Prepared worlds, one per (N, sides), built on first use and copied by each
// run. sides = 0: disks; 3..: regular polygons (cdbench::polygon_pile).
const cd::World& prepared(int n, int sides = 0) {
  static std::map<std::pair<int, int>, std::unique_ptr<cd::World>> cache;
  auto& slot = cache[{n, sides}];
  if (!slot) {
    Threads one(1);
    const auto t0 = Clock::now();
    if (n == kBase && sides > 0) {
      slot = std::make_unique<cd::World>(cdbench::polygon_pile(kBase, sides));
    } else if (n == kBase) {
      slot = std::make_unique<cd::World>(cdbench::pile_world(cdbench::pile_scene(kBase)));
      cdbench::settle(*slot);
    } else {
      slot = std::make_unique<cd::World>(cdbench::tile(prepared(kBase, sides), n / kBase));
      // The warm start is lost by tiling: rebuild a force network. Fixed
      // sweeps keep this affordable at 1e5 (converging it from zero would
      // take thousands of sweeps a step).
      const cd::WorldParams p = slot->params();
      slot->set_params(fixed_sweeps(p, 200));
      for (int k = 0; k < 3; ++k) slot->step();
      slot->set_params(p);
    }
    std::cerr << "cdbench: prepared N = " << n
              << (sides ? " polygons of " + std::to_string(sides) + " sides" : std::string())
              << " (" << slot->last().contacts << " contacts, max overlap "
              << 100 * slot->last().max_overlap << " % d, kinetic energy "
              << slot->kinetic_energy() << " J) in " << since(t0) << " s\n";
  }
  return *slot;
}

// A frozen contact problem: the rows of the last step of a prepared world,
// coloured, with the body velocities they were solved with.
struct Frozen {
  std::vector<cd::ContactRow> rows;
  cd::Colouring col;
  std::vector<cd::BodyVel> vel;
  cd::SolverParams prm;
  cd::LocalLaw law;
  bool rotation = true;
  int contacts = 0;  // distinct body pairs (a polygon side-side contact has 2 rows)
};

const Frozen& frozen(int n, int sides = 0) {
  static std::map<std::pair<int, int>, std::unique_ptr<Frozen>> cache;
  auto& slot = cache[{n, sides}];
  if (!slot) {
    const cd::World& w = prepared(n, sides);
    slot = std::make_unique<Frozen>();
    const std::vector<cd::ContactRow>& r = w.rows();
    slot->col = cd::colour_rows(r, w.bodies);
    slot->rows.resize(r.size());
    for (std::size_t k = 0; k < r.size(); ++k) slot->rows[k] = r[slot->col.perm[k]];
    slot->vel = w.bodies.vel;
    slot->prm = w.params().solver;
    slot->law = w.law();
    slot->rotation = w.params().rotation;
    slot->prm.tol = 0.0;
    slot->prm.max_iter = kSweeps;
    std::vector<std::pair<int, int>> pairs;
    pairs.reserve(r.size());
    for (const cd::ContactRow& row : r) pairs.emplace_back(row.b1, row.b2);
    std::sort(pairs.begin(), pairs.end());
    slot->contacts =
        static_cast<int>(std::unique(pairs.begin(), pairs.end()) - pairs.begin());
  }
  return *slot;
}

// The same problem with the bodies numbered at random, as a sample that
// flows and is never renumbered ends up: isolates the cost of memory
// locality (the rows, their order and their colours are unchanged).
const Frozen& frozen_shuffled(int n) {
  static std::map<int, std::unique_ptr<Frozen>> cache;
  auto& slot = cache[n];
  if (!slot) {
    const Frozen& f = frozen(n);
    const cd::Bodies& B0 = prepared(n).bodies;
    std::vector<std::int32_t> to(B0.size());
    std::iota(to.begin(), to.end(), 0);
    std::shuffle(to.begin(), to.end(), std::mt19937_64(7));
    cd::Bodies B;  // what colour_rows reads: the count and which bodies are driven
    B.pos.resize(B0.size());
    B.driven.resize(B0.size());
    slot = std::make_unique<Frozen>(f);
    for (std::size_t i = 0; i < B0.size(); ++i) {
      slot->vel[to[i]] = f.vel[i];
      B.driven[to[i]] = B0.driven[i];
    }
    for (cd::ContactRow& r : slot->rows) {
      r.b1 = to[r.b1];
      r.b2 = to[r.b2];
    }
    const std::vector<cd::ContactRow> rows = slot->rows;
    slot->col = cd::colour_rows(rows, B);
    for (std::size_t k = 0; k < rows.size(); ++k) slot->rows[k] = rows[slot->col.perm[k]];
  }
  return *slot;
}

// Timed runs a benchmark makes so that it does about kWork contact updates.
int runs_for(int n, int sweeps) {
  const double rows = 2.3 * n;  // contacts a disk in these piles (alert 0.1 d)
  return static_cast<int>(std::clamp(kWork / (rows * sweeps), 3.0, 200.0));
}

void time_nlgs(benchmark::State& state, const Frozen& f, int n, int threads) {
  Threads scope(threads);
  cd::ContactProblem p;
  p.colouring = f.col;
  p.law = f.law;
  p.rotation = f.rotation;
  double t = 0, sweeps = 0;
  for (auto _ : state) {
    p.rows = f.rows;  // the same problem every run (untimed: manual time)
    p.vel = f.vel;
    const auto t0 = Clock::now();
    const cd::SolveStats st = cd::nlgs_solve(p, f.prm);
    const double dt = since(t0);
    state.SetIterationTime(dt);
    t += dt;
    sweeps += st.iterations;
  }
  const double updates = static_cast<double>(f.rows.size()) * sweeps;
  state.counters["n"] = n;
  state.counters["threads"] = threads;
  state.counters["rows"] = static_cast<double>(f.rows.size());
  state.counters["colours"] = static_cast<double>(f.col.start.size() - 1);
  state.counters["sweeps"] = sweeps / state.iterations();
  state.counters["updates_per_s_per_core"] = updates / t / threads;
  state.counters["ns_per_update"] = 1e9 * t / updates;
  state.counters["contacts"] = f.contacts;
  state.counters["ns_per_contact_sweep"] = 1e9 * t / (static_cast<double>(f.contacts) * sweeps);
}

void bm_nlgs(benchmark::State& state, int n, int threads, bool shuffled) {
  time_nlgs(state, shuffled ? frozen_shuffled(n) : frozen(n), n, threads);
}

// nlgs_poly/<sides>/N: nlgs/N on a settled pile of regular polygons. The
// solver only sees rows; a side-side contact is two rows on the same body
// pair, so updates count rows (as for disks) and ns_per_contact_sweep counts
// distinct body pairs.
void bm_nlgs_poly(benchmark::State& state, int sides, int n) {
  time_nlgs(state, frozen(n, sides), n, 1);
}
const int kPolySides[] = {4, 6};
const int kPolySizes[] = {1000, 10000};

// Steps a copy of a prepared world with the given parameters; one warm-up
// step first (the row set changes with the parameters), then one step a run.
void run_steps(benchmark::State& state, int n, int threads, const cd::WorldParams& p,
               bool fixed) {
  cd::World w = prepared(n);
  Threads scope(threads);
  w.set_params(p);
  w.step();
  const cd::StageTimes t0 = w.times;
  double rows = 0, sweeps = 0, caps = 0, solve_row_sweeps = 0;
  for (auto _ : state) {
    w.step();
    const cd::StepStats& s = w.last();
    if (fixed && s.solve.iterations != p.solver.max_iter) {
      state.SkipWithError("the solver stopped before the fixed sweep count");
      break;
    }
    rows += s.contacts;
    sweeps += s.solve.iterations;
    caps += s.solve.iterations >= p.solver.max_iter;
    solve_row_sweeps += static_cast<double>(s.contacts) * s.solve.iterations;
  }
  const double k = static_cast<double>(state.iterations());
  state.counters["n"] = n;
  state.counters["threads"] = threads;
  state.counters["rows"] = rows / k;
  state.counters["sweeps"] = sweeps / k;
  if (!fixed) state.counters["cap_hits"] = caps;
  auto spent = [&](std::initializer_list<cd::Stage> st) {
    double s = 0;
    for (const cd::Stage x : st) s += w.times[x] - t0[x];
    return s;
  };
  // detect_ms: everything before the solve (predict, detect, build, colour).
  state.counters["detect_ms"] =
      1e3 * spent({cd::Stage::Predict, cd::Stage::Detect, cd::Stage::Build, cd::Stage::Colour}) / k;
  state.counters["solve_ms"] = 1e3 * spent({cd::Stage::Solve}) / k;
  state.counters["ns_per_row_sweep"] = 1e9 * spent({cd::Stage::Solve}) / solve_row_sweeps;
}

void bm_step(benchmark::State& state, int n, int threads) {
  run_steps(state, n, threads, fixed_sweeps(prepared(n).params(), kSweeps), true);
}

void bm_step_converged(benchmark::State& state, int n) {
  run_steps(state, n, 1, prepared(n).params(), false);
}

// An effect on or off: a parameter change from the default scene.
struct Effect {
  const char* name;
  void (*off)(cd::WorldParams&);
  void (*on)(cd::WorldParams&);
};

const Effect kEffects[] = {
    {"friction", [](cd::WorldParams& p) { p.mu = p.mu_wall = 0.0; },
     [](cd::WorldParams& p) { p.mu = p.mu_wall = 0.4; }},
    {"rotation", [](cd::WorldParams& p) { p.rotation = false; },
     [](cd::WorldParams& p) { p.rotation = true; }},
    // Restitution also sets the alert distance to 0 (World::configure): fewer
    // rows, so compare the cost a row-sweep, not only a step.
    {"restitution", [](cd::WorldParams& p) { p.e_n = 0.0; },
     [](cd::WorldParams& p) { p.e_n = 0.5; }},
    {"gravity", [](cd::WorldParams& p) { p.gravity = cd::Vec2::Zero(); },
     [](cd::WorldParams& p) { p.gravity = cd::Vec2(0.0, -9.81); }},
    // A vanishing pull-off force with a zero debonding distance: the same rows
    // and nearly the same solution, so the difference is the cost of the
    // cohesive sweep and of the adhesion bookkeeping alone.
    {"adhesion", [](cd::WorldParams& p) { p.adhesion = 0.0; },
     [](cd::WorldParams& p) {
       p.adhesion = 1e-12;
       p.debond = 0.0;
     }},
    // Width 0: set to the pile's box width + d by bm_effect.
    {"periodicity", [](cd::WorldParams& p) { p.cell = {}; },
     [](cd::WorldParams& p) {
       p.cell = {};
       p.cell.mode = cd::CellParams::Mode::Walls;
     }},
};
constexpr int kEffectN = 10000;

void bm_effect(benchmark::State& state, const Effect& e, bool on) {
  const cd::World& w = prepared(kEffectN);
  cd::WorldParams p = fixed_sweeps(w.params(), kSweeps);
  (on ? e.on : e.off)(p);
  if (p.cell.mode != cd::CellParams::Mode::None) {
    double xmax = 0;
    for (const cd::Vec2& x : w.bodies.pos) xmax = std::max(xmax, x.x());
    p.cell.width = xmax + p.d_ref;
  }
  run_steps(state, kEffectN, 1, p, true);
}

// ---------------------------------------------------------------- summary

// Console output, plus a copy of every run for the summary.
class Recorder : public benchmark::ConsoleReporter {
 public:
  struct Result {
    double ms = 0;  // wall time a run (iteration), ms
    std::map<std::string, double> counters;
  };
  std::map<std::string, Result> results;  // by function name
  std::vector<std::string> order;

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      // Plain runs, or the median when repetitions are asked for.
      if (r.error_occurred || r.report_big_o || r.report_rms) continue;
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      const std::string name = r.run_name.function_name;
      if (!results.count(name)) order.push_back(name);
      Result& out = results[name];
      out.ms = r.GetAdjustedRealTime();  // every benchmark reports in ms
      for (const auto& [k, c] : r.counters) out.counters[k] = c.value;
    }
  }
  const Result* get(const std::string& name) const {
    auto it = results.find(name);
    return it == results.end() ? nullptr : &it->second;
  }
};

struct Line {
  std::string metric;
  double value;
  std::string unit, what;
};

std::vector<Line> summarise(const Recorder& rec, const std::vector<int>& sizes) {
  std::vector<Line> out;
  auto ms = [&](const std::string& k) {
    const auto* r = rec.get(k);
    return r ? r->ms : double(NAN);
  };
  auto counter = [&](const std::string& k, const std::string& c) {
    const auto* r = rec.get(k);
    if (!r || !r->counters.count(c)) return double(NAN);
    return r->counters.at(c);
  };
  for (int n : {1000, 10000, 100000})
    out.push_back({"nlgs_updates_per_s_per_core/" + std::to_string(n),
                   counter("nlgs/" + std::to_string(n), "updates_per_s_per_core"), "1/s",
                   "contact updates a second, one thread"});
  for (int sides : kPolySides)
    for (int n : kPolySizes) {
      const std::string p = "nlgs_poly/" + std::to_string(sides) + "/" + std::to_string(n);
      const std::string d = "nlgs/" + std::to_string(n);
      const std::string shape = std::to_string(sides) + "-gons";
      out.push_back({"nlgs_poly_updates_per_s_per_core/" + std::to_string(sides) + "/" +
                         std::to_string(n),
                     counter(p, "updates_per_s_per_core"), "1/s",
                     "contact (row) updates a second, one thread, " + shape});
      out.push_back({"nlgs_poly_over_disk_ns_per_update/" + std::to_string(sides) + "/" +
                         std::to_string(n),
                     counter(p, "ns_per_update") / counter(d, "ns_per_update"), "",
                     "cost per contact (row) update, " + shape + " / disks, same N"});
      out.push_back({"nlgs_poly_over_disk_ns_per_contact/" + std::to_string(sides) + "/" +
                         std::to_string(n),
                     counter(p, "ns_per_contact_sweep") / counter(d, "ns_per_contact_sweep"), "",
                     "sweep cost per contact (body pair; side-side = 2 rows), " + shape +
                         " / disks, same N"});
    }
  for (int n : {10000, 100000})
    out.push_back({"nlgs_shuffled_over_sorted/" + std::to_string(n),
                   ms("nlgs_shuffled/" + std::to_string(n)) / ms("nlgs/" + std::to_string(n)), "",
                   "sweep time, bodies numbered at random / row by row"});
  // Least-squares slope of log(ms/step) against log(N).
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (int n : sizes) {
    const double t = ms("step/" + std::to_string(n));
    out.push_back({"step_ms/" + std::to_string(n), t, "ms",
                   std::to_string(kSweeps) + " sweeps a step, one thread"});
    out.push_back({"step_ns_per_row_sweep/" + std::to_string(n),
                   counter("step/" + std::to_string(n), "ns_per_row_sweep"), "ns",
                   "solve time / (rows x sweeps)"});
    if (!std::isfinite(t)) continue;
    const double x = std::log(n), y = std::log(t);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++m;
  }
  if (m >= 2)
    out.push_back({"step_ms_slope_vs_N", (m * sxy - sx * sy) / (m * sxx - sx * sx), "",
                   "d log(ms/step) / d log(N); 1 = linear"});
  out.push_back({"converged_step_ms/" + std::to_string(kBase),
                 ms("step_converged/" + std::to_string(kBase)), "ms", "default eps_f, one thread"});
  out.push_back({"converged_sweeps_per_step/" + std::to_string(kBase),
                 counter("step_converged/" + std::to_string(kBase), "sweeps"), "",
                 "default eps_f"});
  for (const char* kind : {"nlgs", "step"})
    for (int n : {10000, 100000}) {
      const std::string b = std::string("threads/") + kind + "/" + std::to_string(n) + "/";
      out.push_back({b + "speedup_2_vs_1", ms(b + "1") / ms(b + "2"), "",
                     "wall time 1 thread / 2 threads"});
    }
  for (const Effect& e : kEffects) {
    const std::string b = std::string("effect/") + e.name;
    out.push_back({b + "/step_off_over_on", ms(b + ":off") / ms(b + ":on"), "",
                   "ms/step off / on (" + std::to_string(kSweeps) + " sweeps)"});
    out.push_back({b + "/row_sweep_off_over_on",
                   counter(b + ":off", "ns_per_row_sweep") / counter(b + ":on", "ns_per_row_sweep"),
                   "", "solve ns per row-sweep off / on"});
  }
  return out;
}

void write_csvs(const std::string& dir, const Recorder& rec, const std::vector<Line>& summary,
                const std::vector<std::pair<std::string, std::string>>& mach) {
  std::filesystem::create_directories(dir);
  cdbench::write_machine_csv(dir + "/machine.csv", mach);
  const auto quote = cdbench::csv_quote;
  {
    std::ofstream f(dir + "/summary.csv");
    // The machine on every line: summaries of several machines concatenate.
    auto get = [&](const std::string& k) {
      for (const auto& [key, v] : mach)
        if (key == k) return v;
      return std::string();
    };
    f << "metric,value,unit,what,cpu_model,nproc,load_avg_start\n";
    for (const Line& l : summary)
      if (std::isfinite(l.value))
        f << l.metric << "," << l.value << "," << l.unit << "," << quote(l.what) << ","
          << quote(get("cpu_model")) << "," << get("nproc") << ","
          << quote(get("load_avg_start")) << "\n";
  }
  {
    const char* cols[] = {"n",         "threads",          "rows",
                          "colours",   "sweeps",           "cap_hits",
                          "detect_ms", "solve_ms",         "ns_per_row_sweep",
                          "updates_per_s_per_core",        "ns_per_update",
                          "contacts",  "ns_per_contact_sweep"};
    std::ofstream f(dir + "/runs.csv");
    f << "name,ms_per_run";
    for (const char* c : cols) f << "," << c;
    f << "\n";
    for (const std::string& name : rec.order) {
      const Recorder::Result& r = rec.results.at(name);
      f << name << "," << r.ms;
      for (const char* c : cols) {
        f << ",";
        if (r.counters.count(c)) f << r.counters.at(c);
      }
      f << "\n";
    }
  }
}

// Plots from this run's results into dir: plot_step.dat and plot_nlgs.dat,
// plots.gp, and with gnuplot (pngcairo) step_ms_vs_N.png and
// nlgs_updates_disk_vs_polygon.png. Plots without data are left out; a
// missing gnuplot only costs the PNGs.
void write_plots(const std::string& dir, const Recorder& rec, const std::vector<int>& sizes) {
  auto run = [&](const std::string& k) { return rec.get(k); };
  auto upd = [&](const std::string& k) {
    const auto* r = run(k);
    return r && r->counters.count("updates_per_s_per_core") ? r->counters.at("updates_per_s_per_core")
                                                             : double(NAN);
  };
  std::vector<std::pair<int, double>> step;
  for (int n : sizes)
    if (const auto* r = run("step/" + std::to_string(n)); r && std::isfinite(r->ms) && r->ms > 0)
      step.emplace_back(n, r->ms);
  {
    std::ofstream f(dir + "/plot_step.dat");
    f << "# N ms_per_step (step/N: " << kSweeps << " sweeps a step, one thread)\n";
    for (const auto& [n, t] : step) f << n << " " << t << "\n";
  }
  std::vector<int> ns;  // N with a disk or polygon nlgs result
  for (int n : {1000, 10000, 100000}) {
    bool any = std::isfinite(upd("nlgs/" + std::to_string(n)));
    for (int sides : kPolySides)
      any = any || std::isfinite(
                       upd("nlgs_poly/" + std::to_string(sides) + "/" + std::to_string(n)));
    if (any) ns.push_back(n);
  }
  {
    std::ofstream f(dir + "/plot_nlgs.dat");
    f << "# N disks";
    for (int sides : kPolySides) f << " " << sides << "-gons";
    f << "   (contact row updates a second, one thread; ? = not run)\n";
    auto put = [&](double v) {
      if (std::isfinite(v)) f << " " << v;
      else f << " ?";
    };
    for (int n : ns) {
      f << n;
      put(upd("nlgs/" + std::to_string(n)));
      for (int sides : kPolySides)
        put(upd("nlgs_poly/" + std::to_string(sides) + "/" + std::to_string(n)));
      f << "\n";
    }
  }
  std::ofstream g(dir + "/plots.gp");
  g << "# cdbench plots (gnuplot " << "plots.gp, run in this directory)\n"
    << "set terminal pngcairo size 800,560 enhanced font ',11'\n"
    << "set datafile missing '?'\nset grid\n";
  if (step.size() >= 1) {
    // Slope-1 guide through the smallest N measured.
    g << "set output 'step_ms_vs_N.png'\n"
      << "set title 'Time per step against N (" << kSweeps << " NLGS sweeps a step, 1 thread)'\n"
      << "set logscale xy\nset xlabel 'N (bodies)'\nset ylabel 'ms / step'\n"
      << "set key top left\n"
      << "guide(x) = " << step.front().second << " * x / " << step.front().first << ".0\n"
      << "plot 'plot_step.dat' using 1:2 with linespoints pt 7 lw 2 title 'step/N', \\\n"
      << "     guide(x) with lines dt 2 lc rgb 'gray40' title 'slope 1 (linear)'\n"
      << "unset logscale\nunset output\n";
  }
  if (!ns.empty()) {
    g << "set output 'nlgs_updates_disk_vs_polygon.png'\n"
      << "set title 'NLGS throughput: contact row updates per second per core (" << kSweeps
      << " sweeps, 1 thread)'\n"
      << "set style data histograms\nset style histogram clustered gap 1\n"
      << "set style fill solid 0.8 border -1\nset boxwidth 0.9\n"
      << "set xlabel 'N (bodies)'\nset ylabel 'updates / s / core'\nset yrange [0:*]\n"
      << "set key top right\n"
      << "plot 'plot_nlgs.dat'";
    // Only the shapes measured in this run (an empty column makes gnuplot warn).
    auto measured = [&](const std::string& prefix) {
      for (int n : ns)
        if (std::isfinite(upd(prefix + std::to_string(n)))) return true;
      return false;
    };
    bool first = true;
    auto column = [&](int col, const std::string& title) {
      g << (first ? "" : ", \\\n     ''") << " using " << col << ":xtic(1) title '" << title
        << "'";
      first = false;
    };
    if (measured("nlgs/")) column(2, "disks");
    int col = 3;
    for (int sides : kPolySides) {
      if (measured("nlgs_poly/" + std::to_string(sides) + "/"))
        column(col, std::to_string(sides) +
                        (sides == 4 ? "-gons (squares)" : sides == 6 ? "-gons (hexagons)" : "-gons"));
      ++col;
    }
    g << "\nunset output\n";
  }
  g.close();
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    std::cout << "cdbench: gnuplot not found: wrote " << dir
              << "/plots.gp and its data, no PNG (run gnuplot plots.gp there)\n";
    return;
  }
  const std::string cmd = "cd '" + dir + "' && gnuplot plots.gp";
  if (std::system(cmd.c_str()) != 0)
    std::cout << "cdbench: gnuplot failed on " << dir << "/plots.gp; continuing\n";
  else
    std::cout << "cdbench: wrote " << dir << "/plots.gp and its PNGs\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::string load_start = cdbench::load_average();
  benchmark::Initialize(&argc, argv);
  std::string csv_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--csv_dir=", 0) == 0) {
      csv_dir = a.substr(10);
    } else {
      std::cerr << "cdbench: unknown argument " << a << " (besides Google Benchmark's "
                << "--benchmark_* flags, only --csv_dir=DIR)\n";
      return 2;
    }
  }
  const auto mach = cdbench::machine(load_start);
  for (const auto& [k, v] : mach) benchmark::AddCustomContext(k, v);

  const std::vector<int> sizes = {1000, 3000, 10000, 30000, 100000};
  using benchmark::kMillisecond;
  for (int n : {1000, 10000, 100000})
    benchmark::RegisterBenchmark(("nlgs/" + std::to_string(n)).c_str(), bm_nlgs, n, 1, false)
        ->UseManualTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
  for (int n : {10000, 100000})
    benchmark::RegisterBenchmark(("nlgs_shuffled/" + std::to_string(n)).c_str(), bm_nlgs, n, 1,
                                 true)
        ->UseManualTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
  for (int sides : kPolySides)
    for (int n : kPolySizes)
      benchmark::RegisterBenchmark(
          ("nlgs_poly/" + std::to_string(sides) + "/" + std::to_string(n)).c_str(), bm_nlgs_poly,
          sides, n)
          ->UseManualTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
  for (int n : sizes)
    benchmark::RegisterBenchmark(("step/" + std::to_string(n)).c_str(), bm_step, n, 1)
        ->UseRealTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
  benchmark::RegisterBenchmark(("step_converged/" + std::to_string(kBase)).c_str(),
                               bm_step_converged, kBase)
      ->UseRealTime()->Unit(kMillisecond)->Iterations(20);
  for (int n : {10000, 100000})
    for (int t : {1, 2}) {
      const std::string s = "/" + std::to_string(n) + "/" + std::to_string(t);
      benchmark::RegisterBenchmark(("threads/nlgs" + s).c_str(), bm_nlgs, n, t, false)
          ->UseManualTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
      benchmark::RegisterBenchmark(("threads/step" + s).c_str(), bm_step, n, t)
          ->UseRealTime()->Unit(kMillisecond)->Iterations(runs_for(n, kSweeps));
    }
  for (const Effect& e : kEffects)
    for (bool on : {false, true})
      benchmark::RegisterBenchmark(
          (std::string("effect/") + e.name + (on ? ":on" : ":off")).c_str(), bm_effect, e, on)
          ->UseRealTime()->Unit(kMillisecond)->Iterations(runs_for(kEffectN, kSweeps));

  Recorder rec;
  benchmark::RunSpecifiedBenchmarks(&rec);
  if (rec.results.empty()) {  // --benchmark_list_tests, or a filter that matched nothing
    benchmark::Shutdown();
    return 0;
  }
  const std::vector<Line> summary = summarise(rec, sizes);
  std::cout << "\nSummary (ratios measured in this run; load average at start " << load_start
            << ")\n";
  for (const Line& l : summary)
    if (std::isfinite(l.value))
      std::cout << "  " << l.metric << " = " << l.value << (l.unit.empty() ? "" : " " + l.unit)
                << "   (" << l.what << ")\n";
  if (!csv_dir.empty()) {
    write_csvs(csv_dir, rec, summary, cdbench::machine(load_start));
    std::cout << "cdbench: wrote " << csv_dir << "/{runs,summary,machine}.csv\n";
    write_plots(csv_dir, rec, sizes);
  }
  benchmark::Shutdown();
  return 0;
}
