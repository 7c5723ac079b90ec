// tensile: tensile strength of a cohesive aggregate against the time step
// (effective cohesion in CD is known to depend on dt; this measures by how
// much).
//
// Units: mean diameter d = 1, areal density 1, pull-off force f_a = 1, so
// the mass of a mean disk is m = pi/4 and the time unit of cohesion is
// t_a = sqrt(m d / f_a) = 0.886. Lengths are in d, times in t_a.
//
// Sample (per seed): N disks, diameters uniform in [2/3, 4/3] d, deposited
// geometrically in a box about as wide as deep (pile.hpp: every disk rests
// on two others or on the floor, contacts touch exactly). The box is then
// dropped: no side walls, no gravity. Each disk of the top face carries up
// to three short wall segments ("pads", tangent at 90, 45 and 135 degrees)
// that move up together (the ceiling); the bottom face likewise, fixed (the
// floor). Friction mu = 0.3 and the adhesion law (f_a, debonding distance
// delta_a = 0.01 d) on every contact, pads included. Rejected: a flat
// ceiling on a compacted sample (measured: a frictionless compaction leaves
// the resting ceiling touching no grain, and a deposit's free surface
// touches a flat wall at one or two, so the interface fails at ~1 f_a, not
// the bulk); gluing the face layers as driven disks, as cohesive DEM tests
// do (a contact between two driven bodies has a zero Delassus block, which
// the solver cannot take). With pads the crack runs through the bulk, at
// 0.2-0.4 of the height.
//
// Test: the ceiling's speed is ramped from 0 to V over delta_a / (2 V), then
// held at V = 0.01 d / t_a. Rigid grains do not stretch: the sample fails at
// the first step along the crack that costs least, the part above the crack
// leaves with the ceiling, the part below stays at rest. So the pull of the
// FLOOR (sum of floor-pad impulses / dt) is the force carried by the crack,
// with no inertia in it (the ceiling's pull adds M_up dV/dt during the
// ramp). sigma = floor pull / L, L the width of the sample; the tensile
// strength sigma_t is its peak over the first delta_a of ceiling travel (by
// then the crack's first bonds have broken; what follows is grains rolling
// and rebonding, since a pair within delta_a always bonds). Also recorded:
// the work of the ceiling over its first 2 delta_a of travel, per unit width,
// in f_a delta_a / d (one bond per d broken at f_a over delta_a gives 1).
//
// Closed forms, run first at every dt (the program fails if they do not
// hold below V dt = 2 delta_a): a vertical chain of 8 equal disks between a
// flat floor and ceiling holds exactly f_a, an 8 x 8 square lattice exactly
// f_a / d (every column a chain; the crack is straight, since any other would
// also have to slide columns past each other against friction).
//
// The first seed is also pulled at a tenth of the speed (the same V dt /
// delta_a at ten times the dt), and at other NLGS tolerances.
//
// Writes DIR/tensile.csv (one line a run), DIR/history.csv (sigma against
// the ceiling's travel, first seed), DIR/machine.csv, DIR/plots.gp and, with
// gnuplot, DIR/tensile.png.
//
// 3D (after the 2D study, or alone with --dim 3; the same dt study): sphere
// blocks with closed-form strengths (cd/bench/tensile3.hpp: a chain, f_a; a
// simple-cubic block of k x k columns, k^2 f_a; an FCC block stacked along
// [001], bonds at 45 degrees, (spheres a layer) 4 f_a / sqrt(2)) pulled
// at the same V, delta_a, mu and eps_f over the same time steps, in units
// d = 1, m = 1 (a sphere), f_a = 1, t_a = 1. Writes DIR/tensile3.csv,
// DIR/plots3.gp and, with gnuplot, DIR/tensile3.png; fails if a block is
// not within 2 eps_f f_a dt/(m V) + 1e-3 of its closed form while its
// bonds open by less than 1.9 delta_a a step.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "machine.hpp"
#include "pile.hpp"
#include "tensile3.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using cd::Vec2;

constexpr double kDensity = 1.0, kFa = 1.0, kD = 1.0;
const double kMass = std::numbers::pi / 4 * kD * kD * kDensity;
const double kTa = std::sqrt(kMass * kD / kFa);

