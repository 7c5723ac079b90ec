// The NLGS sweep (method.md section 5), written once over a "coupling": how a
// row sees the impulses of the others, and over the row type (2D and 3D
// rows). 2d/coupling.hpp and 3d/coupling3.hpp couple rows through the
// velocities of the bodies they touch (the simulator's steps); 2d/problem.cpp
// and 3d/problem3.cpp through the off-diagonal blocks of W (frozen problems
// in matrix form). The sweep order, the convergence test, the boundary dofs
// and the residuals are this code for all of them, so a frozen problem is
// replayed by the production solver.
// Studies that visit rows in their own order (cd/bench/ss_pair) use the
// coupling's update, the sweep's own row update, rather than a copy, and
// solve_units, this sweep's convergence test and residuals in their order.
//
// Nothing here depends on the dimension. A coupling C provides
//   template <class L, bool Write1>
//   void update(Row& r, double& dp2, double& pabs)
//       one local solve of row r with law L; dp2 = |dp|^2, pabs = |p|.
//       Write1 = false when body 1 is driven (read, never written).
//       A coupling with `static constexpr bool kNormBound = true` gives in
//       pabs a cheap upper bound of |p| instead (3D: |p_n| + |p_t1| +
//       |p_t2|, no square root); the sweep then sums the exact |p| only on
//       the sweeps where the bound cannot rule the stop out (norm_bound,
//       exact_psum below), so the stop is that of the exact sum.
// and the row type provides, found by argument-dependent lookup,
//   double row_residual(const C& c, const Row& r)   the law residual of r
//   double impulse_norm(const Row& r)               |p| of r
//   double update_dof(Dof& d, Row* rows)            one boundary dof update
//       (returns its residual; see 2d/nlgs.hpp).
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <climits>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "solver.hpp"

namespace cd::sweep {

constexpr int kBlock = 128;  // rows per reduction block (fixed: see nlgs.hpp)
constexpr int kResidualEvery = 10;  // sweeps between checks of SolverParams::residual_tol

struct RowBlock {
  std::int32_t begin, end;
  bool write1;
};

struct BlockStats {
  double dp2sum = 0, psum = 0, rmax = 0, rsum = 0;
  int loaded = 0;  // rows with an impulse after their update, or a change in it
};

// Splits [begin, end) into fixed blocks.
inline void push_blocks(std::vector<RowBlock>& out, int begin, int end, bool write1) {
  for (int b = begin; b < end; b += kBlock) out.push_back({b, std::min(end, b + kBlock), write1});
}

template <class L, class Row, class C>
void run_block(const RowBlock& k, Row* rows, C& c, BlockStats& s) {
  double dsum = 0, psum = 0;
  int loaded = 0;
  if (k.write1) {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      c.template update<L, true>(rows[i], dp2, pabs);
      dsum += dp2;
      psum += pabs;
      loaded += (pabs > 0) | (dp2 > 0);
    }
  } else {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      c.template update<L, false>(rows[i], dp2, pabs);
      dsum += dp2;
      psum += pabs;
      loaded += (pabs > 0) | (dp2 > 0);
    }
  }
  s.dp2sum = dsum;
  s.psum = psum;
  s.loaded = loaded;
}

// Anderson acceleration of the sweep (SolverParams::anderson; Walker & Ni,
// SIAM J. Numer. Anal. 49 (2011) 1715, "type II"). The fixed-point map G is
// one symmetric pair of sweeps (forward, backward) on the impulses x of all
// rows; after the pair, with f = G(x) - x, the next start is
//     x+ = G(x) - dG gamma,   gamma = argmin |f - dF gamma|,
// dF, dG the differences of the last m f's and G's. The mix is put into the
// rows through the coupling (add_impulse: the row's impulse and its bodies'
// velocities together), so the next sweep sees a consistent state. Its
// local solves do not read the row's old impulse beyond q = u - W r, so a
// mixed impulse outside the cone is harmless: the sweep projects it. The
// boundary dofs keep their own update (not mixed). Safeguards: when |f|
// grows tenfold over a pair, the memory is cleared and the plain G(x) is
// kept (kRestartGrowth); and when the solve stalls (Stall: kStallPairs
// pairs in a row without the pair's rms |dp| falling 10 % below its best),
// Anderson is off for the rest of the solve and plain NLGS goes on from
// where it is. On frictional dense-shear steps the mixing can settle on a
// plateau that NLGS alone leaves (docs/accuracy.md: a 1000-sphere step held
// at rms |dp| 4e-4 for 5000 sweeps, where plain NLGS reached 1e-4 in 2050;
// tests/test_sweep_accel.cpp a 150-sphere one at tol 3e-6). The rule bounds
// what a stall costs at 2 kStallPairs sweeps. 40 pairs: 25 turned Anderson
// off on a plateau it would have left (436 sweeps to tol 1e-4 became 848);
// 40 keeps that, and costs 0-5 % more than 25 on the stalling steps.
// All of it on one thread, in row order: results do not depend on threads.
template <class C, class Row>
concept AddsImpulse = requires(const C& c, const Row& cr, Row& r, const double* dx, double* x) {
  { C::kImpulseDim } -> std::convertible_to<int>;
  c.read_impulse(cr, x);
  c.add_impulse(r, dx);
};

