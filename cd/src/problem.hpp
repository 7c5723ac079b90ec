// A frictional contact problem as plain data (Siconos "FrictionContact"
// layout, method.md sections 3 and 12): find (u, r) with
//     u = W r + q
// and the Signorini-Coulomb law at every contact. Per contact the normal
// component comes first, then the tangential one; W is the Delassus matrix
// H^T M^-1 H (2nc x 2nc), q the free local velocity, mu one coefficient per
// contact. r is an impulse (force times dt), as in the simulator's rows.
//
// The matrix form exists so that the solver can be replayed on frozen
// problems dumped from other codes (shared/data/contact-problems) and be
// compared with a reference solver (lemke.hpp). The simulator's own NLGS
// (nlgs.hpp) never assembles W; assemble_problem() builds it only to compare.
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "bodies.hpp"
#include "contact.hpp"

namespace cd {

struct Problem {
  int dim = 2;                    // only 2 is supported
  int nc = 0;                     // contacts
  Eigen::SparseMatrix<double> W;  // 2nc x 2nc, column-major, compressed
  Eigen::VectorXd q;              // 2nc
  Eigen::VectorXd mu;             // nc
};

// .dat text format (shared/data/contact-problems/README.md): dim, nc, W as a
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
// The velocities held in 'bodies' are taken to already include the rows'
// current impulses p (the simulator applies the warm start before solving),
// so the free velocity is G U - W p, and the law sees u + (bn, bt):
//   q = G U - W p + b,   so that the law's velocity is u = W p' + q
// for any new impulses p'. Body velocities are read, never changed.
Problem assemble_problem(const Bodies& bodies, const std::vector<ContactRow>& rows, bool rotation);

// Law residual of (r, u = W r + q): cd::law_residual per contact with
// rho = 1/W_nn, max and mean over contacts, both divided by the mean impulse
// norm mean_k |r_k| (1 if that is 0, i.e. absolute).
struct Residual {
  double max = 0, mean = 0;
  double r_mean = 0;  // mean_k |r_k|, the scale used
};
Residual problem_residual(const Problem& p, const Eigen::VectorXd& r);

struct NlgsOptions {
  double tol = 1e-6;  // both max_k |dr_k| / mean |r| over a sweep and Residual::max
  int max_sweeps = 10000;
  int check_every = 10;  // law residual (one product W r) every k sweeps, and when dr passes
};

struct NlgsCheckpoint {
  int sweep;
  double dr_rel, residual_max, residual_mean;
};

struct NlgsStats {
  int sweeps = 0;
  bool converged = false;  // dr_rel < tol and residual.max < tol at the last check
  double dr_rel = 0;       // last sweep
  Residual residual;       // at the end (recomputed from r)
  double time = 0;         // wall-clock seconds of the solve (setup included)
  std::vector<NlgsCheckpoint> history;
};

// Matrix-form nonlinear Gauss-Seidel (method.md section 5), contacts in index
// order, starting from r (resized to zero if its size is not 2nc). The local
// problem of contact k is solved exactly by cd::solve_coulomb (mu = 0:
// solve_frictionless) on the block W_kk. Throws std::invalid_argument if a
// block has W_nn <= 0 or is singular with friction.
NlgsStats solve_nlgs(const Problem& p, Eigen::VectorXd& r, const NlgsOptions& opt = {});

}  // namespace cd