struct Options {
  std::string out = "outputs/tensile";
  int n = 300;
  std::vector<unsigned> seeds = {1, 2, 3};
  // dt / t_a; the crossover V dt = 2 delta_a (see docs/accuracy.md) is at dt = 2 t_a.
  std::vector<double> dt = {3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 1.5, 2.5, 4.0};
  double speed = 0.01;    // V, d / t_a
  double debond = 0.01;   // delta_a, d
  double mu = 0.3;
  double tol = 1e-4;
  std::vector<double> tol_sweep = {1e-2, 1e-3, 1e-5};  // at dt_tol, first seed
  double dt_tol = 0.03;
  double slow_speed = 1e-3;  // d / t_a
  // (V dt / delta_a, eps_f) at slow_speed, first seed.
  std::vector<std::pair<double, double>> slow = {{0.1, 1e-4}, {1.0, 1e-4}, {2.5, 1e-4}, {1.0, 1e-5}};
  int max_iter = 20000;
  bool quick = false, plot = true;
  std::string dim = "both";  // 2, 3 or both (2D first, its output unchanged)
};

// ---------------------------------------------------------------- samples

// Disks and the segments that hold them: pads of the floor (fixed) and of
// the ceiling (pulled up), each a driven wall.
struct Pad {
  Vec2 a, b;
  bool top;
};
struct Sample {
  std::vector<Vec2> x;
  std::vector<double> r;
  std::vector<Pad> pads;
  double bottom = 0, top = 0, x_lo = 0, x_hi = 0;  // extent of the disks
  double width() const { return x_hi - x_lo; }
  double height() const { return top - bottom; }
  void extent() {
    x_lo = bottom = 1e300;
    x_hi = top = -1e300;
    for (std::size_t i = 0; i < x.size(); ++i) {
      x_lo = std::min(x_lo, x[i].x() - r[i]);
      x_hi = std::max(x_hi, x[i].x() + r[i]);
      bottom = std::min(bottom, x[i].y() - r[i]);
      top = std::max(top, x[i].y() + r[i]);
    }
  }
};

// Distance from disk j's surface to the segment [a, b].
double clearance(const Sample& s, int j, const Vec2& a, const Vec2& b) {
  const Vec2 e = b - a;
  const double u = std::clamp((s.x[j] - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (s.x[j] - (a + u * e)).norm() - s.r[j];
}

// Pads on the disks of one face (side = +1: top, -1: bottom): a disk of that
// face is one whose vertical ray away from the sample meets no other disk.
// It gets up to three pads, tangent at the angles 90, 45 and 135 degrees
// (top; mirrored for the bottom), of length 0.6 r, each kept only if every
// other disk stays clear of it by 3 delta_a (so that a pad bonds one disk).
void add_pads(Sample& s, int side, double debond) {
  const int n = static_cast<int>(s.x.size());
  for (int i = 0; i < n; ++i) {
    bool exposed = true;
    for (int j = 0; j < n && exposed; ++j)
      if (j != i && std::abs(s.x[j].x() - s.x[i].x()) < s.r[j] &&
          side * (s.x[j].y() - s.x[i].y()) > 0)
        exposed = false;
    if (!exposed) continue;
    for (double deg : {90.0, 45.0, 135.0}) {
      const double phi = side * deg * std::numbers::pi / 180;
      const Vec2 nrm(std::cos(phi), std::sin(phi)), tan(-nrm.y(), nrm.x());
      const Vec2 c = s.x[i] + s.r[i] * nrm, h = 0.3 * s.r[i] * tan;
      bool clear = true;
      for (int j = 0; j < n && clear; ++j)
        if (j != i && clearance(s, j, c - h, c + h) < 3 * debond) clear = false;
      if (clear) s.pads.push_back({c - h, c + h, side > 0});
    }
  }
}

// N disks, diameters uniform in [2/3, 4/3] d, deposited in a box about as
// wide as deep, with pads on both faces. Deterministic for a seed.
Sample deposited(int n, unsigned seed, double debond) {
  std::mt19937_64 g(seed);
  std::vector<double> d(n);
  for (double& x : d) x = kD * (2.0 / 3 + (2.0 / 3) * (static_cast<double>(g() >> 11) * 0x1.0p-53));
  double area = 0;
  for (double x : d) area += 0.25 * std::numbers::pi * x * x;
  const cdbench::Pile p = cdbench::deposit(d, std::sqrt(area / 0.72), seed);
  // Row by row numbering (pile.cpp: cache locality).
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const auto ka = std::floor(p.x[a].y() / 1.5), kb = std::floor(p.x[b].y() / 1.5);
    return ka != kb ? ka < kb : p.x[a].x() < p.x[b].x();
  });
  Sample s;
  for (int i : order) {
    s.x.push_back(p.x[i]);
    s.r.push_back(p.r[i]);
  }
  s.extent();
  add_pads(s, +1, debond);
  add_pads(s, -1, debond);
  return s;
}

