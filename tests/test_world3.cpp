// The 3D sphere engine (cd/src/3d/: bodies3, detect3, contact3, coupling3,
// world3): frames and Delassus blocks, the closed-form sphere solve against
// law3's general one, and closed-form dynamics (rest on a plane, incline
// stick/slide/roll, a column at rest), a settling pile, thread independence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <omp.h>

#include "coupling3.hpp"
#include "law3.hpp"
#include "pile3d.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

constexpr double kG = 9.81;

Eigen::Matrix3d skew(const Vec3& c) {
  Eigen::Matrix3d m;
  m << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  return m;
}

// W = J M^-1 J^T assembled from the two bodies' 6 dofs each:
// u = F (v2 - [c2]x w2 - v1 + [c1]x w1).
Eigen::Matrix3d assembled_W(const SphereRow& r, const BodyVel3& A, const BodyVel3& B) {
  Eigen::Matrix3d F;
  F.row(0) = r.n.transpose();
  F.row(1) = r.t1.transpose();
  F.row(2) = r.t2.transpose();
  Eigen::Matrix<double, 3, 12> J;
  J.block<3, 3>(0, 0) = -F;
  J.block<3, 3>(0, 3) = F * skew(r.c1);
  J.block<3, 3>(0, 6) = F;
  J.block<3, 3>(0, 9) = -F * skew(r.c2);
  Eigen::Matrix<double, 12, 1> m;
  m << Vec3::Constant(A.inv_m), Vec3::Constant(A.inv_I), Vec3::Constant(B.inv_m), Vec3::Constant(B.inv_I);
  return J * m.asDiagonal() * J.transpose();
}

// The row between bodies a and b (any order), or nullptr.
const SphereRow* find_row(const World3& w, int a, int b) {
  for (const SphereRow& r : w.rows())
    if ((r.b1 == a && r.b2 == b) || (r.b1 == b && r.b2 == a)) return &r;
  return nullptr;
}

}  // namespace

TEST(Frame3, OrthonormalRightHandedEverywhere) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N;
  std::vector<Vec3> ns = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {1e-9, 0, -1}, {0, 1e-12, 1}};
  for (int k = 0; k < 1000; ++k) ns.push_back(Vec3(N(rng), N(rng), N(rng)));
  for (Vec3 n : ns) {
    n.normalize();
    Vec3 t1, t2;
    orthonormal_basis(n, t1, t2);
    EXPECT_NEAR(t1.norm(), 1.0, 1e-14);
    EXPECT_NEAR(t2.norm(), 1.0, 1e-14);
    EXPECT_NEAR(n.dot(t1), 0.0, 1e-14);
    EXPECT_NEAR(n.dot(t2), 0.0, 1e-14);
    EXPECT_NEAR(t1.dot(t2), 0.0, 1e-14);
    EXPECT_LT((n.cross(t1) - t2).norm(), 1e-14);
  }
}

TEST(Frame3, SphereBlockIsTheAssembledDelassus) {
  Bodies3 b;
  const int p = b.add_plane(Vec3(0.1, -0.2, 0.05), Vec3(0.3, -0.2, 1.0));
  const int i = b.add_sphere(Vec3(0.0, 0.0, 0.3), 0.2, 2600);
  const int j = b.add_sphere(Vec3(0.25, 0.2, 0.45), 0.13, 1000);
  SphereRow r;
  ContactInfo3 f;
  ASSERT_TRUE(sphere_sphere(i, j, b.pos[i], b.pos[j], b.radius[i], b.radius[j], 0.1, r, f));
  set_block(r, b.vel[i], b.vel[j]);
  Eigen::Matrix3d W = assembled_W(r, b.vel[i], b.vel[j]);
  Eigen::Matrix3d D = Vec3(r.wnn, r.wtt, r.wtt).asDiagonal();
  EXPECT_LT((W - D).norm(), 1e-13 * W.norm());
  EXPECT_GT(r.wtt, r.wnn);  // rotation adds to the tangential part only
  ASSERT_TRUE(plane_sphere(p, i, b.pos[p], b.normal[p], b.pos[i], b.radius[i], 1.0, r, f));
  set_block(r, b.vel[p], b.vel[i]);
  W = assembled_W(r, b.vel[p], b.vel[i]);
  D = Vec3(r.wnn, r.wtt, r.wtt).asDiagonal();
  EXPECT_LT((W - D).norm(), 1e-13 * W.norm());
}

