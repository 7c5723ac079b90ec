// The adhesion-shifted Signorini law (method.md section 2): thresholds of
// pull-off and of sliding with closed forms, and the f_a = 0 limit.
#include <gtest/gtest.h>

#include <cmath>

#include "world_util.hpp"

using cd::Vec2;
using cdtest::params;

namespace {

cd::WorldParams cohesive(double dt, double g, double mu, double fa, double debond) {
  auto p = params(dt, g, mu);
  p.adhesion = fa;
  p.debond = debond;
  return p;
}

}  // namespace

class PullOff : public ::testing::TestWithParam<double> {};

TEST_P(PullOff, BondedPairHoldsBelowFaAndSeparatesAbove) {
  // Two touching disks pulled apart by +-F, no gravity, f_a = 1. Below f_a
  // the contact holds with tension F (f_n = -F) and nothing moves; above, it
  // pulls with f_a while the gap is below the debonding distance, so the
  // relative acceleration is 2 (F - f_a)/m, then the bond breaks.
  const double ratio = GetParam(), fa = 1.0, dt = 1e-3;
  cd::World w(cohesive(dt, 0.0, 0.4, fa, 0.05));
  const int a = w.bodies.add_disk({0, 0}, 0.5, 1.0);
  const int b = w.bodies.add_disk({1.0, 0}, 0.5, 1.0);
  const double F = ratio * fa, m = w.bodies.mass[a];
  w.bodies.force[a] = Vec2(-F, 0);
  w.bodies.force[b] = Vec2(F, 0);
  w.step();
  ASSERT_EQ(w.rows().size(), 1u);
  if (ratio < 1) {
    for (int k = 0; k < 500; ++k) w.step();
    // one contact, solved exactly each step: round-off
    EXPECT_NEAR(w.rows()[0].pn / dt, -F, 1e-12);
    EXPECT_NEAR(w.bodies.vel[b].vx - w.bodies.vel[a].vx, 0.0, 1e-12);
    EXPECT_NEAR(w.bodies.pos[b].x() - w.bodies.pos[a].x(), 1.0, 1e-12);
  } else {
    EXPECT_NEAR(w.rows()[0].pn / dt, -fa, 1e-12);
    EXPECT_NEAR(w.bodies.vel[b].vx - w.bodies.vel[a].vx, 2 * (F - fa) / m * dt, 1e-12);
    for (int k = 0; k < 2000; ++k) w.step();
    EXPECT_GT(w.bodies.pos[b].x() - w.bodies.pos[a].x(), 1.0 + 0.05);  // debonded
    EXPECT_TRUE(w.rows().empty());
  }
}
INSTANTIATE_TEST_SUITE_P(Ratios, PullOff, ::testing::Values(0.9, 1.1));

class Hanging : public ::testing::TestWithParam<double> {};

TEST_P(Hanging, DiskUnderACeilingStaysIfWeightBelowFa) {
  // A disk touching a ceiling from below: it stays if m g < f_a (the contact
  // carries tension m g), and falls at g - f_a/m, then freely, if m g > f_a.
  const double ratio = GetParam(), g = 9.81, dt = 1e-3;
  cd::World probe(params(dt, g, 0.4));
  const double m = probe.bodies.mass[probe.bodies.add_disk({0, 0}, 0.5, 1.0)];
  const double fa = m * g / ratio;  // ratio = m g / f_a
  cd::World w(cohesive(dt, g, 0.4, fa, 0.05));
  w.bodies.add_wall({5, 0}, {-5, 0});
  const int d = w.bodies.add_disk({0, -0.5}, 0.5, 1.0);
  w.step();
  if (ratio < 1) {
    for (int k = 0; k < 1000; ++k) w.step();
    EXPECT_NEAR(w.bodies.pos[d].y(), -0.5, 1e-12);
    EXPECT_NEAR(w.rows()[0].pn / dt, -m * g, 1e-9 * m * g);
  } else {
    EXPECT_NEAR(w.bodies.vel[d].vy, -(g - fa / m) * dt, 1e-12);
    for (int k = 0; k < 1000; ++k) w.step();
    EXPECT_LT(w.bodies.pos[d].y(), -0.5 - 0.05);
  }
}
INSTANTIATE_TEST_SUITE_P(Ratios, Hanging, ::testing::Values(0.9, 1.1));

class BondedSlide : public ::testing::TestWithParam<double> {};

