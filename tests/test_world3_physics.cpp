// The 3D engine's physics options: restitution by mean
// velocities (Newton's cradle, a ball's rebound, a rough elastic bounce),
// orthotropic Coulomb on walls (the elliptic projection against law3's
// general solver; sliding direction and acceleration on an anisotropic
// plane; stick below the elliptic threshold), and the periodic cell with
// Lees-Edwards images (detection against brute force over images, a
// collision through the sheared boundary, thread independence).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>
#include <tuple>

#include <omp.h>

#include "coupling3.hpp"
#include "detect3.hpp"
#include "law3.hpp"
#include "pile3d.hpp"
#include "world3.hpp"
#include "world3_hash.hpp"

using namespace cd;

namespace {

constexpr double kG = 9.81;

}  // namespace

// Scenes without the options compute what they computed before the options
// existed, bit for bit: hashes recorded on commit cb1c628 (a standalone
// build of its cd/src/3d with the same -O2 flags; tests/world3_hash.hpp).
// Re-recorded once since, for a change of round-off only: the sweep's rows
// as contact3.hpp's SweepRow3 (c53e3ac; the values before it:
// 0xd9c05964c76f154e, 0xab0eb47c9521ec65, 0x81f8628b9153b7c9,
// 0x7069d1e47d13c479), checked by frozen steps of every law solved both ways
// (impulses within 1.2e-14 of the largest after 3000 sweeps) and pile runs
// agreeing to 9 digits over 150 steps.
TEST(World3Options, OffLeavesTheDefaultPathBitIdentical) {
  const std::uint64_t expect[4] = {0x3ef6f60f46f8baf7ull, 0xd265802c13d6ad6bull, 0xb5225d8fd73317f4ull,
                                   0x5f0fca0280d94942ull};
  for (int k = 0; k < 4; ++k) EXPECT_EQ(cdtest::world3_scene_hash(k), expect[k]) << "scene " << k;
}

// ---------------------------------------------------------------- restitution

// Five equal spheres on a line along (1, 2, 2)/3, gaps of 1e-3 r between
// them, the first at v0 towards the others (no gravity, friction on, e_n =
// 1). The impacts are sequential (the gaps take 10 steps to close), and a
// binary impact with e_n = 1 exchanges the two velocities exactly: the last
// sphere leaves with the whole momentum and energy, the others stay at rest.
TEST(Restitution3, NewtonsCradle) {
  WorldParams3 p;
  p.dt = 1e-6;
  p.mu = p.mu_wall = 0.3;
  p.e_n = 1.0;
  p.alert = 1e-3;  // ignored with restitution (alert 0)
  p.solver.tol = 1e-14;
  World3 w(p);
  const Vec3 d = Vec3(1, 2, 2) / 3.0;
  const double r = 0.01, gap = 1e-5, v0 = 1.0;
  const int n = 5;
  for (int k = 0; k < n; ++k)
    w.bodies.add_sphere(Vec3(0.1, -0.2, 0.3) + k * (2 * r + gap) * d, r, 7800, k == 0 ? Vec3(v0 * d) : Vec3::Zero());
  const double m = w.bodies.mass[0];
  int impacts = 0;
  for (int s = 0; s < 100; ++s) {
    w.step();
    for (const SphereRow& row : w.rows()) impacts += row.r[0] > 0.0;
  }
  EXPECT_EQ(impacts, n - 1);  // one step each, one row active in it
  for (int k = 0; k < n - 1; ++k) {
    EXPECT_LT(w.bodies.vel[k].v.norm(), 1e-14 * v0) << k;
    EXPECT_LT(w.bodies.vel[k].w.norm() * r, 1e-14 * v0) << k;
  }
  EXPECT_LT((w.bodies.vel[n - 1].v - v0 * d).norm(), 1e-14 * v0);
  Vec3 P = Vec3::Zero();
  for (int k = 0; k < n; ++k) P += m * w.bodies.vel[k].v;
  EXPECT_LT((P - m * v0 * d).norm(), 1e-14 * m * v0);
  EXPECT_NEAR(w.kinetic_energy(), 0.5 * m * v0 * v0, 1e-14 * 0.5 * m * v0 * v0);
  std::printf("cradle: last %.17g m/s, others <= %.3g m/s\n", w.bodies.vel[n - 1].v.dot(d),
              std::max({w.bodies.vel[0].v.norm(), w.bodies.vel[1].v.norm(), w.bodies.vel[2].v.norm(),
                        w.bodies.vel[3].v.norm()}));
}

