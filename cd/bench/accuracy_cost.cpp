// accuracy_cost: what accuracy costs in time.
//
// Scene: a settled pile of N disks in a box (pile.hpp: the default scene's
// disks, mu = 0.4, alert 0.1 d) loaded from rest: at t = 0 every velocity
// and every impulse is zero, so the solver must build the whole force
// network (the hard part of a solve), then hold it for a fixed physical
// time. The exact answer is known: the pile hardly moves (a few rattlers
// may creep) and the walls carry the whole weight. What moves, overlaps or
// is missing from the wall reaction is the error of the run, and a reference
// run at eps_f = 1e-7 gives positions to compare with. Rejected: a pile
// settling from a loose state, whose collapse is chaotic (two runs a
// tolerance apart end in different piles, so the error stops falling with
// eps_f); and the settled pile with its warm start, which every eps_f solves
// in one or two sweeps (measured: N = 100 at eps_f = 0.1 stayed within
// 4e-6 d of the reference), so it shows no cost and no error.
//
// Sweeps, every run from the same pile at rest, for every N:
//   tol  eps_f = 1e-1 ... 1e-6 at the default dt
//   dt   dt = dt0/4 ... 4 dt0 at the default eps_f
//   ref  eps_f = ref_tol at dt0, the reference of both
// Cost: wall time a step (one thread: the piles are below the solver's
// parallel threshold), sweeps a step. Accuracy: law residual (solver's
// measure, / mean |p|), overlap / d, floor reaction error |R_y/W - 1| (mean
// over steps), drift of the centre of mass / d (exact: 0), and the distance
// to the reference: centre-of-mass height and rms position, / d.
//
// Writes DIR/runs.csv, DIR/machine.csv, DIR/plots.gp and, if gnuplot is
// installed, DIR/cost_vs_tol.png, DIR/error_vs_cost.png, DIR/dt.png.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "machine.hpp"
#include "pile.hpp"
#include "setup.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string out = "outputs/accuracy-cost";
  // ~2 min on a quiet machine, the eps_f = 1e-7 reference of N = 1000
  // (~8e3 sweeps a step) taking 1; N = 2000 would add ~10 min.
  std::vector<int> n = {100, 300, 1000};
  std::vector<double> tol = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
  std::vector<double> dt_factor = {0.25, 0.5, 1.0, 2.0, 4.0};
  double ref_tol = 1e-7;
  double time = 0.01;    // physical time of a run (s)
  int max_iter = 100000; // high, so that eps_f stops the solver; hits are counted
  int threads = 1;
  bool quick = false;
  bool plot = true;
};

struct Result {
  std::string sweep;
  int n = 0;
  double tol = 0, dt = 0;
  int steps = 0;
  double rows = 0, wall = 0, sweeps = 0;
  int max_sweeps = 0, cap_hits = 0;
  double residual_max = 0, overlap_max = 0, overlap_growth = 0, reaction_err = 0, drift = 0;
  double h_err = NAN, pos_rms = NAN, pos_max = NAN;
  std::vector<cd::Vec2> pos;  // final disk positions
  double h_cm = 0;
};

double centre_height(const cd::World& w) {
  double m = 0, my = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) {
      m += w.bodies.mass[i];
      my += w.bodies.mass[i] * w.bodies.pos[i].y();
    }
  return my / m;
}

// The settled pile for N, as a fresh world: at rest, no warm start, so that
// every run builds the force network from zero, the hard part of the solve.
cd::World start(int n) {
  static std::map<int, cd::World> piles;
  if (!piles.count(n)) {
    const auto t0 = Clock::now();
    cd::World w = cdbench::pile_world(cdbench::pile_scene(n));
    cdbench::settle(w);
    piles.emplace(n, w);
    std::cerr << fmt::format("accuracy_cost: settled N = {} in {:.1f} s\n", n,
                             std::chrono::duration<double>(Clock::now() - t0).count());
  }
  const cd::World& settled = piles.at(n);
  cd::World w(settled.params());
  w.bodies = settled.bodies;
  for (cd::BodyVel& v : w.bodies.vel)
    if (v.inv_m > 0) v.vx = v.vy = v.w = 0.0;
  return w;
}

