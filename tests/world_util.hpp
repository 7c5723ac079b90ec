// Small helpers shared by the physics tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "world.hpp"

namespace cdtest {

inline cd::WorldParams params(double dt, double g, double mu, double e_n = 0.0) {
  cd::WorldParams p;
  p.dt = dt;
  p.gravity = cd::Vec2(0.0, -g);
  p.mu = p.mu_wall = mu;
  p.e_n = e_n;
  p.d_ref = 1.0;
  p.alert = 0.1;
  p.solver.tol = 1e-10;
  p.solver.max_iter = 10000;
  return p;
}

// FNV-1a over the raw bytes of positions, angles and velocities.
inline std::uint64_t state_hash(const cd::World& w) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  };
  const cd::Bodies& b = w.bodies;
  for (std::size_t i = 0; i < b.size(); ++i) {
    mix(b.pos[i].data(), 2 * sizeof(double));
    mix(&b.angle[i], sizeof(double));
    mix(&b.vel[i], 3 * sizeof(double));
  }
  mix(&w.cell, sizeof(w.cell));
  return h;
}

inline bool all_finite(const cd::World& w) {
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    const auto& v = w.bodies.vel[i];
    if (!std::isfinite(w.bodies.pos[i].x()) || !std::isfinite(w.bodies.pos[i].y()) ||
        !std::isfinite(v.vx) || !std::isfinite(v.vy) || !std::isfinite(v.w))
      return false;
  }
  return true;
}

// A box of walls [0, W] x [0, H] with n disks of diameters in [d_min, d_max]
// on a loose jittered lattice (no overlap), for piles.
inline void fill_box(cd::World& w, int n, double W, double H, double dmin, double dmax,
                     unsigned seed, double density = 1.0) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double pitch = 1.02 * dmax;
  const int nx = static_cast<int>(W / pitch);
  for (int k = 0; k < n; ++k) {
    const double d = dmin + (dmax - dmin) * U(g);
    const double slack = 0.5 * (pitch - d);
    const double x = (k % nx + 0.5) * pitch + slack * (2 * U(g) - 1);
    const double y = (k / nx + 0.5) * pitch + slack * (2 * U(g) - 1);
    w.bodies.add_disk({x, y}, 0.5 * d, density);
  }
  w.bodies.add_wall({0, 0}, {W, 0});
  w.bodies.add_wall({0, H}, {0, 0});
  w.bodies.add_wall({W, 0}, {W, H});
}

// Solves a copy of the rows from the given body velocities with `sp` (tol
// 1e-8, 500 sweeps unless set): for tests that compare two sweep variants on
// the same problem.
struct SolvedCopy {
  std::vector<cd::ContactRow> rows;
  std::vector<cd::BodyVel> vel;
  int iterations;
};
inline SolvedCopy solve_copy(const std::vector<cd::ContactRow>& rows, const cd::Colouring& col,
                             const std::vector<cd::BodyVel>& vel, cd::SolverParams sp,
                             cd::LocalLaw law = cd::Coulomb{}, bool rotation = true) {
  cd::ContactProblem p{rows, col, vel, {}, law, rotation};
  const int it = cd::nlgs_solve(p, sp).iterations;
  return {std::move(p.rows), std::move(p.vel), it};
}
inline cd::SolverParams tight_solver() {
  cd::SolverParams sp;
  sp.tol = 1e-8;
  sp.max_iter = 500;
  return sp;
}

inline double total_mass(const cd::World& w) {
  double m = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) m += w.bodies.mass[i];
  return m;
}

// Runs `steps` steps and checks the hard-case invariants at every step: no
// NaN (a test failure), and records the largest overlap and the largest
// growth of the mechanical energy KE + PE (without driving and with e_n = 0
// the scheme may only dissipate), with iteration counts for the report.
struct Watch {
  double max_overlap = 0, max_energy_gain = 0, mean_iter = 0;
  int max_iter = 0, cap_hits = 0;
};
inline Watch run_watched(cd::World& w, int steps) {
  Watch r;
  const double e0 = w.kinetic_energy() + w.potential_energy();
  long it = 0;
  for (int k = 0; k < steps; ++k) {
    w.step();
    EXPECT_TRUE(all_finite(w)) << "NaN at step " << k;
    if (!all_finite(w)) break;
    r.max_overlap = std::max(r.max_overlap, w.last().max_overlap);
    r.max_energy_gain =
        std::max(r.max_energy_gain, w.kinetic_energy() + w.potential_energy() - e0);
    it += w.last().solve.iterations;
    r.max_iter = std::max(r.max_iter, w.last().solve.iterations);
    r.cap_hits += w.last().solve.cap_hit;
  }
  r.mean_iter = double(it) / steps;
  return r;
}

inline void report(const char* name, const Watch& r, double energy_scale = 1.0) {
  std::printf("[ hard case ] %s: iterations mean %.1f max %d, cap hits %d, max overlap %.2e d, "
              "max energy gain %.2e\n",
              name, r.mean_iter, r.max_iter, r.cap_hits, r.max_overlap,
              r.max_energy_gain / energy_scale);
}

}  // namespace cdtest