// The same law with three touching spheres (overlaps of 1e-9 r): the two
// impacts are simultaneous and Moreau's law solves them together. With p, q
// the impulses of contacts 12, 23: u+_12 - v0 = (2p - q)/m - 2 v0 >= 0 and
// u+_23 = (2q - p)/m >= 0, both active: p = 4/3 m v0, q = 2/3 m v0, so the
// spheres leave at (-1/3, 2/3, 2/3) v0 (momentum and, here, energy kept),
// not at (0, 0, v0): why the cradle above has gaps.
TEST(Restitution3, TouchingCradleSharesTheMomentum) {
  WorldParams3 p;
  p.dt = 1e-6;
  p.e_n = 1.0;
  p.solver.tol = 1e-15;
  p.solver.max_iter = 100000;
  World3 w(p);
  const Vec3 d = Vec3(2, -1, 2) / 3.0;
  const double r = 0.01, v0 = 1.0;
  for (int k = 0; k < 3; ++k)
    w.bodies.add_sphere(k * (2 * r - 1e-9 * r) * d, r, 7800, k == 0 ? Vec3(v0 * d) : Vec3::Zero());
  w.step();
  ASSERT_EQ(w.rows().size(), 2u);
  const double expect[3] = {-1.0 / 3, 2.0 / 3, 2.0 / 3};
  for (int k = 0; k < 3; ++k) EXPECT_LT((w.bodies.vel[k].v - expect[k] * v0 * d).norm(), 1e-12 * v0) << k;
  std::printf("touching cradle: %.15g %.15g %.15g (-1/3, 2/3, 2/3), %d sweeps\n", w.bodies.vel[0].v.dot(d),
              w.bodies.vel[1].v.dot(d), w.bodies.vel[2].v.dot(d), w.last().solve.iterations);
}

// A ball dropped from h onto a plane with e_n = 0.5: in the impact step the
// law u+ + e_n u- = 0 (u- the velocity at the step's start, before gravity)
// gives v+ = -e_n v- exactly; v- is sqrt(2 g h) to one step's g dt; the
// rebound peaks at e_n^2 h to the distance of a step at impact speed.
TEST(Restitution3, BallReboundsAtHalfTheImpactSpeed) {
  WorldParams3 p;
  p.dt = 1e-4;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.5;
  p.e_n = 0.5;
  p.solver.tol = 1e-14;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.01, h = 0.05;
  const int s = w.bodies.add_sphere(Vec3(0.02, -0.03, r + h), r, 2600);
  double v_before = 0, v_after = 0;
  int impact_steps = 0;
  for (int k = 0; k < 2000 && impact_steps == 0; ++k) {
    const double vz = w.bodies.vel[s].v.z();
    w.step();
    if (!w.rows().empty() && w.rows()[0].r[0] > 0.0) {
      ++impact_steps;
      v_before = vz;
      v_after = w.bodies.vel[s].v.z();
    }
  }
  ASSERT_EQ(impact_steps, 1);
  const double vi = std::sqrt(2 * kG * h);
  EXPECT_NEAR(-v_before, vi, kG * p.dt);
  EXPECT_NEAR(v_after, -0.5 * v_before, 1e-13 * vi);
  EXPECT_EQ(w.bodies.vel[s].v.x(), 0.0);
  double zmax = 0;
  for (int k = 0; k < 2000; ++k) {
    w.step();
    zmax = std::max(zmax, w.bodies.pos[s].z() - r);
    if (w.bodies.vel[s].v.z() < 0) break;
  }
  EXPECT_NEAR(zmax, 0.25 * h, 2 * vi * p.dt);
  std::printf("rebound: impact %.6f m/s (sqrt(2gh) %.6f), after %.17g = %.17g x impact; peak %.6g (e^2 h %.6g)\n",
              -v_before, vi, v_after, -v_after / v_before, zmax, 0.25 * h);
}

// A rough elastic bounce (e_n = e_t = 1, mu large: the stick trial is inside
// the cone): a sphere at (1, 0, -1) m/s without spin meets a plane. The
// contact velocity reverses, u+ = -u- (slip measured at the row's lever arm
// c, of length l = r - overlap/2): v_z = 1, slip -1, v_x = 1 - 2/(m W_tt)
// with W_tt = 1/m + l^2/I (3/7 for l = r); kinetic energy is conserved.
TEST(Restitution3, RoughElasticBounceReversesTheContactVelocity) {
  WorldParams3 p;
  p.dt = 1e-5;
  p.mu = p.mu_wall = 10.0;
  p.e_n = p.e_t = 1.0;
  p.solver.tol = 1e-14;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.01;
  const int s = w.bodies.add_sphere(Vec3(0, 0, r + 2e-6), r, 2600, Vec3(1, 0, -1));
  const double e0 = w.kinetic_energy(), m = w.bodies.mass[s], I = w.bodies.inertia[s];
  int impacts = 0;
  Vec3 c = Vec3::Zero();
  for (int k = 0; k < 20; ++k) {
    w.step();
    for (const SphereRow& row : w.rows())
      if (row.r[0] > 0.0) {
        ++impacts;
        c = row.c2;
      }
  }
  ASSERT_EQ(impacts, 1);
  const BodyVel3& v = w.bodies.vel[s];
  const double wtt = 1 / m + c.squaredNorm() / I;
  EXPECT_NEAR(v.v.z(), 1.0, 1e-14);
  EXPECT_NEAR(v.v.x(), 1.0 - 2.0 / (m * wtt), 1e-14);
  EXPECT_NEAR(v.v.x(), 3.0 / 7.0, 2 * (r - c.norm()) / r);  // l = r to the overlap
  EXPECT_NEAR((v.v + v.w.cross(c)).x(), -1.0, 1e-14);
  EXPECT_LT(std::abs(v.v.y()) + std::abs((v.v + v.w.cross(c)).y()), 1e-14);
  EXPECT_NEAR(w.kinetic_energy(), e0, 1e-14 * e0);
  std::printf("rough bounce: v_x %.15g (3/7 = %.15g at l = r; l = r - %.3g), slip %.15g\n", v.v.x(), 3.0 / 7,
              r - c.norm(), (v.v + v.w.cross(c)).x());
}

