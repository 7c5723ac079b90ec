// Polyhedra in the 3D engine (bodies3's polyhedra, poly_rows3, block_coupling3,
// World3's stages): closed forms a wrong lever arm, inertia tensor, frame
// or local solve would break. A cube at rest on a plane (four points, m g,
// the centre of pressure under the centroid), a cube on an incline (sticks
// with the centre of pressure moved downhill by (a/2) tan(theta), slides at
// g (sin - mu cos) above), two cubes stacked, a free asymmetric body
// (energy and |L| to round-off, L's direction to second order in dt), a
// tetrahedron dropped on a vertex coming to rest on a face, the block
// solve against the assembled W, slide or tip of a tall block at mu
// against b/H, and one thread against two.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include <omp.h>

#include "block_coupling3.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "polyhedra_box_util.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"
#include "polyhedron.hpp"
#include "rigid_rotation.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

constexpr double kG = 9.81;
constexpr double kRho = 2600.0;


// Sum of the rows' impulses on body b (world frame), and their centre of
// pressure (normal impulses as weights) with the total normal impulse.
struct Load {
  Vec3 impulse = Vec3::Zero();
  Vec3 cop = Vec3::Zero();
  double normal = 0.0;
  int rows = 0;
};
Load load_on(const World3& w, int b) {
  Load l;
  for (std::size_t k = 0; k < w.rows().size(); ++k) {
    const SphereRow& r = w.rows()[k];
    if (r.b2 != b && r.b1 != b) continue;
    const double s = r.b2 == b ? 1.0 : -1.0;
    l.impulse += s * r.to_world(r.r);
    l.cop += r.r[0] * w.infos()[k].point;
    l.normal += r.r[0];
    ++l.rows;
  }
  if (l.normal > 0) l.cop /= l.normal;
  return l;
}

}  // namespace

// A cube of side a resting face down on a plane: four contact points (the
// face's corners), normal impulses summing to m g dt, no tangential
// impulse, the centre of pressure under the centroid, and the cube does not
// move. Four points are hyperstatic: only the sum and the moment are
// determined, and only they are checked.
TEST(Polyhedra3, CubeRestsOnPlaneWithFourPoints) {
  World3 w(cdtest::exact_params3(0.3));
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02;
  const int shape = w.bodies.add_shape(cuboid(a, a, a));
  const Vec3 x0(0.1, -0.05, a / 2);
  const int c = w.bodies.add_polyhedron(x0, shape, kRho);
  const double m = w.bodies.mass[c];
  EXPECT_NEAR(m, kRho * a * a * a, 1e-12 * m);
  const double dt = w.params().dt;
  for (int k = 0; k < 500; ++k) {
    w.step();
    const Load l = load_on(w, c);
    ASSERT_EQ(l.rows, 4);
    for (const ContactInfo3& f : w.infos())
      EXPECT_EQ(f.kind, 1 + static_cast<int>(PolyContactKind::FaceFace));
    EXPECT_NEAR(l.impulse.z(), m * kG * dt, 1e-11 * m * kG * dt);
    EXPECT_LT(l.impulse.head<2>().norm(), 1e-11 * m * kG * dt);
    EXPECT_LT((l.cop - Vec3(x0.x(), x0.y(), 0)).head<2>().norm(), 1e-9 * a);
    EXPECT_LE(w.last().solve.residual_max, 1e-11);
  }
  EXPECT_LT((w.bodies.pos[c] - x0).norm(), 1e-12 * a);
  EXPECT_LT(w.bodies.vel[c].v.norm(), 1e-12);
  EXPECT_LT(w.bodies.vel[c].w.norm(), 1e-10);
  EXPECT_NEAR(std::abs(w.bodies.orient[c].w()), 1.0, 1e-12);
}

namespace {

struct Block {
  double v_along = 0, v_normal = 0;
  double w = 0, w_tip = 0;  // |omega|; omega about the downhill edge (> 0: turning over it)
  Load load;
  double cop_downhill = 0;  // centre of pressure from the centroid's foot, down the slope
  double cop_to_edge = 0;   // from the centre of pressure down the slope to the lowest contact point
  double max_residual = 0;
  int steps = 0;
};

// A block of base b x b and height H released at rest on a plane tilted by
// theta about y (its base on the plane), mu on the plane, `steps` steps.
Block block_on_incline(double b, double H, double theta, double mu, int steps) {
  World3 w(cdtest::exact_params3(mu));
  const Vec3 n(std::sin(theta), 0, std::cos(theta)), d(std::cos(theta), 0, -std::sin(theta));
  w.bodies.add_plane(Vec3::Zero(), n);
  const int shape = w.bodies.add_shape(cuboid(b, b, H));
  const Quat q(Eigen::AngleAxisd(theta, Vec3::UnitY()));  // a face on the plane
  const int c = w.bodies.add_polyhedron(0.5 * H * n, shape, kRho, q);
  Block out;
  for (int k = 0; k < steps; ++k) {
    w.step();
    out.max_residual = std::max(out.max_residual, w.last().solve.residual_max);
  }
  const BodyVel3& v = w.bodies.vel[c];
  out.v_along = v.v.dot(d);
  out.v_normal = v.v.dot(n);
  out.w = v.w.norm();
  out.w_tip = v.w.dot(n.cross(d));
  out.load = load_on(w, c);
  // The contact points are the midpoint configuration's: the centroid there.
  const Vec3 x = w.bodies.pos[c] - 0.5 * w.params().dt * v.v;
  out.cop_downhill = out.load.normal > 0 ? (out.load.cop - (x - x.dot(n) * n)).dot(d) : 0.0;
  double edge = -1e300;
  for (const ContactInfo3& f : w.infos()) edge = std::max(edge, f.point.dot(d));
  out.cop_to_edge = edge - out.load.cop.dot(d);
  out.steps = steps;
  return out;
}

// A cube of side 0.02 on the incline.
Block cube_incline(double theta, double mu, int steps) { return block_on_incline(0.02, 0.02, theta, mu, steps); }

}  // namespace

