// A sphere against a convex polyhedron: the narrow phase
// (polyhedron_contact.hpp's collide_sphere), each contact against a closed
// form computed here, not by the code under test: on a turned cube of side
// 2, the sphere above a face, beside an edge, off a vertex, sunk slightly
// into a face, its centre inside; gap = distance - r, the normal and the
// midway point by hand, the kind and the key of the feature; alert; the
// swapped order mirrors the normal; random centres about a random hull give
// the projection on it (x on the surface, (c - x).(v - x) <= 0 for every
// vertex v); repeated calls bit-identical.
// Tolerances: as tests/test_polyhedron_contact.cpp's (1e-12 on O(1)
// coordinates).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "polyhedron.hpp"
#include "polyhedron_contact.hpp"

using namespace cd;

namespace {

constexpr double kTol = 1e-12;

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
