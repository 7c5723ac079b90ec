// Friction between two spheres in 3D against closed forms.
// Every other 3D friction test has a plane as body 1 (mu_wall); these put
// the Coulomb law on sphere-sphere rows (mu, mu_b), so that a bug in those
// rows alone (a halved mu, a wrong sign) changes an asserted number.
//
// Scenes, built through World3 as the other 3D tests build theirs:
//  - a ball on a sphere (one contact, normal vertical) or in the groove of
//    two spheres (two contacts whose normals make the angle alpha with the
//    vertical, in the x-z plane), gravity tilted by theta towards +y, the
//    direction along the groove: the incline of the 2D tests, with a sphere
//    for the plane. The supports are either glued (driven: the rows then
//    take mu_wall, contact.mu_wall's rule) or free and 10^12 times heavier
//    than the ball, resting on a floor with their rotation locked (the rows
//    take mu: the sphere-sphere law). Closed forms are for fixed supports;
//    the heavy ones move by m/M = 1e-12 of the ball.
//  - a frictional oblique impact of two free spheres (Moreau's impact law
//    with e_n, e_t, mu), against the impulse computed by hand.
//  - a ball on a heavy sphere with an orthotropic cone (mu_a along axis_a,
//    mu_b across it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "world3.hpp"

using namespace cd;