// Below tan(theta) = mu the cube sticks: the plane carries m g cos dt
// normal and m g sin dt up the slope, and the friction at the base, a/2
// below the centroid, turns the cube downhill unless the normal force
// moves downhill by (a/2) tan(theta) (moments about the centroid). Above,
// it slides with a = g (sin - mu cos) without turning (the centre of
// pressure then at (a/2) mu, inside the face while mu < 1).
TEST(Polyhedra3, CubeOnInclineSticksThenSlides) {
  const double mu = 0.4, dt = 1e-3, a = 0.02;
  const double m = kRho * a * a * a;
  const double t1 = std::atan(0.8 * mu);
  const Block s = cube_incline(t1, mu, 300);
  EXPECT_LT(std::abs(s.v_along), 1e-12);
  EXPECT_LT(std::abs(s.v_normal), 1e-12);
  EXPECT_LT(s.w, 1e-9);
  EXPECT_EQ(s.load.rows, 4);
  EXPECT_NEAR(s.load.normal, m * kG * std::cos(t1) * dt, 1e-10 * m * kG * dt);
  EXPECT_NEAR(s.cop_downhill, 0.5 * a * std::tan(t1), 1e-8 * a);
  EXPECT_LE(s.max_residual, 1e-10);

  const double t2 = std::atan(1.2 * mu);
  const Block g = cube_incline(t2, mu, 300);
  const double expect = kG * (std::sin(t2) - mu * std::cos(t2)) * dt * g.steps;
  EXPECT_NEAR(g.v_along, expect, 1e-9 * expect);
  EXPECT_LT(std::abs(g.v_normal), 1e-10 * expect);
  EXPECT_LT(g.w * a, 1e-9 * expect);
  EXPECT_NEAR(g.cop_downhill, 0.5 * a * mu, 1e-8 * a);
  EXPECT_LE(g.max_residual, 1e-10);
}

// Slide or tip: a block of base b and height H = 2b on an incline. Resting,
// the plane's reaction passes through the centroid's vertical, so its
// centre of pressure sits (H/2) tan(theta) downhill of the centroid's
// foot; the block tips when that reaches the downhill edge, tan(theta) >
// b/H = 0.5, and slides when tan(theta) > mu. Below both it rests (the
// centre of pressure where the moments say); with mu = 0.3 < b/H it
// slides at g (sin - mu cos) without turning (the centre of pressure at
// (H/2) mu < b/2); with mu = 0.8 > tan(theta) = 0.6 > b/H it tips over its
// downhill edge, the whole normal load on that edge.
TEST(Polyhedra3, BlockOnInclineSlidesOrTipsAtMuAgainstBOverH) {
  const double b = 0.01, H = 0.02, dt = 1e-3;
  const double t_rest = std::atan(0.45);
  const Block rest = block_on_incline(b, H, t_rest, 0.8, 200);
  EXPECT_LT(std::abs(rest.v_along) + std::abs(rest.v_normal), 1e-12);
  EXPECT_LT(std::abs(rest.w_tip), 1e-9);
  EXPECT_NEAR(rest.cop_downhill, 0.5 * H * std::tan(t_rest), 1e-8 * H);
  EXPECT_LE(rest.max_residual, 1e-10);

  const double t_slide = std::atan(0.4), mu = 0.3;
  const Block slide = block_on_incline(b, H, t_slide, mu, 200);
  const double expect = kG * (std::sin(t_slide) - mu * std::cos(t_slide)) * dt * 200;
  EXPECT_NEAR(slide.v_along, expect, 1e-9 * expect);
  EXPECT_LT(std::abs(slide.w_tip) * H, 1e-9 * expect);
  EXPECT_NEAR(slide.cop_downhill, 0.5 * H * mu, 1e-8 * H);

  const double t_tip = std::atan(0.6);
  const Block tip = block_on_incline(b, H, t_tip, 0.8, 100);
  EXPECT_GT(tip.w_tip, 0.1);  // rad/s after 0.1 s: turning over its downhill edge
  EXPECT_NEAR(tip.cop_to_edge, 0.0, 1e-9 * b);  // the load on the downhill edge alone
  EXPECT_NEAR(rest.cop_to_edge, 0.5 * b - 0.5 * H * std::tan(t_rest), 1e-8 * H);  // resting: inside the base
}

