// What every contact solver shares, whatever the dimension: its parameters,
// the statistics it reports, the per-sweep observer, and the colouring of
// rows into sets that may be updated at once.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "defaults.hpp"
#include "parallel.hpp"

namespace cd {

// The largest Anderson memory (SolverParams::anderson): scene/config.cpp's
// range of solver.anderson, [0, 50].
inline constexpr int kAndersonMaxMemory = 50;

struct SolverParams {
  double tol = defaults::tol;  // eps_f on rms |dp| / mean |p| over a sweep (LMGC90's "Quad" norm)
  // All: the rms and the mean over every row, the open rows within the alert
  // distance included (each counts as a row that has converged: with n rows
  // of which n_f are loaded, the test is sqrt(n/n_f) times the same test
  // over the loaded rows alone, and how tight it is depends on the alert
  // distance). Loaded: over the rows loaded in the sweep (an impulse after
  // their update, or a change in it), and the law-residual stop's scale,
  // mean |p|, over the rows with an impulse: the test of the forces alone,
  // whatever the alert distance keeps open.
  StopRows stop_rows = defaults::stop_rows;
  int max_iter = defaults::max_iter;  // iteration cap
  // Below this many rows the sweep runs on one thread: a colour of a few
  // dozen rows costs less than the barrier that ends it (measured: a
  // 600-row pile ran 3x slower on 2 threads than on 1). Loops over bodies
  // (predict, integrate, detection) use half of it (kMinParallelBodies).
  int min_parallel = kMinParallelRows;
  // > 0: also stop when the largest law residual (relative to mean |p|, as
  // SolveStats::residual_max) is below this, checked every 10 sweeps: a
  // criterion on what the contact laws miss rather than on how much the
  // impulses still move (which, in dense shear, can stay above tol long
  // after the laws are met). 0: off, the rms |dp| test alone.
  double residual_tol = defaults::residual_tol;
  // > 0: Anderson acceleration of the sweep (core/sweep.hpp, Anderson):
  // the fixed-point map of one symmetric pair of sweeps, mixed over the
  // last `anderson` pairs, the memory cleared when the pair's change grows.
  // Needs a coupling that can add an impulse to a row (AddsImpulse); 0: off.
  int anderson = defaults::anderson;
  // > 0: the subspace correction of the sweep (core/sweep.hpp, Subspace):
  // every two pairs of sweeps, the linear problem of the sticking and
  // sliding rows is solved by at most this many conjugate-gradient
  // iterations and put into the rows, until a stall (the Anderson rule)
  // stops them for the rest of the solve. Needs a coupling and law that
  // take it (3D spheres and polyhedra with the round cone, adhesion or
  // not); 0: off.
  int subspace = defaults::subspace;
};

struct SolveStats {
  int iterations = 0;
  bool cap_hit = false;
  double dp_rel = 0;         // last sweep's rms |dp| / mean |p| (the convergence test)
  double residual_max = 0;   // law residual, max over contacts / mean |p|
  double residual_mean = 0;  // law residual, mean over contacts / mean |p|
  double p_mean = 0;         // mean |p| (impulse scale)
  double dof_rel = 0;        // last sweep's largest dof residual / (inv_mass scale) (update_dof)
  bool residual_met = false; // stopped by SolverParams::residual_tol
  int anderson_off = 0;      // > 0: Anderson stalled and was turned off after this many sweeps
  int subspace_off = 0;      // > 0: the subspace corrections stalled and stopped after this many sweeps
  int subspace_iterations = 0;  // conjugate-gradient iterations of the subspace corrections (each ~ half a sweep)
};

// Called after every sweep with the sweep count and its dp_rel, on one
// thread, between sweeps (cdproblem's history); may be empty.
using SweepObserver = std::function<void(int sweep, double dp_rel)>;

// A solve that stopped without meeting its criterion. Written as "not
// converged", so that a NaN criterion counts as a cap hit.
inline bool not_converged(const SolveStats& st, const SolverParams& prm) {
  return !((st.dp_rel < prm.tol && st.dof_rel < prm.tol) || st.residual_met);
}

// Colouring: rows are permuted so that colour c is [start[c], start[c+1]);
// inside a colour the rows whose body 1 is driven come first, up to split[c].
// The last colour may be an overflow colour, solved on one thread.
struct Colouring {
  std::vector<std::int32_t> start, split;
  bool overflow = false;
  std::vector<std::int32_t> perm;  // new index -> old index
};

}  // namespace cd
