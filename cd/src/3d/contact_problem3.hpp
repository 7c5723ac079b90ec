// The contact problem of one 3D time step, as plain data: the seam between
// World3's step (whose build, colour and solve stages fill it) and the
// solver (nlgs_solve3, which consumes it), the 3D sibling of
// 2d/contact_problem.hpp. Nothing in it knows of spheres' radii, planes,
// cells or walls; cdproblem replays it from a .cdp3 file, and its matrix form
// (W = H^T M^-1 H, q, mu: to_matrix, problem3.hpp) goes to FCLib files.
//
// A problem is:
//   rows       one per contact: frame (n, t1, t2), lever arms, the block
//              diag(W_nn, W_tt, W_tt), the normal offset b_n (gap term,
//              restitution, image velocity), mu, the adhesion impulse and
//              the impulse r, in colour order;
//   extra      same index: tangential offsets and mu_b (RowExtra3), empty
//              unless the law reads them or a cell dof writes them;
//   colouring  which rows may be updated at once;
//   vel        every body's velocity and inverse mass and inertia, with the
//              rows' impulses (the warm start) already in it;
//   inv_inertia  every body's world inverse inertia tensor, in scenes with
//              bodies that are not spheres (empty otherwise: vel's scalar
//              inv_I); its rows are then block rows (block_coupling3.hpp);
//   dofs       the cell lengths solved with the contacts (CellDof3);
//   law        the local law, one type for the whole problem (coupling3.hpp).
#pragma once
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "bodies3.hpp"
#include "block_coupling3.hpp"
#include "contact3.hpp"
#include "coupling3.hpp"
#include "solver.hpp"

namespace cd {

// A cell length as a boundary dof of the 3D sweep (the 3D sibling of 2D's
// BoundaryDof): its velocity v enters the relative velocity of the rows
// that touch an image across its face as a.(u_n, u_t1, u_t2) += a v, and
// their impulses act back. Updated between sweeps by core/cell_dof.hpp's
// damped step; the change goes into the rows' offsets (bn, and the
// tangential ones in `extra`, null in frictionless scenes).
struct CellDof3 {
  double v0 = 0.0, v = 0.0, inv_mass = 0.0;
  double scale = 1.0;  // impulse scale of the convergence test (the imposed impulse)
  int axis = 0;
  std::vector<std::int32_t> rows;
  std::vector<Vec3> a;  // coefficients in the row's frame (n, t1, t2)
  RowExtra3* extra = nullptr;  // the problem's extras (set by nlgs_solve3), or null
};
double update_dof(CellDof3& d, SweepRow3* rows);
double update_dof(CellDof3& d, BlockRow3* rows);

struct ContactProblem3 {
  std::vector<SphereRow> rows;
  std::vector<RowExtra3> extra;
  Colouring colouring;
  std::vector<BodyVel3> vel;
  std::vector<Mat3> inv_inertia;
  std::vector<CellDof3> dofs;
  LocalLaw3 law;
  // rho = 1 / (k dt^2) of compliant contacts (contact.stiffness k), the
  // velocity per unit impulse the law adds to u (coupling3.hpp,
  // BodyCouplingT3); 0: rigid contacts.
  double compliance = 0.0;
  // rho_t = 1 / (k_t dt^2) of the tangential springs (contact.stiffness_ratio
  // k_t / k); 0: the same as compliance (k_t = k).
  double compliance_t = 0.0;
  double tangential_compliance() const { return compliance_t > 0 ? compliance_t : compliance; }
};

// Solves the problem in place (impulses, velocities, dofs) from the impulses
// held in the rows, which must already be in the velocities. The law is
// resolved here, once, into a template instance of core/sweep.hpp, which
// sweeps the rows as contact3.hpp's SweepRow3, or, with inv_inertia, as
// block_coupling3.hpp's BlockRow3 (rigid contacts only). Throws
// std::invalid_argument naming the row when a row is not a sphere's (see
// SweepRow3) in a problem without inv_inertia, or when inv_inertia's size
// is not the bodies' or it comes with compliant contacts.
SolveStats nlgs_solve3(ContactProblem3& p, const SolverParams& prm, const SweepObserver& observer = {});

// Adds the impulses held in the rows to the body velocities (warm start);
// in row order, one thread (bodies are shared). With inverse inertia
// tensors J (not empty), the rotations are J (c x P).
void apply_impulses(const std::vector<SphereRow>& rows, std::vector<BodyVel3>& vel,
                    const std::vector<Mat3>& J = {});

// ---- files -------------------------------------------------------------
// cdlab's own text format of a ContactProblem3 (".cdp3"): every number a C
// hexadecimal float, so that a problem read back is the same bits and its
// solve the same impulses as the step it was dumped from. Layout: a header
// line "cdlab-contact-problem3 V", then `law NAME` (law_name3), with
// V = 2 a line `compliance RHO` (compliant contacts; V = 1: rigid), the
// solver's `tol`, `max_iter`, `min_parallel` and optional `residual_tol`;
// `bodies N` and N lines "vx vy vz wx wy wz inv_m inv_I"; `colours C
// overflow 0|1` and the lines "start" and "split"; `rows R` and R lines "b1
// b2 n(3) t1(3) t2(3) c1(3) c2(3) wnn wtt bn r(3) mu adh"; `extras E` (0 or
// R) and E lines "bt1 bt2 mu_b"; `dofs D` and per dof "v0 v inv_mass scale
// axis M" then M lines "row a_n a_t1 a_t2". Malformed input throws
// std::runtime_error naming the file, the line and what was expected.
// Problems with inverse inertia tensors (polyhedra) have no such file yet:
// write_contact_problem throws std::invalid_argument for them.
// (dump3.cpp writes the text with core/files.hpp's atomic write.)
void write_contact_problem(const ContactProblem3& p, const SolverParams& prm, std::ostream& out);
ContactProblem3 read_contact_problem3(std::istream& in, const std::string& name, SolverParams& prm);
ContactProblem3 read_contact_problem3(const std::string& path, SolverParams& prm);

}  // namespace cd