TEST(Law3Sphere, ClosedFormMatchesTheGeneralSolver) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0), P(0.1, 3.0), M(0.0, 1.5);
  int branches[4] = {0, 0, 0, 0};
  for (int k = 0; k < 20000; ++k) {
    const double wnn = P(rng), wtt = wnn + P(rng), mu = M(rng);
    const double a = (k % 3 == 0) ? 0.5 * P(rng) : 0.0;
    const Vec3 q(U(rng), U(rng), U(rng));
    Vec3 r1, r2;
    const Branch3 b1 = solve_sphere3(wnn, wtt, q, mu, a, r1);
    const Mat3 W = Vec3(wnn, wtt, wtt).asDiagonal();
    solve_local3(W, q, Cone3::round(mu), a, r2);
    ++branches[static_cast<int>(b1)];
    EXPECT_LT((r1 - r2).norm(), 1e-12 * (1.0 + r2.norm())) << k;
    EXPECT_LT(law_residual3(W * r1 + q, r1, Cone3::round(mu), a, 1.0 / wnn), 1e-13 * (1.0 + r1.norm()));
  }
  EXPECT_GT(branches[0], 1000);  // open, stick and slide all seen
  EXPECT_GT(branches[1], 1000);
  EXPECT_GT(branches[2], 1000);
}

// A sphere resting on a plane: every step's normal impulse is m g dt, the
// sphere does not move, over 1000 steps.
TEST(World3, SphereRestsOnPlane) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.3;
  p.alert = 1e-3;
  p.solver.tol = 1e-12;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.01;
  const int s = w.bodies.add_sphere(Vec3(0.2, -0.1, r), r, 2600);
  const double m = w.bodies.mass[s];
  for (int k = 0; k < 1000; ++k) {
    w.step();
    ASSERT_EQ(w.rows().size(), 1u);
    EXPECT_NEAR(w.rows()[0].r[0], m * kG * p.dt, 1e-15 * m * kG * p.dt);
    EXPECT_EQ(w.rows()[0].r[1], 0.0);
    EXPECT_EQ(w.rows()[0].r[2], 0.0);
    EXPECT_LE(w.last().solve.residual_max, 1e-12);
  }
  EXPECT_NEAR(w.bodies.pos[s].z(), r, 1e-15);
  EXPECT_EQ(w.bodies.pos[s].x(), 0.2);
  EXPECT_EQ(w.bodies.pos[s].y(), -0.1);
  EXPECT_LT(w.bodies.vel[s].v.norm(), 1e-15);
}

namespace {

struct Incline {
  double v_along = 0;     // velocity down the slope at the end
  double v_normal = 0;    // velocity along the plane's normal
  double w_axis = 0;      // angular velocity about n x d (rolling axis)
  double slip = 0;        // contact-point velocity along the slope
  double max_residual = 0;
  int steps = 0;
};

// A sphere released at rest on a plane tilted by theta about y (friction
// mu), for `steps` steps; rotation locked (inv_I = 0) or free.
Incline incline(double theta, double mu, bool rotation, int steps) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = mu;
  p.alert = 1e-3;
  p.solver.tol = 1e-13;
  World3 w(p);
  const Vec3 n(std::sin(theta), 0, std::cos(theta)), d(std::cos(theta), 0, -std::sin(theta));
  w.bodies.add_plane(Vec3::Zero(), n);
  const double r = 0.01;
  const int s = w.bodies.add_sphere(r * n, r, 2600);
  if (!rotation) w.bodies.vel[s].inv_I = 0.0;
  Incline out;
  for (int k = 0; k < steps; ++k) {
    w.step();
    out.max_residual = std::max(out.max_residual, w.last().solve.residual_max);
  }
  const BodyVel3& v = w.bodies.vel[s];
  out.v_along = v.v.dot(d);
  out.v_normal = v.v.dot(n);
  out.w_axis = v.w.dot(n.cross(d));
  out.slip = (v.v + v.w.cross(-r * n)).dot(d);
  out.steps = steps;
  return out;
}

}  // namespace