// ------------------------------------------------------------- orthotropic

// project_ellipse: on the ellipse, y - x along the ellipse's normal, and the
// sphere-block orthotropic solve equals law3's general solve_local3 with W =
// diag(W_nn, W_tt, W_tt) on random samples.
TEST(Orthotropic3, EllipticSolveMatchesTheGeneralSolver) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N;
  double worst_on = 0, worst_normal = 0, worst_diff = 0, worst_res = 0;
  int slides = 0;
  for (int k = 0; k < 20000; ++k) {
    const double e1 = std::exp(4 * U(rng) - 2), e2 = std::exp(4 * U(rng) - 2);
    const Eigen::Vector2d y(N(rng) * 3, N(rng) * 3);
    const Eigen::Vector2d x = project_ellipse(y, e1, e2);
    const double q = std::hypot(y[0] / e1, y[1] / e2);
    if (q > 1) {
      worst_on = std::max(worst_on, std::abs(std::hypot(x[0] / e1, x[1] / e2) - 1.0));
      const Eigen::Vector2d nrm(x[0] / (e1 * e1), x[1] / (e2 * e2));
      const Eigen::Vector2d dv = y - x;
      worst_normal = std::max(worst_normal, std::abs(nrm[0] * dv[1] - nrm[1] * dv[0]) / (nrm.norm() * dv.norm()));
      EXPECT_GE(nrm.dot(dv), 0.0);
    } else {
      EXPECT_EQ(x, y);
    }
    // The local solve.
    const double wnn = std::exp(2 * U(rng) - 1), wtt = wnn * (1 + 3 * U(rng));
    const Vec3 qv(N(rng), N(rng), N(rng));
    const double mu_a = 0.05 + U(rng), mu_b = 0.05 + U(rng), a = U(rng) < 0.3 ? 0.5 * U(rng) : 0.0;
    Vec3 r1, r2;
    const Branch3 b1 = solve_sphere3_ortho(wnn, wtt, qv, mu_a, mu_b, a, r1);
    const Mat3 W = Vec3(wnn, wtt, wtt).asDiagonal();
    solve_local3(W, qv, Cone3{mu_a, mu_b}, a, r2);
    slides += b1 == Branch3::Slide;
    const double scale = qv.norm() / wnn + a;
    worst_diff = std::max(worst_diff, (r1 - r2).norm() / scale);
    worst_res = std::max(worst_res, law_residual3(W * r1 + qv, r1, Cone3{mu_a, mu_b}, a, 1.0 / wnn) / scale);
  }
  std::printf("ellipse: on %.2g, normal %.2g; solve vs solve_local3 %.2g, residual %.2g, %d slides\n",
              worst_on, worst_normal, worst_diff, worst_res, slides);
  EXPECT_LT(worst_on, 1e-14);
  EXPECT_LT(worst_normal, 1e-12);
  EXPECT_LT(worst_diff, 1e-12);
  EXPECT_LT(worst_res, 1e-13);
  EXPECT_GT(slides, 4000);
}

namespace {

// A sphere (rotation locked) on a tilted plane whose friction axes are
// axis_a projected on it (mu_a along it, mu_b across); gravity chosen in the
// test. Returns the world, the sphere, and the plane's frame (n, ta, tb).
struct OrthoPlane {
  World3 w;
  int s;
  Vec3 n, ta, tb;
  double m;
};

OrthoPlane ortho_plane(double mu_a, double mu_b, const Vec3& gravity, const Vec3& v0, const Vec3& n,
                       const Vec3& axis) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = gravity;
  p.mu_wall = mu_a;
  p.mu_wall_b = mu_b;
  p.mu = 0.9;
  p.mu_b = 0.1;
  p.orthotropic = true;
  p.axis_a = axis;
  p.alert = 1e-3;
  p.solver.tol = 1e-14;
  OrthoPlane o{World3(p), 0, n, Vec3::Zero(), Vec3::Zero(), 0};
  o.w.bodies.add_plane(Vec3(0.01, 0.02, -0.03), n);
  const double r = 0.01;
  o.s = o.w.bodies.add_sphere(Vec3(0.01, 0.02, -0.03) + r * n, r, 2600, v0);
  o.w.bodies.vel[o.s].inv_I = 0.0;
  o.m = o.w.bodies.mass[o.s];
  o.ta = (axis - axis.dot(n) * n).normalized();
  o.tb = n.cross(o.ta);
  return o;
}

}  // namespace

