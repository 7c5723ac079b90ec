#include "lemke.hpp"

#include <chrono>

namespace cd {

void friction_lcp(const Problem& p, Eigen::MatrixXd& M, Eigen::VectorXd& q) {
  const int nc = p.nc;
  M.setZero(4 * nc, 4 * nc);
  q.setZero(4 * nc);
  // Each entry W(a, c) couples row a%2 (0: u_n, 1: u_t) of contact a/2 with
  // column c%2 (0: r_n, 1: r_t = r_t+ - r_t-) of contact c/2.
  for (int c = 0; c < p.W.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(p.W, c); it; ++it) {
      const int k = static_cast<int>(it.row()) / 2, j = c / 2;
      const double v = it.value();
      const int zc = 4 * j + (c % 2);  // r_n or r_t+ column; r_t- is zc + 1 when tangential
      if (it.row() % 2 == 0) {         // u_n row
        M(4 * k, zc) += v;
        if (c % 2) M(4 * k, zc + 1) -= v;
      } else {  // u_t enters lambda + u_t and lambda - u_t
        M(4 * k + 1, zc) += v;
        M(4 * k + 2, zc) -= v;
        if (c % 2) {
          M(4 * k + 1, zc + 1) -= v;
          M(4 * k + 2, zc + 1) += v;
        }
      }
    }
  for (int k = 0; k < nc; ++k) {
    M(4 * k + 1, 4 * k + 3) = 1.0;
    M(4 * k + 2, 4 * k + 3) = 1.0;
    M(4 * k + 3, 4 * k) = p.mu[k];
    M(4 * k + 3, 4 * k + 1) = -1.0;
    M(4 * k + 3, 4 * k + 2) = -1.0;
    q[4 * k] = p.q[2 * k];
    q[4 * k + 1] = p.q[2 * k + 1];
    q[4 * k + 2] = -p.q[2 * k + 1];
  }
}

LemkeResult solve_lemke(const Problem& p, int max_pivots) {
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd M;
  Eigen::VectorXd q;
  friction_lcp(p, M, q);
  const LcpSolution s = solve_lcp_lemke(M, q, max_pivots);
  LemkeResult res;
  res.status = s.status;
  res.pivots = s.pivots;
  res.r.resize(2 * p.nc);
  for (int k = 0; k < p.nc; ++k) {
    res.r[2 * k] = s.z[4 * k];
    res.r[2 * k + 1] = s.z[4 * k + 1] - s.z[4 * k + 2];
  }
  res.time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace cd
