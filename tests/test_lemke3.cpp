// The polyhedral-cone LCP of 3D problems (cd/src/3d/lemke3.hpp): Lemke's
// solution satisfies its LCP to round-off, tends to the exact round-cone
// solution as the number of faces grows, and for e = 2 on an orthotropic
// problem is the rectangle law.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "lemke3.hpp"
#include "problem3.hpp"

namespace {

using cd::Cone3;
using cd::Mat3;
using cd::Vec3;
using Eigen::MatrixXd;
using Eigen::VectorXd;

cd::Problem3 one_contact(const Mat3& W, const Vec3& q, const Cone3& c) {
  cd::Problem3 p;
  p.nc = 1;
  p.W = MatrixXd(W).sparseView();
  p.q = q;
  p.mu = VectorXd::Constant(1, c.mu_a);
  p.mu_b = VectorXd::Constant(1, c.mu_b);
  return p;
}

// Dense random W = A A^T / n + 0.2 I (every contact coupled to every other).
cd::Problem3 random_problem(std::mt19937& g, int nc, double mu) {
  std::normal_distribution<double> N(0, 1);
  MatrixXd A(3 * nc, 3 * nc);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = N(g);
  cd::Problem3 p;
  p.nc = nc;
  p.W = (A * A.transpose() / (3 * nc) + 0.2 * MatrixXd::Identity(3 * nc, 3 * nc)).sparseView();
  p.q.resize(3 * nc);
  for (int i = 0; i < 3 * nc; ++i) p.q[i] = N(g) - (i % 3 == 0 ? 0.5 : 0.0);
  p.mu = VectorXd::Constant(nc, mu);
  return p;
}

TEST(Lemke3, SatisfiesItsLcpToRoundOff) {
  // max |min(z, w)| / max|q| after the final LU solve: round-off (seen
  // 2026-11-25: ~1e-16 to 1e-15); 1e-12 leaves room for conditioning.
  std::mt19937 g(3);
  for (int nc : {1, 4, 10})
    for (int e : {2, 3, 8}) {
      const cd::Problem3 p = random_problem(g, nc, 0.5);
      const cd::Lemke3Result L = cd::solve_lemke(p, e);
      ASSERT_EQ(L.status, cd::LemkeStatus::Solved) << "nc " << nc << " e " << e;
      EXPECT_LT(L.lcp_error, 1e-12) << "nc " << nc << " e " << e;
      EXPECT_GT(L.r.cwiseAbs().maxCoeff(), 0.0);
    }
}

TEST(Lemke3, TendsToTheRoundConeLikeOneMinusCos) {
  // The polygon circumscribes the circle; its largest excess is
  // 1/cos(pi/2e) - 1 ~ 1 - cos(pi/2e) ~ pi^2/(8 e^2). Case 1: W = I and q_t
  // along an edge of the polygon (th = pi/2e): the sliding impulse sits on
  // that edge, so the gap |r_poly - r_exact| / (mu r_n) is exactly the
  // excess; the log-log slope of the gap against e is printed and must be
  // close to -2 (measured 2026-11-25: -2.008 over e = 8..64). Case 2:
  // random dense coupled problems (4 contacts): the gap is printed and must
  // not grow from e = 4 to e = 64; it does NOT follow the excess cleanly
  // (seen: 0.9 to 16 times it, and on one draw a constant 2.7e-3, the
  // coupled problem's solution being more sensitive than one contact's).
  const double pi = std::numbers::pi, mu = 0.5;
  std::vector<double> es, gaps;
  for (int e : {2, 4, 8, 16, 32, 64}) {
    const double th = pi / (2.0 * e);
    const Vec3 q(-1.0, -3 * std::cos(th), -3 * std::sin(th));
    const cd::Problem3 p = one_contact(Mat3::Identity(), q, Cone3::round(mu));
    Vec3 rx;
    cd::solve_local3(Mat3::Identity(), q, Cone3::round(mu), 0.0, rx);
    const cd::Lemke3Result L = cd::solve_lemke(p, e);
    ASSERT_EQ(L.status, cd::LemkeStatus::Solved);
    const double gap = (L.r - rx).norm() / (mu * rx[0]), excess = 1.0 / std::cos(th) - 1.0;
    EXPECT_NEAR(gap, excess, 1e-12) << "e " << e;
    es.push_back(std::log(e));
    gaps.push_back(std::log(gap));
    std::printf("[ lemke3 ] e %2d: gap %.4e, 1 - cos(pi/2e) %.4e, 1/cos - 1 %.4e\n", e, gap,
                1 - std::cos(th), excess);
  }
  const double slope = (gaps.back() - gaps[gaps.size() - 4]) / (es.back() - es[es.size() - 4]);
  std::printf("[ lemke3 ] log-log slope of the gap against e (e = 8..64): %.3f\n", slope);
  EXPECT_NEAR(slope, -2.0, 0.02);

  std::mt19937 g(11);
  for (int rep = 0; rep < 3; ++rep) {
    const cd::Problem3 p = random_problem(g, 4, mu);
    VectorXd rx;
    cd::NlgsOptions o;
    o.tol = 1e-14;
    o.max_sweeps = 100000;
    cd::solve_nlgs(p, rx, o);
    ASSERT_LT(cd::problem_residual(p, rx).max, 1e-11);
    double first = -1, gap = 0;
    for (int e : {4, 16, 64}) {
      const cd::Lemke3Result L = cd::solve_lemke(p, e);
      ASSERT_EQ(L.status, cd::LemkeStatus::Solved);
      gap = (L.r - rx).norm() / rx.norm();
      const double excess = 1.0 / std::cos(pi / (2.0 * e)) - 1.0;
      std::printf("[ lemke3 ] random %d, e %2d: gap %.3e = %.2f x (1/cos - 1)\n", rep, e, gap, gap / excess);
      if (first < 0) first = gap;
    }
    EXPECT_LE(gap, first * (1 + 1e-9)) << "rep " << rep;
  }
}

TEST(Lemke3, TwoFacePairsGiveTheRectangleLaw) {
  // e = 2 on an orthotropic cone: |r_a| <= mu_a r_n, |r_b| <= mu_b r_n,
  // each axis its own 1D Coulomb law (r_a = -mu_a r_n sign(u_a) when u_a
  // != 0). W = diag(1, 2, 3) has the closed form r_n = -q_n, r_a =
  // clamp(-q_a / 2, mu_a r_n), r_b = clamp(-q_b / 3, mu_b r_n); random
  // coupled W are checked on the law itself, to round-off.
  const Cone3 c{0.8, 0.2};
  const Mat3 W = Eigen::Vector3d(1, 2, 3).asDiagonal();
  for (const Vec3& q : {Vec3(-1, 0.4, 0.3), Vec3(-1, 4, -0.3), Vec3(-1, -0.4, 3), Vec3(-2, 9, 9)}) {
    const cd::Lemke3Result L = cd::solve_lemke(one_contact(W, q, c), 2);
    ASSERT_EQ(L.status, cd::LemkeStatus::Solved);
    const double rn = -q[0];
    const Vec3 want(rn, std::clamp(-q[1] / 2, -c.mu_a * rn, c.mu_a * rn),
                    std::clamp(-q[2] / 3, -c.mu_b * rn, c.mu_b * rn));
    EXPECT_NEAR((L.r - want).norm(), 0.0, 1e-14) << q.transpose();
  }
  std::mt19937 g(5);
  for (int rep = 0; rep < 5; ++rep) {
    cd::Problem3 p = random_problem(g, 6, 0.0);
    p.mu = VectorXd::Constant(6, c.mu_a);
    p.mu_b = VectorXd::Constant(6, c.mu_b);
    const cd::Lemke3Result L = cd::solve_lemke(p, 2);
    ASSERT_EQ(L.status, cd::LemkeStatus::Solved);
    const VectorXd u = p.W * L.r + p.q;
    const double sc = L.r.cwiseAbs().maxCoeff(), tol = 1e-12 * std::max(1.0, sc);
    for (int k = 0; k < p.nc; ++k) {
      const double rn = L.r[3 * k];
      EXPECT_GE(rn, -tol);
      EXPECT_NEAR(rn * u[3 * k], 0.0, tol);
      for (int a : {1, 2}) {
        const double m = a == 1 ? c.mu_a : c.mu_b, ra = L.r[3 * k + a], ua = u[3 * k + a];
        EXPECT_LE(std::abs(ra), m * rn + tol);
        if (std::abs(ua) > tol) {
          EXPECT_NEAR(ra, -m * rn * (ua > 0 ? 1 : -1), tol) << "k " << k << " axis " << a;
        }
      }
    }
  }
}

}  // namespace
