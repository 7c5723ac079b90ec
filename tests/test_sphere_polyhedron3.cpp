// A sphere against a convex polyhedron: the narrow phase
// (polyhedron_contact.hpp's collide_sphere) and its rows in the step
// (poly_rows3.hpp), each against a closed form computed here, not by the
// code under test.
//  - Narrow phase on a turned cube of side 2: the sphere above a face, beside
//    an edge, off a vertex, sunk slightly into a face, its centre inside;
//    gap = distance - r, the normal and the midway point by hand, the kind
//    and the key of the feature; alert; the swapped order mirrors the
//    normal; random centres about a random hull give the projection on it
//    (x on the surface, (c - x).(v - x) <= 0 for every vertex v); repeated
//    calls bit-identical.
//  - A sphere on a heavy cube's top face: one row carrying m g, the floor's
//    centre of pressure under the pair's centre of mass, no drift.
//  - A cube on three spheres on a plane: each sphere carries M g times the
//    barycentric coordinate of the cube's centroid in their triangle.
//  - A sphere dropped into the groove between two cubes comes to rest on
//    their edges, each pushing m g / (2 cos theta) along its normal; the
//    energy never rises.
//  - A sphere resting on a cube through a Lees-Edwards image.
//  - A mixed pile: one thread and two give the same bits.
// Tolerances: the narrow phase's as tests/test_polyhedron_contact.cpp's
// (1e-12 on O(1) coordinates); the step's to the solver's tolerance
// (1e-13) over the few rows, checked to 1e-10 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include <omp.h>

#include <Eigen/Geometry>

#include "polyhedra_box_util.hpp"
#include "polyhedron.hpp"
#include "polyhedron_contact.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

constexpr double kTol = 1e-12;
constexpr double kG = 9.81;
constexpr double kRho = 2600.0;

// The cube of side 2 at a turned pose.
struct TurnedCube {
  ConvexPolyhedron shape = cuboid(2, 2, 2);
  Pose3 pose{Vec3(0.3, -0.2, 0.5), Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()))};
  Vec3 world(const Vec3& local) const { return pose.position + pose.orientation * local; }
  Vec3 turn(const Vec3& local) const { return pose.orientation * local; }
  int face(const Vec3& n) const {
    for (std::size_t f = 0; f < shape.faces().size(); ++f)
      if ((shape.faces()[f].normal - n).norm() < 1e-12) return static_cast<int>(f);
    return -1;
  }
  int vertex(const Vec3& v) const {
    for (std::size_t k = 0; k < shape.vertices().size(); ++k)
      if ((shape.vertices()[k] - v).norm() < 1e-12) return static_cast<int>(k);
    return -1;
  }
  int edge(const Vec3& a, const Vec3& b) const {
    const int va = vertex(a), vb = vertex(b);
    const int u = std::min(va, vb), w = std::max(va, vb);
    for (std::size_t e = 0; e < shape.edges().size(); ++e)
      if (shape.edges()[e].v0 == u && shape.edges()[e].v1 == w) return static_cast<int>(e);
    return -1;
  }
};

struct Expected {
  Vec3 normal;  // world, from the cube to the sphere
  Vec3 point;
  double gap;
  PolyContactKind kind;
  std::uint64_t key;  // with the cube as A
  int face;           // the face whose plane is farthest from the centre
};