// The impulse components of a row (1 when the coupling cannot add impulses:
// Anderson is then never built).
template <class C>
constexpr int impulse_dim() {
  if constexpr (requires { C::kImpulseDim; })
    return C::kImpulseDim;
  else
    return 1;
}

template <int D>
class Anderson {
 public:
  static constexpr int kMaxMemory = kAndersonMaxMemory;

  Anderson(int memory, int rows)
      : m_(std::min(memory, kMaxMemory)), n_(rows * D), x_(n_), g_(n_), gp_(n_), fp_(n_), gcol_(m_), b_(m_),
        dF_(n_, m_), dG_(n_, m_), gram_(m_, m_) {}

  // The start of a pair: x = the rows' impulses.
  template <class Row, class C>
  void start(const Row* R, const C& c) {
    for (int i = 0, k = 0; k < n_; ++i, k += D) c.read_impulse(R[i], x_.data() + k);
  }

  // The end of a pair: mixes and puts the mix into the rows.
  template <class Row, class C>
  void mix(Row* R, const C& c) {
    for (int i = 0, k = 0; k < n_; ++i, k += D) c.read_impulse(R[i], g_.data() + k);
    const double fn = (g_ - x_).squaredNorm();
    if (have_prev_ && !(fn <= kRestartGrowth * kRestartGrowth * fn_prev_)) {
      cols_ = next_ = 0;  // the pair made things worse: restart from the plain iterate
      have_prev_ = false;
    }
    // The new column (f - f_prev, g - g_prev) in place of the oldest, and
    // f, g kept as the next previous ones; x = g from here on.
    const int j = next_;
    if (have_prev_) {  // Eigen expressions, one pass each: vectorised (a fused plain loop over six arrays is not)
      dF_.col(j) = (g_ - x_) - fp_;
      dG_.col(j) = g_ - gp_;
    }
    fp_ = g_ - x_;
    gp_ = g_;
    x_ = g_;  // the next pair starts at G(x), or at the mix below
    const bool added = have_prev_;
    fn_prev_ = fn;
    have_prev_ = true;
    if (!added) return;
    next_ = (next_ + 1) % m_;
    cols_ = std::min(cols_ + 1, m_);
    // The Gram matrix dF^T dF, updated in the new column's row and column
    // only; b = dF^T f. Whole-matrix products over the stored columns (two
    // matrix-vector products and one below: Eigen vectorises them, where
    // plain reduction loops stay scalar without -ffast-math; perf on a
    // 1000-sphere shear step: the mix cost 0.75 of the sweeps it
    // accelerates with plain loops). Their sums' order is fixed by the
    // build, not by the threads: the mix runs on one thread.
    const auto F = dF_.leftCols(cols_);
    gcol_.head(cols_).noalias() = F.transpose() * dF_.col(j);
    b_.head(cols_).noalias() = F.transpose() * fp_;
    for (int i = 0; i < cols_; ++i) gram_(i, j) = gram_(j, i) = gcol_[i];
    Eigen::MatrixXd A = gram_.topLeftCorner(cols_, cols_);
    // A small Tikhonov term keeps nearly dependent columns harmless.
    A.diagonal().array() += 1e-12 * A.diagonal().maxCoeff() + 1e-300;
    const Eigen::VectorXd gamma = A.ldlt().solve(b_.head(cols_));
    if (!gamma.allFinite()) {
      cols_ = next_ = 0;
      return;
    }
    // x+ = G(x) - dG gamma, then into the rows and their bodies.
    Eigen::VectorXd& dx = g_;  // g is spent: reused for dx
    dx.noalias() = -(dG_.leftCols(cols_) * gamma);
    x_ += dx;
    for (int i = 0, k = 0; k < n_; ++i, k += D) c.add_impulse(R[i], dx.data() + k);
  }