// Sliding on an orthotropic plane (mu_a = 0.6, mu_b = 0.2) along d, at an
// angle phi = 35 deg from the a axis. The elliptic law's friction is
// -m g_n D^2 d / |D d| (D = diag(mu_a, mu_b) in (ta, tb)), not opposite to
// d; with gravity's tangential part g_t = lambda d + g_n D^2 d / |D d| the
// sphere slides straight along d at acceleration lambda, the projection of
// the stick trial being exactly that friction at every step. The plane is
// tilted and axis_a is not in it (its projection is the a axis).
TEST(Orthotropic3, SlidesAlongTheEllipticLawsDirection) {
  const double mu_a = 0.6, mu_b = 0.2, gn = kG, lambda = 1.5, phi = 35 * std::numbers::pi / 180;
  const Vec3 n = Vec3(0.3, -0.2, 1.0).normalized(), axis(1.0, 0.4, 0.7);
  const Vec3 ta = (axis - axis.dot(n) * n).normalized(), tb = n.cross(ta);
  const Eigen::Vector2d dl(std::cos(phi), std::sin(phi));
  const Eigen::Vector2d Dd(mu_a * dl[0], mu_b * dl[1]);
  const Eigen::Vector2d f = -gn * Eigen::Vector2d(mu_a * Dd[0], mu_b * Dd[1]) / Dd.norm();  // per unit mass
  const Eigen::Vector2d gt = lambda * dl - f;
  const Vec3 d = dl[0] * ta + dl[1] * tb;
  const Vec3 g = -gn * n + gt[0] * ta + gt[1] * tb;
  const double v0 = 0.2;
  OrthoPlane o = ortho_plane(mu_a, mu_b, g, v0 * d, n, axis);
  const int steps = 300;
  double res = 0;
  for (int k = 0; k < steps; ++k) {
    o.w.step();
    res = std::max(res, o.w.last().solve.residual_max);
  }
  const Vec3 v = o.w.bodies.vel[o.s].v;
  const double expect = v0 + lambda * steps * o.w.params().dt;
  EXPECT_NEAR(v.dot(d), expect, 1e-12 * expect);
  EXPECT_LT((v - v.dot(d) * d).norm(), 1e-12 * expect);
  // The friction impulse of the last step, world frame: f m dt.
  ASSERT_EQ(o.w.rows().size(), 1u);
  const SphereRow& row = o.w.rows()[0];
  EXPECT_LT((row.t1 - ta).norm(), 1e-14);
  const Vec3 F = row.r[1] * row.t1 + row.r[2] * row.t2;
  const Vec3 Fx = o.m * o.w.params().dt * (f[0] * ta + f[1] * tb);
  EXPECT_LT((F - Fx).norm(), 1e-12 * Fx.norm());
  const double angle = std::acos(-F.normalized().dot(d)) * 180 / std::numbers::pi;
  EXPECT_GT(angle, 10.0);  // the friction is not opposite to the sliding
  EXPECT_LE(res, 1e-12);
  std::printf("orthotropic slide: v.d %.15g (expect %.15g), off-d %.2g, friction %.2f deg off -d\n", v.dot(d),
              expect, (v - v.dot(d) * d).norm(), angle);
}

// Starting at rest with |D^-1 g_t| = 0.95 g_n (direction 60 deg from a,
// where a round cone of mu_b would slide) the sphere sticks, with friction
// -m g_t dt; at 1.05 g_n it slides.
// One friction decision (World3::configure): an orthotropic cone with mu = 0
// along t1 and mu_b > 0 along t2 has friction, so the next step's warm start
// keeps the remembered tangential impulse on the new frame. A build stage
// that decided friction from mu and mu_wall alone would zero it while the
// law (which counts mu_b) solves with friction: each step would start its
// tangential impulses from 0. Checked on a settling pile: the rows handed to
// the solver carry the previous step's impulse, re-projected, tangential
// part included.
TEST(Orthotropic3, WarmStartKeepsFrictionWhenOnlyMuBIsSet) {
  Pile3dParams q;
  q.n_spheres = 100;
  q.solver.tol = 1e-6;
  q.solver.max_iter = 300;
  World3 w = make_pile3d(q);
  WorldParams3 p = w.params();
  p.orthotropic = true;
  p.axis_a = Vec3(1, 0, 0);
  p.mu = p.mu_wall = 0.0;
  p.mu_b = p.mu_wall_b = 0.4;
  w.set_params(p);
  for (int k = 0; k < 150; ++k) w.step();
  const World3::WarmStart warm = w.warm_start();
  double tmax = 0;
  for (const Vec3& P : warm.p) tmax = std::max(tmax, P.norm());
  ASSERT_GT(tmax, 0.0);
  int matched = 0, tangential = 0, differ = 0;
  w.set_problem_hook([&](const ContactProblem3& pr, const SolverParams&) {
    for (std::size_t k = 0; k < pr.rows.size(); ++k) {
      const SphereRow& r = pr.rows[k];
      const auto it = std::lower_bound(warm.keys.begin(), warm.keys.end(), w.infos()[k].key);
      if (it == warm.keys.end() || *it != w.infos()[k].key) continue;
      ++matched;
      const Vec3 expect = r.to_frame(warm.p[it - warm.keys.begin()]);
      if (std::hypot(expect[1], expect[2]) > 1e-9 * tmax) ++tangential;
      differ += r.r != expect;
    }
  });
  w.step();
  std::printf("orthotropic mu = 0, mu_b = 0.4: %d warm-started rows, %d with a tangential impulse, %d differ\n",
              matched, tangential, differ);
  EXPECT_GT(matched, 100);
  EXPECT_GT(tangential, 10);
  EXPECT_EQ(differ, 0);
}

