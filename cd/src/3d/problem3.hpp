// A 3D frictional contact problem as plain data (Siconos/FCLib "local"
// layout, method.md section 13): find (u, r) with u = W r + q and the 3D
// Signorini-Coulomb law (law3.hpp) at every contact; per contact the
// normal component first, then the two tangential ones. W = H^T M^-1 H
// (3nc x 3nc), r an impulse.
//
// Frozen problems come from FCLib .hdf5 files (tests/data/contact-problems):
// a local problem gives W, q, mu directly; a global one (M v = H r + f,
// u = H^T v + w) is condensed, W = H^T M^-1 H and q = H^T M^-1 f + w, with a
// sparse Cholesky factorisation of M. They are solved by the NLGS sweep of
// core/sweep.hpp (the 2D engine's skeleton) with 3D rows coupled through the
// 3x3 blocks of W and the exact local solver, or by the polyhedral-cone LCP
// (lemke3.hpp).
#pragma once
#include <string>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "frozen.hpp"
#include "law3.hpp"

namespace cd {

struct Problem3 {
  int nc = 0;
  Eigen::SparseMatrix<double> W;  // 3nc x 3nc, column-major, compressed
  Eigen::VectorXd q;              // 3nc
  Eigen::VectorXd mu;             // nc: mu_a (round cone: the coefficient)
  Eigen::VectorXd mu_b;           // nc, or empty: round cones (mu_b = mu)
  Cone3 cone(int k) const { return {mu[k], mu_b.size() ? mu_b[k] : mu[k]}; }
};

struct Fclib3 {
  Problem3 problem;
  bool global = false;   // read from fclib_global (condensed) or fclib_local
  int bodies_dofs = 0;   // global: size of M
  // The file's stored solution r (and, global, v), if any (else empty).
  // Siconos' global test files store r = 0 and v = 0 there, equal to their
  // guess: a placeholder, not a solution (tests/test_frozen3.cpp).
  Eigen::VectorXd r_ref, v_ref;
};

struct ContactProblem3;

// The matrix form of a step's problem (contact_problem3.hpp): W = H^T M^-1
// H over the bodies' 6 dofs (scalar inertia) and the cell dofs (one more
// body each: inv_mass a a^T), q the relative velocities the bodies' free
// velocities give (theirs less M^-1 H r of the warm start) plus the rows'
// offsets, mu (and mu_b for an orthotropic law), in the problem's row
// order. Throws std::invalid_argument for a cohesive law (no such form).
Problem3 to_matrix(const ContactProblem3& p);

// Writes p as an FCLib local problem (fclib_write_local: W in compressed
// columns, q, mu, spacedim 3) with `title` and `description`, and, when
// given, the solution r (u = W r + q) and one guess (the warm start).
// Throws std::runtime_error if FCLib cannot write it, std::invalid_argument
// for orthotropic cones (FCLib has one mu a contact).
void write_fclib(const Problem3& p, const std::string& path, const std::string& title,
                 const std::string& description, const Eigen::VectorXd* solution = nullptr,
                 const Eigen::VectorXd* guess = nullptr);

// Reads an FCLib .hdf5 problem of space dimension 3 with the HDF5 C API
// (not FCLib's reader, which trusts the file's counts). Every dataset's
// length is checked against the header (W's m, n, nz, nzmax; 3 values of q
// and 1 of mu a contact, nc = m / 3; global: f of M's size, w and mu of H's
// columns) before anything is allocated for it, and must be stored in the
// file; W's (M's, H's) pointers start at 0, never decrease and stay within
// nzmax, their indices within the matrix; every value is finite and mu >= 0.
// Throws std::runtime_error naming the file and the dataset or what was
// wrong (not HDF5, no fclib_local/fclib_global group, dimension 2, equality
// constraints G, M not positive definite).
Fclib3 read_fclib(const std::string& path);

// Reads a 3D problem in Siconos' text form (.dat; core/siconos_dat.hpp:
// dense, sparse-block or sparse W). Throws std::runtime_error naming the
// file and line (a 2D file is refused: dimension 2).
Problem3 read_dat3(const std::string& path);

// Law residual (law_residual3 with rho = 1/W_nn), max and mean over contacts
// divided by the mean |r_k|.
Residual problem_residual(const Problem3& p, const Eigen::VectorXd& r);

// Siconos' fc3d error (fc3d_compute_error): sqrt(sum_k |r_k - P_K(r_k -
// u~_k)|^2) / ||q||, u~ = (u_n + mu |u_t|, u_t), rho = 1 (absolute if
// ||q|| ~ 0). Round cones only (uses mu).
double siconos_error(const Problem3& p, const Eigen::VectorXd& r);

// NLGS with core/sweep.hpp: rows in the greedy colouring of W's block
// pattern, the exact local solver on the symmetric part of each diagonal
// block, starting from r (zero if its size is not 3nc). Throws
// std::invalid_argument if a diagonal block is not positive definite.
NlgsStats solve_nlgs(const Problem3& p, Eigen::VectorXd& r, const NlgsOptions& opt = {});

}  // namespace cd