// Rotation locked (a block-like sphere): sticks for tan(theta) < mu, slides
// with a = g (sin - mu cos) above.
TEST(World3, InclineStickAndSlideWithoutRotation) {
  const double mu = 0.4, dt = 1e-3;
  const Incline a = incline(std::atan(0.9 * mu), mu, false, 300);
  EXPECT_LT(std::abs(a.v_along), 1e-15);
  EXPECT_LT(std::abs(a.v_normal), 1e-15);
  EXPECT_LE(a.max_residual, 1e-12);
  const double th = std::atan(1.2 * mu);
  const Incline b = incline(th, mu, false, 300);
  const double expect = kG * (std::sin(th) - mu * std::cos(th)) * dt * b.steps;
  EXPECT_NEAR(b.v_along, expect, 1e-12 * expect);
  EXPECT_LT(std::abs(b.v_normal), 1e-15);
  EXPECT_LE(b.max_residual, 1e-12);
}

// Rotation free: a sphere does not stick on an incline, it rolls without
// slipping (a = 5/7 g sin, friction 2/7 m g sin) while that friction is
// inside the cone, tan(theta) < 7/2 mu; above, it slides with
// a = g (sin - mu cos) and spins up at 5 mu g cos / (2 r).
TEST(World3, InclineRollAndSlideWithRotation) {
  const double mu = 0.2, dt = 1e-3, r = 0.01;
  const double t1 = std::atan(0.8 * 3.5 * mu);
  const Incline a = incline(t1, mu, true, 300);
  const double ea = 5.0 / 7.0 * kG * std::sin(t1) * dt * a.steps;
  EXPECT_NEAR(a.v_along, ea, 1e-12 * ea);
  EXPECT_NEAR(a.w_axis * r, a.v_along, 1e-12 * ea);  // no slip
  EXPECT_LT(std::abs(a.slip), 1e-12 * ea);
  EXPECT_LT(std::abs(a.v_normal), 1e-14 * ea);
  EXPECT_LE(a.max_residual, 1e-12);
  const double t2 = std::atan(1.3 * 3.5 * mu);
  const Incline b = incline(t2, mu, true, 300);
  const double eb = kG * (std::sin(t2) - mu * std::cos(t2)) * dt * b.steps;
  const double ew = 2.5 * mu * kG * std::cos(t2) / r * dt * b.steps;
  EXPECT_NEAR(b.v_along, eb, 1e-12 * eb);
  EXPECT_NEAR(b.w_axis, ew, 1e-12 * ew);
  EXPECT_GT(b.slip, 0.1 * eb);
  EXPECT_LE(b.max_residual, 1e-12);
}

// Five equal spheres stacked on a plane: at rest, and each contact carries
// m g dt more than the one above (the floor 5 m g dt), to the solver's tolerance.
TEST(World3, ColumnOfFiveAtRest) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.5;
  p.alert = 1e-3;
  p.solver.tol = 1e-10;
  p.solver.max_iter = 10000;
  World3 w(p);
  const int floor = w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.005;
  std::vector<int> s;
  for (int k = 0; k < 5; ++k) s.push_back(w.bodies.add_sphere(Vec3(0, 0, r + 2 * r * k), r, 2600));
  const double mgdt = w.bodies.mass[s[0]] * kG * p.dt;
  for (int step = 0; step < 200; ++step) {
    w.step();
    ASSERT_EQ(w.rows().size(), 5u);
    const SphereRow* f = find_row(w, floor, s[0]);
    ASSERT_NE(f, nullptr);
    EXPECT_NEAR(f->r[0], 5 * mgdt, 1e-8 * mgdt);
    for (int k = 0; k + 1 < 5; ++k) {
      const SphereRow* c = find_row(w, s[k], s[k + 1]);
      ASSERT_NE(c, nullptr);
      EXPECT_NEAR(c->r[0], (4 - k) * mgdt, 1e-8 * mgdt) << k;
      EXPECT_LT(c->r.tail<2>().norm(), 1e-12 * mgdt);
    }
    EXPECT_LT(w.last().solve.residual_max, 1e-8);
  }
  // Pure CD does not push overlaps apart: what the solver's tolerance
  // leaves in the velocities (~ tol g dt) sinks the column by ~ tol g dt^2
  // a step, a few 1e-14 m over 200 steps.
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(w.bodies.pos[s[k]].z(), r + 2 * r * k, 1e-10 * r) << k;
    EXPECT_LT(w.bodies.vel[s[k]].v.norm(), 1e-10);
  }
}

namespace {

// The pile3d deposition scene (pile3d.hpp), small: n^2 layers spheres on
// an n x n lattice.
World3 make_pile(int n, int layers, const SolverParams& sp) {
  Pile3dParams q;
  q.n_spheres = n * n * layers;
  q.solver = sp;
  // A short fall (<= 10 layers, impacts below 1.5 m/s): 0.2 r_mean covers
  // a step's travel. (The scene's 0.5 adds open candidates, and rows with
  // p = 0 make the rms criterion stricter: 117 capped steps instead of 44.)
  q.alert_rel = 0.2;
  return make_pile3d(q);
}

}  // namespace

