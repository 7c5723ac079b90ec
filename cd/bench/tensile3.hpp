// The 3D tensile test of a cohesive sphere block against the time step
// (the same dt study as 2D), shared by cd/bench/tensile
// (`--dim 3`, the study of `make tensile`) and tests/test_cohesion3.cpp
// (a quick version).
//
// Units: d = 1 (equal spheres), density 6/pi so that a sphere's mass is
// m = 1, f_a = 1: the time unit of cohesion t_a = sqrt(m d / f_a) = 1.
//
// Blocks, each between a bottom layer of driven spheres (fixed: the floor)
// and a top one (pulled up: the ceiling), in contact exactly (gap 0), every
// contact bonded (gap <= delta_a), driven spheres never in contact with each
// other (the 3D detector skips such pairs):
//   chain   one column of `layers` spheres, free laterally;
//   cubic   a simple-cubic block, periodic in x and y (k x k columns), each
//           column a chain;
//   fcc     an FCC block stacked along [001], periodic in x and y (cube edge
//           a = sqrt(2) d, layers a/2 apart, 2 k^2 spheres a layer): each
//           sphere bonded to 4 in the layer above at 45 degrees.
// Closed forms of the strength (the largest pull the floor feels before the
// crack opens) with rigid grains: the part above the crack leaves with the
// ceiling and the part below stays at rest, so the floor's pull is the force
// the crack carries, without inertia (2D's argument, cd/bench/tensile.cpp).
//   chain, cubic: every column is a chain of bonds in series, whose pull is
//     f_a: the block holds (columns) f_a; lateral contacts are along x or y
//     and do no work in the straight crack (any other crack would slide
//     columns past each other against friction).
//   fcc: the part above a (001) plane translating up opens its 4 bonds a
//     sphere at V/sqrt(2) and slides them at V/sqrt(2). An opening bond
//     carries r_n = -f_a and, its shifted cone mu (r_n + f_a) being then 0,
//     no friction: each pulls f_a cos 45 along z, so the crack carries
//     (spheres of a layer) x 4 f_a / sqrt(2) (upper bound of this mechanism).
//     The same forces on every inclined bond (r_n = -f_a, r_t = 0) and 0 on
//     the in-layer contacts balance every sphere of the periodic block, so
//     the load is also statically admissible (lower bound): the two agree.
//     (With mu tan 45 < 1; mu = 0.3 here.)
// The measured strength is exact up to the solver's velocity error,
// eps_f f_a dt / (m V) relative (docs/accuracy.md, "Cohesion and the time
// step"), as long as the opening speed times dt stays below 2 delta_a
// (beyond, the ceiling's bonds are not seen at the midpoint configuration
// and nothing holds).
//
// Test: the ceiling's speed is ramped from 0 to V over delta_a / (2 V), then
// held at V (2D's protocol); sigma_t is the peak of the floor's pull over
// the first delta_a of the ceiling's travel.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "world3.hpp"

namespace cdbench {

struct Pull3Options {
  double speed = 0.01;   // V, d / t_a
  double debond = 0.01;  // delta_a, d
  double mu = 0.3;
  double tol = 1e-4;
  int max_iter = 20000;
};

struct Block3 {
  std::string kind;
  std::vector<cd::Vec3> x;   // centres, layer by layer from the bottom
  std::vector<int> role;     // 0 dynamic, 1 floor (driven), 2 ceiling (driven)
  cd::Vec3 cell = cd::Vec3::Zero();
  bool periodic = false;     // in x and y
  double exact = 0;          // closed-form strength, f_a
  double opening = 1;        // opening speed of the crack's bonds / V
  int dynamic() const { return static_cast<int>(std::count(role.begin(), role.end(), 0)); }
};

// `layers` dynamic layers between the driven floor and ceiling layers.
inline Block3 chain3(int layers) {
  Block3 b;
  b.kind = "chain3";
  for (int l = 0; l < layers + 2; ++l) {
    b.x.emplace_back(0.0, 0.0, l + 0.5);
    b.role.push_back(l == 0 ? 1 : l == layers + 1 ? 2 : 0);
  }
  b.exact = 1;
  return b;
}

inline Block3 cubic3(int k, int layers) {
  Block3 b;
  b.kind = "cubic3";
  b.periodic = true;
  b.cell = cd::Vec3(k, k, layers + 2.0);
  for (int l = 0; l < layers + 2; ++l)
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        b.x.emplace_back(i + 0.5, j + 0.5, l + 0.5);
        b.role.push_back(l == 0 ? 1 : l == layers + 1 ? 2 : 0);
      }
  b.exact = k * k;
  return b;
}

