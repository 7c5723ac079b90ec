// Closed-form checks of the time stepping and the contact laws on one or a
// few bodies. In these scenes the NLGS problem is either a single contact
// (solved exactly by the local solver) or a chain solved to tol = 1e-10, so
// the answers are exact up to round-off or that tolerance; each tolerance
// below says which.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "world_util.hpp"

using cd::Vec2;
using cdtest::params;

TEST(Dynamics, FreeFallIsExactForConstantGravity) {
  // Midpoint scheme: r+ = r + dt v- + g dt^2 / 2, exact for constant g.
  const double dt = 1e-3, g = 9.81;
  cd::World w(params(dt, g, 0.4));
  w.bodies.add_disk({0, 10}, 0.5, 1.0, {0.3, 2.0});
  for (int k = 0; k < 500; ++k) w.step();
  const double t = w.time;
  // 500 steps of O(1) additions: 1e-12 relative covers the accumulated round-off.
  EXPECT_NEAR(w.bodies.vel[0].vy, 2.0 - g * t, 1e-12 * g * t);
  EXPECT_NEAR(w.bodies.pos[0].y(), 10 + 2.0 * t - 0.5 * g * t * t, 1e-11);
  EXPECT_NEAR(w.bodies.pos[0].x(), 0.3 * t, 1e-12);
  EXPECT_EQ(w.last().contacts, 0);
}

class WallImpact : public ::testing::TestWithParam<double> {};

TEST_P(WallImpact, ReboundSpeedIsRestitutionTimesImpactSpeed) {
  // No gravity: the disk arrives at v0 and must leave at e_n v0 (Moreau's
  // impact law u+ = -e_n u-), exactly, whatever mu (head-on: no tangential
  // velocity).
  const double e = GetParam(), v0 = 2.0, dt = 1e-3;
  cd::World w(params(dt, 0.0, 0.4, e));
  w.bodies.add_wall({-5, 0}, {5, 0});
  const int d = w.bodies.add_disk({0, 0.5 + 0.0123}, 0.5, 1.0, {0, -v0});
  for (int k = 0; k < 100; ++k) w.step();
  EXPECT_NEAR(w.bodies.vel[d].vy, e * v0, 1e-12);
  EXPECT_NEAR(w.bodies.vel[d].vx, 0.0, 1e-15);
  // Overlap: at most the penetration of one half step, v0 dt / 2.
  EXPECT_GE(w.bodies.pos[d].y() - 0.5, -0.5 * v0 * dt - 1e-12);
}
INSTANTIATE_TEST_SUITE_P(Restitution, WallImpact, ::testing::Values(0.0, 0.5, 1.0));

class HeadOn : public ::testing::TestWithParam<double> {};

TEST_P(HeadOn, MomentumConservedAndRelativeVelocityRestituted) {
  const double e = GetParam(), dt = 1e-3;
  cd::World w(params(dt, 0.0, 0.3, e));
  const int a = w.bodies.add_disk({0, 0}, 0.5, 1.0, {1.5, 0});
  const int b = w.bodies.add_disk({2.2, 0}, 0.8, 2.0, {-0.7, 0});
  const double ma = w.bodies.mass[a], mb = w.bodies.mass[b];
  const double p0 = ma * 1.5 + mb * (-0.7);
  const double urel0 = -0.7 - 1.5;
  for (int k = 0; k < 1000; ++k) w.step();  // they meet at t ~ 0.41
  const double va = w.bodies.vel[a].vx, vb = w.bodies.vel[b].vx;
  EXPECT_NEAR(ma * va + mb * vb, p0, 1e-12 * std::abs(p0) + 1e-13);
  EXPECT_NEAR(vb - va, -e * urel0, 1e-12);
  EXPECT_NEAR(w.bodies.vel[a].vy, 0.0, 1e-15);
  EXPECT_NEAR(w.bodies.vel[a].w, 0.0, 1e-15);
}
INSTANTIATE_TEST_SUITE_P(Restitution, HeadOn, ::testing::Values(0.0, 0.5, 1.0));

struct InclineCase {
  double theta_deg, mu;
};
class Incline : public ::testing::TestWithParam<InclineCase> {};