 private:
  // |f| may rise and fall from pair to pair while the active set settles
  // (a restart whenever it rose cleared the memory on 97 % of the pairs of
  // a 200-sphere shear step and left NLGS's convergence unchanged); the
  // memory goes when |f| grows tenfold over one pair, or is not finite.
  static constexpr double kRestartGrowth = 10.0;
  int m_, n_, cols_ = 0, next_ = 0;
  bool have_prev_ = false;
  double fn_prev_ = 0;
  Eigen::VectorXd x_, g_, gp_, fp_, gcol_, b_;
  Eigen::MatrixXd dF_, dG_, gram_;
};

// The stall rule of Anderson's mixing (above): fed the rms |dp|^2 sum of
// the sweep that ends each pair, it says when to give up mixing.
class Stall {
 public:
  static constexpr int kStallPairs = 40;
  // True when this pair makes kStallPairs in a row without a 10 % better
  // rms |dp| than the best so far (0.81 on the squares).
  bool stalled(double dsum) {
    if (dsum < 0.81 * best_) {
      best_ = dsum;
      since_ = 0;
      return false;
    }
    return ++since_ >= kStallPairs;
  }

 private:
  double best_ = std::numeric_limits<double>::infinity();
  int since_ = 0;
};

// Subspace correction of the sweep (SolverParams::subspace; after the
// "PGS-SM" of Silcowitz, Niebe & Erleben, VRIPHYS 2009, taken from the
// box-friction LCP to the Coulomb cone). Gauss-Seidel is slow on the
// long-wavelength modes of the sticking, hyperstatic network
// (docs/accuracy.md, "Where the sweeps go"), which is linear once the
// status of each contact is known. Every kSubspaceEvery pairs of sweeps the
// iterate's status fixes a linear problem: a sticking row (r inside its
// cone) keeps u = 0 on all its components, a sliding one u_n = 0 with its
// tangential impulse held, an open one r = 0; W_FF d = -u_F on the free
// components F is solved by Jacobi-preconditioned conjugate gradients from
// d = 0 for at most `subspace` iterations (relative residual kSubspaceRel),
// and r + d (a sliding row's tangential impulse scaled with its normal
// one, so that it stays on the cone's edge) goes through the law's own
// projection into the rows and their bodies. W is symmetric positive
// semidefinite; where the system is consistent CG converges on it and
// leaves the indeterminate part of the forces where the sweeps put it, and
// a direction W barely sees (kNullRel) ends it where it is not. The
// boundary dofs are held (their own update follows in the next sweep). One
// CG iteration is one product W p through the bodies of the closed rows (a
// scatter and a gather). When the pairs stall (Stall, the rule of Anderson's
// mixing, fed apart) the corrections stop for the rest of the solve. One
// thread, in row order: results do not depend on threads.
// A coupling C takes it when, for the law L, it provides
//   C::Scratch c.subspace_scratch()     bodies' storage for the products
//   c.subspace_row<L>(row, free, diag, u)  per component: 1/0 free, W_kk's
//       diagonal, the row's velocity; all-zero free when L has no such step
//       (diag and u are read on free components only: a row without one
//       may leave them)
//   c.subspace_apply(rows, live, p, y, scratch)   y = W p on the rows listed
//       in live (the others' p is 0 and their y unread; no offsets)
//   c.subspace_put<L>(row, d, sticking)    r <- proj(r + d), bodies follow
template <class C, class Row, class L>
concept Subspaces = AddsImpulse<C, Row> && C::template kSubspaceLaw<L>;

template <int D>
class Subspace {
 public:
  static constexpr int kSubspaceEvery = 2;      // pairs of sweeps between corrections
  static constexpr double kSubspaceRel = 1e-2;  // CG's relative residual
  static constexpr double kNullRel = 1e-10;     // p^T W p against p^T diag(W) p: W's null space

  Subspace(int iters, int rows) : iters_(iters), n_(rows * D), free_(n_), diag_(n_), u_(n_), pf_(n_), yf_(n_) {}