// The contact both ways against e: the cube as A, then as B (the normal
// negated bit for bit, the same point and gap, the key's reference bit set).
void expect_contact(const TurnedCube& cube, const Vec3& c, double r, double alert, const Expected& e) {
  const std::optional<PolyContact> a = collide_sphere(cube.shape, cube.pose, c, r, alert);
  ASSERT_TRUE(a.has_value());
  ASSERT_EQ(a->count, 1);
  EXPECT_EQ(a->kind, e.kind);
  EXPECT_LT((a->normal - e.normal).norm(), kTol);
  EXPECT_NEAR(a->normal.norm(), 1.0, kTol);
  EXPECT_NEAR(a->point[0].gap, e.gap, kTol);
  EXPECT_EQ(a->separation, a->point[0].gap);
  EXPECT_LT((a->point[0].position - e.point).norm(), kTol);
  EXPECT_EQ(a->point[0].key, e.key);
  EXPECT_EQ(a->axis, (PolyAxis{PolyAxisKind::FaceA, e.face, 0}));
  const std::optional<PolyContact> b = collide_sphere(c, r, cube.shape, cube.pose, alert);
  ASSERT_TRUE(b.has_value());
  ASSERT_EQ(b->count, 1);
  EXPECT_EQ(b->kind, a->kind);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(b->normal[k], -a->normal[k]);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(b->point[0].position[k], a->point[0].position[k]);
  EXPECT_EQ(b->point[0].gap, a->point[0].gap);
  EXPECT_EQ(b->point[0].key, a->point[0].key | (std::uint64_t{1} << 61));
  EXPECT_EQ(b->axis, (PolyAxis{PolyAxisKind::FaceB, e.face, 0}));
}

}  // namespace

// Above the top face's centre by 1.7 (the face at 1): gap 0.7 - r, the
// face's normal, the point midway between the face and the sphere.
TEST(SpherePolyhedron, AboveAFace) {
  const TurnedCube cube;
  const int top = cube.face(Vec3::UnitZ());
  ASSERT_GE(top, 0);
  const double r = 0.5;
  expect_contact(cube, cube.world(Vec3(0, 0, 1.7)), r, 0.3,
                 {cube.turn(Vec3::UnitZ()), cube.world(Vec3(0, 0, 1.1)), 0.2, PolyContactKind::VertexFace,
                  poly_point_key(PolyKeyTag::Vertex, false, static_cast<std::uint32_t>(top), 0, 0), top});
  // Off the centre, still over the face: the same face, key and normal.
  expect_contact(cube, cube.world(Vec3(0.9, -0.8, 1.6)), r, 0.3,
                 {cube.turn(Vec3::UnitZ()), cube.world(Vec3(0.9, -0.8, 1.05)), 0.1, PolyContactKind::VertexFace,
                  poly_point_key(PolyKeyTag::Vertex, false, static_cast<std::uint32_t>(top), 0, 0), top});
}

// Beside the edge x = z = 1 at (0.3, 0.4) from it: distance 0.5, the
// normal (0.6, 0, 0.8), the point on that line midway. The top face's
// plane is the farthest (0.4 against the side's 0.3).
TEST(SpherePolyhedron, BesideAnEdge) {
  const TurnedCube cube;
  const int e = cube.edge(Vec3(1, -1, 1), Vec3(1, 1, 1));
  ASSERT_GE(e, 0);
  const double r = 0.4;
  const Vec3 n = cube.turn(Vec3(0.6, 0, 0.8));
  expect_contact(cube, cube.world(Vec3(1.3, 0.2, 1.4)), r, 0.3,
                 {n, cube.world(Vec3(1, 0.2, 1)) + 0.05 * n, 0.1, PolyContactKind::SphereEdge,
                  poly_point_key(PolyKeyTag::EdgePair, false, static_cast<std::uint32_t>(e), 0, 0),
                  cube.face(Vec3::UnitZ())});
}

// Off the vertex (1, 1, 1) by (0.1, 0.2, 0.3): gap sqrt(0.14) - r, the
// normal (1, 2, 3) / sqrt(14). The plane z = 1 is the farthest.
TEST(SpherePolyhedron, OffAVertex) {
  const TurnedCube cube;
  const int v = cube.vertex(Vec3(1, 1, 1));
  ASSERT_GE(v, 0);
  const double r = 0.3, gap = std::sqrt(0.14) - r;
  const Vec3 n = cube.turn(Vec3(1, 2, 3) / std::sqrt(14.0));
  expect_contact(cube, cube.world(Vec3(1.1, 1.2, 1.3)), r, 0.3,
                 {n, cube.world(Vec3(1, 1, 1)) + 0.5 * gap * n, gap, PolyContactKind::SphereVertex,
                  poly_point_key(PolyKeyTag::Corner, false, static_cast<std::uint32_t>(v), 0, 0),
                  cube.face(Vec3::UnitZ())});
}

