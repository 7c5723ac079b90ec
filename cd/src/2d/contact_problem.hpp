// The contact problem of one time step, as plain data: the seam between the
// step (which builds it) and the solver (which consumes it). The build stage
// of World::step fills it, nlgs_solve (nlgs.hpp) solves it, and nothing in it
// knows of shapes, cells or walls; cdproblem replays it from a file, and the
// benchmarks solve it in isolation.
//
// A problem is:
//   rows       one per contact point: frame, lever arms, Delassus block W_kk,
//              law offsets (gap, restitution and image velocity terms), the
//              law's per-row data (mu, adhesion impulse) and the impulses,
//              in colour order;
//   colouring  which rows may be updated at once (no two rows of a colour
//              share a dynamic body);
//   vel        the hot state of every body (velocity, inverse mass and
//              inertia); the velocities already include the rows' impulses
//              (the warm start), as the sweep keeps them;
//   dofs       boundary degrees of freedom solved with the contacts (a cell
//              height, a wall), coupled to some rows;
//   law        the local law, one type for the whole problem (law.hpp).
// The matrix form of the same problem (W = H^T M^-1 H, q, mu: Siconos'
// layout) is to_matrix(); problem.hpp reads and writes it.
#pragma once
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"
#include "law.hpp"
#include "solver.hpp"

namespace cd {

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

struct ContactProblem {
  std::vector<ContactRow> rows;
  Colouring colouring;
  std::vector<BodyVel> vel;
  std::vector<BoundaryDof> dofs;
  LocalLaw law = Coulomb{};
  bool rotation = true;
};

// Colours rows (greedy, in row order: deterministic) and returns the
// permutation; the caller applies it to rows and to any parallel arrays.
Colouring colour_rows(const std::vector<ContactRow>& rows, const Bodies& bodies);

// Adds the impulses held in the rows to the body velocities (warm start).
void apply_impulses(const std::vector<ContactRow>& rows, std::vector<BodyVel>& vel, bool rotation);

// ---- files -------------------------------------------------------------
// cdlab's own text format of a ContactProblem (".cdp"): every number as a C
// hexadecimal float, so that a problem read back is the same bits and its
// solve the same impulses as the step it was dumped from. Layout: a header
// line "cdlab-contact-problem 1", then `law NAME`, `rotation 0|1`, the
// solver's `tol`, `max_iter`, `min_parallel`; `bodies N` and N lines
// "vx vy w inv_m inv_I"; `colours C overflow 0|1` and the lines "start" and
// "split"; `rows R` and R lines "b1 b2 nx ny c1n c1t c2n c2t wnn wnt wtt bn
// bt pn pt mu adh"; `dofs D` and per dof "v0 v inv_mass scale M" then M
// lines "row an at". Malformed input throws std::runtime_error naming the
// file, the line and what was expected.
struct SolverParams;
void write_contact_problem(const ContactProblem& p, const SolverParams& prm, std::ostream& out);
void write_contact_problem(const ContactProblem& p, const SolverParams& prm,
                           const std::string& path);
ContactProblem read_contact_problem(std::istream& in, const std::string& name, SolverParams& prm);
ContactProblem read_contact_problem(const std::string& path, SolverParams& prm);

}  // namespace cd