// nx x ny square lattice of equal disks (nx = 1: a chain), touching exactly
// each other and a flat floor and ceiling.
Sample lattice(int nx, int ny) {
  Sample s;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      s.x.emplace_back((i + 0.5) * kD, (j + 0.5) * kD);
      s.r.push_back(0.5 * kD);
    }
  s.extent();
  s.pads.push_back({{-1, 0}, {nx + 1.0, 0}, false});
  s.pads.push_back({{nx + 1.0, ny * kD}, {-1, ny * kD}, true});
  return s;
}

// ---------------------------------------------------------------- the test

// Velocity error the solver leaves, relative to the pull speed: eps_f bounds
// the impulse error relative to the impulses, which are ~f_a dt a bond, and
// an impulse error dp moves a grain at dp / m.
double pi_solver(double tol, double dt_ta, double speed) {
  return tol * kFa * dt_ta * kTa / (kMass * speed * kD / kTa);
}

struct Run {
  std::string kind;
  unsigned seed = 0;
  int n = 0;
  double dt = 0, tol = 0;     // dt in t_a
  double speed = 0;           // V in d / t_a
  int steps = 0;
  double sigma_t = 0;         // peak of the floor's pull, f_a / d
  double sigma_max = 0;       // peak of the ceiling's pull (ramp inertia included), f_a / d
  double t_peak = 0;          // t_a
  double t_break = NAN;       // first time sigma falls below 1 % of sigma_t after the peak
  double work = 0;            // integral of T over the first 2 delta_a of travel / L, in f_a delta_a / d
  int bonds0 = 0;             // cohesive rows at the first step
  int ceil_bonds0 = 0, floor_bonds0 = 0;  // of which on the ceiling, on the floor
  double moved = 0;           // fraction of the disks that left with the ceiling
  double crack_y = NAN;       // height of the crack / sample height (0: floor, 1: ceiling)
  double sweeps = 0;          // mean a step
  int cap_hits = 0;
  double overlap_max = 0;     // d
  double residual_max = 0;
  double wall = 0;            // s
  std::vector<std::pair<double, double>> history;  // (travel / delta_a, sigma d / f_a)
};