TEST(Orthotropic3, SticksBelowTheEllipticThreshold) {
  const double mu_a = 0.6, mu_b = 0.2, gn = kG, phi = 60 * std::numbers::pi / 180;
  const Vec3 n = Vec3(-0.1, 0.25, 1.0).normalized(), axis(0.2, 1.0, 0.0);
  const Vec3 ta = (axis - axis.dot(n) * n).normalized(), tb = n.cross(ta);
  for (const double ratio : {0.95, 1.05}) {
    // g_t along (cos, sin) with |D^-1 g_t| = ratio g_n.
    const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
    const double len = ratio * gn / std::hypot(dir[0] / mu_a, dir[1] / mu_b);
    const Vec3 gtw = len * (dir[0] * ta + dir[1] * tb);
    OrthoPlane o = ortho_plane(mu_a, mu_b, -gn * n + gtw, Vec3::Zero(), n, axis);
    for (int k = 0; k < 200; ++k) o.w.step();
    const Vec3 v = o.w.bodies.vel[o.s].v;
    if (ratio < 1) {
      EXPECT_GT(len, mu_b * gn);  // a round cone of mu_b would let it slide
      EXPECT_LT(v.norm(), 1e-14 * len * 200 * o.w.params().dt);  // round-off of g_t t
      const SphereRow& row = o.w.rows()[0];
      const Vec3 F = row.r[1] * row.t1 + row.r[2] * row.t2;
      EXPECT_LT((F + o.m * o.w.params().dt * gtw).norm(), 1e-12 * o.m * o.w.params().dt * len);
      EXPECT_NEAR(row.r[0], o.m * gn * o.w.params().dt, 1e-12 * o.m * gn * o.w.params().dt);
    } else {
      EXPECT_GT(v.norm(), 0.01 * len * 0.2);
      EXPECT_LT(std::abs(v.dot(n)), 1e-14);
    }
  }
}

// ---------------------------------------------------------------- periodic

namespace {

struct Found {
  double gap;
  Vec3 branch;
  std::array<int, 3> k;
};

// Every (i, j, image) within reach, by brute force over images -2..2 (x:
// -6..6, for Lees-Edwards offsets up to 4 L_x).
std::map<std::pair<int, int>, Found> brute(const Bodies3& b, const PeriodicCell3& c, double alert) {
  std::map<std::pair<int, int>, Found> out;
  const int n = static_cast<int>(b.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int kx = -6; kx <= 6; ++kx)  // offsets up to 4 L_x
        for (int ky = -2; ky <= 2; ++ky)
          for (int kz = -2; kz <= 2; ++kz) {
            const std::array<int, 3> k{kx, ky, kz};
            bool ok = true;
            for (int a = 0; a < 3; ++a) ok = ok && (c.periodic[a] || k[a] == 0);
            if (!ok) continue;
            const Vec3 xj = b.pos[j] + c.shift(k);
            const Vec3 d = xj - b.pos[i];
            const double gap = d.norm() - b.radius[i] - b.radius[j];
            if (gap <= alert) {
              EXPECT_EQ(out.count({i, j}), 0u) << "two images of one pair within reach";
              out[{i, j}] = {gap, d, k};
            }
          }
  return out;
}

}  // namespace