// Sunk 0.01 into the top face: gap -0.01, the point 0.005 below the face;
// the centre inside the cube (0.1 below the top face, its nearest): the
// face of least penetration, gap -0.1 - r.
TEST(SpherePolyhedron, PenetratingAFace) {
  const TurnedCube cube;
  const int top = cube.face(Vec3::UnitZ());
  const Vec3 n = cube.turn(Vec3::UnitZ());
  const std::uint64_t key = poly_point_key(PolyKeyTag::Vertex, false, static_cast<std::uint32_t>(top), 0, 0);
  expect_contact(cube, cube.world(Vec3(0.2, -0.3, 1.49)), 0.5, 0.0,
                 {n, cube.world(Vec3(0.2, -0.3, 0.995)), -0.01, PolyContactKind::VertexFace, key, top});
  expect_contact(cube, cube.world(Vec3(0.2, 0.1, 0.9)), 0.5, 0.0,
                 {n, cube.world(Vec3(0.2, 0.1, 0.7)), -0.6, PolyContactKind::VertexFace, key, top});
}

// A contact exactly as far as alert is kept; a hair farther, nothing (face,
// edge and vertex alike).
TEST(SpherePolyhedron, AlertDistance) {
  const TurnedCube cube;
  const double r = 0.5, alert = 0.25;
  for (const Vec3& dir : std::array<Vec3, 3>{Vec3(0, 0, 1), Vec3(0.6, 0, 0.8), Vec3(Vec3(1, 2, 2) / 3.0)}) {
    const Vec3 foot = dir.z() == 1 ? Vec3(0.1, 0.2, 1) : dir.y() == 0 ? Vec3(1, 0.2, 1) : Vec3(1, 1, 1);
    const Vec3 in = cube.world(foot + (r + alert - 1e-9) * dir), out = cube.world(foot + (r + alert + 1e-9) * dir);
    const auto a = collide_sphere(cube.shape, cube.pose, in, r, alert);
    ASSERT_TRUE(a.has_value());
    EXPECT_NEAR(a->point[0].gap, alert - 1e-9, kTol);
    EXPECT_FALSE(collide_sphere(cube.shape, cube.pose, out, r, alert).has_value());
    EXPECT_FALSE(collide_sphere(out, r, cube.shape, cube.pose, alert).has_value());
  }
}