  // One correction of the rows' impulses; returns the CG iterations spent.
  // The CG vectors hold the free components only (comp_: their places in
  // the rows' D-vectors); the products read and write the full ones.
  template <class L, class Row, class C, class Scratch>
  int correct(Row* R, const C& c, Scratch& s) {
    const int nr = n_ / D;
    for (int i = 0, k = 0; i < nr; ++i, k += D)
      c.template subspace_row<L>(R[i], free_.data() + k, diag_.data() + k, u_.data() + k);
    live_.clear();  // the rows with a free component: the products skip the open ones
    comp_.clear();
    for (int i = 0, k = 0; i < nr; ++i, k += D) {
      if (free_[k] == 0) continue;
      live_.push_back(i);
      for (int j = 0; j < D; ++j)
        if (free_[k + j] != 0) comp_.push_back(k + j);
    }
    const int m = static_cast<int>(comp_.size());
    res_.resize(m);
    idg_.resize(m);
    dgf_.resize(m);
    for (int j = 0; j < m; ++j) {
      res_[j] = -u_[comp_[j]];
      dgf_[j] = diag_[comp_[j]];
      idg_[j] = 1.0 / dgf_[j];
    }
    z_ = res_.cwiseProduct(idg_);
    p_ = z_;
    d_.setZero(m);
    wp_.resize(m);
    pf_.setZero();
    double rz = res_.dot(z_), rr = res_.squaredNorm();
    const double stop = kSubspaceRel * kSubspaceRel * rr;
    int it = 0;
    for (; it < iters_ && rr > stop; ++it) {
      for (int j = 0; j < m; ++j) pf_[comp_[j]] = p_[j];
      c.subspace_apply(R, live_, pf_.data(), yf_.data(), s);
      for (int j = 0; j < m; ++j) wp_[j] = yf_[comp_[j]];
      const double pwp = p_.dot(wp_);
      // A direction W barely sees (its Rayleigh quotient against W's
      // diagonal below kNullRel): the status the iterate gave is not a
      // consistent linear problem there (say a closing row held at u = 0
      // beside resting ones that forbid it), and CG would step along W's
      // null space without bound. Stop before it.
      if (!(pwp > kNullRel * p_.cwiseAbs2().dot(dgf_))) break;
      const double a = rz / pwp;
      d_ += a * p_;
      res_ -= a * wp_;
      z_ = res_.cwiseProduct(idg_);
      const double rz1 = res_.dot(z_);
      rr = res_.squaredNorm();
      p_ = z_ + (rz1 / rz) * p_;
      rz = rz1;
    }
    if (!d_.allFinite()) return it;  // nothing put: the sweeps go on from where they are
    pf_.setZero();  // d in the rows' places
    for (int j = 0; j < m; ++j) pf_[comp_[j]] = d_[j];
    for (const int i : live_) c.template subspace_put<L>(R[i], pf_.data() + D * i, D > 1 && free_[D * i + 1] != 0);
    return it;
  }

 private:
  int iters_, n_;
  Eigen::VectorXd free_, diag_, u_, pf_, yf_;        // full: D per row
  Eigen::VectorXd res_, z_, p_, d_, wp_, idg_, dgf_;  // the free components (dgf_: W's diagonal there)
  std::vector<int> live_, comp_;
};

// Mean |p| over the rows (summed in row order; StopRows::Loaded: over the
// rows with an impulse) and the residuals' scale (mean |p|, or 1 when it is
// 0): one definition for residuals() and for residual_below(), whose stop
// decision must be residuals()'s exactly.
template <class Row>
std::pair<double, double> p_mean_and_scale(const std::vector<Row>& rows, StopRows over) {
  double psum = 0;
  int loaded = 0;
  for (const Row& r : rows) {
    const double p = impulse_norm(r);
    psum += p;
    loaded += p > 0;
  }
  const int n = over == StopRows::Loaded ? std::max(loaded, 1) : static_cast<int>(rows.size());
  const double p_mean = psum / static_cast<double>(n);
  return {p_mean, p_mean > 0 ? p_mean : 1.0};
}

