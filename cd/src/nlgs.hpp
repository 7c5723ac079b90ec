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
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"

namespace cd {

struct SolverParams {
  double tol = 1e-4;       // eps_f on rms |dp| / mean |p| over a sweep (LMGC90's "Quad" norm)
  int max_iter = 2000;     // iteration cap
  bool friction = true;    // law chosen once per scene
  bool adhesion = false;
  bool rotation = true;
  // Below this many rows the sweep runs on one thread: a colour of a few
  // dozen rows costs less than the barrier that ends it (measured: a
  // 600-row pile ran 3x slower on 2 threads than on 1).
  int min_parallel = 4096;
};

// A boundary degree of freedom solved with the contacts: a scalar velocity v
// (a periodic cell's height rate, a wall's normal velocity) that enters the
// relative velocity of some rows, u_n += an v and u_t += at v, and on which
// their impulses act back (the transpose): v = v0 + inv_mass sum (an p_n +
// at p_t), v0 holding the external impulse (imposed stress). Updated after
// every sweep (Gauss-Seidel on one more body); the change of v goes into the
// rows' offsets bn, bt, so the sweep itself does not know it exists.
struct BoundaryDof {
  double v0 = 0.0, v = 0.0, inv_mass = 0.0;
  double scale = 1.0;  // impulse scale of the convergence test (|imposed impulse|)
  std::vector<std::int32_t> rows;
  std::vector<double> an, at;
};

struct SolveStats {
  int iterations = 0;
  bool cap_hit = false;
  double dp_rel = 0;         // last sweep's rms |dp| / mean |p| (the convergence test)
  double residual_max = 0;   // law residual, max over contacts / mean |p|
  double residual_mean = 0;  // law residual, mean over contacts / mean |p|
  double p_mean = 0;         // mean |p| (impulse scale)
  double dof_rel = 0;        // last sweep's largest dof residual / (inv_mass scale) (update_dof)
};

// Colouring: rows are permuted so that colour c is [start[c], start[c+1]);
// inside a colour the rows whose body 1 is driven come first, up to split[c].
// The last colour may be an overflow colour, solved on one thread.
struct Colouring {
  std::vector<std::int32_t> start, split;
  bool overflow = false;
  std::vector<std::int32_t> perm;  // new index -> old index
};

// Colours rows (greedy, in row order: deterministic) and returns the
// permutation; the caller applies it to rows and to any parallel arrays.
Colouring colour_rows(const std::vector<ContactRow>& rows, const Bodies& bodies);

// Adds the impulses held in the rows to the body velocities (warm start).
void apply_impulses(const std::vector<ContactRow>& rows, std::vector<BodyVel>& vel, bool rotation);

// Solves the rows in place (p and the body velocities), starting from the
// impulses already held in the rows, which must already be applied to vel.
// Boundary dofs, if any, are updated after each sweep and must converge too.
SolveStats nlgs_solve(std::vector<ContactRow>& rows, const Colouring& col,
                      std::vector<BodyVel>& vel, const SolverParams& prm,
                      std::vector<BoundaryDof>* dofs = nullptr);

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
void law_residuals(const std::vector<ContactRow>& rows, const std::vector<BodyVel>& vel,
                   const SolverParams& prm, SolveStats& st);

}  // namespace cd