inline Block3 fcc3(int k, int layers) {
  Block3 b;
  b.kind = "fcc3";
  b.periodic = true;
  const double a = std::numbers::sqrt2, h = 0.5 * a;
  b.cell = cd::Vec3(k * a, k * a, (layers + 2) * h + 1.0);
  for (int l = 0; l < layers + 2; ++l) {
    const double s = l % 2 ? 0.5 : 0.0;  // odd layers: shifted by a/2 along x
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i)
        for (const auto& [u, v] : {std::pair{0.0, 0.0}, std::pair{0.5, 0.5}}) {
          double xx = (i + u + s) * a, yy = (j + v) * a;
          xx -= b.cell.x() * std::floor(xx / b.cell.x());
          b.x.emplace_back(xx, yy, 0.5 + l * h);
          b.role.push_back(l == 0 ? 1 : l == layers + 1 ? 2 : 0);
        }
  }
  b.exact = 2.0 * k * k * 4.0 / std::numbers::sqrt2;  // spheres a layer x 4 f_a cos 45
  b.opening = 1 / std::numbers::sqrt2;
  return b;
}

struct Pull3 {
  double dt = 0;           // t_a
  int steps = 0;
  double sigma_t = 0;      // peak pull of the floor over the first delta_a of travel, f_a
  double ceiling_max = 0;  // peak pull of the ceiling (ramp inertia included), f_a
  int bonds0 = 0;          // bonded rows at the first step
  double sweeps = 0;       // mean a step
  int cap_hits = 0;
  double overlap_max = 0;  // d
  double wall = 0;         // s (filled by the caller if it times)
};

// Solver's velocity error relative to the pull speed: eps_f f_a dt / (m V).
inline double pull3_solver_error(double tol, double dt, double speed) { return tol * dt / speed; }

inline Pull3 pull3(const Block3& blk, double dt, const Pull3Options& o) {
  cd::WorldParams3 p;
  p.dt = dt;
  p.mu = p.mu_wall = o.mu;
  p.adhesion = 1.0;
  p.debond = o.debond;
  p.alert = o.debond;
  p.d_ref = 1.0;
  p.solver.tol = o.tol;
  p.solver.max_iter = o.max_iter;
  p.solver.min_parallel = 1 << 30;  // tens of rows: one thread
  if (blk.periodic) {
    p.cell = blk.cell;
    p.periodic = {true, true, false};
  }
  cd::World3 w(p);
  const double rho = 6.0 / std::numbers::pi;  // m = 1 for d = 1
  for (std::size_t i = 0; i < blk.x.size(); ++i) {
    const int b = w.bodies.add_sphere(blk.x[i], 0.5, rho);
    if (blk.role[i] != 0) w.bodies.drive(b);
  }
  const double V = o.speed;
  const double t_ramp = 0.5 * o.debond / V;
  const double t_end = std::max(t_ramp + 2 * o.debond / V, 20 * dt);
  Pull3 r;
  r.dt = dt;
  r.steps = static_cast<int>(std::ceil(t_end / dt - 1e-9));
  double travel = 0;
  for (int k = 0; k < r.steps; ++k) {
    const double v = V * std::min(1.0, (k + 0.5) * dt / t_ramp);  // the ramp at the step's midpoint
    for (std::size_t i = 0; i < blk.x.size(); ++i)
      if (blk.role[i] == 2) w.bodies.vel[i].v = cd::Vec3(0, 0, v);
    w.step();
    const cd::StepStats& st = w.last();
    r.sweeps += st.solve.iterations;
    r.cap_hits += st.solve.cap_hit;
    r.overlap_max = std::max(r.overlap_max, st.max_overlap);
    // The force on body 2 (dynamic) is to_world(r) / dt; body 1 is the
    // driven one. Floor pull: minus its z component (> 0 in tension);
    // ceiling pull: its z component.
    double floor = 0, ceil = 0;
    int bonds = 0;
    for (const cd::SphereRow& c : w.rows()) {
      bonds += c.adh > 0;
      const double fz = c.to_world(c.r).z() / dt;
      if (blk.role[c.b1] == 1) floor -= fz;
      else if (blk.role[c.b1] == 2) ceil += fz;
    }
    if (k == 0) r.bonds0 = bonds;
    r.ceiling_max = std::max(r.ceiling_max, ceil);
    if (travel < o.debond) r.sigma_t = std::max(r.sigma_t, floor);
    travel += v * dt;
  }
  r.sweeps /= r.steps;
  return r;
}

}  // namespace cdbench