// Law residual of every row (normalised by mean |p|), read-only.
template <class Row, class C>
void residuals(const std::vector<Row>& rows, const C& c, const SolverParams& prm, SolveStats& st) {
  const int n = static_cast<int>(rows.size());
  if (n == 0) {
    st.residual_max = st.residual_mean = 0;
    return;
  }
  std::vector<RowBlock> blocks;
  push_blocks(blocks, 0, n, true);
  std::vector<BlockStats> bs(blocks.size());
  const int nb = static_cast<int>(blocks.size());
#pragma omp parallel for schedule(static) if (n >= prm.min_parallel)
  for (int b = 0; b < nb; ++b) {
    double rmax = 0, rsum = 0;
    for (int i = blocks[b].begin; i < blocks[b].end; ++i) {
      const double e = row_residual(c, rows[i]);
      rmax = std::max(rmax, e);
      rsum += e;
    }
    bs[b].rmax = rmax;
    bs[b].rsum = rsum;
  }
  double rmax = 0, rsum = 0;
  for (const BlockStats& s : bs) {
    rmax = std::max(rmax, s.rmax);
    rsum += s.rsum;
  }
  const auto [p_mean, scale] = p_mean_and_scale(rows, prm.stop_rows);
  st.p_mean = p_mean;
  st.residual_max = rmax / scale;
  st.residual_mean = rsum / n / scale;
}

// The law-residual stop's test, residuals(...).residual_max < tol, with
// the same figures and decision but leaving at the first row that fails
// it: the test fails on all but the last of a solve's checks, and a full
// pass (a velocity and a natural-map residual with two hypot calls a row)
// cost a quarter of a 3D run at I = 1e-3 (perf). The scale is the same
// (p_mean_and_scale); e / scale >= tol for some row exactly when max e /
// scale >= tol (rounded division is monotone), and a NaN residual is
// skipped as std::max skips it there. Read-only, one thread.
template <class Row, class C>
bool residual_below(const std::vector<Row>& rows, const C& c, const SolverParams& prm) {
  if (rows.empty()) return true;
  const double scale = p_mean_and_scale(rows, prm.stop_rows).second;
  for (const Row& r : rows)
    if (row_residual(c, r) / scale >= prm.residual_tol) return false;
  return true;
}

// A problem without rows: the dofs keep their free velocity, nothing to solve.
template <class Dof>
SolveStats no_rows(std::vector<Dof>* dofs) {
  if (dofs)
    for (Dof& d : *dofs) d.v = d.v0;
  return {};
}

// The end of a sweep: the convergence test on the sweep's sums (dsum of
// |dp|^2, psum of |p| over the rows, averaged over n: every row, or the
// loaded ones under StopRows::Loaded), the dofs' update, the observer.
// Returns true when the solve stops (dp_rel < tol and every dof converged,
// or max_iter sweeps).
template <class Row, class Dof>
bool end_sweep(int it, double dsum, double psum, int n, Row* R, std::vector<Dof>* dofs,
               const SolverParams& prm, const SweepObserver& observer, SolveStats& st) {
  st.p_mean = psum / n;
  const double scale = st.p_mean > 0 ? st.p_mean : 1.0;
  st.dp_rel = std::sqrt(dsum / n) / scale;
  st.iterations = it;
  st.dof_rel = 0.0;
  if (dofs)
    for (Dof& d : *dofs) st.dof_rel = std::max(st.dof_rel, update_dof(d, R));
  if (observer) observer(it, st.dp_rel);
  return it >= prm.max_iter || (st.dp_rel < prm.tol && st.dof_rel < prm.tol);
}

// The scale of the convergence test, mean |p|, for couplings whose row
// update returns a bound of |p| (kNormBound): a sweep's bound sum B >= the
// exact sum P, so when rms |dp| >= tol B / n the test fails at P as well and
// P is not needed. Otherwise (and on every sweep an observer watches, and
// after the last) P is summed by impulse_norm in the sweep's own blocks and
// order, so it is the sum the update's |p| would have given, bit for bit:
// the stop, dp_rel and p_mean are exactly those of the plain sum.
template <class C>
constexpr bool norm_bound() {
  if constexpr (requires { C::kNormBound; })
    return C::kNormBound;
  else
    return false;
}

template <class Row>
double exact_psum(const std::vector<RowBlock>& blocks, const Row* R) {
  double psum = 0;
  for (const RowBlock& k : blocks) {
    double s = 0;
    for (int i = k.begin; i < k.end; ++i) s += impulse_norm(R[i]);
    psum += s;
  }
  return psum;
}

