// The general 3x3 local solver (cd/src/3d/alart_curnier3.hpp): Alart-Curnier
// semismooth Newton on full SPD blocks with round, orthotropic and
// one-axis cones, with and without adhesion. Checked against the law itself
// (law3.hpp's natural-map residual, with De Saxce's modified velocity, a
// different function from the one Newton zeroes) and against law3's exact
// enumerative solve_local3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Geometry>

#include "alart_curnier3.hpp"
#include "law3.hpp"

using namespace cd;

namespace {

struct Sample {
  Mat3 W;
  Vec3 q;
  Cone3 c;
  double a;
};

// W = Q diag(l) Q^T, l in [e^-2, e^2] (condition up to ~55), a random
// rotation Q; or diagonal (diag = true). Cones: round, orthotropic, one
// frictionless axis; mu in [0, 1.5]; adhesion on a third of the samples.
Sample sample(std::mt19937_64& rng, bool diag) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N;
  Sample s;
  const Vec3 l(std::exp(4 * U(rng) - 2), std::exp(4 * U(rng) - 2), std::exp(4 * U(rng) - 2));
  if (diag) {
    s.W = l.asDiagonal();
  } else {
    const Eigen::Quaterniond Q = Eigen::Quaterniond(N(rng), N(rng), N(rng), N(rng)).normalized();
    const Mat3 R = Q.toRotationMatrix();
    s.W = R * l.asDiagonal() * R.transpose();
    s.W = 0.5 * (s.W + s.W.transpose()).eval();
  }
  s.q = Vec3(N(rng), N(rng), N(rng));
  const int kind = static_cast<int>(U(rng) * 4);
  const double m1 = 1.5 * U(rng), m2 = 1.5 * U(rng);
  switch (kind) {
    case 0: s.c = Cone3::round(m1); break;
    case 1: s.c = Cone3{m1, m2}; break;
    case 2: s.c = Cone3{0.0, m2}; break;
    default: s.c = Cone3{m1, 0.0}; break;
  }
  s.a = U(rng) < 1.0 / 3 ? U(rng) : 0.0;
  return s;
}

struct Tally {
  double res_max = 0, diff_max = 0;
  int n = 0, not_converged = 0, fallbacks = 0, iters_max = 0, differ = 0;
};

Tally run(bool diag, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Tally t;
  for (int k = 0; k < count; ++k) {
    const Sample s = sample(rng, diag);
    Vec3 r, re;
    const NewtonStats3 st = solve_alart_curnier3(s.W, s.q, s.c, s.a, r);
    solve_local3(s.W, s.q, s.c, s.a, re);
    const double scale = s.q.norm() / s.W(0, 0) + s.a + r.norm();
    const double res = law_residual3(s.W * r + s.q, r, s.c, s.a, 1.0 / s.W(0, 0)) / scale;
    const double diff = (r - re).norm() / scale;
    t.res_max = std::max(t.res_max, res);
    t.diff_max = std::max(t.diff_max, diff);
    t.differ += diff > 1e-9;
    t.not_converged += !st.converged;
    t.fallbacks += st.projections > 0;
    t.iters_max = std::max(t.iters_max, st.iterations);
    ++t.n;
  }
  return t;
}

}  // namespace

// Diagonal blocks (the sphere rows' shape, where the solution is unique):
// the law holds to round-off and Newton agrees with the enumeration.
TEST(AlartCurnier3, DiagonalBlocksMatchTheExactSolver) {
  const Tally t = run(true, 20000, 21);
  std::printf("diagonal W: %d samples, residual <= %.2g, |r - r_exact| <= %.2g, %d fallbacks, <= %d Newton steps\n",
              t.n, t.res_max, t.diff_max, t.fallbacks, t.iters_max);
  EXPECT_EQ(t.not_converged, 0);
  EXPECT_LT(t.res_max, 1e-12);
  EXPECT_LT(t.diff_max, 1e-12);
}

// Full SPD blocks: the law holds to round-off on every sample, and on this
// fixed sample the enumeration's solution is the same everywhere (a block
// with strong normal-tangential coupling and a large mu can have several
// solutions; none of these does).
TEST(AlartCurnier3, FullBlocksSatisfyTheLawToRoundOff) {
  const Tally t = run(false, 20000, 22);
  std::printf("full W: %d samples, residual <= %.2g, |r - r_exact| <= %.2g (%d differ > 1e-9), %d fallbacks, <= %d "
              "Newton steps, %d not converged\n",
              t.n, t.res_max, t.diff_max, t.differ, t.fallbacks, t.iters_max, t.not_converged);
  EXPECT_EQ(t.not_converged, 0);
  EXPECT_LT(t.res_max, 1e-12);
  EXPECT_EQ(t.differ, 0);
  EXPECT_LT(t.diff_max, 1e-12);
}