TEST_P(Incline, RollsOrSlidesWithTheRightAcceleration) {
  // Disk on a plane inclined at theta: rolling without slip at
  // a = (2/3) g sin(theta) when tan(theta) <= 3 mu, else slipping at
  // a = g (sin(theta) - mu cos(theta)) with angular acceleration
  // 2 mu g cos(theta) / r. The contact persists and is solved exactly each
  // step, so v(t) = a t to round-off (1e-9 relative covers 3000 steps).
  const auto [deg, mu] = GetParam();
  const double th = deg * std::numbers::pi / 180, g = 9.81, r = 0.05, dt = 1e-4;
  cd::World w(params(dt, g, mu));
  const Vec2 down(std::cos(th), -std::sin(th)), up_n(std::sin(th), std::cos(th));
  w.bodies.add_wall(-2.0 * down, 2.0 * down);
  const int d = w.bodies.add_disk(r * up_n, r, 7.8);
  for (int k = 0; k < 3000; ++k) w.step();
  const double t = w.time;
  const Vec2 v(w.bodies.vel[d].vx, w.bodies.vel[d].vy);
  const bool rolls = std::tan(th) <= 3 * mu;
  const double a = rolls ? 2.0 / 3.0 * g * std::sin(th) : g * (std::sin(th) - mu * std::cos(th));
  EXPECT_NEAR(v.dot(down), a * t, 1e-9 * a * t);
  EXPECT_NEAR(v.dot(up_n), 0.0, 1e-9 * a * t);
  const double spin = -w.bodies.vel[d].w * r;  // rolling to the right spins clockwise
  if (rolls)
    EXPECT_NEAR(spin, v.dot(down), 1e-9 * a * t);
  else
    EXPECT_NEAR(spin, 2 * mu * g * std::cos(th) * t, 1e-9 * a * t);
}
INSTANTIATE_TEST_SUITE_P(RollAndSlip, Incline,
                         ::testing::Values(InclineCase{20, 0.5}, InclineCase{40, 0.2},
                                           // both sides of tan(theta) = 3 mu = 0.9
                                           InclineCase{40.36, 0.3}, InclineCase{42.0, 0.3}));

TEST(Dynamics, ColumnCarriesTheWeightAbove) {
  // n equal disks stacked on a floor, exactly touching: the floor carries
  // the total weight and contact k (from the bottom) the weight of the
  // n - k disks above it. Solver tolerance 1e-10 on a chain: forces to 1e-8
  // relative.
  const int n = 10;
  const double r = 0.5, dt = 1e-3, g = 9.81;
  cd::World w(params(dt, g, 0.5));
  w.bodies.add_wall({-5, 0}, {5, 0});
  for (int k = 0; k < n; ++k) w.bodies.add_disk({0, r + 2 * r * k}, r, 1.0);
  for (int k = 0; k < 200; ++k) w.step();
  const double mg = w.bodies.mass[1] * g;
  ASSERT_EQ(w.rows().size(), static_cast<std::size_t>(n));
  for (const cd::ContactRow& row : w.rows()) {
    // body 0 is the floor; disk k is body k + 1
    const int below = row.b1;  // frames go from lower to higher index
    const int carried = n - below;
    EXPECT_NEAR(row.pn / dt, carried * mg, 1e-8 * carried * mg) << "contact above body " << below;
    EXPECT_NEAR(row.pt, 0.0, 1e-12);
  }
  // At rest to the solver tolerance: the impulses are exact to tol = 1e-10
  // relative, so velocities to ~tol n g dt; 5x margin.
  for (int k = 1; k <= n; ++k) EXPECT_NEAR(w.bodies.vel[k].vy, 0.0, 5e-10 * n * g * dt);
}

TEST(Dynamics, FreeFlightEnergyIsConserved) {
  // Elastic head-on and wall impacts with e_n = 1, no gravity: kinetic
  // energy is conserved exactly by Moreau's law (relative 1e-12).
  cd::World w(params(1e-3, 0.0, 0.0, 1.0));
  w.bodies.add_wall({-5, 0}, {5, 0});
  w.bodies.add_wall({5, 10}, {-5, 10});
  w.bodies.add_disk({0, 2}, 0.5, 1.0, {0, -3});
  w.bodies.add_disk({0, 6}, 0.5, 3.0, {0, 1});
  const double e0 = w.kinetic_energy();
  for (int k = 0; k < 5000; ++k) w.step();
  EXPECT_NEAR(w.kinetic_energy(), e0, 1e-12 * e0);
}

TEST(Dynamics, OverlapCorrectionIsBoundedAndItsEnergyReported) {
  // Two disks at rest overlapping by 0.01, no gravity. Pure CD (beta = 0)
  // never pushes them apart: the overlap stays, no work, no energy. With
  // beta, the law u_n >= beta |g|/dt gives them the separating velocity
  // u = beta |g|/dt exactly (one exact local solve), which then persists:
  // the correction injects kinetic energy 1/2 m_eff u^2, and the reported
  // work p_n u = m_eff u^2 bounds it (here: equals twice it). Round-off: 1e-12.
  for (double beta : {0.0, 0.3}) {
    auto p = params(1e-3, 0.0, 0.4);
    p.overlap_correction = beta;
    cd::World w(p);
    w.bodies.add_disk({0, 0}, 0.5, 1.0);
    w.bodies.add_disk({0.99, 0}, 0.5, 1.0);
    w.step();
    EXPECT_NEAR(w.infos()[0].gap, -0.01, 1e-12);
    const double u = w.bodies.vel[1].vx - w.bodies.vel[0].vx;
    EXPECT_NEAR(u, beta * 0.01 / p.dt, 1e-12);
    EXPECT_NEAR(w.kinetic_energy(), 0.5 * w.last().correction_work,
                1e-12 * (1 + w.last().correction_work));
    if (beta == 0.0) {
      EXPECT_EQ(w.last().correction_work, 0.0);
      for (int k = 0; k < 5; ++k) w.step();
      EXPECT_NEAR(w.infos()[0].gap, -0.01, 1e-12);  // overlap kept, not pushed out
      EXPECT_EQ(w.kinetic_energy(), 0.0);
    }
  }
}
