// The matrix form of a frozen contact problem (find r with u = W r + q and
// the law at every contact, Dim components a contact, the normal first),
// what 2D (2d/problem.cpp) and 3D (3d/problem3.cpp) do the same way: the
// condensation of a step's rows into W and q, the law residual and Siconos'
// error summed over contacts, and the production NLGS (core/sweep.hpp) run
// through the blocks of W. The dimensions keep their rows, blocks,
// couplings and laws (a `Form`, below).
#pragma once
#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "block_rows.hpp"
#include "colour_blocks.hpp"
#include "frozen.hpp"
#include "sweep.hpp"

namespace cd::matrix_form {

using Triplets = std::vector<Eigen::Triplet<double>>;

// W = H^T M^-1 H and q = H_b^T U - W_b r + b, from H and MH = M^-1 H as
// triplets (nrows x ncols: the bodies' nbody dofs first, then the boundary
// dofs; a column a contact component). MH holds only what has an inverse
// mass, so W has no structural entry through a wall. The bodies'
// velocities U (nbody) hold the warm start (H_b^T U includes W_b r); the
// boundary dofs' do not (v = v0 before the solve, its v0 part already in
// the rows' offsets b), so a dof adds inv_mass a a^T to W and nothing to q.
inline void condense(Eigen::Index nrows, Eigen::Index ncols, Eigen::Index nbody, const Triplets& h,
                     const Triplets& mh, const Eigen::VectorXd& U, const Eigen::VectorXd& r,
                     const Eigen::VectorXd& b, Eigen::SparseMatrix<double>& W, Eigen::VectorXd& q) {
  using SpMat = Eigen::SparseMatrix<double>;
  SpMat H(nrows, ncols), MH(nrows, ncols);
  H.setFromTriplets(h.begin(), h.end());
  MH.setFromTriplets(mh.begin(), mh.end());
  W = SpMat(H.transpose() * MH);
  W.makeCompressed();
  const SpMat Hb = H.topRows(nbody), MHb = MH.topRows(nbody);
  const SpMat Wb(Hb.transpose() * MHb);
  q = Hb.transpose() * U - Wb * r + b;
}

// Residual (frozen.hpp) from term(k) = {law residual of contact k, |r_k|}:
// max and mean over the nc contacts, divided by mean |r_k| (1 if 0).
template <class Term>
Residual residual_over(int nc, Term&& term) {
  Residual res;
  if (nc == 0) return res;
  double rmax = 0, rsum = 0, psum = 0;
  for (int k = 0; k < nc; ++k) {
    const auto [e, rk] = term(k);
    rmax = std::max(rmax, e);
    rsum += e;
    psum += rk;
  }
  res.r_mean = psum / nc;
  const double scale = res.r_mean > 0 ? res.r_mean : 1.0;
  res.max = rmax / scale;
  res.mean = rsum / nc / scale;
  return res;
}

// Siconos' error (fc2d/fc3d_compute_error) from term(k) = |r_k - P_K(r_k -
// u~_k)|^2: the root of the sum over contacts divided by ||q|| (absolute
// if ||q|| ~ 0).
template <class Term>
double siconos_over(const Eigen::VectorXd& q, int nc, Term&& term) {
  double e2 = 0;
  for (int k = 0; k < nc; ++k) e2 += term(k);
  const double nq = q.norm();
  return nq > std::numeric_limits<double>::epsilon() ? std::sqrt(e2) / nq : std::sqrt(e2);
}

// The production NLGS on the matrix form of problem p (p.nc contacts, p.W
// column-major, p.q): W's Dim x Dim block rows, contacts coloured on their
// pattern, rows in colour order coupled through the blocks, starting from r
// (zero if its size is not Dim nc). The caller has checked p's shape. The
// dimension's Form provides
//   static constexpr int dim; types Row, Block, Coupling (base, start, col, blk);
//   static Block zero(); static void add(Block&, int i, int j, double v)
//   bool row(int k, const Block list of k, const VectorXd& r, Row&)
//       contact k's row (true if it has friction), or std::invalid_argument;
//   SolveStats solve(bool friction, rows, colouring, coupling, prm, observer)
//       the sweep with the law chosen once;
//   static void store(const Row&, Eigen::VectorXd& r, int k)
// and p's own problem_residual and siconos_error give the statistics.
template <class Form, class P>
NlgsStats nlgs(const P& p, Eigen::VectorXd& r, const NlgsOptions& opt, const Form& form) {
  using clock = std::chrono::steady_clock;
  constexpr int D = Form::dim;
  using Row = typename Form::Row;
  using Block = typename Form::Block;
  const auto t0 = clock::now();
  const int nc = p.nc;
  if (r.size() != D * nc) r = Eigen::VectorXd::Zero(D * nc);
  NlgsStats st;

  // Block rows of W: for contact a, the blocks W_ab of every b it couples
  // to (W is column-major: entry (i, j) goes to block (i/D, j/D)).
  auto brow = block_rows<D>(p.W, nc, Form::zero(),
                            [](Block& b, int i, int j, double v) { Form::add(b, i, j, v); });
  const Colouring col = colour_blocks(nc, block_adjacency(brow));
  const std::vector<std::int32_t> inv = inverse_permutation(col.perm);
  std::vector<Row> rows(nc);
  bool friction = false;
  for (int i = 0; i < nc; ++i) {
    const int k = col.perm[i];
    friction = form.row(k, brow[k], r, rows[i]) || friction;
  }
  typename Form::Coupling c;
  c.base = rows.data();
  colour_ordered_rows(brow, col.perm, inv, c.start, c.col, c.blk);

  const SolverParams prm = solver_params(opt);
  const int every = std::max(1, opt.check_every);
  SolverParams serial = prm;
  serial.min_parallel = INT_MAX;  // the history's residual pass on this thread
  auto record = [&](int sweep, double dp_rel) {
    SolveStats s;
    sweep::residuals(rows, c, serial, s);
    st.history.push_back({sweep, dp_rel, s.residual_max, s.residual_mean});
  };
  SolveStats s;
  if (nc > 0)
    s = form.solve(friction, rows, col, c, prm, [&](int it, double dp) {
      if (it % every == 0) record(it, dp);
    });
  st.sweeps = s.iterations;
  st.converged = !s.cap_hit;
  st.dr_rel = s.dp_rel;
  for (int i = 0; i < nc; ++i) Form::store(rows[i], r, col.perm[i]);
  if (nc > 0 && (st.history.empty() || st.history.back().sweep != st.sweeps))
    record(st.sweeps, st.dr_rel);
  st.residual = problem_residual(p, r);
  st.siconos_error = siconos_error(p, r);
  st.time = std::chrono::duration<double>(clock::now() - t0).count();
  return st;
}

}  // namespace cd::matrix_form
