// Nonlinear Gauss-Seidel over contact rows coupled through body velocities
// (method.md section 5). The solver sees rows (frames, lever arms, W blocks,
// velocity offsets, impulses) and the hot body velocities; it knows nothing
// of shapes or boundaries.
//
// Parallel sweep: rows are coloured so that no two rows of a colour share a
// dynamic body; each colour is one parallel loop. A row's update depends only
// on the colours before it, so the result is the same for any thread count.
// Reductions that decide convergence are either max (order-free) or sums over
// fixed blocks of rows added in block order, never per-thread partial sums.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"
#include "contact_problem.hpp"
#include "parallel.hpp"
#include "solver.hpp"

namespace cd {

// Solves the problem in place (impulses, body velocities, dofs), starting
// from the impulses held in the rows, which must already be applied to the
// velocities. Boundary dofs are updated after each sweep and must converge
// too. The law is resolved here, once, into a template instance of the
// sweep. Stops when dp_rel < tol (and every dof's residual < tol), or at
// max_iter sweeps (cap_hit); then computes the law residuals.
SolveStats nlgs_solve(ContactProblem& p, const SolverParams& prm,
                      const SweepObserver& observer = {});

// The matrix form of a problem (problem.hpp: W, q, mu) is solved by the
// same sweep, law, convergence test and residual (sweep.hpp), through the
// blocks of W instead of body velocities: solve_nlgs in problem.hpp.

// One update of a boundary dof from the rows' impulses, damped by the active
// rows' response (nlgs.cpp); returns the residual of its equation before the
// update, |v0 + inv_mass sum(an p_n + at p_t) - v| / (inv_mass scale).
double update_dof(BoundaryDof& d, ContactRow* rows);

// Relative velocity (u_n, u_t) of a row from body velocities.
inline void row_velocity(const ContactRow& r, const std::vector<BodyVel>& vel, bool rotation,
                         double& un, double& ut) {
  const BodyVel& A = vel[r.b1];
  const BodyVel& B = vel[r.b2];
  const double dx = B.vx - A.vx, dy = B.vy - A.vy;
  un = r.nx * dx + r.ny * dy;
  ut = -r.ny * dx + r.nx * dy;
  if (rotation) {
    un += -B.w * r.c2t + A.w * r.c1t;
    ut += B.w * r.c2n - A.w * r.c1n;
  }
}

// Fills the Delassus block of a row from its lever arms and the bodies'
// inverse inertia (contact.hpp gives the formula and its sign convention).
inline void set_block(ContactRow& r, const BodyVel& A, const BodyVel& B, bool rotation) {
  const double iI1 = rotation ? A.inv_I : 0.0, iI2 = rotation ? B.inv_I : 0.0;
  const double im = A.inv_m + B.inv_m;
  r.wnn = im + r.c1t * r.c1t * iI1 + r.c2t * r.c2t * iI2;
  r.wtt = im + r.c1n * r.c1n * iI1 + r.c2n * r.c2n * iI2;
  r.wnt = -(r.c1n * r.c1t * iI1 + r.c2n * r.c2t * iI2);
}

// Law residual of every row (normalised by mean |p|), computed read-only.
void law_residuals(const ContactProblem& p, const SolverParams& prm, SolveStats& st);

}  // namespace cd