// Two cubes stacked face to face on a plane, the upper one shifted by a/4
// along x: the floor carries 2 m g dt under the pair's centre of mass, the
// upper contact m g dt under the upper centroid (its overlap with the lower
// face is a rectangle: four points).
TEST(Polyhedra3, TwoCubesStacked) {
  World3 w(cdtest::exact_params3(0.5));
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02;
  const int shape = w.bodies.add_shape(cuboid(a, a, a));
  const int lo = w.bodies.add_polyhedron(Vec3(0, 0, a / 2), shape, kRho);
  const int hi = w.bodies.add_polyhedron(Vec3(a / 4, 0, 1.5 * a), shape, kRho);
  const double m = w.bodies.mass[lo], dt = w.params().dt;
  for (int k = 0; k < 300; ++k) w.step();
  int floor_rows = 0;
  double floor_n = 0;
  Vec3 floor_cop = Vec3::Zero();
  for (std::size_t k = 0; k < w.rows().size(); ++k) {
    const SphereRow& r = w.rows()[k];
    if (r.b2 == lo && r.b1 == 0) {
      ++floor_rows;
      floor_n += r.r[0];
      floor_cop += r.r[0] * w.infos()[k].point;
    }
  }
  floor_cop /= floor_n;
  EXPECT_EQ(floor_rows, 4);
  EXPECT_NEAR(floor_n, 2 * m * kG * dt, 1e-10 * m * kG * dt);
  EXPECT_NEAR(floor_cop.x(), a / 8, 1e-8 * a);  // (0 + a/4) / 2
  const Load top = load_on(w, hi);
  EXPECT_EQ(top.rows, 4);
  EXPECT_NEAR(top.impulse.z(), m * kG * dt, 1e-10 * m * kG * dt);
  EXPECT_NEAR(top.cop.x(), a / 4, 1e-8 * a);
  EXPECT_LT(w.bodies.vel[hi].v.norm() + w.bodies.vel[lo].v.norm(), 1e-10);
}