// Random centres about a random hull at a random pose, outside it: the
// polyhedron's point x = position - gap/2 n is the projection of the centre
// c on the hull: on its surface, and (c - x).(v - x) <= 0 for every vertex
// v; |c - x| = gap + r. Centres inside: the gap is the least depth below a
// face's plane, less r. Faces, edges and vertices are all met. Repeated
// calls give the same bits.
TEST(SpherePolyhedron, RandomCentresProjectOnTheHull) {
  const ConvexPolyhedron P = random_polyhedron(20, Vec3(1.0, 0.7, 0.5), 17).scaled_to_circumradius(1.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  const Pose3 pose{Vec3(3, -1, 2), Quat(Eigen::AngleAxisd(2.0, Vec3(1, -1, 0.5).normalized()))};
  const Eigen::Matrix3d R = pose.orientation.toRotationMatrix();
  std::array<int, 6> kinds{};
  int inside = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec3 local = 1.6 * Vec3(U(rng), U(rng), U(rng));
    const Vec3 c = pose.position + R * local;
    const double r = 0.2 + 0.3 * (U(rng) + 1);
    const auto a = collide_sphere(P, pose, c, r, 10.0);
    ASSERT_TRUE(a.has_value());
    ++kinds[static_cast<std::size_t>(a->kind)];
    const Vec3 n = a->normal;
    const double gap = a->point[0].gap;
    const Vec3 x = R.transpose() * (a->point[0].position - 0.5 * gap * n - pose.position);
    double s = -1e300, depth = 1e300;
    for (const PolyFace& f : P.faces()) {
      s = std::max(s, f.normal.dot(x) - f.offset);
      depth = std::min(depth, f.offset - f.normal.dot(local));
    }
    EXPECT_NEAR(s, 0.0, kTol) << trial;
    if (depth >= 0) {  // centre inside
      ++inside;
      EXPECT_NEAR(gap, -depth - r, kTol) << trial;
      continue;
    }
    EXPECT_NEAR((local - x).norm(), gap + r, kTol) << trial;
    for (const Vec3& v : P.vertices()) EXPECT_LE((local - x).dot(v - x), kTol) << trial;
    const auto again = collide_sphere(P, pose, c, r, 10.0);
    EXPECT_EQ(again->point[0].key, a->point[0].key);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(again->normal[k], a->normal[k]);
      EXPECT_EQ(again->point[0].position[k], a->point[0].position[k]);
    }
    EXPECT_EQ(again->point[0].gap, a->point[0].gap);
  }
  std::printf("face %d, edge %d, vertex %d (centre inside: %d)\n", kinds[0], kinds[4], kinds[5], inside);
  EXPECT_GT(kinds[static_cast<int>(PolyContactKind::VertexFace)], 100);
  EXPECT_GT(kinds[static_cast<int>(PolyContactKind::SphereEdge)], 100);
  EXPECT_GT(kinds[static_cast<int>(PolyContactKind::SphereVertex)], 100);
  EXPECT_GT(inside, 10);
}

namespace {


// The rows between bodies a and b (either body 1): their number, their
// impulse on b (world frame), the last one's kind and feature.
struct PairRows {
  int rows = 0;
  Vec3 impulse_on_b = Vec3::Zero();
  int kind = -1;
  std::uint64_t feature = 0;
};
PairRows rows_between(const World3& w, int a, int b) {
  PairRows p;
  for (std::size_t k = 0; k < w.rows().size(); ++k) {
    const SphereRow& r = w.rows()[k];
    if (!((r.b1 == a && r.b2 == b) || (r.b1 == b && r.b2 == a))) continue;
    ++p.rows;
    p.impulse_on_b += (r.b2 == b ? 1.0 : -1.0) * r.to_world(r.r);
    p.kind = w.infos()[k].kind;
    p.feature = w.infos()[k].feature;
  }
  return p;
}

// The floor's (body 0) normal impulse on body b and its centre of pressure.
std::pair<double, Vec3> floor_load(const World3& w, int b) {
  double n = 0;
  Vec3 cop = Vec3::Zero();
  for (std::size_t k = 0; k < w.rows().size(); ++k) {
    const SphereRow& r = w.rows()[k];
    if (r.b1 != 0 || r.b2 != b) continue;
    n += r.r[0];
    cop += r.r[0] * w.infos()[k].point;
  }
  return {n, n > 0 ? Vec3(cop / n) : cop};
}

}  // namespace

