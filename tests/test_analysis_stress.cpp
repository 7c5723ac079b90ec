// Stress and connectivity of hand-built contact networks: exact values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analysis/src/coordination.hpp"
#include "analysis/src/stress.hpp"

using namespace cda;
constexpr double pi = std::numbers::pi;

namespace {
Contact make(int b1, int b2, double theta, double fn, double ft, double lx, double ly, int type = 0,
             int status = 1) {
  Contact c;
  c.b1 = b1;
  c.b2 = b2;
  c.theta = theta;
  c.fn = fn;
  c.ft = ft;
  c.lx = lx;
  c.ly = ly;
  c.type = type;
  c.status = status;
  return c;
}
Particle part(int id) {
  Particle p;
  p.id = id;
  p.radius = 0.5;
  return p;
}
}  // namespace

TEST(AnalysisStress, SingleContactIsTheOuterProduct) {
  // n = x, f = 3 n + 1 t = (3, 1), l = (2, 0): sigma = f l^T / V.
  const auto s = contact_stress({make(0, 1, 0.0, 3, 1, 2, 0)}, 4.0);
  EXPECT_DOUBLE_EQ(s.xx, 1.5);
  EXPECT_DOUBLE_EQ(s.xy, 0.0);
  EXPECT_DOUBLE_EQ(s.yx, 0.5);
  EXPECT_DOUBLE_EQ(s.yy, 0.0);
  EXPECT_DOUBLE_EQ(s.skew(), -0.25);
}

