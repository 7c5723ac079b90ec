#include "lemke3.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

namespace cd {

Eigen::Matrix2Xd polyhedral_generators(const Cone3& c, int e) {
  if (e < 2) throw std::invalid_argument(fmt::format("polyhedral cone: e = {} face pairs, need >= 2", e));
  const double pi = std::numbers::pi, L = 1.0 / std::cos(pi / (2.0 * e));
  Eigen::Matrix2Xd G(2, 2 * e);
  for (int j = 0; j < 2 * e; ++j) {
    const double th = (2 * j + 1) * pi / (2.0 * e);
    G(0, j) = c.mu_a * L * std::cos(th);
    G(1, j) = c.mu_b * L * std::sin(th);
  }
  return G;
}

void polyhedral_lcp(const Problem3& p, int e, Eigen::MatrixXd& M, Eigen::VectorXd& q) {
  const int nc = p.nc, m = 2 * e + 2;
  // P_k (3 x m): z_k -> r_k;  R_k (m x 3): u_k -> the velocity part of w_k.
  std::vector<Eigen::MatrixXd> P(nc), R(nc);
  for (int k = 0; k < nc; ++k) {
    const Eigen::Matrix2Xd G = polyhedral_generators(p.cone(k), e);
    P[k].setZero(3, m);
    P[k](0, 0) = 1.0;
    P[k].block(1, 1, 2, 2 * e) = G;
    R[k].setZero(m, 3);
    R[k](0, 0) = 1.0;
    R[k].block(1, 1, 2 * e, 2) = G.transpose();
  }
  M.setZero(m * nc, m * nc);
  q.setZero(m * nc);
  // Blocks W_kj of W, gathered from its columns.
  const Eigen::MatrixXd Wd(p.W);
  for (int k = 0; k < nc; ++k)
    for (int j = 0; j < nc; ++j) {
      const Eigen::Matrix3d Wkj = Wd.block<3, 3>(3 * k, 3 * j);
      if (Wkj.isZero(0.0)) continue;
      M.block(m * k, m * j, m, m) = R[k] * Wkj * P[j];
    }
  for (int k = 0; k < nc; ++k) {
    const int o = m * k;
    for (int i = 1; i <= 2 * e; ++i) M(o + i, o + m - 1) = 1.0;  // lambda
    M(o + m - 1, o) = 1.0;                                       // r_n - sum beta
    for (int i = 1; i <= 2 * e; ++i) M(o + m - 1, o + i) = -1.0;
    q.segment(o, m) = R[k] * p.q.segment<3>(3 * k);
  }
}

Lemke3Result solve_lemke(const Problem3& p, int e, int max_pivots) {
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd M;
  Eigen::VectorXd q;
  polyhedral_lcp(p, e, M, q);
  const LcpSolution s = solve_lcp_lemke(M, q, max_pivots);
  Lemke3Result res;
  res.status = s.status;
  res.pivots = s.pivots;
  const int m = 2 * e + 2;
  res.r.resize(3 * p.nc);
  for (int k = 0; k < p.nc; ++k) {
    const Eigen::Matrix2Xd G = polyhedral_generators(p.cone(k), e);
    res.r[3 * k] = s.z[m * k];
    res.r.segment<2>(3 * k + 1) = G * s.z.segment(m * k + 1, 2 * e);
  }
  const double scale = std::max(1.0, q.size() ? q.cwiseAbs().maxCoeff() : 0.0);
  res.lcp_error = q.size() ? s.z.cwiseMin(s.w).cwiseAbs().maxCoeff() / scale : 0.0;
  res.time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace cd