// True when the bound sums (dsum, bsum over n rows) leave the stop open.
inline bool bound_leaves_stop_open(double dsum, double bsum, int n, double tol) {
  const double scale = bsum > 0 ? bsum / n : 1.0;
  // 1e-9: the bound's own round-off (each row's |p_n| + |p_t1| + |p_t2| >=
  // its computed norm to a few ulps), kept far on the safe side.
  return std::sqrt(dsum / n) / scale < tol * (1.0 + 1e-9);
}

template <class L, class Row, class C, class Dof>
SolveStats solve(std::vector<Row>& rows, const Colouring& col, C& c, const SolverParams& prm,
                 std::vector<Dof>* dofs, const SweepObserver& observer) {
  if (rows.empty()) return no_rows(dofs);
  SolveStats st;
  const int n = static_cast<int>(rows.size());

  const int ncol = static_cast<int>(col.start.size()) - 1;
  std::vector<RowBlock> blocks;
  std::vector<int> cb(ncol + 1, 0);  // blocks of colour c: [cb[c], cb[c+1])
  for (int k = 0; k < ncol; ++k) {
    cb[k] = static_cast<int>(blocks.size());
    push_blocks(blocks, col.start[k], col.split[k], false);
    push_blocks(blocks, col.split[k], col.start[k + 1], true);
  }
  cb[ncol] = static_cast<int>(blocks.size());
  const int nb = cb[ncol];
  std::vector<BlockStats> bs(nb);
  Row* R = rows.data();
  const bool parallel = n >= prm.min_parallel;
  bool done = false;
  int it = 0;
  bool psum_exact = true;  // kNormBound: was the last sweep's |p| sum exact
  double last_dsum = 0;
  int last_n = n;  // the rows the last sweep's test averaged over
  // kNormBound: an upper bound of the exact |p| sum, tighter than the
  // sweep's bound sum in a slow tail (where the stop stays near and the exact
  // sum would be taken every sweep: 4 % of a 1000-sphere step at I = 1e-3):
  // the last exact sum plus sqrt(n dsum) for each sweep since (a row's |p|
  // moves by at most its |dp| in a sweep, and sum |dp| <= sqrt(n sum |dp|^2));
  // infinite once anything else moved the impulses (a mix, a correction).
  double psum_up = std::numeric_limits<double>::infinity();
  // Anderson acceleration (off unless asked and the coupling can take it).
  std::optional<Anderson<impulse_dim<C>()>> acc;
  Stall stall;
  if constexpr (AddsImpulse<C, Row>) {
    if (prm.anderson > 0) {
      acc.emplace(prm.anderson, n);
      acc->start(R, c);
    }
  }
  // The subspace correction (off unless asked and the coupling takes it for L).
  std::optional<Subspace<impulse_dim<C>()>> sub;
  Stall sub_stall;
  auto scratch = [&] {
    if constexpr (Subspaces<C, Row, L>)
      return prm.subspace > 0 ? c.subspace_scratch() : typename C::Scratch{};
    else
      return 0;
  }();
  if constexpr (Subspaces<C, Row, L>) {
    if (prm.subspace > 0) sub.emplace(prm.subspace, n);
  }

#pragma omp parallel if (parallel)
  {
    while (!done) {
      // Symmetric Gauss-Seidel: colours forward on odd sweeps, backward on
      // even ones, so that forces travel both ways along a chain (a pile's
      // weight down, the floor's reaction up) within two sweeps. Inside a
      // colour the order does not matter. The overflow colour stays last.
      const bool backward = (it % 2) == 1;
      const int nreg = col.overflow ? ncol - 1 : ncol;
      for (int cc = 0; cc < ncol; ++cc) {
        const int k = (cc < nreg && backward) ? nreg - 1 - cc : cc;
        if (col.overflow && k == ncol - 1) {
#pragma omp single
          for (int b = cb[k]; b < cb[k + 1]; ++b) run_block<L>(blocks[b], R, c, bs[b]);
        } else {
#pragma omp for schedule(static)
          for (int b = cb[k]; b < cb[k + 1]; ++b) run_block<L>(blocks[b], R, c, bs[b]);
        }
      }
#pragma omp single
      {
        double dsum = 0, psum = 0;
        int loaded = 0;
        for (int b = 0; b < nb; ++b) {
          dsum += bs[b].dp2sum;
          psum += bs[b].psum;
          loaded += bs[b].loaded;
        }
        // The rows the test averages over: every row, or the loaded ones
        // (their sums are the whole sums: an unloaded row adds 0 to both).
        const int nt = prm.stop_rows == StopRows::Loaded ? std::max(loaded, 1) : n;
        if constexpr (norm_bound<C>()) {
          psum_up += std::sqrt(static_cast<double>(n) * dsum) * (1.0 + 1e-9);
          psum = std::min(psum, psum_up);  // >= the exact sum: the test fails at it when it fails here
          psum_exact = observer || it + 1 >= prm.max_iter || bound_leaves_stop_open(dsum, psum, nt, prm.tol);
          if (psum_exact) psum_up = psum = exact_psum(blocks, R);
          last_dsum = dsum;
          last_n = nt;
        }
        const double pair_dsum = dsum;
        done = end_sweep(++it, dsum, psum, nt, R, dofs, prm, observer, st);
        // The optional second criterion: the law residual itself, checked
        // every kResidualEvery sweeps (a read-only pass over the rows, on
        // this thread). Off (residual_tol = 0) it costs nothing.
        if (!done && prm.residual_tol > 0 && it % kResidualEvery == 0) {
          st.residual_met = residual_below(rows, c, prm) && st.dof_rel < prm.tol;
          done = st.residual_met;
        }
        if constexpr (AddsImpulse<C, Row>) {
          if (acc && !done && it % 2 == 0) {  // after the backward sweep: a pair done
            if (stall.stalled(pair_dsum)) {
              acc.reset();  // plain NLGS from here
              st.anderson_off = it;
            } else {
              acc->mix(R, c);
              psum_up = std::numeric_limits<double>::infinity();
            }
          }
        }
        if constexpr (Subspaces<C, Row, L>) {
          if (sub && !done && it % 2 == 0 && sub_stall.stalled(pair_dsum)) {
            sub.reset();  // stalled: no more corrections in this solve
            st.subspace_off = it;
          }
          if (sub && !done && it % (2 * Subspace<impulse_dim<C>()>::kSubspaceEvery) == 0) {
            st.subspace_iterations += sub->template correct<L>(R, c, scratch);
            psum_up = std::numeric_limits<double>::infinity();
            if (acc) acc->start(R, c);  // the next pair starts from the corrected impulses
          }
        }
      }
      // implicit barrier: every thread sees the same 'done'
    }
  }

  if constexpr (norm_bound<C>()) {
    if (!psum_exact) {  // stopped by the law residual on a sweep the bound ruled out: the exact figures
      const double p_mean = exact_psum(blocks, R) / last_n;
      st.p_mean = p_mean;
      st.dp_rel = std::sqrt(last_dsum / last_n) / (p_mean > 0 ? p_mean : 1.0);
    }
  }
  residuals(rows, c, prm, st);
  st.cap_hit = not_converged(st, prm);
  return st;
}