// ~300 polydisperse spheres fall into a box and settle: the largest overlap
// stays below 1e-3 d, the kinetic energy decays, and every step's law
// residual stays below 1e-2 (a max over rows, with tol = 1e-4 on the rms
// impulse change: the 2D pile's criterion, tests/test_pile.cpp).
// Measured (7 x 7 x 6 = 294 spheres, 550 steps of 1 ms, tol 1e-4): overlap
// max 1.9e-4 d, kinetic energy from 9.4e-3 J to 2.8e-7 J, residual max
// 4.3e-3, 44 steps at the 2000-sweep cap (compaction, 0.15-0.4 s); ~10 s
// on one unloaded core.
TEST(World3, PileSettles) {
  SolverParams sp;
  sp.tol = 1e-4;
  World3 w = make_pile(7, 6, sp);
  double ke_peak = 0, omax = 0, res_max = 0;
  int caps = 0;
  const int steps = 550;
  std::vector<double> ke(steps);
  for (int k = 0; k < steps; ++k) {
    w.step();
    ke[k] = w.kinetic_energy();
    ke_peak = std::max(ke_peak, ke[k]);
    omax = std::max(omax, w.last().max_overlap);
    res_max = std::max(res_max, w.last().solve.residual_max);
    caps += w.last().solve.cap_hit;
  }
  std::printf("pile 294: rows %d, overlap max %.3g d, KE peak %.3g J end %.3g J, residual max %.3g, "
              "sweep caps %d of %d steps\n",
              w.last().contacts, omax, ke_peak, ke.back(), res_max, caps, steps);
  EXPECT_GT(w.last().contacts, 900);
  EXPECT_LT(omax, 1e-3);
  EXPECT_LT(ke.back(), 1e-4 * ke_peak);
  // Decays: the last 50 steps' energy below the peak's 1e-3 throughout.
  for (int k = steps - 50; k < steps; ++k) EXPECT_LT(ke[k], 1e-3 * ke_peak);
  EXPECT_LT(res_max, 1e-2);
  EXPECT_LT(caps, steps / 10);
}

namespace {

// Positions, orientations, velocities of every body, bit for bit.
std::vector<double> state(const World3& w) {
  std::vector<double> s;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    const auto& b = w.bodies;
    for (int k = 0; k < 3; ++k) s.insert(s.end(), {b.pos[i][k], b.vel[i].v[k], b.vel[i].w[k]});
    s.insert(s.end(), {b.orient[i].w(), b.orient[i].x(), b.orient[i].y(), b.orient[i].z()});
  }
  return s;
}

}  // namespace

// 1000 spheres shaken in a box, every loop on the parallel path
// (min_parallel = 0) and over 3000 rows, so that the colours hold several
// 128-row blocks and two threads share them: identical to one thread, bit
// for bit. Short (10 steps, at most 40 sweeps each): on a loaded machine
// every barrier of the 2-thread sweep can cost a scheduler time slice
// (measured: 20 steps of 100 sweeps took 0.16 s on 1 thread, 43 s on 2
// with the machine's load at 5 on 2 cores).
TEST(World3, IdenticalWithOneAndTwoThreads) {
  auto run = [](int threads, int& rows) {
    omp_set_num_threads(threads);
    EXPECT_EQ(omp_get_max_threads(), threads);
    SolverParams sp;
    sp.tol = 1e-4;
    sp.min_parallel = 0;
    sp.max_iter = 40;  // the same sweeps on both runs: identity, not convergence, is tested
    World3 w = make_pile(10, 10, sp);
    WorldParams3 p = w.params();
    p.alert = 1.2 * 0.005;  // every lattice neighbour is a row from the start
    w.set_params(p);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> U(-0.5, 0.5);
    for (std::size_t i = 0; i < w.bodies.size(); ++i)
      if (w.bodies.is_dynamic(i)) {
        w.bodies.vel[i].v = Vec3(U(rng), U(rng), U(rng));
        w.bodies.vel[i].w = Vec3(U(rng), U(rng), U(rng)) * 20.0;
      }
    int active = 0;
    const double t0 = omp_get_wtime();
    for (int k = 0; k < 10; ++k) {
      w.step();
      active = std::max(active, w.last().active);
    }
    rows = w.last().contacts;
    std::printf("%d thread(s): %d rows, %d active, %.2f s\n", threads, rows, active, omp_get_wtime() - t0);
    EXPECT_GT(active, 50);  // real contacts, not only open candidates
    return state(w);
  };
  int rows1 = 0, rows2 = 0;
  const std::vector<double> s1 = run(1, rows1), s2 = run(2, rows2);
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_GT(rows1, 3000);
  EXPECT_EQ(rows1, rows2);
  ASSERT_EQ(s1.size(), s2.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < s1.size(); ++k) diff += s1[k] != s2[k];
  EXPECT_EQ(diff, 0u);
}