// A sphere of radius r resting off-centre on the top face of a cube (side
// a, 4 times the sphere's mass or so) resting on the floor: one row of kind
// 1 (vertex-face) carrying m g dt straight up, no tangential impulse; the
// floor carries (M + m) g dt with its centre of pressure under the pair's
// centre of mass (a wrong lever arm on the cube would move it); nothing
// moves over 500 steps.
TEST(SpherePolyhedron3, SphereRestsOnACubesFace) {
  World3 w(cdtest::exact_params3(0.4));
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02, r = 0.006;
  const int cube = w.bodies.add_polyhedron(Vec3(0, 0, a / 2), w.bodies.add_shape(cuboid(a, a, a)), kRho);
  const Vec3 xs(0.004, -0.003, a + r);
  const int s = w.bodies.add_sphere(xs, r, kRho);
  const double m = w.bodies.mass[s], M = w.bodies.mass[cube], dt = w.params().dt;
  const int top = [&] {
    for (std::size_t f = 0; f < w.bodies.polyhedra[0].faces().size(); ++f)
      if (w.bodies.polyhedra[0].faces()[f].normal.z() > 0.5) return static_cast<int>(f);
    return -1;
  }();
  for (int k = 0; k < 500; ++k) {
    w.step();
    const PairRows p = rows_between(w, cube, s);
    ASSERT_EQ(p.rows, 1);
    EXPECT_EQ(p.kind, 1 + static_cast<int>(PolyContactKind::VertexFace));
    EXPECT_EQ(p.feature, poly_point_key(PolyKeyTag::Vertex, false, static_cast<std::uint32_t>(top), 0, 0));
    EXPECT_NEAR(p.impulse_on_b.z(), m * kG * dt, 1e-10 * m * kG * dt);
    EXPECT_LT(p.impulse_on_b.head<2>().norm(), 1e-10 * m * kG * dt);
    const auto [fn, cop] = floor_load(w, cube);
    EXPECT_NEAR(fn, (M + m) * kG * dt, 1e-10 * (M + m) * kG * dt);
    EXPECT_LT((cop.head<2>() - m / (M + m) * xs.head<2>()).norm(), 1e-9 * a);
  }
  EXPECT_LT((w.bodies.pos[s] - xs).norm(), 1e-12 * a);
  EXPECT_LT((w.bodies.pos[cube] - Vec3(0, 0, a / 2)).norm(), 1e-12 * a);
  EXPECT_LT(w.bodies.vel[s].v.norm() + w.bodies.vel[cube].v.norm(), 1e-11);
  EXPECT_LT(w.bodies.vel[s].w.norm() + w.bodies.vel[cube].w.norm(), 1e-9);
}

// A cube (side a, mass M) on three equal spheres on the floor, at the
// corners of a scalene triangle holding the cube's centroid: statics is
// determinate (three vertical forces, three equations; a sphere pinched
// between two planes carries no tangential force, or it would turn), each
// sphere carries M g times the barycentric coordinate of the centroid's
// foot, and the floor that plus m g. The spheres come before the cube, so
// each pair has the sphere as body 1 (collide_sphere's other order).
TEST(SpherePolyhedron3, CubeOnThreeSpheresSharesItsWeightByBarycentres) {
  World3 w(cdtest::exact_params3(0.5));
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.03, r = 0.004;
  const std::array<Vec3, 3> foot{Vec3(-0.011, -0.008, 0), Vec3(0.012, -0.005, 0), Vec3(-0.002, 0.013, 0)};
  std::array<int, 3> sph;
  for (int i = 0; i < 3; ++i) sph[i] = w.bodies.add_sphere(foot[i] + Vec3(0, 0, r), r, kRho);
  const Vec3 xc(0.001, 0.0005, 2 * r + a / 2);
  const int cube = w.bodies.add_polyhedron(xc, w.bodies.add_shape(cuboid(a, a, a)), kRho);
  const double m = w.bodies.mass[sph[0]], M = w.bodies.mass[cube], dt = w.params().dt;
  // Barycentric coordinates of the centroid's foot in the triangle.
  Eigen::Matrix3d A;
  for (int i = 0; i < 3; ++i) A.col(i) = Vec3(foot[i].x(), foot[i].y(), 1.0);
  const Vec3 lambda = A.inverse() * Vec3(xc.x(), xc.y(), 1.0);
  ASSERT_GT(lambda.minCoeff(), 0.1);
  for (int k = 0; k < 300; ++k) w.step();
  for (int i = 0; i < 3; ++i) {
    const PairRows p = rows_between(w, sph[i], cube);
    ASSERT_EQ(p.rows, 1) << i;
    EXPECT_EQ(p.kind, 1 + static_cast<int>(PolyContactKind::VertexFace));
    EXPECT_NEAR(p.impulse_on_b.z(), lambda[i] * M * kG * dt, 1e-10 * M * kG * dt) << i;
    EXPECT_LT(p.impulse_on_b.head<2>().norm(), 1e-10 * M * kG * dt) << i;
    EXPECT_NEAR(floor_load(w, sph[i]).first, (lambda[i] * M + m) * kG * dt, 1e-10 * M * kG * dt) << i;
    EXPECT_LT((w.bodies.pos[sph[i]] - foot[i] - Vec3(0, 0, r)).norm(), 1e-12 * a);
  }
  EXPECT_LT((w.bodies.pos[cube] - xc).norm(), 1e-12 * a);
  EXPECT_LT(w.bodies.vel[cube].v.norm() + w.bodies.vel[cube].w.norm(), 1e-9);
}