TEST(AnalysisStress, BiaxialAndRotatedNetworks) {
  // Two frictionless contacts along x (fn = 2) and y (fn = 1), l = 1: the
  // principal stresses are 2 and 1 (V = 1): p = 1.5, q = 0.5, theta = 0.
  const ContactSet cs = {make(0, 1, 0.0, 2, 0, 1, 0), make(0, 2, pi / 2, 1, 0, 0, 1)};
  const auto s = contact_stress(cs, 1.0);
  EXPECT_NEAR(s.p(), 1.5, 1e-15);
  EXPECT_NEAR(s.q(), 0.5, 1e-15);
  EXPECT_NEAR(s.q_over_p(), 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(s.theta(), 0.0, 1e-15);
  // The same network rotated by 30 degrees: same invariants, theta = 30 deg.
  const double r = pi / 6;
  const ContactSet rot = {make(0, 1, r, 2, 0, std::cos(r), std::sin(r)),
                          make(0, 2, r + pi / 2, 1, 0, -std::sin(r), std::cos(r))};
  const auto t = contact_stress(rot, 1.0);
  EXPECT_NEAR(t.p(), 1.5, 1e-14);
  EXPECT_NEAR(t.q(), 0.5, 1e-14);
  EXPECT_NEAR(t.theta(), r, 1e-14);
  EXPECT_NEAR(t.xy, t.yx, 1e-14);
  // Pure shear by friction only: contacts along x and y with ft = 1, l = 1:
  // sigma_yx = 1 from the x contact (f = t = +y), sigma_xy = -1 from the y
  // contact (f = t = -x): sigma = [[0, -1], [1, 0]] is antisymmetric
  // (skew = -1), p = q = 0: such a network is not in equilibrium.
  const ContactSet fr = {make(0, 1, 0.0, 0, 1, 1, 0), make(0, 2, pi / 2, 0, 1, 0, 1)};
  const auto u = contact_stress(fr, 1.0);
  EXPECT_NEAR(u.xy, -1.0, 1e-15);
  EXPECT_NEAR(u.yx, 1.0, 1e-15);
  EXPECT_NEAR(u.q(), 0.0, 1e-15);
  EXPECT_NEAR(u.skew(), -1.0, 1e-15);
}

TEST(AnalysisStress, PartialStressesSumToTotal) {
  const ContactSet cs = {make(0, 1, 0.3, 2, 0.1, 1, 0.2, 1), make(0, 2, 1.3, 1, -0.2, 0.1, 1, 2),
                         make(1, 2, 2.0, 4, 0.3, -0.5, 0.8, 2), make(3, 2, 2.5, 1, 0, -1, 0.1, 0)};
  const auto s = contact_stress(cs, 2.0);
  const auto ps = partial_stress(cs, 2.0);
  EXPECT_NEAR(ps.disk.xx + ps.sv.xx + ps.ss.xx, s.xx, 1e-15);
  EXPECT_NEAR(ps.disk.xy + ps.sv.xy + ps.ss.xy, s.xy, 1e-15);
  EXPECT_NEAR(ps.disk.yx + ps.sv.yx + ps.ss.yx, s.yx, 1e-15);
  EXPECT_NEAR(ps.disk.yy + ps.sv.yy + ps.ss.yy, s.yy, 1e-15);
  // Merging the two points of an ss contact keeps the stress (same l, n).
  const ContactSet two = {make(4, 5, 0.2, 1, 0.1, 1, 0.2, 2), make(4, 5, 0.2, 3, -0.3, 1, 0.2, 2)};
  const auto merged = merge_side_side(two);
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_DOUBLE_EQ(merged[0].fn, 4.0);
  EXPECT_NEAR(contact_stress(merged, 1).xx, contact_stress(two, 1).xx, 1e-15);
  EXPECT_THROW(contact_stress(cs, 0.0), AnalysisError);
}

TEST(AnalysisConnectivity, IterativeRattlerRemoval) {
  // Particles 0..7; body 100 is a wall (not in the particle set).
  //   triangle 0-1-2 (each 2 contacts)
  //   chain 2-3-4: 4 has 1 contact -> rattler, then 3 drops to 1 -> rattler
  //   5 touches 1 and the wall: 2 contacts, stays
  //   6 touches 0 by a contact with zero force (not force-bearing): 6 -> rattler
  //   7 floats (no contact)
  //   an ss contact 0-1 given as two points (counted once)
  const ParticleSet ps = {part(0), part(1), part(2), part(3), part(4), part(5), part(6), part(7)};
  const ContactSet cs = {
      make(0, 1, 0, 1, 0, 1, 0, 2), make(0, 1, 0, 1, 0, 1, 0, 2),  // ss: two points
      make(1, 2, 0, 1, 0, 1, 0), make(2, 0, 0, 1, 0, 1, 0),
      make(2, 3, 0, 1, 0, 1, 0), make(3, 4, 0, 1, 0, 1, 0),
      make(5, 1, 0, 1, 0, 1, 0), make(100, 5, 0, 1, 0, 1, 0),
      make(0, 6, 0, 0, 0, 1, 0, 0, 0)};
  const auto c = connectivity(cs, ps);
  EXPECT_EQ(c.particles, 8u);
  EXPECT_EQ(c.force_bearing, 7u);  // pairs 01, 12, 20, 23, 34, 51, 5-wall
  EXPECT_EQ(c.rattlers, 4u);       // 3, 4, 6, 7
  const std::vector<bool> expect = {false, false, false, true, true, false, true, true};
  EXPECT_EQ(c.is_rattler, expect);
  // Remaining: 0 (1, 2), 1 (0, 2, 5), 2 (0, 1), 5 (1, wall): 9 contact ends / 4.
  EXPECT_DOUBLE_EQ(c.z, 9.0 / 4.0);
  EXPECT_DOUBLE_EQ(c.non_floating, 0.5);
  // P_c over all 8 particles with raw counts 0:2 1:3 2:3 3:2 4:1 5:2 6:0 7:0.
  ASSERT_EQ(c.P.size(), 4u);
  EXPECT_DOUBLE_EQ(c.P[0], 2.0 / 8);
  EXPECT_DOUBLE_EQ(c.P[1], 1.0 / 8);
  EXPECT_DOUBLE_EQ(c.P[2], 3.0 / 8);
  EXPECT_DOUBLE_EQ(c.P[3], 2.0 / 8);
}