// Random spheres (some just outside the cell, as midpoints are) in cells
// periodic along every subset of axes, with and without a Lees-Edwards
// offset, periodic lengths from 2 to 6 reaches (1 to 6 cells of the grid):
// detect3 finds exactly the pairs brute force over the images finds, with
// the same image, gap and branch vector (to 1e-12 of the radius).
TEST(Periodic3, DetectionEqualsBruteForceOverImages) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double r = 1.0, alert = 0.2;
  const double reach = 2 * 1.2 * r + alert;
  int cases = 0, total = 0, imaged = 0;
  for (int mask = 1; mask < 8; ++mask)
    for (const double le : {0.0, 0.37, -0.81})
      for (int rep = 0; rep < 4; ++rep) {
        PeriodicCell3 c;
        c.periodic = {(mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0};
        if (le != 0.0 && !(c.periodic[0] && c.periodic[1])) continue;
        c.origin = Vec3(-1.3, 2.1, 0.4);
        for (int a = 0; a < 3; ++a) c.size[a] = reach * (2.0 + 4.0 * U(rng));
        c.le_offset = le * c.size.x() * (1 + rep);
        Bodies3 b;
        const int n = 60 + 40 * rep;
        for (int i = 0; i < n; ++i) {
          Vec3 x;
          for (int a = 0; a < 3; ++a)
            x[a] = c.origin[a] + (U(rng) * 1.04 - 0.02) * (c.periodic[a] ? c.size[a] : 12.0 * r);
          b.add_sphere(x, r * (0.8 + 0.4 * U(rng)), 1000);
        }
        CellGrid3 grid;
        std::vector<SphereRow> rows;
        std::vector<ContactInfo3> info;
        detect3(b, b.pos, alert, c, grid, rows, info, 1 << 30);
        const auto ref = brute(b, c, alert);
        ASSERT_EQ(rows.size(), ref.size()) << "mask " << mask << " le " << le;
        for (std::size_t k = 0; k < rows.size(); ++k) {
          const int i = std::min(rows[k].b1, rows[k].b2), j = std::max(rows[k].b1, rows[k].b2);
          const auto it = ref.find({i, j});
          ASSERT_NE(it, ref.end());
          EXPECT_EQ(rows[k].b1, i);
          EXPECT_NEAR(info[k].gap, it->second.gap, 1e-12 * r);
          EXPECT_LT((info[k].branch - it->second.branch).norm(), 1e-12 * r);
          EXPECT_EQ(info[k].ix, it->second.k[0]);
          EXPECT_EQ(info[k].iy, it->second.k[1]);
          EXPECT_EQ(info[k].iz, it->second.k[2]);
          EXPECT_LT((rows[k].n - it->second.branch.normalized()).norm(), 1e-14);
          imaged += info[k].ix != 0 || info[k].iy != 0 || info[k].iz != 0;
        }
        ++cases;
        total += static_cast<int>(rows.size());
      }
  std::printf("periodic detection: %d cases, %d pairs (%d through images)\n", cases, total, imaged);
  EXPECT_GT(imaged, 200);
}

// A collision through the sheared y boundary of a tri-periodic
// Lees-Edwards cell (offset 0.3 L_x, images moving at V = 0.5 m/s): sphere A
// crosses the top before it meets B's image, and is brought back at the
// bottom (y - L_y, x - offset, v_x - V). The relative velocity the contact
// sees (through the image of whichever body is body 2) is unchanged by the
// crossing; the frictionless elastic impact (e_n = 1) reverses its normal
// part, keeps its tangential part and conserves the pair's momentum, to
// round-off. With the images' velocity missing the normal velocity would be
// off by V n_x.
// cross_first: A crosses the top and is brought back before the contact
// (which is then inside the cell: the crossing's velocity shift is what is
// tested); otherwise A starts 0.6 r_a below the top, meets B's image before
// it would cross and bounces back: the contact is through the moving image
// (row with iy != 0), so the image velocity the row adds is what is tested
// (its sign flipped, u_n would be off by 2 V n_x).
static void sheared_boundary_impact(bool cross_first) {
  const double ra = 0.01, rb = 0.013, L = 0.1, V = 0.5, u = 1.0;
  WorldParams3 p;
  p.dt = 1e-5;
  p.e_n = 1.0;
  p.solver.tol = 1e-14;
  p.cell = Vec3(L, L, L);
  p.periodic = {true, true, true};
  p.le_offset = 0.3 * L;
  p.le_velocity = V;
  World3 w(p);
  // A at the top moving up; B at the bottom moving down. B's image (+1 in
  // y) is at x_B + (offset, L, 0) and moves at v_B + V e_x; placed at t = 0
  // so that A crosses the top (after 0.1 r_a / u) before the contact (after
  // ~0.25 r_a / u), with a normal having x and z parts.
  const Vec3 xa(0.05, L - (cross_first ? 0.1 : 0.6) * ra, 0.05);
  const Vec3 xb_img = xa + Vec3(0.4 * ra, ra + rb + 0.5 * ra, 0.3 * ra);
  const Vec3 xb = xb_img - Vec3(p.le_offset, L, 0.0);
  const int a = w.bodies.add_sphere(xa, ra, 2600, Vec3(0.1, u, 0.0));
  const int b = w.bodies.add_sphere(xb, rb, 2600, Vec3(-0.2, -u, 0.05));
  const double ma = w.bodies.mass[a], mb = w.bodies.mass[b];
  // Relative velocity of B's image as seen from A, with the image counts of
  // the row (or of the nearest image when there is no row).
  auto rel_velocity = [&](Vec3& n) {
    PeriodicCell3 c;
    c.size = p.cell;
    c.periodic = p.periodic;
    c.le_offset = w.cell().le_offset;
    std::array<int, 3> k;
    const Vec3 xi = c.nearest_image(w.bodies.pos[a], w.bodies.pos[b], k);
    n = (xi - w.bodies.pos[a]).normalized();
    return Vec3(w.bodies.vel[b].v + Vec3(k[1] * V, 0, 0) - w.bodies.vel[a].v);
  };
  Vec3 n0;
  const Vec3 u0 = rel_velocity(n0);
  bool crossed = false;
  int impact = -1;
  Vec3 P0 = Vec3::Zero(), u_pre = Vec3::Zero(), n_pre = Vec3::Zero();
  int impact_iy = 0;
  for (int k = 0; k < 2000 && impact < 0; ++k) {
    Vec3 nn;
    const Vec3 uk = rel_velocity(nn);
    EXPECT_LT((uk - u0).norm(), 1e-14) << k;  // unchanged by the crossing
    u_pre = uk;
    P0 = ma * w.bodies.vel[a].v + mb * w.bodies.vel[b].v;
    const bool a_top = w.bodies.pos[a].y() > 0.5 * L;
    w.step();
    if (a_top && w.bodies.pos[a].y() < 0.5 * L) {
      crossed = true;
      EXPECT_EQ(impact, -1);
    }
    for (std::size_t j = 0; j < w.rows().size(); ++j) {
      const SphereRow& row = w.rows()[j];
      if (row.r[0] > 0.0) {
        impact = k;
        n_pre = row.b1 == a ? row.n : Vec3(-row.n);
        impact_iy = w.infos()[j].iy;
      }
    }
  }
  ASSERT_EQ(crossed, cross_first);
  ASSERT_GE(impact, 0);
  EXPECT_EQ(impact_iy != 0, !cross_first) << "the contact is through B's image only when A has not crossed";
  Vec3 n1;
  const Vec3 u1 = rel_velocity(n1);
  const double un = u_pre.dot(n_pre);
  EXPECT_LT(un, -0.5);
  EXPECT_LT(std::abs(n_pre.x()), 0.9);
  EXPECT_GT(std::abs(n_pre.x() * V), 0.05);
  EXPECT_NEAR(u1.dot(n_pre), -un, 1e-13);
  EXPECT_LT(((u1 - u1.dot(n_pre) * n_pre) - (u_pre - un * n_pre)).norm(), 1e-13);
  const Vec3 P1 = ma * w.bodies.vel[a].v + mb * w.bodies.vel[b].v;
  EXPECT_LT((P1 - P0).norm(), 1e-14 * (ma + mb) * u);
  std::printf("sheared-boundary impact (%s) at step %d: u_n %.15g -> %.15g, n = (%.3f %.3f %.3f)\n",
              cross_first ? "after the crossing" : "through the image", impact, un, u1.dot(n_pre), n_pre.x(),
              n_pre.y(), n_pre.z());
}

