// Small helpers shared by the physics tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

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

// Energy of one step of the midpoint scheme (method.md section 6), from the
// step's rows, for scenes without periodic images or restitution.
//
// With v+ = v- + dt g + M^-1 H p and x+ = x- + dt (v- + v+)/2, gravity's
// work is exactly -(PE+ - PE-), and
//     E(k+1) - E(k) = 1/2 sum_c p_c.(u+_c + u-_c)                       (1)
// exactly (E = KE + PE), u-/u+ the relative velocities of row c (its
// midpoint frame) from the velocities at the start/end of the step. Split:
//   scheme   S = 1/2 sum p.u-: the scheme's own term, not signed. A contact
//            separating at the step's start (u_n- > 0) that the step closes
//            (p_n > 0) gives some energy back: a ball lifting off the floor
//            at u < (2/3) g dt gains m u (g dt - 3u/2)/4 <= m (g dt)^2/24.
//   adhesion A = -1/2 sum a u_n+ (a = f_a dt): the pull-off force's work, the
//            change of its potential f_a min(gap, debond) (cohesion stores
//            energy in the bonds: a pair drawn together gains f_a per unit of
//            approach).
//   law      D = 1/2 sum (p_n + a) u_n+ + p_t.u_t+: <= 0 when the law holds.
//            The shifted Signorini law gives (p_n + a)(u_n + b_n) = 0 with
//            the gap term b_n = gap/dt >= 0 (no overlap correction), so
//            (p_n + a) u_n = -(p_n + a) b_n <= 0; Coulomb gives p_t.u_t <= 0.
// A converged e = 0 step therefore has E(k+1) <= E(k) + S + A. The solver
// stops with each row exact against the velocities it saw at its last
// update; the rows updated after it in the last sweep have since moved its
// velocity by du_k = sum_l W_kl dp_l, so
//     D <= 1/2 sum_k |p_k| sum_{l ~ k} |W_kl| |dp_l|
//       <= 1/2 w_max z_max ||dp||_2 ||p||_2 = eps,
// l ~ k: the rows sharing a dynamic body with row k (at most z_max), |W_kl|
// <= w_max the largest block norm (Cauchy-Schwarz on the PSD W), the sum
// over k bounded by Young's inequality, and ||dp||_2 = sqrt(N) dp_rel
// p_mean: the last sweep's rms change, below tol unless the step hit the
// cap (the solver reports dp_rel and p_mean). So with tol on the rms |dp|
// the energy a not fully converged solve can inject is of order w_max z tol
// N p_mean^2: tol times the kinetic energy scale of the impulses.
struct StepEnergy {
  double gain = 0;     // E(k+1) - E(k)
  double scheme = 0;   // S
  double adhesion = 0; // A
  double law = 0;      // D
  double eps = 0;      // the solver's bound on D
  double scale = 0;    // sum |p.u| + |E|: round-off scale of (1)
};

// The rows' relative velocity (n and t parts) from the velocities vel.
inline void row_velocity(const cd::ContactRow& r, const std::vector<cd::BodyVel>& vel, double& un,
                         double& ut) {
  const cd::BodyVel& A = vel[r.b1];
  const cd::BodyVel& B = vel[r.b2];
  const double dx = B.vx - A.vx, dy = B.vy - A.vy;
  un = r.nx * dx + r.ny * dy - B.w * r.c2t + A.w * r.c1t;
  ut = -r.ny * dx + r.nx * dy + B.w * r.c2n - A.w * r.c1n;
}

// One row's share of the step's energy: S, A, D as above, the round-off
// scale |p.(u+ + u-)|, |p|^2 and its block's norm.
struct RowEnergy {
  double scheme, adhesion, law, scale, p2, w;
};

// Steps w (2D World or World3) and returns the step's energy, with
// terms(row, velocities before, after) -> RowEnergy for the world's rows.
template <class W, class Terms>
StepEnergy step_energy_with(W& w, Terms terms) {
  const auto v0 = w.bodies.vel;
  const double e0 = w.kinetic_energy() + w.potential_energy();
  w.step();
  StepEnergy s;
  const double e1 = w.kinetic_energy() + w.potential_energy();
  s.gain = e1 - e0;
  s.scale = std::abs(e0) + std::abs(e1);
  const auto& rows = w.rows();
  std::vector<int> per_body(w.bodies.size(), 0);
  for (const auto& r : rows) {
    if (w.bodies.is_dynamic(r.b1)) ++per_body[r.b1];
    if (w.bodies.is_dynamic(r.b2)) ++per_body[r.b2];
  }
  double p2 = 0, wmax = 0;
  int zmax = 0;
  for (const auto& r : rows) {
    const RowEnergy q = terms(r, v0, w.bodies.vel);
    s.scheme += q.scheme;
    s.adhesion += q.adhesion;
    s.law += q.law;
    s.scale += q.scale;
    p2 += q.p2;
    wmax = std::max(wmax, q.w);
    zmax = std::max(zmax, (w.bodies.is_dynamic(r.b1) ? per_body[r.b1] - 1 : 0) +
                              (w.bodies.is_dynamic(r.b2) ? per_body[r.b2] - 1 : 0));
  }
  const cd::SolveStats& st = w.last().solve;
  const double dp2 = std::sqrt(double(rows.size())) * st.dp_rel * st.p_mean;
  s.eps = 0.5 * wmax * zmax * dp2 * std::sqrt(p2);
  return s;
}