namespace {

// A free cuboid of sides (1, 2, 3) a spun about a generic axis, no gravity:
// energy, |L| and L after `steps` steps of dt.
struct Flight {
  double e0, e1, l0, l1;
  Vec3 L0, L1;
};
Flight free_flight(double dt, int steps) {
  WorldParams3 p;
  p.dt = dt;
  World3 w(p);
  const double a = 0.01;
  const int shape = w.bodies.add_shape(cuboid(a, 2 * a, 3 * a));
  const Quat q(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  const int b = w.bodies.add_polyhedron(Vec3(0, 0, 0), shape, kRho, q, Vec3(0.1, 0, 0), Vec3(3, 40, 5));
  (void)b;
  Flight f;
  f.e0 = w.kinetic_energy();
  f.L0 = w.angular_momentum() - w.bodies.mass[b] * w.bodies.pos[b].cross(w.bodies.vel[b].v);
  for (int k = 0; k < steps; ++k) w.step();
  f.e1 = w.kinetic_energy();
  f.L1 = w.angular_momentum() - w.bodies.mass[b] * w.bodies.pos[b].cross(w.bodies.vel[b].v);
  f.l0 = f.L0.norm();
  f.l1 = f.L1.norm();
  return f;
}

}  // namespace

// The implicit midpoint rule keeps the energy and |L| of a free body to
// round-off at any step (rigid_rotation.hpp); the direction of L, fixed in
// the world for the exact motion, moves by O(dt^2) over a fixed time: its
// error falls by 4 (3.5 to 4.5 allowed) when dt halves. The body spins near
// its intermediate axis (40 rad/s about the 2a side), where an explicit
// gyroscopic term would blow up.
TEST(Polyhedra3, FreeAsymmetricBodyKeepsEnergyAndAngularMomentum) {
  const double T = 0.5;
  const Flight f1 = free_flight(1e-3, static_cast<int>(T / 1e-3));
  const Flight f2 = free_flight(5e-4, static_cast<int>(T / 5e-4));
  EXPECT_NEAR(f1.e1, f1.e0, 1e-12 * f1.e0);
  EXPECT_NEAR(f1.l1, f1.l0, 1e-12 * f1.l0);
  EXPECT_NEAR(f2.e1, f2.e0, 1e-12 * f2.e0);
  const double err1 = (f1.L1 - f1.L0).norm() / f1.l0, err2 = (f2.L1 - f2.L0).norm() / f2.l0;
  std::printf("L direction error over %.1f s: %.3g at dt 1e-3, %.3g at dt 5e-4 (ratio %.3f)\n", T, err1, err2,
              err1 / err2);
  EXPECT_GT(err1, 0.0);
  EXPECT_GT(err1 / err2, 3.5);
  EXPECT_LT(err1 / err2, 4.5);
}

// A regular tetrahedron released on one vertex with a small tilt, under
// gravity, friction 0.5: it falls over and comes to rest on a face, three
// contact points carrying m g dt, the face's outward normal pointing down.
TEST(Polyhedra3, TetrahedronDroppedOnAVertexRestsOnAFace) {
  World3 w(cdtest::exact_params3(0.5));
  w.params();
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.01;
  const ConvexPolyhedron tet = platonic(Platonic::Tetrahedron, r);
  const int shape = w.bodies.add_shape(tet);
  // Vertex (1, 1, 1)/sqrt(3) r turned to point straight down, then tilted by 0.05 rad.
  const Vec3 v0 = w.bodies.polyhedra[0].vertices()[0];
  Quat q = Quat::FromTwoVectors(v0.normalized(), Vec3(0, 0, -1));
  q = Quat(Eigen::AngleAxisd(0.05, Vec3(1, 0.3, 0).normalized())) * q;
  const double low = [&] {
    double z = 0;
    for (const Vec3& v : w.bodies.polyhedra[0].vertices()) z = std::min(z, (q * v).z());
    return z;
  }();
  const int b = w.bodies.add_polyhedron(Vec3(0, 0, -low + 1e-5), shape, kRho, q);
  const double m = w.bodies.mass[b], dt = w.params().dt;
  for (int k = 0; k < 1500; ++k) w.step();
  const Load l = load_on(w, b);
  EXPECT_EQ(l.rows, 3);
  for (const ContactInfo3& f : w.infos()) EXPECT_EQ(f.kind, 1 + static_cast<int>(PolyContactKind::FaceFace));
  EXPECT_NEAR(l.normal, m * kG * dt, 1e-8 * m * kG * dt);
  double down = 1.0;
  for (const PolyFace& f : w.bodies.polyhedra[0].faces()) down = std::min(down, (w.bodies.orient[b] * f.normal).z());
  EXPECT_NEAR(down, -1.0, 1e-8);
  EXPECT_LT(w.kinetic_energy(), 1e-12 * m * kG * r);
  // The centroid a quarter of the height above the floor: r / 3 for a
  // regular tetrahedron of circumradius r (its inradius).
  EXPECT_NEAR(w.bodies.pos[b].z(), r / 3, 1e-9 * r);
}

// Each Platonic solid released just above a plane at a generic
// orientation, with an alert distance of 0.7 circumradii, so that the
// vertices next to the face it lands on are within alert of the plane too
// (an icosahedron's and a dodecahedron's next ring is 0.6 r above that
// face): it comes to rest on a face, its centroid at the inradius (r/3 for
// the tetrahedron, r/sqrt 3 for the cube and the octahedron,
// r sqrt((5 + 2 sqrt 5)/15) for the dodecahedron and the icosahedron),
// borne by the face's vertices (at most 4 kept) carrying m g. When the
// plane's contact kept the widest 4 of all the vertices within alert, the
// icosahedron and the dodecahedron lost two bearing vertices and sank into
// the plane by 0.3 d in 1.5 s, never at rest.
TEST(Polyhedra3, EverySolidDroppedOnAPlaneRestsOnAFace) {
  const double r = 0.01;
  const double s5 = std::sqrt(5.0);
  const struct {
    Platonic kind;
    double inradius;  // over r
    int face_vertices;
  } solids[] = {{Platonic::Tetrahedron, 1.0 / 3.0, 3},
                {Platonic::Cube, 1.0 / std::sqrt(3.0), 4},
                {Platonic::Octahedron, 1.0 / std::sqrt(3.0), 3},
                {Platonic::Dodecahedron, std::sqrt((5.0 + 2.0 * s5) / 15.0), 5},
                {Platonic::Icosahedron, std::sqrt((5.0 + 2.0 * s5) / 15.0), 3}};
  for (const auto& solid : solids) {
    WorldParams3 p = cdtest::exact_params3(0.4);
    p.alert = 0.7 * r;
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
    const int shape = w.bodies.add_shape(platonic(solid.kind, r));
    const Quat q(Eigen::AngleAxisd(0.7, Vec3(0.3, 1.0, 0.2).normalized()));
    double low = 0;
    for (const Vec3& v : w.bodies.polyhedra[0].vertices()) low = std::min(low, (q * v).z());
    const int b = w.bodies.add_polyhedron(Vec3(0, 0, -low + 0.01 * r), shape, kRho, q);
    const double m = w.bodies.mass[b], dt = w.params().dt;
    double deepest = 0;
    for (int k = 0; k < 1500; ++k) {
      w.step();
      for (const Vec3& v : w.bodies.polyhedra[0].vertices())
        deepest = std::min(deepest, (w.bodies.pos[b] + w.bodies.orient[b] * v).z());
    }
    SCOPED_TRACE(static_cast<int>(solid.kind));
    const Load l = load_on(w, b);
    EXPECT_EQ(l.rows, std::min(solid.face_vertices, 4));
    EXPECT_NEAR(l.normal, m * kG * dt, 1e-8 * m * kG * dt);
    EXPECT_NEAR(w.bodies.pos[b].z(), solid.inradius * r, 1e-6 * r);
    EXPECT_LT(w.kinetic_energy(), 1e-12 * m * kG * r);
    // Pure contact dynamics lets a point enter the plane by what it moves
    // in a step as it lands: below 1e-8 r for the solids whose landing
    // face keeps all its vertices, 5e-3 r for the dodecahedron, whose
    // pentagon keeps 4 (the fifth enters as the face closes, and leaves);
    // 0.6 r before the fix.
    std::printf("deepest %.3g r\n", -deepest / r);
    EXPECT_GT(deepest, -1e-2 * r);
  }
}

namespace {

// A row between two bodies with random lever arms, normal, masses, full
// inverse inertia tensors (moments about (1, 2, 3), turned) and velocities.
struct TwoBodies {
  SphereRow row{};
  BodyVel3 vel[2];
  Mat3 J[2];
};
TwoBodies random_two_bodies(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  TwoBodies t;
  SphereRow& r = t.row;
  r.b1 = 0;
  r.b2 = 1;
  r.n = Vec3(U(rng), U(rng), U(rng)).normalized();
  orthonormal_basis(r.n, r.t1, r.t2);
  r.c1 = Vec3(U(rng), U(rng), U(rng));
  r.c2 = Vec3(U(rng), U(rng), U(rng));
  for (int i = 0; i < 2; ++i) {
    t.vel[i].inv_m = 1.0 + 0.5 * U(rng);
    const Vec3 moments(1 + 0.5 * U(rng), 2 + U(rng), 3 + U(rng));
    t.J[i] = world_inverse_inertia(moments, Quat(Eigen::AngleAxisd(3 * U(rng), Vec3(U(rng), U(rng), U(rng)).normalized())));
    t.vel[i].v = Vec3(U(rng), U(rng), U(rng));
    t.vel[i].w = Vec3(U(rng), U(rng), U(rng));
  }
  return t;
}

}  // namespace

// The block of a polyhedron's row (block_coupling3.hpp) against W = H^T
// M^-1 H assembled from the two bodies' 6 dofs with their full inverse
// inertia tensors, and the sweep's velocity and impulse against the same H.
TEST(Polyhedra3, BlockRowAgainstAssembledDelassus) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const TwoBodies t = random_two_bodies(rng);
    const SphereRow& r = t.row;
    BodyVel3 vel[2] = {t.vel[0], t.vel[1]};
    const Mat3* J = t.J;
    const BlockRow3 b = make_block_row3(r, vel, J);
    Eigen::Matrix3d F;
    F.row(0) = r.n;
    F.row(1) = r.t1;
    F.row(2) = r.t2;
    auto skew = [](const Vec3& c) {
      Eigen::Matrix3d m;
      m << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
      return m;
    };
    // u = F (v2 + w2 x c2 - v1 - w1 x c1) = H^T (v1, w1, v2, w2)
    Eigen::Matrix<double, 3, 12> Ht;
    Ht.block<3, 3>(0, 0) = -F;
    Ht.block<3, 3>(0, 3) = F * skew(r.c1);
    Ht.block<3, 3>(0, 6) = F;
    Ht.block<3, 3>(0, 9) = -F * skew(r.c2);
    Eigen::Matrix<double, 12, 12> Minv = Eigen::Matrix<double, 12, 12>::Zero();
    Minv.block<3, 3>(0, 0) = vel[0].inv_m * Mat3::Identity();
    Minv.block<3, 3>(3, 3) = J[0];
    Minv.block<3, 3>(6, 6) = vel[1].inv_m * Mat3::Identity();
    Minv.block<3, 3>(9, 9) = J[1];
    const Mat3 W = Ht * Minv * Ht.transpose();
    EXPECT_LT((b.W - W).norm(), 1e-13 * W.norm());
    Eigen::Matrix<double, 12, 1> V;
    V << vel[0].v, vel[0].w, vel[1].v, vel[1].w;
    sweep::BlockCoupling3 c{vel, nullptr, &b};
    EXPECT_LT((c.velocity(b) - Ht * V).norm(), 1e-13 * V.norm());
    // An impulse dr changes u by W dr.
    const Vec3 dr(U(rng), U(rng), U(rng));
    const Vec3 u0 = c.velocity(b);
    push_impulse(b, dr, vel);
    EXPECT_LT((c.velocity(b) - u0 - W * dr).norm(), 1e-12 * (u0.norm() + W.norm() * dr.norm()));
  }
}