Run pull(const Sample& s, const std::string& kind, unsigned seed, double dt_ta, double tol,
         double speed, const Options& o, bool keep_history) {
  cd::WorldParams prm;
  prm.dt = dt_ta * kTa;
  prm.mu = prm.mu_wall = o.mu;
  prm.adhesion = kFa;
  prm.debond = o.debond * kD;
  prm.alert = o.debond * kD;  // adhesion sets alert >= debond anyway
  prm.d_ref = kD;
  prm.solver.tol = tol;
  prm.solver.max_iter = o.max_iter;
  cd::World w(prm);
  const int n = static_cast<int>(s.x.size());
  for (int i = 0; i < n; ++i) w.bodies.add_disk(s.x[i], s.r[i], kDensity);
  std::vector<std::uint8_t> is_top(n, 0), is_pad(n, 0);  // by body index
  for (const Pad& q : s.pads) {
    w.bodies.add_wall(q.a, q.b);
    is_top.push_back(q.top);
    is_pad.push_back(1);
  }
  const int nb = static_cast<int>(w.bodies.size());

  const double V = speed * kD / kTa, dt = prm.dt;
  const double t_ramp = 0.5 * o.debond * kD / V;
  // Long enough for the crack to open 2 delta_a after the ramp (it breaks
  // at 1), and at least 20 steps.
  const double t_end = std::max(t_ramp + 2 * o.debond * kD / V, 20 * dt);
  const double L = s.width();

  Run r;
  r.kind = kind;
  r.seed = seed;
  r.n = n;
  r.dt = dt_ta;
  r.tol = tol;
  r.speed = speed;
  r.steps = static_cast<int>(std::ceil(t_end / dt - 1e-9));
  double travel = 0;  // of the ceiling
  for (int k = 0; k < r.steps; ++k) {
    // Wall speed over step k: the ramp's value at the step's midpoint.
    const double tm = (k + 0.5) * dt;
    const double v = V * std::min(1.0, tm / t_ramp);
    for (int i = n; i < nb; ++i)
      if (is_top[i]) w.bodies.vel[i].vy = v;
    const auto t0 = Clock::now();
    w.step();
    r.wall += std::chrono::duration<double>(Clock::now() - t0).count();
    const cd::StepStats& st = w.last();
    r.sweeps += st.solve.iterations;
    r.cap_hits += st.solve.cap_hit;
    r.overlap_max = std::max(r.overlap_max, st.max_overlap);
    r.residual_max = std::max(r.residual_max, st.solve.residual_max);
    double T = 0, Tf = 0;  // pull of the ceiling, of the floor (both > 0 in tension)
    int bonds = 0;
    for (std::size_t q = 0; q < w.rows().size(); ++q) {
      const cd::ContactRow& c = w.rows()[q];
      bonds += c.adh > 0;
      if (k == 0 && c.adh > 0) {
        r.ceil_bonds0 += is_top[c.b1];
        r.floor_bonds0 += is_pad[c.b1] && !is_top[c.b1];
      }
      if (is_top[c.b1]) T += (c.ny * c.pn + c.nx * c.pt) / dt;
      else if (is_pad[c.b1]) Tf -= (c.ny * c.pn + c.nx * c.pt) / dt;
    }
    if (k == 0) r.bonds0 = bonds;
    const double sigma = Tf / L * kD / kFa;
    // Work over the first 2 delta_a of travel (the last step clipped), so
    // that runs of any dt are compared over the same opening.
    r.work += T * std::clamp(2 * o.debond * kD - travel, 0.0, v * dt);
    travel += v * dt;
    r.sigma_max = std::max(r.sigma_max, T / L * kD / kFa);
    // The peak over the first delta_a of travel: by then the first crack's
    // bonds have broken, and what follows is grains rebonding as they roll.
    if (travel - v * dt < o.debond * kD && sigma > r.sigma_t) {
      r.sigma_t = sigma;
      r.t_peak = w.time / kTa;
    }
    if (r.sigma_t > 0 && std::isnan(r.t_break) && sigma < 0.01 * r.sigma_t)
      r.t_break = w.time / kTa;
    if (keep_history) r.history.emplace_back(travel / (o.debond * kD), sigma);
  }
  // The crack: disks that moved up by more than half the ceiling's travel
  // left with it; it lies between the lowest of those and the highest of the rest.
  {
    const double lift = travel;
    double lo_up = 1e300, hi_down = -1e300;
    int up = 0;
    for (int i = 0; i < n; ++i) {
      if (w.bodies.pos[i].y() - s.x[i].y() > 0.5 * lift) {
        ++up;
        lo_up = std::min(lo_up, s.x[i].y());
      } else {
        hi_down = std::max(hi_down, s.x[i].y());
      }
    }
    r.moved = double(up) / n;
    if (up > 0 && up < n) r.crack_y = (0.5 * (lo_up + hi_down) - s.bottom) / s.height();
  }
  r.sweeps /= r.steps;
  r.work /= L * kFa * o.debond;  // (f_a delta_a / d) with d = 1
  std::cerr << fmt::format(
      "  {:8} seed {} N {:4} dt {:7.1e} t_a (V dt / delta_a {:6.3f}) eps_f {:5.0e}: {:6} steps, "
      "{:7.1f} sweeps/step, {:7.2f} s; sigma_t {:.4f} f_a/d (max {:.4f}), G {:.3f}, "
      "overlap {:.1e} d, caps {}; bonds {} (ceiling {}, floor {}), moved {:.2f}, crack at "
      "{:.2f} H\n",
      kind, seed, n, dt_ta, speed * dt_ta / o.debond, tol, r.steps, r.sweeps, r.wall, r.sigma_t,
      r.sigma_max, r.work, r.overlap_max, r.cap_hits, r.bonds0, r.ceil_bonds0, r.floor_bonds0,
      r.moved, r.crack_y);
  return r;
}

// ---------------------------------------------------------------- output

// Columns of tensile.csv, 1-based, for gnuplot.
enum Col { kKind = 1, kSeed, kN, kDtTa, kDt, kSpeed, kPiBond, kPiSolver, kTol, kSteps, kSigma,
           kSigmaCeil, kTPeak, kTBreak, kWork, kBonds, kSweeps, kCaps, kOverlap, kResidual, kWall };

void write_csv(const std::string& path, const std::vector<Run>& rs, const Options& o) {
  std::ofstream f(path);
  f << "kind,seed,n,dt_over_ta,dt,speed_ta_over_d,v_dt_over_debond,solver_error_over_v,eps_f,"
       "steps,sigma_t_d_over_fa,sigma_ceiling_max_d_over_fa,t_peak_over_ta,t_break_over_ta,"
       "work_over_fa_debond,bonds0,sweeps_per_step,cap_hits,overlap_max_d,residual_max,wall_s\n";
  for (const Run& r : rs)
    f << fmt::format("{},{},{},{:g},{:.6g},{:g},{:.6g},{:.4g},{:g},{},{:.6g},{:.6g},{:.6g},{:.6g},"
                     "{:.6g},{},{:.4g},{},{:.4g},{:.4g},{:.4g}\n",
                     r.kind, r.seed, r.n, r.dt, r.dt * kTa, r.speed, r.speed * r.dt / o.debond,
                     pi_solver(r.tol, r.dt, r.speed), r.tol, r.steps, r.sigma_t, r.sigma_max,
                     r.t_peak, r.t_break, r.work, r.bonds0, r.sweeps, r.cap_hits, r.overlap_max,
                     r.residual_max, r.wall);
}