namespace {

constexpr double kG = 9.81;
constexpr double kPi = std::numbers::pi;
constexpr double kR = 0.015;  // support radius
constexpr double kr = 0.01;   // ball radius

struct Perch {
  World3 w;
  int ball = -1;
  double m = 0, I = 0;
};

// The ball on nsup = 1 support (alpha = 0) or in the groove of 2 (contact
// normals at +-alpha from the vertical, in the x-z plane; the groove runs
// along y). Friction (mu_a, mu_b) on the ball-support rows: mu_wall(_b) if
// glued, else mu(_b); the heavy supports' floor has mu_wall = 2 (they must
// not slide: tan theta < 2). spin = false locks the ball's rotation.
Perch perch(WorldParams3 p, int nsup, double alpha, double mu_a, double mu_b, bool glued, bool spin) {
  if (glued) {
    p.mu_wall = mu_a;
    p.mu_wall_b = mu_b;
    p.mu = p.mu_b = 0.0;
  } else {
    p.mu = mu_a;
    p.mu_b = mu_b;
    p.mu_wall = p.mu_wall_b = 2.0;
  }
  p.alert = 1e-4;
  // tol 0: every step runs max_iter sweeps. The heavy supports' floor
  // impulses are 10^12 times the ball's and dominate the rms |dp| test,
  // which would stop before the ball's rows converge; 400 sweeps of 3-5 rows
  // reach round-off (measured: the answers do not move from 200 to 2000).
  p.solver.tol = 0.0;
  p.solver.max_iter = 400;
  Perch s{World3(p)};
  const double h = kr + kR;
  if (!glued) s.w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double sx = nsup == 1 ? 0.0 : h * std::sin(alpha);
  for (int k = 0; k < nsup; ++k) {
    const int i = s.w.bodies.add_sphere(Vec3(k == 0 ? sx : -sx, 0.0, kR), kR, glued ? 2600.0 : 2600.0e12);
    if (glued) {
      s.w.bodies.drive(i);
    } else {
      s.w.bodies.vel[i].inv_I = 0.0;
    }
  }
  s.ball = s.w.bodies.add_sphere(Vec3(0.0, 0.0, kR + h * std::cos(alpha)), kr, 2600.0);
  s.m = s.w.bodies.mass[s.ball];
  s.I = s.w.bodies.inertia[s.ball];
  if (!spin) s.w.bodies.vel[s.ball].inv_I = 0.0;
  return s;
}

WorldParams3 tilted(double theta, double dt) {
  WorldParams3 p;
  p.dt = dt;
  p.gravity = kG * Vec3(0.0, std::sin(theta), -std::cos(theta));
  return p;
}

// Closed forms for a ball of radius r on fixed supports, contact normals at
// +-alpha from the vertical (alpha = 0: one contact), gravity g (0, sin
// theta, -cos theta), friction mu on each contact.
//
// Normal forces (statics of the contact normals, in the x-z plane, which
// the motion along y does not change): one contact N = m g cos theta; two,
// 2 N cos alpha = m g cos theta.  Friction acts along y (below), so the
// total friction available is mu (2N) = mu m g cos theta / cos alpha: the
// groove's effective coefficient is mu / cos alpha.
//
// Locked rotation, sliding: a = g (sin theta - mu cos theta / cos alpha)
// once positive; sticks (a = 0) for tan theta <= mu / cos alpha.
//
// Free rotation, rolling without slip: the contact points c_i = r (+-sin
// alpha, 0, -cos alpha) are at rest: v + w x c_1 = v + w x c_2 = 0, so w is
// along c_1 - c_2 (x) and v = w r cos alpha along y: the ball rolls on the
// circle of radius r cos alpha through the two contacts. Energy (or
// Newton-Euler with friction F along y and torque F r cos alpha):
//   a = g sin theta / (1 + I / (m r^2 cos^2 alpha)),   I = (2/5) m r^2,
// = (5/7) g sin theta on one contact, and the friction it needs,
//   F = m (g sin theta - a) = m g sin theta 2 / (5 cos^2 alpha + 2),
// stays within mu (2N) iff tan theta <= mu (5 cos^2 alpha + 2) / (2 cos alpha)
// ((7/2) mu on one contact). Above it both contacts slip: a as in sliding,
// and the friction torque gives dw_x/dt = -mu m g r cos theta / I
// (independent of alpha: each contact's friction mu N has the arm
// r cos alpha about x).
//
// The groove is statically indeterminate: two contacts can squeeze the ball
// along the line c_1 - c_2 (equal and opposite forces, no resultant, no
// moment) without changing its motion. A squeeze lambda raises each normal
// force by lambda sin alpha and adds a tangential part lambda cos alpha in
// the x-z plane, and stick is possible as long as some lambda keeps both
// forces in the cone: maximising mu^2 (N + lambda sin alpha)^2 - lambda^2
// cos^2 alpha over lambda, the friction each contact can give while
// sticking is mu N / sqrt(1 - mu^2 tan^2 alpha), not mu N. So the rigid
// problem has both a stick and a slide solution in the band
//   1 < tan theta / tan theta_* < 1 / sqrt(1 - mu^2 tan^2 alpha)
// (2 % at mu = 0.2, alpha = 45 deg), and the tests stay 10 % either side of
// the threshold tan theta_*, where only one exists. Sliding along y has
// its friction along y (the slip is along y: a velocity normal to neither
// contact normal is along n_1 x n_2), so there the forces are unique.
struct Closed {
  double N;       // normal force per contact
  double tan_stick_locked, tan_roll;
  double a_slide, a_roll, dw_slide;  // dw_slide: dw_x/dt while slipping
};

Closed closed(double theta, double alpha, double mu, int nsup, double m, double I) {
  const double ca = std::cos(alpha), st = std::sin(theta), ct = std::cos(theta);
  Closed c;
  c.N = m * kG * ct / (nsup * ca);
  c.tan_stick_locked = mu / ca;
  c.tan_roll = mu * (5 * ca * ca + 2) / (2 * ca);
  c.a_slide = kG * (st - mu * ct / ca);
  c.a_roll = kG * st / (1 + I / (m * kr * kr * ca * ca));
  c.dw_slide = -mu * m * kG * kr * ct / I;
  return c;
}

struct Case {
  int nsup;
  double alpha;
  bool glued;
};

const Case kCases[] = {{1, 0.0, true}, {1, 0.0, false}, {2, kPi / 4, true}, {2, kPi / 4, false}};

const char* name(const Case& c) {
  static char buf[64];
  std::snprintf(buf, sizeof buf, "%s, %s supports", c.nsup == 1 ? "on a sphere" : "in a 45 deg groove",
                c.glued ? "glued" : "heavy");
  return buf;
}

// Steps a perch from rest, checking the ball's velocity along y and its spin
// about x against v(t) = a t, w_x(t) = dw t. After the first step to 1e-16
// m / dt (the step's midpoint is the initial configuration, so the closed
// form is exact but for the placement's round-off: a gap of ~1e-18 m enters
// the law as a normal velocity gap/dt, measured up to 1.3e-12 m/s); after 20
// steps to 1e-5 of the change (the ball has moved 1e-7 m over supports of
// radius 1.5e-2: the normals have turned by ~4e-6).
void expect_motion(Perch& s, double a, double dw, const char* what) {
  const double dt = s.w.params().dt;
  for (int k = 1; k <= 20; ++k) {
    s.w.step();
    const BodyVel3& v = s.w.bodies.vel[s.ball];
    const double tol = k == 1 ? 1e-16 / dt : 1e-5 * kG * k * dt;
    if (k != 1 && k != 20) continue;
    EXPECT_NEAR(v.v.y(), a * k * dt, tol) << what << ", step " << k;
    EXPECT_NEAR(v.v.x(), 0.0, tol) << what << ", step " << k;
    EXPECT_NEAR(v.v.z(), 0.0, tol) << what << ", step " << k;
    EXPECT_NEAR(v.w.x() * kr, dw * kr * k * dt, tol) << what << ", step " << k;
    EXPECT_NEAR(v.w.y() * kr, 0.0, tol) << what << ", step " << k;
    EXPECT_NEAR(v.w.z() * kr, 0.0, tol) << what << ", step " << k;
  }
}

}  // namespace