inline StepEnergy step_energy(cd::World& w) {
  return step_energy_with(w, [](const cd::ContactRow& r, const std::vector<cd::BodyVel>& v0,
                                const std::vector<cd::BodyVel>& v1) {
    double um, tm, up, tp;
    row_velocity(r, v0, um, tm);
    row_velocity(r, v1, up, tp);
    return RowEnergy{0.5 * (r.pn * um + r.pt * tm), -0.5 * r.adh * up,
                     0.5 * ((r.pn + r.adh) * up + r.pt * tp),
                     std::abs(r.pn * (um + up)) + std::abs(r.pt * (tm + tp)), r.pn * r.pn + r.pt * r.pt,
                     0.5 * (r.wnn + r.wtt) + std::hypot(0.5 * (r.wnn - r.wtt), r.wnt)};
  });
}

// Checks one step's energy: the balance (1) to round-off (1e-12 of the
// energies and contact powers involved: nothing but the contacts changes
// E), and D <= eps + round-off, i.e. E(k+1) <= E(k) + S + A + eps at every
// step. `where` names the step in a failure.
inline void expect_step_energy(const StepEnergy& s, int step, const char* where = "") {
  const double round = 1e-12 * s.scale;
  EXPECT_NEAR(s.gain, s.scheme + s.adhesion + s.law, round) << where << " step " << step;
  EXPECT_LE(s.law, s.eps + round) << where << " step " << step << ": E gained " << s.gain
                                  << " of which the law " << s.law << " > solver bound " << s.eps;
}

// Runs `steps` steps and checks the hard-case invariants at every step: no
// NaN (a test failure) and each step's energy (expect_step_energy: the
// step's change of E = KE + PE is the contacts' work, and the law part of it
// is below the solver's bound: E(k+1) <= E(k) + S + A + eps, against the
// step before, not the start: an injection smaller than what was dissipated
// earlier still fails). Records the largest overlap, the largest gain of E
// since the start (max_energy_gain; a global bound for the callers) and
// the largest one step (max_step_gain), the largest law term D and its
// ratio to eps where D exceeds round-off, and iteration counts.
struct Watch {
  double max_overlap = 0, max_energy_gain = 0, max_step_gain = 0, max_law = 0, max_law_over_eps = 0,
         max_scheme = 0, mean_iter = 0;
  int max_iter = 0, cap_hits = 0;
  void merge(const Watch& c, int chunks) {
    max_overlap = std::max(max_overlap, c.max_overlap);
    max_energy_gain = std::max(max_energy_gain, c.max_energy_gain);
    max_step_gain = std::max(max_step_gain, c.max_step_gain);
    max_law = std::max(max_law, c.max_law);
    max_law_over_eps = std::max(max_law_over_eps, c.max_law_over_eps);
    max_scheme = std::max(max_scheme, c.max_scheme);
    mean_iter += c.mean_iter / chunks;
    max_iter = std::max(max_iter, c.max_iter);
    cap_hits += c.cap_hits;
  }
};
inline Watch run_watched(cd::World& w, int steps) {
  Watch r;
  const double e0 = w.kinetic_energy() + w.potential_energy();
  long it = 0;
  for (int k = 0; k < steps; ++k) {
    const StepEnergy e = step_energy(w);
    EXPECT_TRUE(all_finite(w)) << "NaN at step " << k;
    if (!all_finite(w)) break;
    expect_step_energy(e, k);
    r.max_overlap = std::max(r.max_overlap, w.last().max_overlap);
    r.max_energy_gain = std::max(r.max_energy_gain, w.kinetic_energy() + w.potential_energy() - e0);
    r.max_step_gain = std::max(r.max_step_gain, e.gain);
    r.max_law = std::max(r.max_law, e.law);
    r.max_scheme = std::max(r.max_scheme, e.scheme);
    if (e.law > 1e-12 * e.scale) r.max_law_over_eps = std::max(r.max_law_over_eps, e.law / e.eps);
    it += w.last().solve.iterations;
    r.max_iter = std::max(r.max_iter, w.last().solve.iterations);
    r.cap_hits += w.last().solve.cap_hit;
  }
  r.mean_iter = double(it) / steps;
  return r;
}

inline void report(const char* name, const Watch& r, double energy_scale = 1.0) {
  std::printf("[ hard case ] %s: iterations mean %.1f max %d, cap hits %d, max overlap %.2e d, "
              "energy gain since the start %.2e, in one step %.2e, law term %.2e (%.2g of the solver "
              "bound), scheme term %.2e\n",
              name, r.mean_iter, r.max_iter, r.cap_hits, r.max_overlap, r.max_energy_gain / energy_scale,
              r.max_step_gain / energy_scale, r.max_law / energy_scale, r.max_law_over_eps,
              r.max_scheme / energy_scale);
}

}  // namespace cdtest