void write_history(const std::string& path, const std::vector<Run>& rs) {
  std::ofstream f(path);
  f << "dt_over_ta,travel_over_debond,sigma_d_over_fa\n";
  for (const Run& r : rs)
    for (const auto& [t, s] : r.history) f << fmt::format("{:g},{:.6g},{:.6g}\n", r.dt, t, s);
}

void write_gnuplot(const std::string& path, const Options& o) {
  const double dt_cross = 2 * o.debond / o.speed;  // V dt = 2 delta_a, in t_a
  std::ofstream g(path);
  auto sel = [](const char* kind, int c) {
    return fmt::format("(strcol({}) eq '{}' ? column({}) : NaN)", int(kKind), kind, c);
  };
  g << "# gnuplot script written by tensile; run from this folder: gnuplot plots.gp\n"
       "set datafile separator ','\n"
       "set terminal pngcairo size 1400,1000 font ',11'\n"
       "set output 'tensile.png'\n"
       "f = 'tensile.csv'\n"
       "set grid\nset logscale x\nset key bottom left\n"
    << fmt::format("set arrow 1 from {0:g}, graph 0 to {0:g}, graph 1 nohead dt 2\n", dt_cross)
    << fmt::format("set multiplot layout 2,2 title 'Cohesive aggregate pulled apart: N = {}, V = "
                   "{:g} d/t_a, delta_a = {:g} d, mu = {:g}, eps_f = {:g}; dashed: V dt = 2 "
                   "delta_a'\n",
                   o.n, o.speed, o.debond, o.mu, o.tol)
    << "set title 'Tensile strength (peak pull of the floor over the first delta_a)'\n"
       "set xlabel 'dt / t_a'\nset ylabel 'sigma_t d / f_a'\nset yrange [0:1.1]\n"
    << fmt::format("plot f using {}:{} with points pt 7 ps 1.3 title 'aggregate (seeds)', \\\n"
                   "     f using {}:{} with linespoints pt 5 title 'chain and 8 x 8 square "
                   "lattice (exact: 1)', \\\n"
                   "     f using {}:{} with points pt 9 ps 2 title 'aggregate, V / 10 "
                   "(eps_f 1e-4, 1e-5)'\n",
                   sel("aggregate", kDtTa), kSigma, sel("square", kDtTa), kSigma,
                   sel("slow", kDtTa), kSigma)
    << "set title 'Work of the ceiling over its first 2 delta_a of travel'\n"
       "set ylabel 'G / (f_a delta_a / d)'\nset logscale y\nset yrange [*:*]\n"
    << fmt::format("plot f using {}:{} with points pt 7 ps 1.3 title 'aggregate', \\\n"
                   "     f using {}:{} with linespoints pt 5 title 'square lattice'\n",
                   sel("aggregate", kDtTa), kWork, sel("square", kDtTa), kWork)
    << "set title 'Cost of a pull (aggregate, one thread)'\n"
       "set ylabel 'wall-clock s; sweeps / step'\nset key top right\n"
    << fmt::format("plot f using {}:{} with points pt 7 title 'wall-clock s', \\\n"
                   "     f using {}:{} with points pt 5 title 'sweeps / step'\n",
                   sel("aggregate", kDtTa), kWall, sel("aggregate", kDtTa), kSweeps)
    << "unset logscale\nunset arrow 1\nset yrange [0:*]\n"
       "set title 'Pull of the floor, first seed'\nset xlabel 'ceiling travel / delta_a'\n"
       "set ylabel 'sigma d / f_a'\nset key bottom left\n"
       "h = 'history.csv'\n";
  std::string plot = "plot ";
  for (std::size_t i = 0; i < o.dt.size(); ++i)
    plot += fmt::format("{}h using (column(1) == {:g} ? column(2) : NaN):3 with linespoints pt 7 "
                        "ps 0.5 title 'dt = {:g} t_a'",
                        i ? ", \\\n     " : "", o.dt[i], o.dt[i]);
  g << "set xrange [0:6]\n" << plot << "\nunset multiplot\n";
}

