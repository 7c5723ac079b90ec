#include "lcp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/LU>

namespace cd {

const char* to_string(LemkeStatus s) {
  switch (s) {
    case LemkeStatus::Solved: return "solved";
    case LemkeStatus::RayTermination: return "ray termination";
    default: return "pivot cap";
  }
}

namespace {

// Natural-map error of an LCP point: max_i |min(z_i, w_i)|.
double lcp_error(const Eigen::VectorXd& z, const Eigen::VectorXd& w) {
  return z.size() ? z.cwiseMin(w).cwiseAbs().maxCoeff() : 0.0;
}

}  // namespace

LcpSolution solve_lcp_lemke(const Eigen::MatrixXd& M, const Eigen::VectorXd& q, int max_pivots) {
  const int n = static_cast<int>(q.size());
  LcpSolution sol;
  sol.z = Eigen::VectorXd::Zero(n);
  sol.w = q;
  if (n == 0 || q.minCoeff() >= 0.0) return sol;  // z = 0 solves it
  if (max_pivots <= 0) max_pivots = 50 * n + 100;

  // Tableau of  I w - M z - e z0 = q, kept as B^-1 [I, -M, -e | q]: columns
  // 0..n-1 are w (and hold B^-1, used by the lexicographic rule), n..2n-1 are
  // z, 2n is z0.
  const int z0 = 2 * n;
  Eigen::MatrixXd T(n, 2 * n + 1);
  T.leftCols(n).setIdentity();
  T.middleCols(n, n) = -M;
  T.col(z0).setConstant(-1.0);
  Eigen::VectorXd b = q;
  std::vector<int> basis(n);
  for (int i = 0; i < n; ++i) basis[i] = i;

  auto pivot = [&](int r, int c) {
    const double piv = T(r, c);
    T.row(r) /= piv;
    b[r] /= piv;
    Eigen::VectorXd f = T.col(c);
    f[r] = 0.0;
    const Eigen::RowVectorXd pr = T.row(r);
    T.noalias() -= f * pr;
    b -= f * b[r];
    basis[r] = c;
  };

  // z0 enters at the most negative q_i. Among equal minima the last index
  // keeps the rows lexicographically positive: a tied row i becomes
  // (0, e_i - e_t), positive only for i < t.
  int r = 0;
  for (int i = 1; i < n; ++i)
    if (q[i] <= q[r]) r = i;
  pivot(r, z0);
  int entering = n + r;  // complement of w_r, which just left
  sol.pivots = 1;
  sol.status = LemkeStatus::IterationCap;
  std::vector<int> tied;
  while (sol.pivots < max_pivots) {
    const Eigen::VectorXd d = T.col(entering);
    const double dtol = 1e-11 * d.cwiseAbs().maxCoeff();
    // Minimum ratio over the rows that block the entering variable.
    double theta = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i)
      if (d[i] > dtol) theta = std::min(theta, b[i] / d[i]);
    if (!std::isfinite(theta)) {
      sol.status = LemkeStatus::RayTermination;
      break;
    }
    // Ties: rows whose basic variable would also reach (round-off) zero.
    const double btol = 1e-12 * std::max(b.cwiseAbs().maxCoeff(), 1e-300);
    tied.clear();
    for (int i = 0; i < n; ++i)
      if (d[i] > dtol && b[i] - theta * d[i] <= btol) tied.push_back(i);
    r = -1;
    for (int i : tied)
      if (basis[i] == z0) r = i;  // z0 leaving ends the run: take it when it ties
    // Lexicographic rule on the columns of B^-1, one column at a time.
    for (int j = 0; r < 0 && j < n; ++j) {
      if (tied.size() == 1) {
        r = tied[0];
        break;
      }
      double best = std::numeric_limits<double>::infinity(), scale = 0;
      for (int i : tied) {
        best = std::min(best, T(i, j) / d[i]);
        scale = std::max(scale, std::abs(T(i, j) / d[i]));
      }
      std::erase_if(tied, [&](int i) { return T(i, j) / d[i] > best + 1e-12 * scale; });
    }
    if (r < 0) r = tied.front();
    const int leaving = basis[r];
    pivot(r, entering);
    ++sol.pivots;
    if (leaving == z0) {
      sol.status = LemkeStatus::Solved;
      break;
    }
    entering = leaving < n ? leaving + n : leaving - n;
  }

  // Read the basic point off the tableau, and again from one LU solve with the
  // final basis; keep whichever satisfies the LCP better. A degenerate basis
  // carries basic variables that are zero up to round-off (1e-17 where the
  // largest is 1); they are set to zero, else an all-open contact problem
  // (r = 0 exactly) comes out as r ~ 1e-17 and any error relative to mean |r|
  // is meaningless.
  auto point = [&](const Eigen::VectorXd& xb, Eigen::VectorXd& z) {
    const double zero = 64 * std::numeric_limits<double>::epsilon() * xb.cwiseAbs().maxCoeff();
    z.setZero(n);
    for (int i = 0; i < n; ++i)
      if (basis[i] >= n && basis[i] < z0 && xb[i] > zero) z[basis[i] - n] = xb[i];
  };
  point(b, sol.z);
  sol.w = M * sol.z + q;
  if (sol.status == LemkeStatus::Solved) {
    Eigen::MatrixXd B(n, n);
    for (int i = 0; i < n; ++i) {
      const int c = basis[i];
      if (c < n)
        B.col(i) = Eigen::VectorXd::Unit(n, c);
      else
        B.col(i) = -M.col(c - n);
    }
    Eigen::VectorXd z;
    point(B.partialPivLu().solve(q), z);
    const Eigen::VectorXd w = M * z + q;
    if (z.allFinite() && lcp_error(z, w) < lcp_error(sol.z, sol.w)) {
      sol.z = z;
      sol.w = w;
    }
  }
  return sol;
}

}  // namespace cd
