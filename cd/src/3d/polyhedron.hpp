// Convex polyhedra: the shape (convex hull of given vertices, faces as
// planar polygons, edges) and its mass properties at uniform density, with a
// library of shapes (Platonic solids, cuboids, random hulls of points on an
// ellipsoid). Geometry only: no body of the engine is a polyhedron yet.
//
// Frames. The input points are in the *input frame*. The polyhedron keeps
// its geometry in the *centroid frame*: the input frame's axes, its origin
// moved to the centroid, so that an input point x is vertex + origin(). The
// inertia tensor is given in the centroid frame too; principal_axes() is
// the rotation R from the principal frame to the centroid frame (its
// columns are the principal axes), J = R diag(principal moments) R^T.
//
// Tolerance. Every geometric decision (two points coincide, points are
// collinear or coplanar, a point is above a face, a hull triangle lies in
// the plane of a face) compares a distance with tolerance() = 1e-10 L,
// L the largest extent of the input's bounding box: the hull is exact up to
// that, a million times the round-off of coordinates of size L (distances
// are computed about the bounding box's centre, so a translated input loses
// nothing). A point within the tolerance of the hull's surface is on it.
// Every result is checked: Euler's formula, faces planar and every input
// point inside every face's plane to 2 tolerances, the centroid inside.
// Input a few tolerances from degenerate (points 1e-10 to 1e-8 of the size
// off a plane they nearly share, a shape flatter or thinner than ~1e-6 of
// its size) can fail that check and is then refused as such. Coplanar
// vertices rounded to 12 or more significant digits make one face; rounded
// to 9 or fewer, they are coplanar beyond the tolerance and a face comes
// out split into several (a valid hull, with more faces).
//
// Determinism. The result depends only on the input (values and order):
// vertices in input order, each face's loop starting at its smallest vertex
// index, faces sorted by their loops, edges by their vertex pair. The hull
// algorithm's own order does not show.
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "vec3.hpp"

namespace cd {

// A face: a convex planar polygon, its vertex loop counter-clockwise seen
// from outside (so (v1 - v0) x (v2 - v1) points along normal), and its plane
// normal . x = offset; the polyhedron is normal . x <= offset.
struct PolyFace {
  std::vector<int> loop;
  Vec3 normal = Vec3::Zero();  // outward, unit
  double offset = 0.0;         // centroid frame
};

// An edge between vertices v0 < v1. Face f0's loop runs v0 -> v1, face f1's
// runs v1 -> v0 (f0 is on the left of v0 -> v1 seen from outside).
struct PolyEdge {
  int v0 = 0, v1 = 0;
  int f0 = 0, f1 = 0;
};

// What the hull does with input points that are not its vertices (strictly
// inside, within the tolerance of a face or an edge, or a duplicate): user
// input refuses them (it is then not convex, or redundant), generators of
// random shapes drop them.
enum class RedundantPoints : std::uint8_t { Refuse, Drop };

class ConvexPolyhedron {
 public:
  // The convex hull of points (input frame). std::invalid_argument, with a
  // message naming the fault, for: fewer than 4 points; a non-finite
  // coordinate; zero volume (all points coincident, collinear or coplanar);
  // with RedundantPoints::Refuse, two coincident points or a point that is
  // not a vertex of the hull (points are counted from 0 in messages); input
  // too close to degenerate for the tolerance (see above).
  explicit ConvexPolyhedron(const std::vector<Vec3>& points,
                            RedundantPoints redundant = RedundantPoints::Refuse);

  // Geometry, centroid frame.
  const std::vector<Vec3>& vertices() const { return vertices_; }
  const std::vector<PolyFace>& faces() const { return faces_; }
  const std::vector<PolyEdge>& edges() const { return edges_; }
  // For each vertex, the index of its point in the input.
  const std::vector<int>& input_index() const { return input_index_; }
  // The centroid in the input frame: input point = vertex + origin().
  const Vec3& origin() const { return origin_; }
  // Largest distance of a vertex from the centroid (the broad phase's sphere).
  double circumradius() const { return circumradius_; }
  double tolerance() const { return tolerance_; }