// Sequential symmetric Gauss-Seidel over `units` groups of rows in the
// caller's order, for studies that visit rows in their own order
// (cd/bench/ss_pair: a side-side pair as one block): update(k, backward,
// dp2, pabs) updates unit k (dp2 and pabs summed over its rows, pabs the
// exact |p| also for a kNormBound coupling's rows); units go forward on odd
// sweeps, backward on even ones, and dp2, pabs are summed in visiting order. The convergence test, the
// dofs, the observer and the residuals are solve's, over every row (a unit
// does not say how many of its rows are loaded: StopRows::Loaded is refused). One thread.
template <class Row, class C, class Dof, class Update>
SolveStats solve_units(std::vector<Row>& rows, int units, const C& c, const SolverParams& prm,
                       std::vector<Dof>* dofs, const SweepObserver& observer, Update&& update) {
  if (prm.stop_rows != StopRows::All)
    throw std::invalid_argument("solve_units: the stop over the loaded rows needs the rows' own sweep");
  if (rows.empty()) return no_rows(dofs);
  SolveStats st;
  const int n = static_cast<int>(rows.size());
  for (int it = 0;;) {
    const bool backward = (it % 2) == 1;
    double dsum = 0, psum = 0;
    for (int kk = 0; kk < units; ++kk) {
      double dp2, pabs;
      update(backward ? units - 1 - kk : kk, backward, dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
    if (end_sweep(++it, dsum, psum, n, rows.data(), dofs, prm, observer, st)) break;
  }
  residuals(rows, c, prm, st);
  st.cap_hit = not_converged(st, prm);
  return st;
}

}  // namespace cd::sweep