Result run(const std::string& sweep, int n, double tol, double dt, const Options& o) {
  cd::World w = start(n);
  cd::WorldParams p = w.params();
  p.dt = dt;
  p.solver.tol = tol;
  p.solver.max_iter = o.max_iter;
  w.set_params(p);
  const double d = p.d_ref, weight = cdbench::total_weight(w), h0 = centre_height(w);
  Result r;
  r.sweep = sweep;
  r.n = n;
  r.tol = tol;
  r.dt = dt;
  r.steps = static_cast<int>(std::lround(o.time / dt));
  for (int k = 0; k < r.steps; ++k) {
    const auto t0 = Clock::now();
    w.step();
    r.wall += std::chrono::duration<double>(Clock::now() - t0).count();
    const cd::StepStats& s = w.last();
    r.rows += s.contacts;
    r.sweeps += s.solve.iterations;
    r.max_sweeps = std::max(r.max_sweeps, s.solve.iterations);
    r.cap_hits += s.solve.iterations >= o.max_iter;
    r.residual_max = std::max(r.residual_max, s.solve.residual_max);
    if (k == 0) r.overlap_growth = -s.max_overlap;  // the pile's own, from its preparation
    r.overlap_max = std::max(r.overlap_max, s.max_overlap);
    r.reaction_err += std::abs(cdbench::wall_force_y(w) / weight - 1.0);
  }
  r.overlap_growth += r.overlap_max;
  r.rows /= r.steps;
  r.sweeps /= r.steps;
  r.reaction_err /= r.steps;
  r.h_cm = centre_height(w);
  r.drift = (r.h_cm - h0) / d;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) r.pos.push_back(w.bodies.pos[i]);
  std::cerr << fmt::format(
      "  {:4} N {:5} eps_f {:7.0e} dt {:7.1e}: {:8.2f} ms/step {:8.1f} sweeps/step, "
      "residual {:8.2e}, overlap {:8.2e} d, reaction err {:8.2e}, drift {:9.2e} d\n",
      sweep, n, tol, dt, 1e3 * r.wall / r.steps, r.sweeps, r.residual_max, r.overlap_max,
      r.reaction_err, r.drift);
  return r;
}

void compare(Result& r, const Result& ref, double d) {
  r.h_err = std::abs(r.h_cm - ref.h_cm) / d;
  double s2 = 0, mx = 0;
  for (std::size_t i = 0; i < r.pos.size(); ++i) {
    const double e = (r.pos[i] - ref.pos[i]).norm() / d;
    s2 += e * e;
    mx = std::max(mx, e);
  }
  r.pos_rms = std::sqrt(s2 / r.pos.size());
  r.pos_max = mx;
}

void write_csv(const std::string& path, const std::vector<Result>& rs) {
  std::ofstream f(path);
  f << "sweep,n,tol,dt,steps,rows,ms_per_step,sweeps_per_step,max_sweeps,cap_hits,"
       "residual_max,overlap_max_d,overlap_growth_d,reaction_err,drift_d,h_err_d,pos_rms_d,"
       "pos_max_d,wall_s\n";
  for (const Result& r : rs)
    f << fmt::format("{},{},{:g},{:g},{},{:.1f},{:.6g},{:.6g},{},{},{:.4g},{:.4g},{:.4g},{:.4g},"
                     "{:.4g},{:.4g},{:.4g},{:.4g},{:.4g}\n",
                     r.sweep, r.n, r.tol, r.dt, r.steps, r.rows, 1e3 * r.wall / r.steps, r.sweeps,
                     r.max_sweeps, r.cap_hits, r.residual_max, r.overlap_max, r.overlap_growth,
                     r.reaction_err, r.drift, r.h_err, r.pos_rms, r.pos_max, r.wall);
}

// Columns of runs.csv, 1-based, for gnuplot.
enum Col { kSweep = 1, kN, kTol, kDt, kSteps, kRows, kMs, kSweeps, kMaxSweeps, kCaps, kResidual,
           kOverlap, kOverlapGrowth, kReaction, kDrift, kHerr, kPosRms };