TEST(Periodic3, CollisionThroughTheShearedBoundary) { sheared_boundary_impact(true); }
TEST(Periodic3, CollisionWithTheMovingImage) { sheared_boundary_impact(false); }

// ~1700 spheres on a jittered lattice in a tri-periodic Lees-Edwards cell,
// random velocities, every loop on the parallel path (min_parallel = 0):
// one and two threads give the same bits.
TEST(Periodic3, IdenticalWithOneAndTwoThreads) {
  auto run = [](int threads, int& rows, int& imaged) {
    omp_set_num_threads(threads);
    const double r = 0.005, s = 2.05 * r;
    const int m = 12;
    WorldParams3 p;
    p.dt = 1e-4;
    p.mu = 0.3;
    p.alert = 0.3 * r;
    p.solver.tol = 1e-4;
    p.solver.max_iter = 40;
    p.solver.min_parallel = 0;
    p.cell = Vec3(m * s, m * s, m * s);
    p.periodic = {true, true, true};
    p.le_offset = 0.123 * p.cell.x();
    p.le_velocity = 0.3;
    World3 w(p);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> U(-0.5, 0.5);
    for (int iz = 0; iz < m; ++iz)
      for (int iy = 0; iy < m; ++iy)
        for (int ix = 0; ix < m; ++ix)
          w.bodies.add_sphere(Vec3((ix + 0.5) * s, (iy + 0.5) * s, (iz + 0.5) * s) + Vec3(U(rng), U(rng), U(rng)) * 0.02 * r,
                              r * (1 + 0.01 * U(rng)), 2600, Vec3(U(rng), U(rng), U(rng)) * 0.2,
                              Vec3(U(rng), U(rng), U(rng)) * 10.0);
    for (int k = 0; k < 8; ++k) w.step();
    rows = w.last().contacts;
    imaged = 0;
    for (const ContactInfo3& f : w.infos()) imaged += f.iy != 0;
    std::vector<double> st;
    for (std::size_t i = 0; i < w.bodies.size(); ++i) {
      for (int a = 0; a < 3; ++a) {
        st.push_back(w.bodies.pos[i][a]);
        st.push_back(w.bodies.vel[i].v[a]);
        st.push_back(w.bodies.vel[i].w[a]);
      }
    }
    return st;
  };
  int r1 = 0, r2 = 0, i1 = 0, i2 = 0;
  const std::vector<double> s1 = run(1, r1, i1), s2 = run(2, r2, i2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("periodic threads: %d rows, %d through sheared images\n", r1, i1);
  EXPECT_GT(r1, 3000);
  EXPECT_GT(i1, 100);
  EXPECT_EQ(r1, r2);
  ASSERT_EQ(s1.size(), s2.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < s1.size(); ++k) diff += s1[k] != s2[k];
  EXPECT_EQ(diff, 0u);
}

// A sphere placed two cells above a Lees-Edwards cell is brought in before
// the first step: y - 2 L_y, x - 2 offset, v_x - 2 V (modulo L_x); then it
// moves freely and the offset advances by V dt.
TEST(Periodic3, SpherePlacedOutsideIsBroughtIn) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.cell = Vec3(0.1, 0.2, 0.3);
  p.periodic = {true, true, true};
  p.le_offset = 0.03;
  p.le_velocity = 0.7;
  World3 w(p);
  const Vec3 x0(0.05, 0.13 + 2 * 0.2, 0.1), v0(0.2, -0.1, 0.05);
  const int s = w.bodies.add_sphere(x0, 0.01, 1000, v0);
  w.step();
  const double vx = v0.x() - 2 * p.le_velocity;
  double x = x0.x() - 2 * p.le_offset + vx * p.dt;
  x -= 0.1 * std::floor(x / 0.1);
  EXPECT_NEAR(w.bodies.vel[s].v.x(), vx, 1e-15);
  EXPECT_NEAR(w.bodies.pos[s].x(), x, 1e-15);
  EXPECT_NEAR(w.bodies.pos[s].y(), 0.13 + v0.y() * p.dt, 1e-15);
  EXPECT_NEAR(w.bodies.pos[s].z(), 0.1 + v0.z() * p.dt, 1e-15);
  EXPECT_NEAR(w.cell().le_offset, 0.03 + 0.7 * p.dt, 1e-16);
}

