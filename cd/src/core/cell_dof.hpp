// A periodic cell's length as a degree of freedom at imposed stress
// (method.md section 9), the arithmetic 2D (2d/boundary.cpp) and 3D
// (3d/world3.cpp) share: the free velocity of a length under its load, its
// bounds (the approach floor, the compaction brake), and the damped Gauss-Seidel update of the dof between
// sweeps (update: its loop, over the engine's rows). Each dimension keeps its own row coupling (which rows cross the
// boundary, with which coefficients); the numbers those give go through
// these functions, so the two cells answer a pressure the same way.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>

namespace cd::cell_dof {

// The fastest approach a pressure-driven boundary may make: a quarter of
// the alert distance a step, so that what it closes on comes within the
// alert distance a step or more before they touch and those contacts are
// detected before they close. It holds for every pressure-driven boundary
// whatever the scene's brake (the 2D top wall, the periodic cells'
// lengths): it is what makes the detection see the boundary's contacts,
// not a choice of compaction rate. Without it a cell loaded by p with
// nothing to resist it (a loose start) collapsed at 0.13 d a step, past
// the 0.1 d alert distance, and its contacts were seen only once closed
// (tests/test_shear.cpp,
// PressureControl.CompactionThenShearAtImposedInertialNumber). The scene's
// alert distance, also where contacts are detected at touch (restitution):
// it then bounds the overlap a boundary makes in a step.
inline double approach_floor(double alert, double dt) { return -0.25 * alert / dt; }

// Lower bound of the free velocity of a length L: -min(rate L, alert /
// (4 dt)). The compaction brake (shear.compaction_rate) `rate` > 0 bounds
// the strain rate too; rate = 0: no bound on the rate, the approach floor
// alone.
inline double floor(double rate, double L, double alert, double dt) {
  return rate > 0.0 ? std::max(-rate * L, approach_floor(alert, dt)) : approach_floor(alert, dt);
}

// Free velocity of a length of mass M whose velocity at the start of the
// step is v_start, under the load `load` (imposed stress minus the kinetic
// stress, times the face it acts on; > 0 pushes the length shorter), over a
// step dt, bounded below by v_floor.
inline double free_velocity(double v_start, double load, double M, double dt, double v_floor) {
  return std::max(v_start - dt * load / M, v_floor);
}

// Whether the approach floor held that free velocity where the load cannot
// be applied at all: the step's load alone asks the length to shrink faster
// than the floor allows (dt load / M > alert / (4 dt): even from rest it
// would be clipped), the length's velocity at the step's start did not keep
// it above the floor, and v_floor is the approach floor, not the compaction
// brake (floor()'s -rate L, a rate the scene chose). On such a step the
// length brings the impulse M (v_start - v_floor) instead of dt times its
// load; in steady state that is every step, and the stress the contacts
// carry is M |v_floor| / (dt A), not the imposed one (summary.toml's
// floor_steps counts these steps). A collapse from a loose start, held at
// the floor by the speed it gathered over many steps of a smaller load
// each (the floor's purpose: a speed limit), is not counted.
// Reporting only: free_velocity is unchanged.
inline bool load_past_floor(double v_start, double load, double M, double dt, double v_floor, double alert) {
  const double dv = dt * load / M;
  return -dv < v_floor && v_start - dv < v_floor && v_floor == approach_floor(alert, dt);
}

// One update of a dof between sweeps. s = sum of its coefficients times
// the rows' impulses (the impulse the contacts put on the length), k = the
// active rows' local response sum a^2 / W (per component). The sweep runs
// with the dof frozen, so this is a Jacobi step between the dof and its
// rows: a change dv of the dof makes each active row answer with about -k
// dv, and the plain update v = v0 + s/M overshoots by k/M. It diverges once
// the dof is lighter than the grains it touches (measured in 2D: a top wall
// of 0.1 the mass of 100 disks hit the iteration cap and blew up within 400
// steps). The step is damped by that response (the Newton step of the dof's
// equation with the rows' local response): same fixed point, and a
// contraction. Returns dv (to add to v and to the rows' offsets, times their
// coefficients); res = the residual of the dof's equation before the step.
inline double damped_step(double v0, double v, double inv_mass, double s, double k, double& res) {
  res = v0 + inv_mass * s - v;
  return res / (1.0 + inv_mass * k);
}

// One update of a dof between sweeps, the engines' update_dof (called by
// core/sweep.hpp): load(i, s, k) adds the i-th coupled row's impulse along
// the dof to s and, if the row is active, its response a^2 / W to k;
// push(i, dv) adds the dof's change dv, times the row's coefficients, to its
// offsets. Dof: rows, v0, v, inv_mass, scale. Returns the residual of the
// dof's equation relative to its imposed impulse (the sweep's stopping test).
template <class Dof, class Load, class Push>
double update(Dof& d, Load&& load, Push&& push) {
  double s = 0.0, k = 0.0;
  const std::size_t m = d.rows.size();
  for (std::size_t i = 0; i < m; ++i) load(i, s, k);
  double res;
  const double dv = damped_step(d.v0, d.v, d.inv_mass, s, k, res);
  for (std::size_t i = 0; i < m; ++i) push(i, dv);
  d.v += dv;
  return std::abs(res) / (d.inv_mass * d.scale);
}

// The velocity profile a controlled length's kinetic stress is taken about:
// the mass-weighted least-squares line v_a = c + b x_a of the velocity
// component along the length against the coordinate along it. add() each
// grain, then slope() = b (0 with fewer than two distinct coordinates).
struct Profile {
  double m = 0.0, mx = 0.0, mxx = 0.0, mv = 0.0, mxv = 0.0;
  void add(double mi, double x, double v) {
    m += mi;
    mx += mi * x;
    mxx += mi * x * x;
    mv += mi * v;
    mxv += mi * x * v;
  }
  double slope() const {
    if (!(m > 0.0)) return 0.0;
    const double var = mxx - mx * mx / m;
    return var > 0.0 ? (mxv - mx * mv / m) / var : 0.0;
  }
};

}  // namespace cd::cell_dof