// A ball with its rotation locked on a sphere (tan theta_* = mu) and in a
// 45 deg groove (tan theta_* = mu / cos alpha = 1.41 mu), mu = 0.2: at 0.9
// tan theta_* it sticks (no motion at all), at 1.1 it slides at g (sin
// theta - mu cos theta / cos alpha), each contact carrying N and mu N along
// -y. With mu halved on the rows, 0.9 tan theta_* slides; with the
// friction's sign wrong, nothing sticks.
TEST(SphereFriction3, SlidesOrSticksOnASphereAndInAGroove) {
  const double mu = 0.2, dt = 1e-5;
  for (const Case& cs : kCases)
    for (const double f : {0.9, 1.1}) {
      const double tan_star = mu / std::cos(cs.alpha);
      const double theta = std::atan(f * tan_star);
      Perch s = perch(tilted(theta, dt), cs.nsup, cs.alpha, mu, mu, cs.glued, false);
      const Closed c = closed(theta, cs.alpha, mu, cs.nsup, s.m, s.I);
      char what[128];
      std::snprintf(what, sizeof what, "%s, tan theta = %.1f tan theta_*", name(cs), f);
      expect_motion(s, f < 1 ? 0.0 : c.a_slide, 0.0, what);
      if (f > 1) {
        // The last step's ball rows: normal force N, friction mu N along -y.
        int rows = 0;
        for (const SphereRow& r : s.w.rows()) {
          if (r.b2 != s.ball && r.b1 != s.ball) continue;
          ++rows;
          const double sgn = r.b2 == s.ball ? 1.0 : -1.0;  // force on the ball
          const Vec3 F = sgn * r.to_world(r.r) / dt;
          const Vec3 nb = (sgn * r.n);                      // from the support to the ball
          EXPECT_NEAR(F.dot(nb), c.N, 1e-4 * c.N) << what;
          EXPECT_NEAR(F.y(), -mu * c.N, 1e-4 * c.N) << what;
        }
        EXPECT_EQ(rows, cs.nsup) << what;
      }
      std::printf("%s: v_y %.12g m/s after 20 steps (closed form %.12g)\n", what, s.w.bodies.vel[s.ball].v.y(),
                  (f < 1 ? 0.0 : c.a_slide) * 20 * dt);
    }
}

// The same with rotation: below tan theta_* = mu (5 cos^2 alpha + 2) /
// (2 cos alpha) ((7/2) mu on one sphere, 3.18 mu in the groove) the ball
// rolls at a = g sin theta / (1 + 2 / (5 cos^2 alpha)) ((5/7) g sin theta)
// with v = -w_x r cos alpha; above it both contacts slip: a = g (sin theta -
// mu cos theta / cos alpha), dw_x/dt = -(5/2) mu g cos theta / r.
TEST(SphereFriction3, RollsOrSlipsOnASphereAndInAGroove) {
  const double mu = 0.2, dt = 1e-5;
  for (const Case& cs : kCases)
    for (const double f : {0.9, 1.1}) {
      const double ca = std::cos(cs.alpha);
      const double theta = std::atan(f * mu * (5 * ca * ca + 2) / (2 * ca));
      Perch s = perch(tilted(theta, dt), cs.nsup, cs.alpha, mu, mu, cs.glued, true);
      const Closed c = closed(theta, cs.alpha, mu, cs.nsup, s.m, s.I);
      EXPECT_NEAR(std::tan(theta), f * c.tan_roll, 1e-12);
      char what[128];
      std::snprintf(what, sizeof what, "%s, rolling, tan theta = %.1f tan theta_*", name(cs), f);
      if (f < 1) {
        if (cs.nsup == 1) {
          EXPECT_NEAR(c.a_roll, 5.0 / 7.0 * kG * std::sin(theta), 1e-12);
        }
        expect_motion(s, c.a_roll, -c.a_roll / (kr * ca), what);
      } else {
        expect_motion(s, c.a_slide, c.dw_slide, what);
      }
      std::printf("%s: v_y %.12g m/s, w_x r %.12g after 20 steps (closed form %.12g, %.12g)\n", what,
                  s.w.bodies.vel[s.ball].v.y(), s.w.bodies.vel[s.ball].w.x() * kr,
                  (f < 1 ? c.a_roll : c.a_slide) * 20 * dt,
                  (f < 1 ? -c.a_roll / ca : c.dw_slide * kr) * 20 * dt);
    }
}