// Two cubes (side a) on the floor, a gap g apart along x; a sphere of
// radius r > g/2 dropped from 2 mm above its rest into the groove between
// them. Frictionless sphere-cube contacts (floor friction holds the cubes):
// it comes to rest on the two upper edges, its centre at a + sqrt(r^2 -
// g^2/4), each edge pushing along its normal (30 degrees from the vertical
// here) with m g / (2 cos theta): rows of kind 5 (sphere-edge). The
// mechanical energy never rises above its start by more than the sphere
// piles' bound, 1e-5 m g d (tests/test_pile.cpp).
TEST(SpherePolyhedron3, SphereDroppedIntoAGrooveRestsOnTwoEdges) {
  WorldParams3 p = cdtest::exact_params3(0.0);
  p.mu_wall = 0.5;
  // It lands at 0.2 m/s, 2e-4 a step: an alert distance beyond that closes
  // the gap without an overlap (which pure contact dynamics would keep).
  p.alert = 1e-3;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02, r = 0.006, g = r;  // sin(theta) = g / (2 r) = 1/2
  const int shape = w.bodies.add_shape(cuboid(a, a, a));
  const int left = w.bodies.add_polyhedron(Vec3(-(a + g) / 2, 0, a / 2), shape, kRho);
  const int right = w.bodies.add_polyhedron(Vec3((a + g) / 2, 0, a / 2), shape, kRho);
  const double z_rest = a + std::sqrt(r * r - g * g / 4);
  const int s = w.bodies.add_sphere(Vec3(0, 0, z_rest + 0.002), r, kRho);
  const double m = w.bodies.mass[s], dt = w.params().dt;
  const double e0 = w.kinetic_energy() + w.potential_energy(), bound = 1e-5 * m * kG * 2 * r;
  double rise = -1e300;
  for (int k = 0; k < 400; ++k) {
    w.step();
    rise = std::max(rise, w.kinetic_energy() + w.potential_energy() - e0);
  }
  std::printf("largest rise of the energy over its start: %.3g m g d\n", rise / (m * kG * 2 * r));
  EXPECT_LT(rise, bound);
  EXPECT_LT(w.kinetic_energy(), 1e-12 * m * kG * r);
  EXPECT_NEAR(w.bodies.pos[s].z(), z_rest, 1e-9 * r);
  EXPECT_NEAR(w.bodies.pos[s].x(), 0.0, 1e-9 * r);
  const double cos_t = std::sqrt(1 - 0.25);
  for (const int c : {left, right}) {
    const PairRows pr = rows_between(w, c, s);
    ASSERT_EQ(pr.rows, 1);
    EXPECT_EQ(pr.kind, 1 + static_cast<int>(PolyContactKind::SphereEdge));
    const double side = c == left ? 1.0 : -1.0;  // the edge's push on the sphere along x
    EXPECT_NEAR(pr.impulse_on_b.norm(), m * kG * dt / (2 * cos_t), 1e-9 * m * kG * dt);
    EXPECT_NEAR(pr.impulse_on_b.z(), m * kG * dt / 2, 1e-9 * m * kG * dt);
    EXPECT_NEAR(pr.impulse_on_b.x(), side * m * kG * dt / 2 * std::tan(std::acos(cos_t)), 1e-9 * m * kG * dt);
  }
}