void write_gnuplot(const std::string& path, const Options& o, double dt0) {
  std::ofstream g(path);
  g << "# gnuplot script written by accuracy_cost; run from this folder: gnuplot plots.gp\n"
       "set datafile separator ','\n"
       "set terminal pngcairo size 1400,1000 font ',11'\n"
       "set logscale xy\nset grid\nset format y '%.0e'\nset format x '%.0e'\n"
       "f = 'runs.csv'\n"
       // Rows of one sweep and one N only; errors of 0 drawn at the floor of the log axis.
       "sel(s, n, c) = (strcol(1) eq s && column(2) == n) ? column(c) : NaN\n"
       "abs0(x) = x == 0 ? 1e-17 : abs(x)\n";
  // One curve per N: x is column xc, y an expression in which each "@c)" reads
  // column c of the rows of that sweep and N.
  auto curves = [&](const std::string& sweep, int xc, const std::string& y) {
    std::string s;
    for (std::size_t i = 0; i < o.n.size(); ++i) {
      std::string yi = y;
      for (auto p = yi.find('@'); p != std::string::npos; p = yi.find('@'))
        yi.replace(p, 1, fmt::format("sel('{}', {}, ", sweep, o.n[i]));
      s += fmt::format("{}f using (sel('{}', {}, {})):({}) with linespoints lw 2 pt {} "
                       "title 'N = {}'",
                       i ? ", \\\n     " : "", sweep, o.n[i], xc, yi,
                       5 + 2 * static_cast<int>(i), o.n[i]);
    }
    return s + "\n";
  };
  auto col = [](int c) { return fmt::format("@{})", c); };
  auto abscol = [](int c) { return fmt::format("abs0(@{}))", c); };
  auto panel = [&](const std::string& title, const std::string& xl, const std::string& yl,
                   const std::string& plot) {
    g << fmt::format("set title '{}'\nset xlabel '{}'\nset ylabel '{}'\nplot {}", title, xl, yl,
                     plot);
  };
  const std::string run = fmt::format("{:g} s from rest, one thread", o.time);

  g << "set output 'cost_vs_tol.png'\nset key top right\n"
    << fmt::format("set multiplot layout 1,2 title 'Cost of the NLGS tolerance "
                   "(dt = {:g} s, {})'\n",
                   dt0, run);
  panel("NLGS sweeps a step", "eps_f", "sweeps / step", curves("tol", kTol, col(kSweeps)));
  panel("Wall time a step", "eps_f", "ms / step", curves("tol", kTol, col(kMs)));
  g << "unset multiplot\n";

  g << "set output 'error_vs_cost.png'\nset key bottom left\n"
    << fmt::format("set multiplot layout 2,2 title 'Error against cost: eps_f = {:g} (left point) "
                   "to {:g} (right), dt = {:g} s, {}'\n",
                   o.tol.front(), o.tol.back(), dt0, run);
  panel(fmt::format("Distance to the eps_f = {:g} run: rms position", o.ref_tol), "ms / step",
        "rms |x - x_{ref}| / d", curves("tol", kMs, abscol(kPosRms)));
  panel("Drift of the centre of mass (exact: 0)", "ms / step", "|drift| / d",
        curves("tol", kMs, abscol(kDrift)));
  panel("Wall reaction against the weight (exact: 1)", "ms / step", "mean |R_y / W - 1|",
        curves("tol", kMs, abscol(kReaction)));
  panel("Growth of the largest overlap", "ms / step", "overlap growth / d",
        curves("tol", kMs, abscol(kOverlapGrowth)));
  g << "unset multiplot\n";

  g << "set output 'dt.png'\nset key top left\n"
    << fmt::format("set multiplot layout 2,2 title 'Time step (default {:g} s, dashed), eps_f = "
                   "{:g}, {}'\n",
                   dt0, cd::Scene{}.tol, run)
    << fmt::format("set arrow 1 from {0:g}, graph 0 to {0:g}, graph 1 nohead dt 2\n", dt0);
  panel("Cost of simulated time", "dt (s)", "wall ms / simulated ms",
        curves("dt", kDt, fmt::format("@{}) / (1e3 * column({}))", kMs, kDt)));
  panel("NLGS sweeps a step", "dt (s)", "sweeps / step", curves("dt", kDt, col(kSweeps)));
  panel("Drift of the centre of mass (exact: 0)", "dt (s)", "|drift| / d",
        curves("dt", kDt, abscol(kDrift)));
  panel("Wall reaction against the weight (exact: 1)", "dt (s)", "mean |R_y / W - 1|",
        curves("dt", kDt, abscol(kReaction)));
  g << "unset multiplot\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::string load_start = cdbench::load_average();
  Options o;
  CLI::App app{"accuracy_cost: NLGS tolerance, time step and size against cost and error"};
  app.add_option("--out", o.out, "output folder")->capture_default_str();
  app.add_option("--n", o.n, "pile sizes")->capture_default_str();
  app.add_option("--tol", o.tol, "tolerances eps_f of the tol sweep")->capture_default_str();
  app.add_option("--dt-factor", o.dt_factor, "time steps of the dt sweep, in units of the default")
      ->capture_default_str();
  app.add_option("--ref-tol", o.ref_tol, "tolerance of the reference run")->capture_default_str();
  app.add_option("--time", o.time, "physical time of a run (s)")->capture_default_str();
  app.add_option("--max-iter", o.max_iter, "NLGS cap (hits are counted)")->capture_default_str();
  app.add_option("--threads", o.threads, "OpenMP threads")->capture_default_str();
  app.add_flag("--quick", o.quick, "about a minute: N = 100 and 300 only");
  app.add_flag("!--no-plot", o.plot, "write plots.gp but do not run gnuplot");
  CLI11_PARSE(app, argc, argv);
  if (o.quick) o.n = {100, 300};
  omp_set_num_threads(o.threads);
  std::filesystem::create_directories(o.out);

  const double dt0 = cdbench::pile_scene(1).dt;
  const double d = cd::world_params(cdbench::pile_scene(1)).d_ref;
  std::vector<Result> all;
  for (int n : o.n) {
    Result ref = run("ref", n, o.ref_tol, dt0, o);
    std::vector<Result> rs;
    for (double tol : o.tol) rs.push_back(run("tol", n, tol, dt0, o));
    for (double f : o.dt_factor) rs.push_back(run("dt", n, cd::Scene{}.tol, f * dt0, o));
    compare(ref, ref, d);
    all.push_back(ref);
    for (Result& r : rs) {
      compare(r, ref, d);
      all.push_back(std::move(r));
    }
    write_csv(o.out + "/runs.csv", all);  // after every N: a partial run still leaves data
  }
  cdbench::write_machine_csv(o.out + "/machine.csv", cdbench::machine(load_start));
  write_gnuplot(o.out + "/plots.gp", o, dt0);

  std::cout << fmt::format("{:>4} {:>6} {:>7} {:>8} {:>9} {:>9} {:>6} {:>9} {:>9} {:>9} {:>9} "
                           "{:>9}\n",
                           "run", "N", "eps_f", "dt", "ms/step", "sweeps", "caps", "residual",
                           "overlap", "R_y err", "drift", "pos err");
  for (const Result& r : all)
    std::cout << fmt::format("{:>4} {:>6} {:>7.0e} {:>8.1e} {:>9.3f} {:>9.1f} {:>6} {:>9.2e} "
                             "{:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e}\n",
                             r.sweep, r.n, r.tol, r.dt, 1e3 * r.wall / r.steps, r.sweeps,
                             r.cap_hits, r.residual_max, r.overlap_max, r.reaction_err, r.drift,
                             r.pos_rms);
  if (o.plot) {
    const std::string cmd = "cd '" + o.out + "' && gnuplot plots.gp";
    if (std::system(cmd.c_str()) != 0)
      std::cerr << "accuracy_cost: gnuplot failed or is missing; plots.gp is in " << o.out << "\n";
  }
  std::cout << "accuracy_cost: wrote " << o.out << "/{runs.csv,machine.csv,plots.gp"
            << (o.plot ? ",*.png" : "") << "}\n";
  return 0;
}