  // Mass properties: exact volume; the inertia tensor about the centroid
  // (centroid frame) per unit density, i.e. J = integral (|x|^2 1 - x x^T) dV;
  // its eigenvalues in ascending order and the rotation R to them.
  double volume() const { return volume_; }
  const Eigen::Matrix3d& unit_inertia() const { return unit_inertia_; }
  const Vec3& unit_principal_moments() const { return unit_principal_; }
  // Orthonormal, det +1. Convention: columns in ascending order of their
  // moments; the component of largest magnitude of the first two columns is
  // positive (the first such component on a tie within 1e-9), the third is
  // their cross product. Moments closer than 1e-9 times the largest one
  // are equal, and their axes are not left to the eigensolver's
  // round-off: all three equal (Platonic solids) give R = 1; two equal ones
  // take as first of their pair the input frame's axis least aligned with
  // the distinct axis (the first on a tie), projected off it (then
  // J = R diag(moments) R^T holds to that 1e-9, else to round-off).
  const Eigen::Matrix3d& principal_axes() const { return principal_axes_; }

  // At density rho.
  double mass(double rho) const { return rho * volume_; }
  Eigen::Matrix3d inertia(double rho) const { return rho * unit_inertia_; }
  Vec3 principal_moments(double rho) const { return rho * unit_principal_; }

  // The same shape scaled by s > 0 about its centroid (origin() scaled too):
  // same topology and axes, volume s^3, inertia s^5.
  ConvexPolyhedron scaled(double s) const;
  ConvexPolyhedron scaled_to_circumradius(double r) const { return scaled(r / circumradius_); }

 private:
  std::vector<Vec3> vertices_;
  std::vector<PolyFace> faces_;
  std::vector<PolyEdge> edges_;
  std::vector<int> input_index_;
  Vec3 origin_ = Vec3::Zero();
  double circumradius_ = 0.0, tolerance_ = 0.0, volume_ = 0.0;
  Eigen::Matrix3d unit_inertia_ = Eigen::Matrix3d::Zero();
  Vec3 unit_principal_ = Vec3::Zero();
  Eigen::Matrix3d principal_axes_ = Eigen::Matrix3d::Identity();
};

// The library of shapes (polyhedron_shapes.cpp).

enum class Platonic : std::uint8_t { Tetrahedron, Cube, Octahedron, Dodecahedron, Icosahedron };

// A Platonic solid of circumradius r centred at the origin. Orientation:
// cube faces normal to the axes; tetrahedron at alternate cube corners
// (1, 1, 1) ...; octahedron vertices on the axes; icosahedron (0, +-1, +-phi)
// and dodecahedron (+-1, +-1, +-1), (0, +-1/phi, +-phi) with their cyclic
// permutations, phi the golden ratio.
ConvexPolyhedron platonic(Platonic kind, double r);

// A cuboid of side lengths a, b, c along x, y, z, centred at the origin.
ConvexPolyhedron cuboid(double a, double b, double c);

// n points uniformly distributed on the sphere, mapped onto the ellipsoid
// of semi-axes (a, b, c) along x, y, z: (a x, b y, c z). Portable: the same
// points on every platform (std::mt19937_64 is fully specified; its 53 high
// bits make a uniform double in [0, 1); a point of the cube [-1, 1]^3 is
// kept if 1e-6 < |x|^2 <= 1 and normalised, which needs only correctly
// rounded IEEE operations, no library sin/cos/log).
std::vector<Vec3> random_points_on_ellipsoid(int n, const Vec3& semi_axes, std::uint64_t seed);

// The hull of random_points_on_ellipsoid (points that are not vertices of
// it dropped). Scale it with scaled_to_circumradius.
ConvexPolyhedron random_polyhedron(int n, const Vec3& semi_axes, std::uint64_t seed);

}  // namespace cd