// ---------------------------------------------------------------- 3D

// The 3D blocks at every dt (tensile3.hpp); returns false if a closed form
// fails below the cliff.
bool study3(const Options& o) {
  cdbench::Pull3Options p;
  p.speed = o.speed;
  p.debond = o.debond;
  p.mu = o.mu;
  p.tol = o.tol;
  p.max_iter = o.max_iter;
  const std::vector<cdbench::Block3> blocks =
      o.quick ? std::vector<cdbench::Block3>{cdbench::chain3(8), cdbench::cubic3(3, 8), cdbench::fcc3(2, 8)}
              : std::vector<cdbench::Block3>{cdbench::chain3(8), cdbench::cubic3(3, 8), cdbench::fcc3(2, 8),
                                             cdbench::fcc3(3, 8)};
  bool ok = true;
  std::ofstream f(o.out + "/tensile3.csv");
  f << "kind,spheres,dynamic,exact_over_fa,dt_over_ta,v_open_dt_over_debond,solver_error_over_v,eps_f,steps,"
       "sigma_t_over_fa,relative_error,ceiling_max_over_fa,bonds0,sweeps_per_step,cap_hits,overlap_max_d,wall_s\n";
  std::cout << fmt::format("\n3D: sphere blocks (d = 1, m = 1, f_a = 1, t_a = 1), V = {:g} d/t_a, delta_a = {:g} d, "
                           "mu = {:g}, eps_f = {:g}\n",
                           o.speed, o.debond, o.mu, o.tol);
  std::cout << fmt::format("{:>7} {:>5} {:>8} {:>11} {:>6} {:>10} {:>10} {:>9} {:>8} {:>8} {:>8}\n", "kind",
                           "N", "dt/t_a", "V_n dt/d_a", "steps", "sigma_t", "exact", "rel err", "sweeps",
                           "wall s", "overlap");
  for (const cdbench::Block3& b : blocks)
    for (double dt : o.dt) {
      const auto t0 = Clock::now();
      cdbench::Pull3 r = cdbench::pull3(b, dt, p);
      r.wall = std::chrono::duration<double>(Clock::now() - t0).count();
      const double vn = o.speed * b.opening * dt / o.debond;  // the bonds' opening a step, in delta_a
      const double err = std::abs(r.sigma_t / b.exact - 1);
      const double allowed = 2 * cdbench::pull3_solver_error(o.tol, dt, o.speed) + 1e-3;
      if (vn < 1.9 && err > allowed) {
        ok = false;
        std::cerr << fmt::format("tensile: SANITY FAILED: {} at dt = {:g} t_a: sigma_t = {:.6f} f_a, exact {:.6f}, "
                                 "relative error {:.2g} > {:.2g}\n",
                                 b.kind, dt, r.sigma_t, b.exact, err, allowed);
      }
      f << fmt::format("{},{},{},{:.6g},{:g},{:.6g},{:.4g},{:g},{},{:.8g},{:.4g},{:.6g},{},{:.4g},{},{:.4g},{:.4g}\n",
                       b.kind, b.x.size(), b.dynamic(), b.exact, dt, vn,
                       cdbench::pull3_solver_error(o.tol, dt, o.speed), o.tol, r.steps, r.sigma_t, err,
                       r.ceiling_max, r.bonds0, r.sweeps, r.cap_hits, r.overlap_max, r.wall);
      std::cout << fmt::format("{:>7} {:>5} {:>8.1e} {:>11.3f} {:>6} {:>10.5f} {:>10.5f} {:>9.2e} {:>8.1f} {:>8.2f} "
                               "{:>8.1e}\n",
                               b.kind, b.x.size(), dt, vn, r.steps, r.sigma_t, b.exact, err, r.sweeps, r.wall,
                               r.overlap_max);
    }
  f.close();
  std::ofstream g(o.out + "/plots3.gp");
  g << "# gnuplot script written by tensile (3D); run from this folder: gnuplot plots3.gp\n"
       "set datafile separator ','\n"
       "set terminal pngcairo size 1400,600 font ',11'\n"
       "set output 'tensile3.png'\n"
       "set grid\nset logscale x\nset key bottom left\n"
    << fmt::format("set multiplot layout 1,2 title 'Cohesive sphere blocks pulled apart: V = {:g} d/t_a, delta_a = "
                   "{:g} d, mu = {:g}, eps_f = {:g}'\n",
                   o.speed, o.debond, o.mu, o.tol)
    << "set title 'Strength'\nset xlabel 'dt / t_a'\nset ylabel 'sigma_t / closed form'\nset yrange [0:1.1]\n"
       "f = 'tensile3.csv'\n"
       "plot f using 5:(strcol(1) eq 'chain3' ? column(10) / column(4) : NaN) with linespoints pt 5 title 'chain (f_a)', \\\n"
       "     f using 5:(strcol(1) eq 'cubic3' ? column(10) / column(4) : NaN) with linespoints pt 7 title 'simple cubic, 3 x 3 columns (9 f_a)', \\\n"
       "     f using 5:(strcol(1) eq 'fcc3' ? column(10) / column(4) : NaN) with points pt 9 ps 1.5 "
       "title 'FCC [001], bonds at 45 deg (8 or 18 spheres a layer)'\n"
       "set title 'Distance to the closed form (dashed: the solver bound 2 eps_f f_a dt / (m V))'\n"
       "set logscale y\nset yrange [1e-7:0.1]\nset ylabel '|sigma_t / closed form - 1|'\nset key top left\n"
       "nz(x) = x > 0 && x < 0.5 ? x : NaN\n"
       "plot f using 5:(strcol(1) eq 'chain3' ? nz(column(11)) : NaN) with linespoints pt 5 title 'chain', \\\n"
       "     f using 5:(strcol(1) eq 'cubic3' ? nz(column(11)) : NaN) with linespoints pt 7 title 'simple cubic', "
       "\\\n"
       "     f using 5:(strcol(1) eq 'fcc3' ? nz(column(11)) : NaN) with points pt 9 ps 1.5 title 'FCC', \\\n"
       "     f using 5:(2 * column(7)) with lines dt 2 lc black title 'bound'\n"
       "unset multiplot\n";
  g.close();
  if (o.plot) {
    const std::string cmd = "cd '" + o.out + "' && gnuplot plots3.gp";
    if (std::system(cmd.c_str()) != 0)
      std::cerr << "tensile: gnuplot failed or is missing; plots3.gp is in " << o.out << "\n";
  }
  std::cout << "tensile: wrote " << o.out << "/{tensile3.csv,plots3.gp" << (o.plot ? ",tensile3.png" : "") << "}\n";
  if (ok)
    std::cout << "tensile: 3D closed-form checks (chain f_a, cubic k^2 f_a, FCC 4 f_a/sqrt(2) a sphere) hold "
                 "while the bonds open by less than 2 delta_a a step\n";
  else
    std::cerr << "tensile: a 3D closed-form check failed\n";
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string load_start = cdbench::load_average();
  Options o;
  CLI::App app{"tensile: tensile strength of a cohesive disk aggregate against the time step"};
  app.add_option("--out", o.out, "output folder")->capture_default_str();
  app.add_option("--n", o.n, "disks in the aggregate")->capture_default_str();
  app.add_option("--seeds", o.seeds, "samples")->capture_default_str();
  app.add_option("--dt", o.dt, "time steps, in t_a = sqrt(m d / f_a)")->capture_default_str();
  app.add_option("--speed", o.speed, "pull speed V, in d / t_a")->capture_default_str();
  app.add_option("--debond", o.debond, "debonding distance, in d")->capture_default_str();
  app.add_option("--mu", o.mu, "friction coefficient (grains and walls)")->capture_default_str();
  app.add_option("--tol", o.tol, "NLGS tolerance eps_f")->capture_default_str();
  app.add_option("--tol-sweep", o.tol_sweep, "other tolerances, first seed at --dt-tol")
      ->capture_default_str();
  app.add_option("--dt-tol", o.dt_tol, "time step of the tolerance sweep, in t_a")
      ->capture_default_str();
  app.add_flag("--quick", o.quick, "about 20 s: N = 200, one seed, six time steps");
  app.add_flag("!--no-plot", o.plot, "write plots.gp but do not run gnuplot");
  app.add_option("--dim", o.dim, "2, 3 or both (2D first; 3D: the sphere blocks of tensile3.hpp)")
      ->check(CLI::IsMember({"2", "3", "both"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (o.quick) {
    o.n = 200;
    o.seeds = {1};
    o.dt = {1e-2, 0.1, 0.3, 1.0, 2.5, 4.0};
    o.tol_sweep = {1e-3};
    o.slow = {{0.1, 1e-4}, {1.0, 1e-4}};
  }
  omp_set_num_threads(1);  // a few hundred rows: below the solver's parallel threshold
  std::filesystem::create_directories(o.out);
  if (o.dim == "3") {
    const bool ok3 = study3(o);
    cdbench::write_machine_csv(o.out + "/machine.csv", cdbench::machine(load_start));
    return ok3 ? 0 : 1;
  }
  std::cerr << fmt::format("tensile: t_a = {:.4g}, V = {:g} d/t_a, delta_a = {:g} d: V dt = "
                           "delta_a at dt = {:g} t_a\n",
                           kTa, o.speed, o.debond, o.debond / o.speed);

  std::vector<Run> all;
  // Closed forms first, on the smallest and the largest time step below the
  // crossover: a chain holds f_a, a square lattice f_a / d.
  bool ok = true;
  for (double dt : o.dt) {
    for (const auto& [kind, nx] : {std::pair<std::string, int>{"chain", 1}, {"square", 8}}) {
      Run r = pull(lattice(nx, 8), kind, 0, dt, o.tol, o.speed, o, false);
      // Chain: T = f_a, sigma = f_a / d; lattice: sigma = f_a / d. Exact up
      // to the solver's velocity error eps_f f_a dt / (m V) (see docs/accuracy.md);
      // beyond V dt = 2 delta_a the ceiling's bonds are not seen, and
      // nothing holds.
      const double err = std::abs(r.sigma_t - 1.0);
      const double allowed = 2 * pi_solver(o.tol, dt, o.speed) + 1e-3;
      if (o.speed * dt < 1.9 * o.debond && err > allowed) {
        ok = false;
        std::cerr << fmt::format("tensile: SANITY FAILED: {} at dt = {:g} t_a: sigma d / f_a = "
                                 "{:.6f}, exact 1, allowed error {:.2g}\n",
                                 kind, dt, r.sigma_t, allowed);
      }
      all.push_back(std::move(r));
    }
  }
  for (unsigned seed : o.seeds) {
    const auto t0 = Clock::now();
    const Sample s = deposited(o.n, seed, o.debond * kD);
    std::cerr << fmt::format("tensile: sample {} ({} disks, {:.2f} x {:.2f} d, {} pads) in {:.1f} s\n",
                             seed, o.n, s.width(), s.height(), s.pads.size(),
                             std::chrono::duration<double>(Clock::now() - t0).count());
    const bool first = seed == o.seeds.front();
    for (double dt : o.dt)
      all.push_back(pull(s, "aggregate", seed, dt, o.tol, o.speed, o, first));
    if (first) {
      for (double tol : o.tol_sweep)
        all.push_back(pull(s, "tol", seed, o.dt_tol, tol, o.speed, o, false));
      // The same V dt / delta_a at a tenth of the speed (dt ten times larger):
      // does the strength follow V dt / delta_a or dt / t_a?
      for (const auto& [x, tol] : o.slow)
        all.push_back(pull(s, "slow", seed, x * o.debond / o.slow_speed, tol, o.slow_speed, o,
                           false));
    }
    write_csv(o.out + "/tensile.csv", all, o);
  }
  write_history(o.out + "/history.csv", all);
  cdbench::write_machine_csv(o.out + "/machine.csv", cdbench::machine(load_start));
  write_gnuplot(o.out + "/plots.gp", o);

  std::cout << fmt::format("{:>9} {:>4} {:>8} {:>9} {:>6} {:>7} {:>9} {:>9} {:>8} {:>8} {:>8}\n",
                           "kind", "seed", "dt/t_a", "V dt/d_a", "eps_f", "steps", "sigma_t",
                           "G", "sweeps", "wall s", "overlap");
  for (const Run& r : all)
    std::cout << fmt::format("{:>9} {:>4} {:>8.1e} {:>9.3f} {:>6.0e} {:>7} {:>9.4f} {:>9.3f} "
                             "{:>8.1f} {:>8.2f} {:>8.1e}\n",
                             r.kind, r.seed, r.dt, r.speed * r.dt / o.debond, r.tol, r.steps,
                             r.sigma_t, r.work, r.sweeps, r.wall, r.overlap_max);
  if (o.plot) {
    const std::string cmd = "cd '" + o.out + "' && gnuplot plots.gp";
    if (std::system(cmd.c_str()) != 0)
      std::cerr << "tensile: gnuplot failed or is missing; plots.gp is in " << o.out << "\n";
  }
  std::cout << "tensile: wrote " << o.out << "/{tensile.csv,history.csv,machine.csv,plots.gp"
            << (o.plot ? ",tensile.png" : "") << "}\n";
  if (!ok) {
    std::cerr << "tensile: a closed-form check failed\n";
  } else {
    std::cout << "tensile: closed-form checks (chain f_a, square lattice f_a / d) hold below "
                 "V dt = 2 delta_a\n";
  }
  const bool ok3 = o.dim == "both" ? study3(o) : true;
  return ok && ok3 ? 0 : 1;
}