namespace {

// Bodies of the library's shapes dropped in a box of five planes, random
// orientations and velocities: the state after `steps` steps.
std::vector<double> polyhedra_box(int threads, int steps, int& rows) {
  omp_set_num_threads(threads);
  World3 w = cdtest::polyhedra_box(cdtest::exact_params3(0.4), [](World3& w, int k, const Vec3& x, const Quat& q, const Vec3& v,
                                                   const Vec3& om, const int* shapes) {
    w.bodies.add_polyhedron(x, shapes[k % 3], kRho, q, v, om);
  });
  for (int s = 0; s < steps; ++s) w.step();
  rows = static_cast<int>(w.rows().size());
  return cdtest::body_state(w);
}

}  // namespace

TEST(Polyhedra3, IdenticalWithOneAndTwoThreads) {
  int rows1 = 0, rows2 = 0;
  const std::vector<double> s1 = polyhedra_box(1, 120, rows1), s2 = polyhedra_box(2, 120, rows2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("%d rows at the end\n", rows1);
  EXPECT_GT(rows1, 40);
  EXPECT_EQ(rows1, rows2);
  ASSERT_EQ(s1.size(), s2.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < s1.size(); ++k) diff += s1[k] != s2[k];
  EXPECT_EQ(diff, 0u);
}

namespace {

// The world of configs/pile-polyhedra.toml, made smaller: 64 cubes.
Scene small_polyhedra_pile(Shape3d shape) {
  Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/pile-polyhedra.toml");
  s.shape = {shape};
  s.n = 64;
  s.max_iter = 100;  // identity, not convergence, is what these tests see
  return s;
}

std::vector<double> state_bits(const World3& w) { return cdtest::body_state(w); }

}  // namespace

// A scene's polyhedra: each grain the scene's solid with the circumscribed
// diameter of its size, its volume the solid's (a cube of circumradius r:
// (2 r / sqrt 3)^3), at a unit orientation; the placement is the spheres'.
TEST(Polyhedra3, SceneMakesTheSolidsOfItsSizes) {
  const World3 w = build_world3(small_polyhedra_pile(Shape3d::Cube));
  const World3 spheres = build_world3(small_polyhedra_pile(Shape3d::Sphere));
  ASSERT_EQ(w.bodies.size(), spheres.bodies.size());
  int cubes = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    if (w.bodies.shape[i] == Shape3::Plane) continue;
    ++cubes;
    ASSERT_EQ(w.bodies.shape[i], Shape3::Polyhedron);
    const double r = spheres.bodies.radius[i];
    EXPECT_EQ(w.bodies.pos[i], spheres.bodies.pos[i]);
    EXPECT_NEAR(w.bodies.polyhedron(i).circumradius(), r, 1e-14 * r);
    const double side = 2 * r / std::sqrt(3.0);
    EXPECT_NEAR(w.bodies.mass[i], 2600.0 * side * side * side, 1e-12 * w.bodies.mass[i]);
    EXPECT_NEAR(w.bodies.moments[i].x(), w.bodies.mass[i] * side * side / 6, 1e-12 * w.bodies.moments[i].x());
    EXPECT_NEAR(w.bodies.orient[i].norm(), 1.0, 1e-15);
  }
  EXPECT_EQ(cubes, 64);
}

