// The narrow phase of convex polyhedra (polyhedron.hpp): polyhedron against
// polyhedron by the separating axis test, polyhedron against a plane, and
// polyhedron against a sphere by the closest point of its surface.
// A contact has one normal, a kind, and up to 4 points, each with its gap
// and a feature key that names it from step to step (for the warm start).
//
// Axes. The candidate axes are the face normals of A, those of B, and the
// cross products of an edge of A and an edge of B that build a face of the
// Minkowski difference (their arcs on the Gauss map cross: Gregorius, GDC
// 2013); pairs with |e_A x e_B| < kParallel |e_A| |e_B| are skipped (their
// cross product turns more than 1000 times faster than the bodies, and two
// parallel edges in contact are a line, which the face axes describe). The
// separation along an axis is the signed distance between the bodies'
// support planes (negative: overlap). The largest separation over the axes
// is the least penetration of overlapping bodies and, for bodies apart, the
// separation closest to their distance (which it never exceeds; it equals
// it for the closest features vertex-face, edge-face, face-face, edge-edge).
//
// Stability. An axis x beats an axis y if s_x > s_y + m(s_y), with the
// margin m(s) = (1 - kRelativeTol) |s| + kAbsoluteTol L, L the smaller
// circumradius (Box2D's k_relativeTol 0.98, k_absoluteTol 0.001 times a
// length). Faces: A's best face, replaced by B's best face if it beats it;
// a hinted face is kept unless that face beats it. Edge pairs: the best
// pair, or the hinted pair unless the best beats it. Then an edge pair is
// the axis only if it beats the face: a face is preferred within the
// margin, hint or not (a face gives a manifold of several points, and in a
// face-face contact the edge axes of the touching faces tie with the face
// axis). Exact ties go to the lower index and to A.
//
// Points. Face axis: the reference face (the axis' face) and the incident
// face (the other body's face most anti-parallel to it); the incident face
// is clipped against the side planes of the reference face (the planes
// through its edges containing its normal: Sutherland-Hodgman; a point
// less than kSideSlack L outside one is on it, so that a vertex lying on a
// side stays that vertex under round-off), and points within the alert
// distance of the reference plane are kept, with every vertex of the
// incident body inside the reference body that the clipping left out. If
// there is none of either, the incident body's deepest vertex is the
// point; when that vertex lies outside the face's prism (beside the
// reference body: the face won only by the margin or the hint), the
// contact is made on the axis of least penetration instead, the best edge
// pair unless a face separates more.
// Their number names the kind: 1 VertexFace, 2 EdgeFace, 3 or more
// FaceFace, reduced to 4 (reduce_points). Edge pair: the closest points of
// the two edges, 1 point, EdgeEdge. A point's position is midway between
// the two surfaces along the normal; its gap is the signed distance along
// it.
//
// Determinism. Plain loops in index order, no threads, no unordered
// containers: the same input gives bit-identical output.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "bodies3.hpp"
#include "polyhedron.hpp"

namespace cd {

namespace poly_contact {
inline constexpr double kRelativeTol = 0.98;  // margin: 2% of the separation
inline constexpr double kAbsoluteTol = 1e-3;  // plus 1e-3 L
inline constexpr double kParallel = 1e-3;     // edge pairs skipped below this sin
inline constexpr double kSideSlack = 1e-6;    // on a side plane: within this times L
}  // namespace poly_contact

// Where a polyhedron is: its centroid and the unit quaternion from its
// centroid frame (ConvexPolyhedron's) to the world: x = position + q v.
struct Pose3 {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
};

// The axis a contact was built on, to be passed back as the next step's
// hint: a face of A (a), a face of B (a), or an edge of A (a) with an edge
// of B (b), indices into faces() and edges().
enum class PolyAxisKind : std::uint8_t { FaceA, FaceB, EdgePair };
struct PolyAxis {
  PolyAxisKind kind = PolyAxisKind::FaceA;
  int a = 0, b = 0;
  bool operator==(const PolyAxis&) const = default;
};

// A sphere's contact (collide_sphere) is VertexFace on a face (its one
// point as a vertex: the face's normal) and SphereEdge or SphereVertex on
// an edge or a vertex (the normal along the line from that feature's
// nearest point to the centre, which no pair of polyhedra has).
enum class PolyContactKind : std::uint8_t { VertexFace, EdgeFace, FaceFace, EdgeEdge, SphereEdge, SphereVertex };

// A point's feature key: 64 bits, tag (2) | reference is B (1) | reference
// (21) | a (20) | b (20). The reference is the reference face (face axis),
// A's edge (edge pair) or 0 (plane). Tags:
//   Vertex:   a vertex a of the incident body (b = 0);
//   EdgeSide: the incident body's edge a cut by side b of the reference
//             face (b counts the face's loop edges from 0);
//   Corner:   sides a < b of the reference face meeting on the incident face;
//   EdgePair: edge a of B (b = 0), the reference being A's edge.
// A sphere's point (collide_sphere) has the polyhedron's feature nearest
// the centre as its reference, a = b = 0 (the sphere's one point), and the
// reference bit set when the polyhedron is B: tag Vertex on a face (the
// sphere's point as the incident vertex), EdgePair on an edge, Corner on a
// vertex (the reference then a vertex index).
// Indices must fit (collide throws std::invalid_argument otherwise).
enum class PolyKeyTag : std::uint8_t { Vertex, EdgeSide, Corner, EdgePair };
constexpr std::uint64_t poly_point_key(PolyKeyTag tag, bool reference_b, std::uint32_t reference,
                                       std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t(tag) << 62) | (std::uint64_t(reference_b) << 61) |
         (std::uint64_t(reference) << 40) | (std::uint64_t(a) << 20) | std::uint64_t(b);
}