// WorldParams3 is constant during a run: what a Lees-Edwards
// cell with L_y at imposed stress changes (lengths, rates, offset, strain,
// the images' velocity) is the world's state, World3::cell(). One sphere,
// no contact: L_y falls under the load p L_x L_z of mass M (a = p A / M =
// 100 m/s^2: L_y = L0 - a t^2/2), the strain is gamma-dot t, the offset
// the sum of dt gamma-dot L_y at each step's midpoint.
TEST(Periodic3, ParametersStayConstantWhileTheCellMoves) {
  WorldParams3 p;
  p.dt = 1e-4;
  p.cell = Vec3(0.1, 0.1, 0.1);
  p.periodic = {true, true, true};
  p.shear_rate = 2.0;
  p.pressure = 100.0;
  p.cell_mass = 0.01;
  p.cell_dof = {false, true, false};
  p.alert = 0.01;  // the approach floor, alert / (4 dt) = 25 m/s, not reached
  World3 w(p);
  w.bodies.add_sphere(Vec3(0.05, 0.05, 0.05), 0.01, 1000);
  const int n = 10;
  double offset = 0.0;
  for (int k = 0; k < n; ++k) {
    // L_y at the step's midpoint: L0 - a dt^2 (k^2 + k) / 2.
    offset += p.dt * p.shear_rate * (0.1 - 0.5 * 100.0 * p.dt * p.dt * (k * k + k));
    w.step();
  }
  ASSERT_EQ(w.rows().size(), 0u);
  const WorldParams3& q = w.params();
  EXPECT_EQ(q.cell, p.cell);
  EXPECT_EQ(q.le_offset, 0.0);
  EXPECT_EQ(q.le_velocity, 0.0);
  const double t = n * p.dt;
  EXPECT_NEAR(w.cell().rate.y(), -100.0 * t, 1e-12);
  EXPECT_NEAR(w.cell().size.y(), 0.1 - 0.5 * 100.0 * t * t, 1e-15);
  EXPECT_EQ(w.cell().size.x(), 0.1);
  EXPECT_NEAR(w.cell().strain, p.shear_rate * t, 1e-15);
  EXPECT_NEAR(w.cell().le_offset, offset, 1e-16);
  EXPECT_NEAR(w.le_velocity(), p.shear_rate * (0.1 - 0.5 * 100.0 * p.dt * p.dt * ((n - 1) * (n - 1) + n - 1)), 1e-14);
}

// Refused: Lees-Edwards without periodic x and y, a periodic axis without a
// length, and a periodic length below 2 (2 r_max + alert) (a pair could then
// meet through two images).
TEST(Periodic3, InconsistentCellsAreRefused) {
  WorldParams3 p;
  p.cell = Vec3(0.1, 0.1, 0.1);
  p.periodic = {true, false, true};
  p.le_velocity = 0.1;
  EXPECT_THROW(World3 w(p), std::invalid_argument);
  p.periodic = {true, true, false};
  p.cell = Vec3(0.1, 0.0, 0.1);
  EXPECT_THROW(World3 w(p), std::invalid_argument);
  p.cell = Vec3(0.1, 0.1, 0.1);
  p.alert = 0.0;
  World3 w(p);
  w.bodies.add_sphere(Vec3(0.01, 0.01, 0.01), 0.026, 1000);  // 2 (2 r) = 0.104 > 0.1
  w.bodies.add_sphere(Vec3(0.05, 0.05, 0.05), 0.01, 1000);
  EXPECT_THROW(w.step(), std::invalid_argument);
}
