// The exact local solver and the Delassus block.
//
// Tolerances: every check is at round-off. Quantities are O(1) by
// construction (random b in [-1, 1], W entries O(1)), so 1e-12 absolute is
// ~1e4 ulp: room for the few dozen flops of a local solve, nothing more.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <map>
#include <random>

#include "law.hpp"
#include "nlgs.hpp"

namespace {

constexpr double kTol = 1e-12;

struct Rng {
  std::mt19937_64 g{12345};
  double operator()(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
};

// Checks that (u, p) with u = b + W p satisfies the adhesion-shifted
// Signorini-Coulomb law, independently of the solver's own branch logic.
void expect_law(double bn, double bt, const cd::Block& W, double mu, double a, double pn, double pt) {
  const double un = bn + W.wnn * pn + W.wnt * pt;
  const double ut = bt + W.wnt * pn + W.wtt * pt;
  const double s = pn + a;
  EXPECT_GE(s, -kTol);
  EXPECT_GE(un, -kTol);
  EXPECT_NEAR(s * un, 0.0, kTol);
  EXPECT_LE(std::abs(pt), mu * s + kTol);
  if (std::abs(pt) < mu * s - 1e-9) {
    EXPECT_NEAR(ut, 0.0, kTol) << "sticking contact must not slide";
  } else if (s > kTol) {
    EXPECT_LE(pt * ut, kTol) << "friction must oppose sliding";
  }
}

cd::Block random_spd_block(Rng& r, bool coupled) {
  // W = J M^-1 J^T of a contact with random lever arms: SPD by construction.
  const double im = r(0.2, 2.0), iI = r(0.2, 2.0);
  const double cn = r(-1, 1), ct = coupled ? r(-1, 1) : 0.0;
  return {im + ct * ct * iI, -(cn * ct * iI), im + cn * cn * iI};
}

}  // namespace

TEST(LocalSolver, EveryBranchSatisfiesTheLawToRoundOff) {
  Rng r;
  std::map<cd::LocalBranch, int> hits;
  for (int coupled = 0; coupled < 2; ++coupled) {
    for (int k = 0; k < 20000; ++k) {
      const cd::Block W = random_spd_block(r, coupled);
      const double bn = r(-1, 1), bt = r(-1, 1), mu = r(0, 1.0);
      const double a = (k % 2) ? r(0, 0.5) : 0.0;  // half the cases cohesive
      double pn, pt;
      const cd::LocalBranch br = cd::solve_coulomb(bn, bt, W, mu, a, pn, pt);
      // Fallback only for ill-posed blocks (mu |W_nt| >= W_nn).
      if (br == cd::LocalBranch::Fallback) {
        EXPECT_GE(mu * std::abs(W.wnt), W.wnn * 0.999);
        continue;
      }
      ++hits[br];
      expect_law(bn, bt, W, mu, a, pn, pt);
      EXPECT_NEAR(cd::law_residual(bn + W.wnn * pn + W.wnt * pt, bt + W.wnt * pn + W.wtt * pt, pn,
                                   pt, mu, a, 1.0 / W.wnn),
                  0.0, kTol);
    }
  }
  for (auto b : {cd::LocalBranch::Open, cd::LocalBranch::Stick, cd::LocalBranch::SlidePlus,
                 cd::LocalBranch::SlideMinus})
    EXPECT_GT(hits[b], 100) << "branch " << int(b) << " not exercised";
}

TEST(LocalSolver, FrictionlessSatisfiesSignorini) {
  Rng r;
  for (int k = 0; k < 1000; ++k) {
    const cd::Block W = random_spd_block(r, true);
    const double bn = r(-1, 1), a = r(0, 0.3);
    double pn;
    cd::solve_frictionless(bn, W, a, pn);
    const double un = bn + W.wnn * pn;
    EXPECT_GE(pn + a, -kTol);
    EXPECT_GE(un, -kTol);
    EXPECT_NEAR((pn + a) * un, 0.0, kTol);
  }
}

TEST(LocalSolver, ZeroFrictionThroughCoulombEqualsFrictionless) {
  // The mu = 0 limit of the frictional path and the frictionless path must
  // agree (disks: W_nt = 0).
  Rng r;
  for (int k = 0; k < 1000; ++k) {
    const cd::Block W = random_spd_block(r, false);
    const double bn = r(-1, 1), bt = r(-1, 1);
    double pn1, pt1, pn2;
    cd::solve_coulomb(bn, bt, W, 0.0, 0.0, pn1, pt1);
    cd::solve_frictionless(bn, W, 0.0, pn2);
    EXPECT_NEAR(pn1, pn2, kTol);
    EXPECT_EQ(pt1, 0.0);
  }
}

TEST(LocalSolver, ResidualDetectsViolations) {
  // The residual is not trivially zero: a penetrating or outside-cone state is caught.
  EXPECT_GT(cd::law_residual(-1.0, 0.0, 0.0, 0.0, 0.5, 0.0, 1.0), 0.5);  // u_n < 0 with p_n = 0
  EXPECT_GT(cd::law_residual(0.0, 0.0, 1.0, 0.8, 0.5, 0.0, 1.0), 0.2);   // |p_t| > mu p_n
  EXPECT_GT(cd::law_residual(0.0, 0.3, 1.0, 0.1, 0.5, 0.0, 1.0), 0.05);  // sliding inside the cone
  EXPECT_GT(cd::law_residual(0.5, 0.0, 1.0, 0.0, 0.5, 0.0, 1.0), 0.4);   // separating with force
}

// W = G M^-1 G^T assembled from the definition u = (U2 + w2 x c2) - (U1 + w1 x c1)
// written with 3D cross products, independently of the formulas in contact.hpp.
TEST(DelassusBlock, FormulaEqualsAssembledHtMinvH) {
  Rng r;
  for (int k = 0; k < 200; ++k) {
    const double th = r(0, 2 * M_PI);
    const Eigen::Vector3d n(std::cos(th), std::sin(th), 0), t(-std::sin(th), std::cos(th), 0);
    const Eigen::Vector3d c1(r(-1, 1), r(-1, 1), 0), c2(r(-1, 1), r(-1, 1), 0);
    cd::BodyVel A{0, 0, 0, r(0.1, 3), r(0.1, 3)}, B{0, 0, 0, r(0.1, 3), r(0.1, 3)};
    if (k % 4 == 0) A.inv_m = A.inv_I = 0;  // a driven body
    // G: rows (n, t), columns (U1x, U1y, w1, U2x, U2y, w2).
    Eigen::Matrix<double, 2, 6> G;
    const Eigen::Vector3d ez(0, 0, 1);
    for (int row = 0; row < 2; ++row) {
      const Eigen::Vector3d& e = row == 0 ? n : t;
      G(row, 0) = -e.x();
      G(row, 1) = -e.y();
      G(row, 2) = -(ez.cross(c1)).dot(e);
      G(row, 3) = e.x();
      G(row, 4) = e.y();
      G(row, 5) = (ez.cross(c2)).dot(e);
    }
    Eigen::Matrix<double, 6, 6> Minv = Eigen::Matrix<double, 6, 6>::Zero();
    Minv.diagonal() << A.inv_m, A.inv_m, A.inv_I, B.inv_m, B.inv_m, B.inv_I;
    const Eigen::Matrix2d W = G * Minv * G.transpose();

    cd::ContactRow row{};
    row.b1 = 0;
    row.b2 = 1;
    row.nx = n.x();
    row.ny = n.y();
    row.c1n = c1.dot(n);
    row.c1t = c1.dot(t);
    row.c2n = c2.dot(n);
    row.c2t = c2.dot(t);
    cd::set_block(row, A, B, true);
    EXPECT_NEAR(row.wnn, W(0, 0), 1e-13);
    EXPECT_NEAR(row.wnt, W(0, 1), 1e-13);
    EXPECT_NEAR(row.wnt, W(1, 0), 1e-13);
    EXPECT_NEAR(row.wtt, W(1, 1), 1e-13);

    // The solver's velocity update applies exactly this W: an impulse p
    // changes the row velocity by W p.
    std::vector<cd::BodyVel> vel{A, B};
    vel[0].vx = r(-1, 1);
    vel[1].w = r(-1, 1);
    double un0, ut0, un1, ut1;
    cd::row_velocity(row, vel, true, un0, ut0);
    row.pn = r(0, 1);
    row.pt = r(-1, 1);
    cd::apply_impulses({row}, vel, true);
    cd::row_velocity(row, vel, true, un1, ut1);
    EXPECT_NEAR(un1 - un0, W(0, 0) * row.pn + W(0, 1) * row.pt, 1e-13);
    EXPECT_NEAR(ut1 - ut0, W(1, 0) * row.pn + W(1, 1) * row.pt, 1e-13);
  }
}