struct PolyContactPoint {
  Vec3 position = Vec3::Zero();  // world, midway between the surfaces
  double gap = 0.0;              // along the normal; negative: overlap
  std::uint64_t key = 0;
};

struct PolyContact {
  PolyContactKind kind = PolyContactKind::VertexFace;
  PolyAxis axis;
  Vec3 normal = Vec3::UnitZ();  // unit, from A to B (from the plane to the body)
  double separation = 0.0;      // along the axis (plane: the deepest vertex's gap)
  int count = 0;
  std::array<PolyContactPoint, 4> point{};
  std::span<const PolyContactPoint> points() const { return {point.data(), static_cast<std::size_t>(count)}; }
};

// The contact of A and B, or nothing if an axis separates them by more than
// alert (>= 0, a distance). hint: the previous step's axis of this pair
// (ignored if it is no longer a valid axis). Tolerances scale with L, the
// smaller circumradius.
// face_too (optional): when an edge pair is the axis, the points of the
// best face axis' contact too (its separation is within alert, or there
// would be no contact) that are not deeper than the edge pair's separation
// less its margin, their keys distinct from the edge point's; count 0
// otherwise (and when no such point is left). An edge–edge point alone holds the bodies at one point, and
// they can turn about it until their faces meet inside each other within a
// step (measured in a pile of cubes: overlaps of 0.1 d); the face's points,
// with their own normal, hold the faces apart as they close.
std::optional<PolyContact> collide(const ConvexPolyhedron& A, const Pose3& pose_a,
                                   const ConvexPolyhedron& B, const Pose3& pose_b, double alert,
                                   const std::optional<PolyAxis>& hint = std::nullopt,
                                   PolyContact* face_too = nullptr);

// The plane through p0 with unit normal n (into the free side; body 1)
// against B: the vertices of B's incident face (the most anti-parallel to
// n) within alert of the plane (gap n . (v - p0)) and B's deepest vertex,
// reduced to 4; keys Vertex with the vertex index; kind by their number as
// for a face axis; axis FaceA 0 (the plane's one face).
std::optional<PolyContact> collide_plane(const Vec3& p0, const Vec3& n, const ConvexPolyhedron& B,
                                         const Pose3& pose_b, double alert);

// The sphere of centre c and radius r (world) against a polyhedron: one
// point, or nothing if its gap exceeds alert. The polyhedron's nearest
// feature to c: with c outside, the face whose plane is farthest from c if
// c's projection on that plane lies in the face (a point less than
// kSideSlack L outside a side is in it, so that a sphere resting near an
// edge keeps the face's normal under round-off), else the nearest point of
// the edges (a vertex if within kSideSlack L of one); with c inside (an
// overlap beyond the radius), the face of least penetration. The gap is
// the signed distance of c to the surface less r, the point midway between
// the two surfaces along the normal, the axis the face farthest from c
// (FaceA or FaceB by the polyhedron's side), the separation the gap; kind
// and key as above, L the smaller of r and the circumradius. The first
// call's polyhedron is A (normal from it to the sphere), the second's is B
// (normal from the sphere to it): the same point, gap and axis face, the
// normal negated. Cost O(F + E) plus the face's sides; the centre is taken
// into the polyhedron's frame (one rotation) rather than the polyhedron
// placed in the world's.
std::optional<PolyContact> collide_sphere(const ConvexPolyhedron& A, const Pose3& pose_a, const Vec3& c,
                                          double r, double alert);
std::optional<PolyContact> collide_sphere(const Vec3& c, double r, const ConvexPolyhedron& B,
                                          const Pose3& pose_b, double alert);

// The reduction of more than 4 contact points (a clipped polygon, or a
// plane's vertices; positions, gaps, the normal) to at most 4 that keep
// their extent: the deepest, the one farthest from it across the normal,
// the one spanning the largest triangle with these two, then the one adding
// the most area outside that triangle. At each choice the first point (in
// the given order) within band of the best is taken, so that points tied up
// to round-off or to the solver's jitter (a face lying level) give the same
// choice at every step (collide: band = kAbsoluteTol L in depth and
// distance; for areas, band times the first two points' distance).
// Returns the indices kept, ascending; 4 or fewer points are all kept.
std::vector<int> reduce_points(std::span<const PolyContactPoint> points, const Vec3& n, double band);

}  // namespace cd
