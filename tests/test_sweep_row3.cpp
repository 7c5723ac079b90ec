// The rows the 3D sweep streams (contact3.hpp's SweepRow3, coupling3.hpp):
// their relative velocity and impulse push, written for lever arms along
// the normal, against the definitions on SphereRow (u = F((v2 + w2 x c2) -
// (v1 + w1 x c1)), dw_i = +-inv_I_i c_i x P) on random sphere-sphere and
// plane-sphere contacts; a row that is not a sphere's refused by the solve.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "contact_problem3.hpp"
#include "coupling3.hpp"
#include "detect3.hpp"

using namespace cd;

namespace {

struct Pair {
  SphereRow row;
  std::vector<BodyVel3> vel;  // body 0, body 1
};

// A random contact between two spheres (or a plane and a sphere), with
// random velocities and inverse masses.
Pair random_pair(std::mt19937_64& rng, bool plane) {
  std::uniform_real_distribution<double> U(-1.0, 1.0), R(0.2, 1.0);
  Pair p;
  p.vel.resize(2);
  for (BodyVel3& b : p.vel) {
    b.v = Vec3(U(rng), U(rng), U(rng));
    b.w = Vec3(U(rng), U(rng), U(rng));
    b.inv_m = R(rng);
    b.inv_I = 3.0 * R(rng);
  }
  ContactInfo3 f;
  const Vec3 x0(U(rng), U(rng), U(rng));
  const double r1 = R(rng);
  Vec3 d(U(rng), U(rng), U(rng));
  d.normalize();
  if (plane) {
    p.vel[0].w = Vec3::Zero();
    p.vel[0].inv_m = p.vel[0].inv_I = 0.0;
    const Vec3 xs = x0 + (r1 + 0.01 * U(rng)) * d;
    EXPECT_TRUE(plane_sphere(0, 1, x0 + Vec3(U(rng), U(rng), U(rng)).cross(d), d, xs, r1, 0.1, p.row, f));
  } else {
    const double r0 = R(rng);
    const Vec3 x1 = x0 + (r0 + r1 + 0.01 * U(rng)) * d;
    EXPECT_TRUE(sphere_sphere(0, 1, x0, x1, r0, r1, 0.1, p.row, f));
  }
  set_block(p.row, p.vel[0], p.vel[1]);
  p.row.bn = U(rng);
  p.row.r = Vec3(R(rng), 0.3 * U(rng), 0.3 * U(rng));
  p.row.mu = 0.4;
  return p;
}

}  // namespace

TEST(SweepRow3, VelocityAndPushAreTheSphereRowDefinitions) {
  std::mt19937_64 rng(7);
  for (int k = 0; k < 2000; ++k) {
    const bool plane = k % 4 == 0;
    Pair p = random_pair(rng, plane);
    SweepRow3 s;
    ASSERT_TRUE(make_sweep_row3(p.row, p.vel.data(), s)) << k;
    EXPECT_NEAR(s.iwnn * p.row.wnn, 1.0, 1e-15);
    EXPECT_NEAR(s.iwtt * p.row.wtt, 1.0, 1e-15);
    const SphereRow& r = p.row;
    const BodyVel3 &A = p.vel[0], &B = p.vel[1];
    const Vec3 u_def = r.to_frame(relative_velocity(r, A, B)) + Vec3(r.bn, 0, 0);
    const sweep::BodyCoupling3 c{p.vel.data(), nullptr, &s};
    const double vscale = B.v.norm() + A.v.norm() + 2.0 * (B.w.norm() + A.w.norm());
    EXPECT_LT((c.velocity(s) - u_def).norm(), 1e-14 * (vscale + std::abs(r.bn))) << k;
    // The push of an impulse change, both ways.
    const Vec3 dr(0.7, -0.2, 0.4);
    std::vector<BodyVel3> v1 = p.vel, v2 = p.vel;
    push_impulse(r, dr, v1.data());
    push_impulse(s, dr, v2.data());
    for (int b = 0; b < 2; ++b) {
      EXPECT_LT((v1[b].v - v2[b].v).norm(), 1e-14 * (1.0 + v1[b].v.norm())) << k;
      EXPECT_LT((v1[b].w - v2[b].w).norm(), 1e-14 * (1.0 + v1[b].w.norm())) << k;
    }
    // A driven body 1 (Write1 = false) is read, never written.
    std::vector<BodyVel3> v3 = p.vel;
    push_impulse<false>(s, dr, v3.data());
    EXPECT_EQ(v3[0].v, p.vel[0].v);
    EXPECT_EQ(v3[0].w, p.vel[0].w);
    EXPECT_EQ(v3[1].v, v2[1].v);
    EXPECT_EQ(v3[1].w, v2[1].w);
  }
}

// Lever arms off the normal of a turning body, or a left-handed frame: the
// solve refuses the problem, naming the row, rather than sweeping it with
// the sphere formulas.
TEST(SweepRow3, NotASphereRowIsRefused) {
  std::mt19937_64 rng(3);
  for (int bad = 0; bad < 2; ++bad) {
    Pair p = random_pair(rng, false);
    if (bad == 0) p.row.c2 += 0.1 * p.row.t1;
    else p.row.t2 = -p.row.t2;
    SweepRow3 s;
    EXPECT_FALSE(make_sweep_row3(p.row, p.vel.data(), s));
    ContactProblem3 prob;
    prob.vel = p.vel;
    prob.rows = {random_pair(rng, false).row, p.row};
    prob.rows[0].b1 = 0;
    prob.rows[0].b2 = 1;
    prob.colouring.start = {0, 2};
    prob.colouring.split = {0};
    prob.law = choose_law3({.friction = Friction3::Round});
    SolverParams prm;
    try {
      nlgs_solve3(prob, prm);
      ADD_FAILURE() << "not refused";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("row 1"), std::string::npos) << e.what();
    }
  }
}
