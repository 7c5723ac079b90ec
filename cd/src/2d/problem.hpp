// A frictional contact problem as plain data (Siconos "FrictionContact"
// layout, method.md sections 3 and 12): find (u, r) with
//     u = W r + q
// and the Signorini-Coulomb law at every contact. Per contact the normal
// component comes first, then the tangential one; W is the Delassus matrix
// H^T M^-1 H (2nc x 2nc), q the free local velocity, mu one coefficient per
// contact. r is an impulse (force times dt), as in the simulator's rows.
//
// The matrix form exists so that the production solver can be replayed on
// frozen problems dumped from other codes (tests/data/contact-problems) or
// from cdsim (--dump-problem), and be compared with a reference solver
// (lemke.hpp). The simulator's own steps never assemble W (they solve a
// ContactProblem, contact_problem.hpp); to_matrix() builds it to compare and
// to write a step in Siconos' format.
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "bodies.hpp"
#include "contact.hpp"
#include "contact_problem.hpp"
#include "frozen.hpp"

namespace cd {

struct Problem {
  int dim = 2;                    // only 2 is supported
  int nc = 0;                     // contacts
  Eigen::SparseMatrix<double> W;  // 2nc x 2nc, column-major, compressed
  Eigen::VectorXd q;              // 2nc
  Eigen::VectorXd mu;             // nc
};

// .dat text format (tests/data/contact-problems/README.md): dim, nc, W as a
// Siconos NumericsMatrix (storage type, rows, columns, then the storage's
// layout), q, mu. Read: storage 0 (dense, column-major: each text line of the
// file is one column) and 2 (CSparse compressed-column listing, or triplet).
// Malformed input throws std::runtime_error naming the file, the line and
// what was expected.
enum class Storage { Dense = 0, Sparse = 2 };
Problem read_problem(const std::string& path);
Problem read_problem(std::istream& in, const std::string& name);

// Writes the same layout, values with 17 significant digits, so that
// read_problem gives back exactly the same W (same stored entries), q and mu.
// (Siconos writes sparse values with %g, six digits: its own dumps do not
// round-trip.)
void write_problem(const Problem& p, const std::string& path, Storage s = Storage::Sparse);
void write_problem(const Problem& p, std::ostream& out, Storage s = Storage::Sparse);

// The problem the simulator's NLGS solves on these rows (same order), with
// W = H^T M^-1 H assembled in full: off-diagonal blocks couple contacts that
// share a dynamic body; driven bodies (inv_m = inv_I = 0) couple nothing.
// H follows contact.hpp (u = G U, G = H^T):
//   u_n = n.(U2 - U1) - w2 c2t + w1 c1t,   u_t = t.(U2 - U1) + w2 c2n - w1 c1n
// (rotation = false drops the w terms, as the solver does).
// The velocities are taken to already include the rows' current impulses p
// (the simulator applies the warm start before solving), so the free
// velocity is G U - W p, and the law sees u + (bn, bt):
//   q = G U - W p + b,   so that the law's velocity is u = W p' + q
// for any new impulses p'. Boundary dofs, if given, are eliminated: each is
// one more body of inverse mass inv_mass, which adds inv_mass a a^T to W.
// Body velocities are read, never changed.
Problem assemble_problem(const std::vector<BodyVel>& vel, const std::vector<ContactRow>& rows,
                         bool rotation, const std::vector<BoundaryDof>* dofs = nullptr);
Problem assemble_problem(const Bodies& bodies, const std::vector<ContactRow>& rows, bool rotation);
// The matrix form of a step's problem (rows, velocities, dofs). Throws
// std::invalid_argument for a cohesive problem (Siconos' format has no
// adhesion).
Problem to_matrix(const ContactProblem& p);

// Law residual of (r, u = W r + q): cd::law_residual per contact with
// rho = 1/W_nn, max and mean over contacts, both divided by the mean impulse
// norm mean_k |r_k| (1 if that is 0, i.e. absolute).
Residual problem_residual(const Problem& p, const Eigen::VectorXd& r);

// The production NLGS (sweep.hpp: the sweep, local solver, convergence test
// and residual of every cdsim step) on the matrix form: rows coupled through
// the blocks of W instead of body velocities, coloured on W's block pattern,
// starting from r (resized to zero if its size is not 2nc). Throws
// std::invalid_argument if a block has W_nn <= 0 or is singular with
// friction.
NlgsStats solve_nlgs(const Problem& p, Eigen::VectorXd& r, const NlgsOptions& opt = {});

// Siconos' error of fc2d solvers (fc2d_compute_error, Acary & Brogliato
// 2008, A.13), reported beside ours: ||r - P_K(r - u~)|| / ||q|| over all
// contacts, u~ = (u_n + mu |u_t|, u_t) De Saxce's modified velocity, P_K the
// projection on the Coulomb cone, rho = 1 (absolute if ||q|| ~ 0).
double siconos_error(const Problem& p, const Eigen::VectorXd& r);

}  // namespace cd