// Cuboids of sides in the ratios particles.aspect (1 : 2 : 3) and
// irregular grains (the hull of particles.vertices points on an ellipsoid),
// each of the circumscribed radius of the sphere it replaces: the cuboid's
// side s from its half-diagonal s sqrt(14) / 2 = r, its mass and principal
// moments those of a (s, 2s, 3s) box, m (b^2 + c^2) / 12 and cyclic;
// irregular grains each a shape of their own, of at most that many
// vertices. Keys that cannot act on a shape are refused by name.
TEST(Polyhedra3, SceneMakesCuboidsAndIrregularGrains) {
  Scene s = small_polyhedra_pile(Shape3d::Cuboid);
  s.aspect = {1.0, 2.0, 3.0};
  const World3 w = build_world3(s);
  const World3 spheres = build_world3(small_polyhedra_pile(Shape3d::Sphere));
  ASSERT_EQ(w.bodies.size(), spheres.bodies.size());
  int grains = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    if (w.bodies.shape[i] == Shape3::Plane) continue;
    ++grains;
    const double r = spheres.bodies.radius[i], side = 2 * r / std::sqrt(14.0), m = w.bodies.mass[i];
    EXPECT_NEAR(w.bodies.polyhedron(i).circumradius(), r, 1e-14 * r);
    EXPECT_NEAR(m, 2600.0 * 6 * side * side * side, 1e-12 * m);
    std::array<double, 3> got{w.bodies.moments[i].x(), w.bodies.moments[i].y(), w.bodies.moments[i].z()};
    std::array<double, 3> box{m * 13 * side * side / 12, m * 10 * side * side / 12, m * 5 * side * side / 12};
    std::sort(got.begin(), got.end());
    std::sort(box.begin(), box.end());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], box[c], 1e-12 * box[c]);
  }
  EXPECT_EQ(grains, 64);

  s.shape = {Shape3d::Irregular};
  s.aspect = {1.0, 1.0, 2.0};
  s.vertices = 10;
  World3 irr = build_world3(s);
  std::set<std::vector<double>> distinct;
  for (std::size_t i = 0; i < irr.bodies.size(); ++i) {
    if (irr.bodies.shape[i] == Shape3::Plane) continue;
    const ConvexPolyhedron& p = irr.bodies.polyhedron(i);
    EXPECT_NEAR(p.circumradius(), spheres.bodies.radius[i], 1e-14 * spheres.bodies.radius[i]);
    EXPECT_GE(p.vertices().size(), 4u);
    EXPECT_LE(p.vertices().size(), 10u);
    EXPECT_NEAR(irr.bodies.mass[i], 2600.0 * p.volume(), 1e-12 * irr.bodies.mass[i]);
    std::vector<double> v;
    for (const Vec3& x : p.vertices()) v.insert(v.end(), {x.x(), x.y(), x.z()});
    distinct.insert(v);
  }
  EXPECT_EQ(distinct.size(), 64u);
  for (int k = 0; k < 30; ++k) irr.step();
  EXPECT_GT(irr.last().contacts, 0);

  const auto refused = [](Scene t, const std::string& key) {
    try {
      build_world3(t);
      ADD_FAILURE() << key << " was not refused";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  Scene t = small_polyhedra_pile(Shape3d::Cube);
  t.aspect = {1.0, 2.0, 3.0};
  refused(t, "particles.aspect");
  t = small_polyhedra_pile(Shape3d::Cuboid);
  t.vertices = 20;
  refused(t, "particles.vertices");
  t.vertices = 12;
  t.aspect = {1.0, 1.0, 200.0};
  refused(t, "particles.aspect");
}

// A run of polyhedra resumes from its checkpoint bit for bit: 60 steps, a
// checkpoint, 60 more, against 120 steps straight (the pair memory of
// impulses and axes, the shapes' ids and moments all restored).
TEST(Polyhedra3, CheckpointResumesBitForBit) {
  const Scene s = small_polyhedra_pile(Shape3d::Tetrahedron);
  World3 a = build_world3(s);
  for (int k = 0; k < 120; ++k) a.step();
  World3 b = build_world3(s);
  for (int k = 0; k < 60; ++k) b.step();
  ASSERT_FALSE(b.polyhedra_memory().keys.empty());
  const auto dir = cdtest::scratch_dir("test_polyhedra3", "ckpt");
  const std::string path = (dir / "checkpoint.bin").string();
  save_checkpoint3(path, b, 7);
  World3 c = build_world3(s);
  EXPECT_EQ(load_checkpoint3(path, c), 7u);
  EXPECT_EQ(c.polyhedra_memory().keys, b.polyhedra_memory().keys);
  for (int k = 0; k < 60; ++k) c.step();
  EXPECT_GT(a.last().contacts, 0);
  const std::vector<double> sa = state_bits(a), sc = state_bits(c);
  ASSERT_EQ(sa.size(), sc.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < sa.size(); ++k) diff += sa[k] != sc[k];
  EXPECT_EQ(diff, 0u);

  // Into a scene of other shapes (cubes): refused, naming the shapes.
  World3 d = build_world3(small_polyhedra_pile(Shape3d::Cube));
  try {
    load_checkpoint3(path, d);
    ADD_FAILURE() << "a checkpoint of tetrahedra loaded into a scene of cubes";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("other shapes"), std::string::npos) << e.what();
  }
}

