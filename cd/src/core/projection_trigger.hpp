// The overlap projection's rule and its steps, which 2D's
// World::project_overlaps (2d/world.cpp) and 3D's World3::project_overlaps
// (3d/projection3.cpp) share: when it runs, for how long, the
// pseudo-velocity each row asks for, and the order of the work (project()
// below). Each dimension keeps its own rows, its own notion of a pair's
// smaller diameter (a wall's or plane's grain's) and its own way of moving
// the bodies and the cell, through an adaptor.
#pragma once
#include <algorithm>
#include <cstddef>

#include "solver.hpp"

namespace cd::projection {

// At most this many sweeps of the projection's solve (they are not in
// StepStats; their time is in the integrate stage's).
constexpr int kSweeps = 100;

// The projection runs only on a step where some overlap reaches kTrigger
// of its pair's smaller diameter: below it, overlaps are left as they are
// (the solve costs sweeps, and on every step it would keep a jammed
// sample's main solve from settling).
constexpr double kTrigger = 1e-3;

// Whether the step is due: some row k < n whose midpoint gap(k) < 0 is an
// overlap of at least kTrigger times diameter(k), its pair's smaller
// diameter (asked only of overlapping rows).
template <class Gap, class Diameter>
bool due(std::size_t n, Gap&& gap, Diameter&& diameter) {
  for (std::size_t k = 0; k < n; ++k) {
    const double g = gap(k);
    if (g < 0.0 && -g >= kTrigger * diameter(k)) return true;
  }
  return false;
}

// The pseudo-velocity a row's gap g asks for: open an overlap by beta of
// it in the step (u_n >= beta |g| / dt), and close no open gap (u_n >= -g / dt).
inline double offset(double g, double beta, double dt) { return g < 0.0 ? beta * g / dt : g / dt; }

// The projection's solver settings from the scene's: at most kSweeps
// sweeps, no law-residual stop, plain NLGS (neither Anderson's mixing nor
// the subspace correction) for the frictionless pseudo-velocity problem;
// the tolerance is the scene's. (No shear policy band runs the subspace
// correction with the projection; a scene that gave both ran the correction
// inside the projection too.)
inline SolverParams solver_params(SolverParams sp) {
  sp.max_iter = std::min(sp.max_iter, kSweeps);
  sp.residual_tol = 0.0;
  sp.anderson = 0;
  sp.subspace = 0;
  return sp;
}

// One projection of the n rows whose midpoint gaps are gap(k), given an
// engine's adaptor E (a World's or World3's):
//   smaller(k)             row k's pair's smaller diameter
//   start()                the pseudo problem from the main one: its rows,
//                          frictionless, bodies and cell lengths at rest
//   set_offset(k, b)       row k's pseudo-velocity bound b, nothing else on it
//   solve()                the pseudo problem's solve (solver_params above)
//   impulse(k)             row k's normal impulse of the main solve
//   normal_velocity(k)     its solved pseudo-velocity across the contact
//   add_dof_work(work)     work plus the cell lengths' share of it
//   move(dt)               dt times the pseudo-velocities into the midpoint
//                          positions and the cell
// Returns the contact forces' work on the displacements, sum f_n (dt u_n)
// over the rows that carry a force (StepStats::projection_work), or 0 when
// no overlap is due.
template <class E, class Gap>
double project(E& e, std::size_t n, Gap&& gap, double beta, double dt) {
  if (!due(n, gap, [&](std::size_t k) { return e.smaller(k); })) return 0.0;
  e.start();
  for (std::size_t k = 0; k < n; ++k) e.set_offset(k, offset(gap(k), beta, dt));
  e.solve();
  double work = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double f = e.impulse(k);
    if (f <= 0.0) continue;
    work += f * e.normal_velocity(k);
  }
  work = e.add_dof_work(work);
  e.move(dt);
  return work;
}

}  // namespace cd::projection