TEST_P(BondedSlide, SlidesOnlyAboveMuTimesNormalPlusAdhesion) {
  // A bonded disk on a floor (rotation off, so it cannot roll) under gravity
  // and a horizontal load F: it stays if F < mu (m g + f_a), else slides
  // with a = (F - mu (m g + f_a)) / m (the Coulomb cone is shifted by f_a).
  const double ratio = GetParam(), g = 9.81, mu = 0.3, dt = 1e-3;
  auto p = cohesive(dt, g, mu, 0.0, 0.05);
  p.rotation = false;
  cd::World probe(p);
  const double m = probe.bodies.mass[probe.bodies.add_disk({0, 0}, 0.5, 1.0)];
  p.adhesion = 2.0 * m * g;
  cd::World w(p);
  w.bodies.add_wall({-50, 0}, {50, 0});
  const int d = w.bodies.add_disk({0, 0.5}, 0.5, 1.0);
  const double limit = mu * (m * g + p.adhesion);
  w.bodies.force[d] = Vec2(ratio * limit, 0);
  for (int k = 0; k < 500; ++k) w.step();
  const double t = w.time;
  if (ratio < 1) {
    EXPECT_NEAR(w.bodies.vel[d].vx, 0.0, 1e-12);
  } else {
    const double a = (ratio * limit - limit) / m;
    EXPECT_NEAR(w.bodies.vel[d].vx, a * t, 1e-9 * a * t);
  }
  EXPECT_NEAR(w.bodies.pos[d].y(), 0.5, 1e-12);  // stays on the floor
}
INSTANTIATE_TEST_SUITE_P(Ratios, BondedSlide, ::testing::Values(0.95, 1.05));

TEST(Cohesion, ZeroAdhesionThroughTheCohesiveSweepIsBitIdentical) {
  // f_a = 0 through the adhesion sweep equals the plain sweep to the bit
  // (a = 0 enters every branch as an exact zero).
  cd::World w(params(1e-3, 9.81, 0.4));
  cdtest::fill_box(w, 300, 15, 1e3, 0.8, 1.2, 5);
  for (int k = 0; k < 200; ++k) w.step();
  const auto rows = w.rows();
  ASSERT_GT(rows.size(), 100u);
  const cd::Colouring col = cd::colour_rows(rows, w.bodies);
  auto solve = [&](bool adhesion) {
    const cd::LocalLaw law = adhesion ? cd::LocalLaw{cd::CohesiveCoulomb{}} : cd::Coulomb{};
    const auto c = cdtest::solve_copy(rows, col, w.bodies.vel, cdtest::tight_solver(), law);
    return std::make_pair(c.rows, c.vel);
  };
  const auto [r1, v1] = solve(true);
  const auto [r0, v0] = solve(false);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(r1[k].pn, r0[k].pn);
    EXPECT_EQ(r1[k].pt, r0[k].pt);
  }
  for (std::size_t i = 0; i < v1.size(); ++i) {
    EXPECT_EQ(v1[i].vx, v0[i].vx);
    EXPECT_EQ(v1[i].w, v0[i].w);
  }
}

TEST(CohesionHardCase, StronglyCohesivePileStaysBounded) {
  // 120 disks poured into a box with f_a = 100 m g (the pressure at the base
  // of this pile is ~10 m g / d, so eta = f_a / (p d) ~ 10 there and ~100 in
  // the upper layers). Adhesion pulls on every contact within the debonding
  // distance, also while a pair approaches (f_n = -f_a with u_n < 0:
  // positive power): the bonds store energy, f_a per unit of approach up to
  // debond, so E = KE + PE may rise. run_watched checks every step: the
  // change of E is the contacts' work, whose law part (the adhesion's work
  // f_a du_n counted apart) dissipates to the solver's bound. Over the run E
  // may gain at most what the bonds hold: f_a debond each, at most 3 a disk
  // (walls included). No NaN, overlap bounded as for the cohesionless pile
  // (1e-2 d).
  auto p = cohesive(2e-3, 9.81, 0.4, 0.0, 0.02);
  p.solver.tol = 1e-4;
  p.solver.max_iter = 1000;
  cd::World probe(p);
  const double mg = probe.bodies.mass[probe.bodies.add_disk({0, 0}, 0.5, 1.0)] * 9.81;
  p.adhesion = 100 * mg;
  cd::World w(p);
  cdtest::fill_box(w, 120, 8, 1e3, 0.8, 1.2, 31);
  const double mgd = cdtest::total_mass(w) * 9.81;
  const cdtest::Watch r = cdtest::run_watched(w, 1500);
  cdtest::report("strong cohesion (f_a = 100 m g)", r, mgd);
  EXPECT_LT(r.max_overlap, 1e-2);
  EXPECT_LT(r.max_energy_gain, 3 * 120 * p.adhesion * p.debond);
}