// The local solve's warm slide (law3.hpp, slide_unit_from) against the
// scan: on random blocks of two bodies with full inertia tensors (the
// blocks of polyhedra), from a guess whose slip is 0.2 rad off the
// answer (of any size), the same slide to 1e-10 of its size, and the law's residual at
// round-off. (Where the law has several slides the two may part; these
// blocks, mu = 0.4, have one.)
TEST(Polyhedra3, WarmSlideFindsTheScansSlide) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  int slides = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const TwoBodies t = random_two_bodies(rng);
    const Mat3 W = make_block_row3(t.row, t.vel, t.J).W;
    const Vec3 q(-0.5 - 0.5 * std::abs(U(rng)), U(rng), U(rng));
    const Cone3 cone = Cone3::round(0.4);
    Vec3 scan, warm;
    if (solve_local3(W, q, cone, 0.0, scan) != Branch3::Slide) continue;
    ++slides;
    const double f = std::atan2(scan[2], scan[1]) + 0.2;
    // The guess is an impulse: its slip direction counts, not its size.
    for (const double size : {1e-6, 1.0, 1e6}) {
      const Vec3 guess(scan[0], size * std::cos(f), size * std::sin(f));
      EXPECT_EQ(solve_local3(W, q, cone, 0.0, warm, &guess), Branch3::Slide);
      EXPECT_LT((warm - scan).norm(), 1e-10 * scan.norm()) << trial;
      const double scale = q.norm() + W.norm() * warm.norm();
      EXPECT_LT(law_residual3(W * warm + q, warm, cone, 0.0, 1.0 / W(0, 0)), 1e-12 * scale) << trial;
    }
  }
  std::printf("%d slides of 400 blocks\n", slides);
  EXPECT_GT(slides, 50);
}

// The tri-periodic shear of polyhedra from a compacted sample of them
// (shear.start): 100 blocks of sides 1 : 1.5 : 2 compacted at p for 150
// steps, their checkpoint started at I = 0.1. The sample carries its shapes
// (their vertices): the started world's library is the sample's to
// round-off, every grain keeps its mass, moments and orientation, and the
// cell its lengths. Sheared to a strain of 0.2, the blocks carry the
// imposed p (within 50 %: the transient) and a shear stress of the flow's
// sign, a twentieth of it or more (means over the 40 steps); the sheared
// run resumes from its own checkpoint bit for bit. A shear scene that
// names a shape is refused (the sample gives them).
TEST(Polyhedra3, ShearStartsFromASampleOfPolyhedra) {
  Scene prep = cdtest::shear3_prep_scene(100);
  prep.shape = {Shape3d::Cuboid};
  prep.aspect = {1.0, 1.5, 2.0};
  World3 p = build_world3(prep);
  for (int k = 0; k < 150; ++k) p.step();
  const auto dir = cdtest::scratch_dir("test_polyhedra3", "start");
  const std::string sample = (dir / "sample.bin").string();
  save_checkpoint3(sample, p, 1);

  const Scene s = cdtest::shear3_shear_scene(sample, 0.1);
  World3 a = build_world3(s);
  ASSERT_EQ(a.bodies.size(), p.bodies.size());
  ASSERT_EQ(a.bodies.polyhedra.size(), p.bodies.polyhedra.size());
  for (std::size_t k = 0; k < p.bodies.polyhedra.size(); ++k) {
    const ConvexPolyhedron &x = a.bodies.polyhedra[k], &y = p.bodies.polyhedra[k];
    ASSERT_EQ(x.vertices().size(), y.vertices().size());
    for (std::size_t v = 0; v < x.vertices().size(); ++v)
      EXPECT_LT((x.vertices()[v] - y.vertices()[v]).norm(), 1e-14 * y.circumradius()) << "shape " << k;
    EXPECT_NEAR(x.volume(), y.volume(), 1e-13 * y.volume());
  }
  for (std::size_t i = 0; i < p.bodies.size(); ++i) {
    EXPECT_EQ(a.bodies.mass[i], p.bodies.mass[i]);
    EXPECT_EQ(a.bodies.moments[i], p.bodies.moments[i]);
    EXPECT_EQ(a.bodies.orient[i].coeffs(), p.bodies.orient[i].coeffs());
  }
  EXPECT_EQ(a.cell().size, p.cell().size);

  // 40 steps straight against 20, a checkpoint, a world built from the
  // scene again (the sample's shapes) and 20 more.
  World3 b = build_world3(s);
  // The stress of each step of the straight run: its mean (a step's value
  // swings by tenths in the transient of 100 blocks).
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 40; ++k) {
    a.step();
    S += a.contact_stress() / 40.0;
  }
  for (int k = 0; k < 20; ++k) b.step();
  const std::string mid = (dir / "shear.bin").string();
  save_checkpoint3(mid, b, 2);
  World3 c = build_world3(s);
  EXPECT_EQ(load_checkpoint3(mid, c), 2u);
  for (int k = 0; k < 20; ++k) c.step();
  const std::vector<double> sa = state_bits(a), sc = state_bits(c);
  ASSERT_EQ(sa.size(), sc.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < sa.size(); ++k) diff += sa[k] != sc[k];
  EXPECT_EQ(diff, 0u);

  // Compression positive (contact_stress): p = tr S / 3, mu = -S_xy / S_yy
  // (the series' shear_stress_ratio; the flow along +x at y above the middle).
  const double pr = S.trace() / 3, mu = -0.5 * (S(0, 1) + S(1, 0)) / S(1, 1);
  std::printf("[ shear ] 100 blocks at I = 0.1, strain %.2f: p %.3g Pa, mu %.3f (means over the run), %d rows\n",
              a.cell().strain, pr, mu,
              static_cast<int>(a.rows().size()));
  EXPECT_GT(a.cell().strain, 0.05);
  EXPECT_NEAR(pr, 1e5, 5e4);
  EXPECT_GT(mu, 0.05);
  EXPECT_LT(mu, 1.5);

  Scene named = s;
  named.shape = {Shape3d::Cube};
  try {
    build_world3(named);
    ADD_FAILURE() << "a started scene naming particles.shape was taken";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("particles.shape"), std::string::npos) << e.what();
  }
}