// ------------------------------------------------------------ oblique impact

namespace {

// Two free spheres (radii 0.01 and 0.013 m, densities 2600 and 7800), no
// gravity, spinning, meeting obliquely: the contact normal makes ~50 deg with
// the relative velocity. Sphere 2 starts 0.3 dt |u_n| beyond contact, so
// the first step's midpoint overlaps and the impact is that step's alone.
struct Impact {
  World3 w;
  Vec3 v1, v2, w1, w2;
};

Impact impact(double mu, double e_n, double e_t) {
  WorldParams3 p;
  p.dt = 1e-5;
  p.mu = mu;
  p.mu_wall = 0.0;
  p.e_n = e_n;
  p.e_t = e_t;
  p.solver.tol = 1e-15;
  p.solver.max_iter = 100;
  Impact s{World3(p), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  const double r1 = 0.01, r2 = 0.013;
  s.v1 = Vec3(1.0, 0.2, -0.1);
  s.v2 = Vec3(-0.3, 0.1, 0.4);
  s.w1 = Vec3(20.0, -35.0, 10.0);
  s.w2 = Vec3(-15.0, 5.0, 30.0);
  const Vec3 n0 = Vec3(1.0, 0.9, 0.6).normalized();
  const double un = (s.v2 - s.v1).dot(n0);  // < 0: approaching
  const Vec3 x1(0.1, -0.2, 0.3);
  s.w.bodies.add_sphere(x1, r1, 2600, s.v1, s.w1);
  s.w.bodies.add_sphere(x1 + (r1 + r2 - 0.3 * p.dt * un) * n0, r2, 7800, s.v2, s.w2);
  return s;
}

}  // namespace

// Moreau's impact law for a sphere pair, one step, one contact: with W_nn =
// 1/m1 + 1/m2 and W_tt = W_nn + l1^2/I1 + l2^2/I2 (l_i the lever arms, the
// radii to the overlap), u- the relative velocity of the contact point
// before, split into u_n n + u_t:
//   P_n = -(1 + e_n) u_n / W_nn                     (u_n+ = -e_n u_n)
//   stick: P_t = -(1 + e_t) u_t / W_tt              (u_t+ = -e_t u_t) if |P_t| <= mu P_n
//   slip:  P_t = -mu P_n u_t / |u_t|                 otherwise
// (the law on the mean velocities u+ + e u-, whose slip is along u_t), then
// v1 -= P/m1, v2 += P/m2, w1 -= c1 x P / I1, w2 += c2 x P / I2. With
// mu_* = |P_t,stick| / P_n the threshold: mu = 1.25 mu_* sticks, 0.8 mu_*
// slips, each for (e_n, e_t) = (0.5, 0), (0.5, 0.4), (0.9, 0.9). mu/2 turns
// the first into a slip and halves the second's tangential impulse.
TEST(SphereFriction3, ObliqueImpactMatchesMoreausLaw) {
  for (const auto& [e_n, e_t] : {std::pair{0.5, 0.0}, std::pair{0.5, 0.4}, std::pair{0.9, 0.9}})
    for (const double f : {1.25, 0.8}) {
      // The threshold from a frictionless dry run's geometry (identical:
      // the midpoint configuration does not depend on mu).
      Impact probe = impact(0.0, e_n, e_t);
      probe.w.step();
      ASSERT_EQ(probe.w.rows().size(), 1u);
      const SphereRow r0 = probe.w.rows()[0];
      const Bodies3& b0 = probe.w.bodies;
      auto impulse = [&](const SphereRow& r, double mu, bool& slip) {
        const double m1 = b0.mass[0], m2 = b0.mass[1], I1 = b0.inertia[0], I2 = b0.inertia[1];
        const Vec3 u = (probe.v2 + probe.w2.cross(r.c2)) - (probe.v1 + probe.w1.cross(r.c1));
        const double un = u.dot(r.n);
        const Vec3 ut = u - un * r.n;
        const double wnn = 1 / m1 + 1 / m2, wtt = wnn + r.c1.squaredNorm() / I1 + r.c2.squaredNorm() / I2;
        const double pn = -(1 + e_n) * un / wnn;
        Vec3 pt = -(1 + e_t) * ut / wtt;
        slip = pt.norm() > mu * pn;
        if (slip) pt = -mu * pn * ut.normalized();
        return Vec3(pn * r.n + pt);
      };
      bool slip0;
      const Vec3 P0 = impulse(r0, 1e300, slip0);
      const double mu_star = (P0 - P0.dot(r0.n) * r0.n).norm() / P0.dot(r0.n);
      const double mu = f * mu_star;

      Impact s = impact(mu, e_n, e_t);
      const double e0 = s.w.kinetic_energy();
      s.w.step();
      ASSERT_EQ(s.w.rows().size(), 1u);
      const SphereRow& r = s.w.rows()[0];
      ASSERT_EQ(r.b1, 0);
      // The frame against the geometry: n along the midpoint centre line,
      // lever arms the radii to the overlap.
      const Vec3 x1m = Vec3(0.1, -0.2, 0.3) + 0.5 * s.w.params().dt * s.v1;
      const Vec3 x2m = s.w.bodies.pos[1] - 0.5 * s.w.params().dt * s.w.bodies.vel[1].v;
      EXPECT_LT((r.n - (x2m - x1m).normalized()).norm(), 1e-12);
      const double overlap = 0.023 - (x2m - x1m).norm();
      EXPECT_GT(overlap, 0.0);
      EXPECT_NEAR(r.c1.norm(), 0.01, overlap);
      EXPECT_NEAR(r.c2.norm(), 0.013, overlap);

      bool slip;
      const Vec3 P = impulse(r, mu, slip);
      EXPECT_EQ(slip, f < 1);
      const Bodies3& b = s.w.bodies;
      const double scale = 1.0;  // m/s: the velocities are O(1)
      char what[96];
      std::snprintf(what, sizeof what, "e_n %.1f e_t %.1f mu %.2f mu_*", e_n, e_t, f);
      EXPECT_LT((b.vel[0].v - (s.v1 - P / b.mass[0])).norm(), 1e-12 * scale) << what;
      EXPECT_LT((b.vel[1].v - (s.v2 + P / b.mass[1])).norm(), 1e-12 * scale) << what;
      EXPECT_LT(0.01 * (b.vel[0].w - (s.w1 - r.c1.cross(P) / b.inertia[0])).norm(), 1e-12 * scale) << what;
      EXPECT_LT(0.013 * (b.vel[1].w - (s.w2 + r.c2.cross(P) / b.inertia[1])).norm(), 1e-12 * scale) << what;
      // The outcome's physics: normal restitution; a stick restitutes the
      // tangential velocity, a slip keeps the friction on the cone.
      const Vec3 um = (s.v2 + s.w2.cross(r.c2)) - (s.v1 + s.w1.cross(r.c1));
      const Vec3 up = (b.vel[1].v + b.vel[1].w.cross(r.c2)) - (b.vel[0].v + b.vel[0].w.cross(r.c1));
      EXPECT_NEAR(up.dot(r.n), -e_n * um.dot(r.n), 1e-12) << what;
      const Vec3 ut_m = um - um.dot(r.n) * r.n, ut_p = up - up.dot(r.n) * r.n;
      if (!slip) {
        EXPECT_LT((ut_p + e_t * ut_m).norm(), 1e-12) << what;
      } else {
        const Vec3 Pt = r.r[1] * r.t1 + r.r[2] * r.t2;
        EXPECT_NEAR(Pt.norm(), mu * r.r[0], 1e-12 * r.r[0]) << what;
        EXPECT_LT(Pt.normalized().dot(ut_m.normalized()), -1 + 1e-12) << what;
      }
      EXPECT_LE(s.w.kinetic_energy(), e0 * (1 + 1e-14)) << what;
      const Vec3 mom = b.mass[0] * b.vel[0].v + b.mass[1] * b.vel[1].v;
      EXPECT_LT((mom - (b.mass[0] * s.v1 + b.mass[1] * s.v2)).norm(), 1e-14 * (b.mass[0] + b.mass[1])) << what;
      std::printf("impact %s (mu_* %.4f): P_n %.6g, |P_t| %.6g, %s; KE %.6g -> %.6g J\n", what, mu_star, r.r[0],
                  std::hypot(r.r[1], r.r[2]), slip ? "slip" : "stick", e0, s.w.kinetic_energy());
    }
}

// -------------------------------------------------------------- orthotropic

// A ball with its rotation locked on a heavy sphere, orthotropic cone
// between them (mu_a = 0.6 along axis_a = (1, 0.4, 0.7) projected on the
// tangent plane, the horizontal plane here, mu_b = 0.2 across it):
//  - sliding along t_a at v0, no tangential gravity, it decelerates at mu_a g,
//    along t_b at mu_b g (a point of the a or b axis projects on the
//    ellipse's vertex, so the friction is -mu_{a,b} N along the sliding);
//  - from rest, tangential gravity at 60 deg from t_a with |D^-1 g_t| = 0.95
//    g_n (D = diag(mu_a, mu_b)) sticks, although |g_t| > mu_b g_n (a round
//    cone of mu_b would slide); at 1.05 g_n it slides.
TEST(SphereFriction3, OrthotropicConeBetweenSpheres) {
  const double mu_a = 0.6, mu_b = 0.2, dt = 1e-5, v0 = 0.01;
  const Vec3 axis(1.0, 0.4, 0.7);
  const Vec3 ta = Vec3(1.0, 0.4, 0.0).normalized(), tb = Vec3(0, 0, 1).cross(ta);
  auto params = [&](const Vec3& g) {
    WorldParams3 p;
    p.dt = dt;
    p.gravity = g;
    p.orthotropic = true;
    p.axis_a = axis;
    return p;
  };
  for (const bool along_a : {true, false}) {
    Perch s = perch(params(Vec3(0, 0, -kG)), 1, 0.0, mu_a, mu_b, false, false);
    const Vec3 d = along_a ? ta : tb;
    const double decel = (along_a ? mu_a : mu_b) * kG;
    s.w.bodies.vel[s.ball].v = v0 * d;
    // 10 steps: the ball moves 1e-6 m over a sphere of radius 1.5e-2 (the
    // normal turns by eps = 4e-5), which lends gravity a tangential 4e-4
    // m/s^2 against a deceleration of 2 to 6 m/s^2 (1e-3 of the velocity
    // change) and tilts the velocity down by v0 eps.
    const Vec3 side = Vec3(0, 0, 1).cross(d);
    for (int k = 1; k <= 10; ++k) {
      s.w.step();
      const Vec3 v = s.w.bodies.vel[s.ball].v;
      const double eps = 2 * v0 * k * dt / (kr + kR);
      EXPECT_NEAR(v.dot(d), v0 - decel * k * dt, 1e-3 * decel * k * dt) << (along_a ? "a" : "b") << " step " << k;
      EXPECT_LT(std::abs(v.dot(side)), 1e-3 * decel * k * dt) << (along_a ? "a" : "b") << " step " << k;
      EXPECT_LT(std::abs(v.z()), v0 * eps) << (along_a ? "a" : "b") << " step " << k;
    }
    std::printf("orthotropic between spheres, sliding along t_%s: v %.12g (closed form %.12g)\n", along_a ? "a" : "b",
                s.w.bodies.vel[s.ball].v.dot(d), v0 - decel * 10 * dt);
  }
  const double phi = 60 * kPi / 180;
  const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
  for (const double ratio : {0.95, 1.05}) {
    const double len = ratio * kG / std::hypot(dir[0] / mu_a, dir[1] / mu_b);
    const Vec3 gt = len * (dir[0] * ta + dir[1] * tb);
    Perch s = perch(params(Vec3(0, 0, -kG) + gt), 1, 0.0, mu_a, mu_b, false, false);
    for (int k = 0; k < 20; ++k) s.w.step();
    const Vec3 v = s.w.bodies.vel[s.ball].v;
    if (ratio < 1) {
      EXPECT_GT(len, mu_b * kG);
      EXPECT_LT(v.norm(), 1e-16 / dt);  // the placement's round-off (above)
    } else {
      EXPECT_GT(v.norm(), 0.01 * len * 20 * dt);
    }
    std::printf("orthotropic between spheres, |D^-1 g_t| = %.2f g_n: |v| %.3g after 20 steps\n", ratio, v.norm());
  }
}