// A periodic cell in x and y with a still Lees-Edwards offset: a sphere
// near the far y face rests on a cube at the near one through its image
// (x - offset, y - L). The row carries m g dt; the cube's floor centre of
// pressure sits under the pair's centre of mass with the sphere at its
// image (the point of the row is the image's).
TEST(SpherePolyhedron3, SphereRestsOnACubeThroughALeesEdwardsImage) {
  WorldParams3 p = cdtest::exact_params3(0.4);
  const double L = 0.1, off = 0.03;
  p.periodic = {true, true, false};
  p.cell = Vec3(L, L, L);
  p.le_offset = off;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02, r = 0.005;
  const Vec3 xc(0.05, 0.006, a / 2);
  const int cube = w.bodies.add_polyhedron(xc, w.bodies.add_shape(cuboid(a, a, a)), kRho);
  const Vec3 image(0.053, -0.002, a + r);  // over the cube's top face
  const Vec3 xs = image + Vec3(off, L, 0);
  const int s = w.bodies.add_sphere(xs, r, kRho);
  const double m = w.bodies.mass[s], M = w.bodies.mass[cube], dt = w.params().dt;
  for (int k = 0; k < 200; ++k) w.step();
  const PairRows pr = rows_between(w, cube, s);
  ASSERT_EQ(pr.rows, 1);
  EXPECT_NEAR(pr.impulse_on_b.z(), m * kG * dt, 1e-10 * m * kG * dt);
  const auto [fn, cop] = floor_load(w, cube);
  EXPECT_NEAR(fn, (M + m) * kG * dt, 1e-10 * (M + m) * kG * dt);
  EXPECT_LT((cop.head<2>() - (M * xc + m * image).head<2>() / (M + m)).norm(), 1e-9 * a);
  EXPECT_LT((w.bodies.pos[s] - xs).norm(), 1e-12 * a);
}

namespace {

// Spheres, cubes, tetrahedra and icosahedra dropped in a box of five
// planes, random orientations and velocities: the state after `steps`
// steps, and the rows between a sphere and a polyhedron summed over them.
std::vector<double> mixed_box(int threads, int steps, int& rows, int& mixed) {
  omp_set_num_threads(threads);
  World3 w = cdtest::polyhedra_box(cdtest::exact_params3(0.4), [](World3& w, int k, const Vec3& x, const Quat& q, const Vec3& v,
                                                   const Vec3& om, const int* shapes) {
    if (k % 2 == 0) w.bodies.add_sphere(x, 0.005, kRho, v, om);
    else w.bodies.add_polyhedron(x, shapes[(k / 2) % 3], kRho, q, v, om);
  });
  mixed = 0;
  for (int s = 0; s < steps; ++s) {
    w.step();
    for (const SphereRow& row : w.rows())
      mixed += (w.bodies.shape[row.b1] == Shape3::Sphere && w.bodies.shape[row.b2] == Shape3::Polyhedron) ||
               (w.bodies.shape[row.b1] == Shape3::Polyhedron && w.bodies.shape[row.b2] == Shape3::Sphere);
  }
  rows = static_cast<int>(w.rows().size());
  return cdtest::body_state(w);
}

}  // namespace

TEST(SpherePolyhedron3, MixedPileIdenticalWithOneAndTwoThreads) {
  int rows1 = 0, rows2 = 0, mixed1 = 0, mixed2 = 0;
  const std::vector<double> s1 = mixed_box(1, 120, rows1, mixed1), s2 = mixed_box(2, 120, rows2, mixed2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("%d rows at the end, %d sphere-polyhedron rows over the steps\n", rows1, mixed1);
  EXPECT_GT(rows1, 40);
  EXPECT_GT(mixed1, 500);
  EXPECT_EQ(rows1, rows2);
  EXPECT_EQ(mixed1, mixed2);
  ASSERT_EQ(s1.size(), s2.size());
  std::size_t diff = 0;
  for (std::size_t k = 0; k < s1.size(); ++k) diff += s1[k] != s2[k];
  EXPECT_EQ(diff, 0u);
}