namespace {

// configs/pile-polyhedra.toml as a mixture of 200 grains: particles.shape a
// list, particles.shape_fractions its number fractions.
Scene mixture_pile(const std::string& fractions) {
  Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/pile-polyhedra.toml",
                       {"particles.n=200", "particles.shape=[\"sphere\", \"cube\"]",
                        "particles.shape_fractions=" + fractions});
  s.max_iter = 100;  // identity, not convergence, is what this test sees
  return s;
}

std::string mixture_error(const std::string& particles) {
  try {
    parse_scene("dimension = 3\n[particles]\n" + particles + "\n[gravity]\ng = [0, 0, -9.81]\n", "m.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A mixture by number: each grain's shape drawn from particles.seed and its
// index, so the counts are binomial (200 grains, p = 1/2: within 4 standard
// deviations, 28 grains, of 100), both shapes present, the spheres spheres
// and the cubes cubes of the grain's circumscribed size at the spheres'
// places; the pile steps, the same with 1 and 2 threads. A single shape
// given as a one-element list is the same world as the string.
TEST(Polyhedra3, SceneMixesShapesByNumber) {
  const Scene s = mixture_pile("[0.5, 0.5]");
  const World3 w = build_world3(s);
  const World3 spheres = build_world3(small_polyhedra_pile(Shape3d::Sphere));
  Scene all_spheres_scene = s;
  all_spheres_scene.shape = {Shape3d::Sphere};
  all_spheres_scene.shape_fractions.clear();
  const World3 ref = build_world3(all_spheres_scene);
  ASSERT_EQ(w.bodies.size(), ref.bodies.size());
  int nsphere = 0, ncube = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    if (w.bodies.shape[i] == Shape3::Plane) continue;
    EXPECT_EQ(w.bodies.pos[i], ref.bodies.pos[i]);
    const double r = ref.bodies.radius[i];
    if (w.bodies.shape[i] == Shape3::Sphere) {
      ++nsphere;
      EXPECT_EQ(w.bodies.radius[i], r);
      EXPECT_EQ(w.bodies.mass[i], ref.bodies.mass[i]);
    } else {
      ASSERT_EQ(w.bodies.shape[i], Shape3::Polyhedron);
      ++ncube;
      EXPECT_NEAR(w.bodies.polyhedron(i).circumradius(), r, 1e-14 * r);
      EXPECT_EQ(w.bodies.polyhedron(i).vertices().size(), 8u);
    }
  }
  std::printf("%d spheres, %d cubes\n", nsphere, ncube);
  EXPECT_EQ(nsphere + ncube, 200);
  EXPECT_LE(std::abs(nsphere - 100), 28);
  EXPECT_GT(nsphere, 0);
  EXPECT_GT(ncube, 0);

  const auto run = [&](int threads) {
    omp_set_num_threads(threads);
    World3 x = build_world3(s);
    for (int k = 0; k < 20; ++k) x.step();
    EXPECT_GT(x.last().contacts, 0);
    return state_bits(x);
  };
  const std::vector<double> s1 = run(1), s2 = run(2);
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_EQ(s1.size(), s2.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < s1.size(); ++k) diff += s1[k] != s2[k];
  EXPECT_EQ(diff, 0u);

  // All cubes by fractions [0, 1]: the world of particles.shape = "cube".
  Scene cubes = s;
  cubes.shape_fractions = {0.0, 1.0};
  Scene cube = s;
  cube.shape = {Shape3d::Cube};
  cube.shape_fractions.clear();
  const World3 a = build_world3(cubes), b = build_world3(cube);
  EXPECT_EQ(state_bits(a), state_bits(b));
  (void)spheres;
}

// Bad mixtures refused by key.
TEST(Polyhedra3, SceneMixtureRefusals) {
  const auto has = [](const std::string& e, const std::string& what) {
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  EXPECT_EQ(mixture_error("shape = [\"sphere\", \"cube\"]\nshape_fractions = [0.25, 0.75]"), "");
  EXPECT_EQ(mixture_error("shape = [\"sphere\", \"cube\"]"), "");
  has(mixture_error("shape = [\"sphere\", \"cube\"]\nshape_fractions = [0.5, 0.6]"),
      "m.toml:4:1: particles.shape_fractions = [0.5, 0.6]: the fractions sum to 1.1: must sum to 1 (within 1e-9)");
  has(mixture_error("shape = [\"sphere\", \"cube\"]\nshape_fractions = [1.5, -0.5]"),
      "particles.shape_fractions = [1.5, -0.5]: element 1 is -0.5: must be >= 0");
  has(mixture_error("shape = [\"sphere\", \"cube\"]\nshape_fractions = [0.2, 0.3, 0.5]"),
      "particles.shape_fractions = [0.2, 0.3, 0.5]: 3 fractions for the 2 shapes of particles.shape = "
      "[\"sphere\", \"cube\"]: one per shape, in its order");
  has(mixture_error("shape = \"cube\"\nshape_fractions = [0.5, 0.5]"), "2 fractions for the 1 shapes");
  has(mixture_error("shape = [\"sphere\", \"blob\"]"), "particles.shape = \"blob\": must be \"sphere\"");
  has(mixture_error("shape = []"), "particles.shape: expected a name or a non-empty list of names");
  try {
    parse_scene("[particles]\nshape_fractions = [1]\n", "m.toml");
    ADD_FAILURE() << "a 2D scene took particles.shape_fractions";
  } catch (const ConfigError& e) {
    has(e.what(), "particles.shape_fractions = [1]: a dimension = 3 key");
  }
}