// A sphere spinning in free space at constant w: the orientation after n
// steps is the rotation by n dt |w| about w, and stays a unit quaternion.
TEST(World3, QuaternionFollowsConstantSpin) {
  WorldParams3 p;
  p.dt = 1e-3;
  World3 w(p);
  const Vec3 omega(3.0, -1.0, 2.0);
  const int s = w.bodies.add_sphere(Vec3::Zero(), 0.01, 1000, Vec3(0.1, 0, 0), omega);
  const int n = 1000;
  for (int k = 0; k < n; ++k) w.step();
  const Quat expect(Eigen::AngleAxisd(n * p.dt * omega.norm(), omega.normalized()));
  EXPECT_NEAR(w.bodies.orient[s].norm(), 1.0, 1e-15);
  EXPECT_LT(w.bodies.orient[s].angularDistance(expect), 1e-12);
  EXPECT_NEAR(w.bodies.pos[s].x(), 0.1 * n * p.dt, 1e-14);  // 2000 half-step sums
  EXPECT_EQ(w.bodies.vel[s].w, omega);
}

// Adhesion: a sphere under a ceiling, pull-off force twice its weight,
// hangs (r_n = -m g dt, no motion), frictionless and frictional law.
TEST(World3, CohesiveSphereHangsUnderACeiling) {
  for (const bool friction : {false, true}) {
    WorldParams3 p;
    p.dt = 1e-3;
    p.gravity = Vec3(0, 0, -kG);
    p.mu = p.mu_wall = friction ? 0.3 : 0.0;
    p.alert = 1e-4;
    p.debond = 1e-3;
    p.solver.tol = 1e-12;
    const double r = 0.01;
    {
      World3 probe(p);
      probe.bodies.add_sphere(Vec3::Zero(), r, 2600);
      p.adhesion = 2.0 * probe.bodies.mass[0] * kG;
    }
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, -1));
    const int s = w.bodies.add_sphere(Vec3(0, 0, -r), r, 2600);
    const double m = w.bodies.mass[s];
    for (int k = 0; k < 200; ++k) {
      w.step();
      ASSERT_EQ(w.rows().size(), 1u);
      EXPECT_NEAR(w.rows()[0].r[0], -m * kG * p.dt, 1e-14 * m * kG * p.dt);
      EXPECT_LE(w.last().solve.residual_max, 1e-12);
    }
    EXPECT_NEAR(w.bodies.pos[s].z(), -r, 1e-15);
    EXPECT_LT(w.bodies.vel[s].v.norm(), 1e-15);
  }
}

// Overlap correction: a sphere overlapping a plane by delta (no gravity)
// leaves it at beta delta / dt in one step; beta = 0 leaves it at rest.
TEST(World3, OverlapCorrectionSeparatesAtBetaGapOverDt) {
  for (const double beta : {0.0, 0.3}) {
    WorldParams3 p;
    p.dt = 1e-3;
    p.mu = p.mu_wall = 0.4;
    p.overlap_correction = beta;
    p.solver.tol = 1e-12;
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
    const double r = 0.01, delta = 1e-5;
    const int s = w.bodies.add_sphere(Vec3(0, 0, r - delta), r, 2600);
    w.step();
    EXPECT_NEAR(w.bodies.vel[s].v.z(), beta * delta / p.dt, 1e-12 * delta / p.dt);
    EXPECT_EQ(w.bodies.vel[s].v.x(), 0.0);
    // r_n = m beta delta / dt, work r_n beta delta / dt = m v^2 (twice the kinetic energy: a bound)
    const double v = beta * delta / p.dt;
    EXPECT_NEAR(w.last().correction_work, w.bodies.mass[s] * v * v, 1e-12 * w.bodies.mass[s] * 1e-4);
  }
}
