// The narrow phase of convex polyhedra: see polyhedron_contact.hpp.
//
// Frame. Both bodies are placed in one frame, the world's axes with the
// origin at A's centroid (so that a pair far from the world's origin loses
// no digits), and every axis is evaluated on the placed geometry: a face
// axis of A against B gives the same number in collide(A, B) and
// collide(B, A) up to the placement's round-off. Placing costs O(V + F) per
// body per call, small next to the O(E_A E_B) edge pairs; an engine would
// place each body once per step.
#include "polyhedron_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace cd {

namespace {

using namespace poly_contact;

// A polyhedron's vertices and face planes (n . x <= d) in the contact frame.
struct Placed {
  const ConvexPolyhedron* shape = nullptr;
  std::vector<Vec3> v, n;
  std::vector<double> d;
};

Placed place(const ConvexPolyhedron& P, const Pose3& pose, const Vec3& origin) {
  Placed out;
  out.shape = &P;
  const Eigen::Matrix3d R = pose.orientation.normalized().toRotationMatrix();
  const Vec3 t = pose.position - origin;
  out.v.reserve(P.vertices().size());
  for (const Vec3& x : P.vertices()) out.v.push_back(R * x + t);
  out.n.reserve(P.faces().size());
  out.d.reserve(P.faces().size());
  for (const PolyFace& f : P.faces()) {
    const Vec3 nw = R * f.normal;
    out.n.push_back(nw);
    out.d.push_back(f.offset + nw.dot(t));
  }
  return out;
}

// The vertex of P lowest along n (the first on a tie).
int support_low_vertex(const Placed& P, const Vec3& n) {
  int v = 0;
  double low = std::numeric_limits<double>::infinity();
  for (int k = 0; k < static_cast<int>(P.v.size()); ++k)
    if (const double s = n.dot(P.v[k]); s < low) {
      low = s;
      v = k;
    }
  return v;
}

// min over the vertices of n . v
double support_low(const Placed& P, const Vec3& n) { return n.dot(P.v[support_low_vertex(P, n)]); }

// Whether x lies strictly inside P (below every face's plane).
bool inside(const Placed& P, const Vec3& x) {
  for (int h = 0; h < static_cast<int>(P.n.size()); ++h)
    if (!(P.n[h].dot(x) < P.d[h])) return false;
  return true;
}

// The separation of I from R along R's face f.
double face_separation(const Placed& R, int f, const Placed& I) {
  return support_low(I, R.n[f]) - R.d[f];
}

struct FaceQuery {
  double s = -std::numeric_limits<double>::infinity();
  int face = 0;
};

FaceQuery best_face(const Placed& R, const Placed& I) {
  FaceQuery q;
  for (int f = 0; f < static_cast<int>(R.n.size()); ++f) {
    const double s = face_separation(R, f, I);
    if (s > q.s) q = {s, f};
  }
  return q;
}

// The axis of edge ea of A and edge eb of B, if they build a face of the
// Minkowski difference A - B and are not parallel: its unit normal (away
// from A) and the separation along it.
bool edge_axis(const Placed& A, int ea, const Placed& B, int eb, Vec3& n, double& s) {
  const PolyEdge& E = A.shape->edges()[ea];
  const PolyEdge& F = B.shape->edges()[eb];
  // The arcs a-b (A's edge) and -c, -d (B's edge, negated) on the Gauss map
  // cross (Gregorius 2013): c, d on opposite sides of the plane of a, b,
  // a, b on opposite sides of that of c, d, and in the same hemisphere.
  const Vec3 &a = A.n[E.f0], &b = A.n[E.f1];
  const Vec3 c = -B.n[F.f0], d = -B.n[F.f1];
  const Vec3 bxa = b.cross(a), dxc = d.cross(c);
  const double cba = c.dot(bxa), dba = d.dot(bxa), adc = a.dot(dxc), bdc = b.dot(dxc);
  if (!(cba * dba < 0 && adc * bdc < 0 && cba * bdc > 0)) return false;
  const Vec3 pa = A.v[E.v0], qa = B.v[F.v0];
  const Vec3 u = A.v[E.v1] - pa, w = B.v[F.v1] - qa;
  const Vec3 x = u.cross(w);
  const double len = x.norm();
  if (len < kParallel * u.norm() * w.norm()) return false;
  n = x / len;
  if (n.dot(pa) < 0) n = -n;  // A's centroid is the frame's origin
  s = n.dot(qa - pa);
  return true;
}

struct EdgeQuery {
  double s = -std::numeric_limits<double>::infinity();
  int ea = -1, eb = -1;
  Vec3 n = Vec3::Zero();
};

EdgeQuery best_edges(const Placed& A, const Placed& B) {
  EdgeQuery q;
  const int na = static_cast<int>(A.shape->edges().size());
  const int nb = static_cast<int>(B.shape->edges().size());
  Vec3 n;
  double s;
  for (int i = 0; i < na; ++i)
    for (int j = 0; j < nb; ++j)
      if (edge_axis(A, i, B, j, n, s) && s > q.s) q = {s, i, j, n};
  return q;
}

double margin(double s, double L) { return (1.0 - kRelativeTol) * std::abs(s) + kAbsoluteTol * L; }
bool beats(double x, double y, double L) { return x > y + margin(y, L); }

// The index of edge (u, w) in P's edges (sorted by their vertex pair).
int edge_index(const ConvexPolyhedron& P, int u, int w) {
  const auto key = std::minmax(u, w);
  const auto& E = P.edges();
  const auto it = std::lower_bound(E.begin(), E.end(), key, [](const PolyEdge& e, const auto& k) {
    return std::pair(e.v0, e.v1) < std::pair(k.first, k.second);
  });
  return static_cast<int>(it - E.begin());
}

// A point of the clipped polygon: its feature (key without the reference),
// and what the polygon's side from it to the next point lies on: an
// incident edge (>= 0) or a side plane s of the reference face (-1 - s).
struct ClipPoint {
  Vec3 x;
  PolyKeyTag tag;
  std::uint32_t a, b;
  int next;
};

// Sutherland-Hodgman: the part of poly inside the plane s . x <= o. A point
// within slack outside is on the plane: kept as it is, and no intersection
// is made next to it (so that a vertex lying on a side stays that vertex
// under round-off, instead of being by turns a vertex, or cut off and
// replaced by two clip points a round-off apart).
void clip(const std::vector<ClipPoint>& poly, const Vec3& s, double o, double slack, int side,
          std::vector<ClipPoint>& out) {
  out.clear();
  const std::size_t m = poly.size();
  for (std::size_t i = 0; i < m; ++i) {
    const ClipPoint& P = poly[i];
    const ClipPoint& Q = poly[(i + 1) % m];
    const double dp = s.dot(P.x) - o, dq = s.dot(Q.x) - o;
    const bool pin = dp <= slack, qin = dq <= slack;
    if (pin) out.push_back(P);
    if (pin == qin) continue;
    if (pin && dp > 0) {  // P on the plane: the side runs on along it
      out.back().next = -1 - side;
      continue;
    }
    if (qin && dq > 0) continue;  // Q on the plane: Q itself comes next
    ClipPoint X = P;
    X.x = P.x + dp / (dp - dq) * (Q.x - P.x);
    if (P.next >= 0) {
      X.tag = PolyKeyTag::EdgeSide;
      X.a = static_cast<std::uint32_t>(P.next);
      X.b = static_cast<std::uint32_t>(side);
    } else {
      const int other = -1 - P.next;
      X.tag = PolyKeyTag::Corner;
      X.a = static_cast<std::uint32_t>(std::min(other, side));
      X.b = static_cast<std::uint32_t>(std::max(other, side));
    }
    X.next = pin ? -1 - side : P.next;  // leaving: along the side plane
    out.push_back(X);
  }
}

PolyContactKind kind_of(int n) {
  return n == 1 ? PolyContactKind::VertexFace : n == 2 ? PolyContactKind::EdgeFace : PolyContactKind::FaceFace;
}

// Fills c's points from candidates (reduced to 4), moved to the world.
void set_points(PolyContact& c, const std::vector<PolyContactPoint>& cand, const Vec3& n_ref,
                double band, const Vec3& origin) {
  c.kind = kind_of(static_cast<int>(cand.size()));
  std::vector<int> keep;
  if (cand.size() > 4) {
    keep = reduce_points(cand, n_ref, band);
  } else {
    for (int i = 0; i < static_cast<int>(cand.size()); ++i) keep.push_back(i);
  }
  c.count = static_cast<int>(keep.size());
  for (int k = 0; k < c.count; ++k) {
    c.point[k] = cand[keep[k]];
    c.point[k].position += origin;
  }
}

// The incident face of I against a reference normal n: its face most
// anti-parallel to n (the first on a tie).
int incident_face(const Placed& I, const Vec3& n) {
  int fi = 0;
  double lowest = std::numeric_limits<double>::infinity();
  for (int g = 0; g < static_cast<int>(I.n.size()); ++g) {
    const double e = I.n[g].dot(n);
    if (e < lowest) {
      lowest = e;
      fi = g;
    }
  }
  return fi;
}

// The outward unit normal of the side plane through edge k of R's face f
// (from its k-th vertex to the next, the plane containing the face's
// normal); the plane passes through that vertex.
Vec3 side_normal(const Placed& R, int f, int k) {
  const std::vector<int>& ref = R.shape->faces()[f].loop;
  const int r = static_cast<int>(ref.size());
  return (R.v[ref[(k + 1) % r]] - R.v[ref[k]]).cross(R.n[f]).normalized();
}

// Whether x lies in the prism of R's face f (its side planes; a point less
// than slack outside one is on it).
bool in_prism(const Placed& R, int f, const Vec3& x, double slack) {
  const std::vector<int>& ref = R.shape->faces()[f].loop;
  for (int k = 0; k < static_cast<int>(ref.size()); ++k)
    if (side_normal(R, f, k).dot(x - R.v[ref[k]]) > slack) return false;
  return true;
}

// The contact on face f of the reference body R (A unless ref_b) with the
// incident body I. beside (if given): set when the contact's only point is
// the deepest vertex taken because nothing was clipped in, and that vertex
// lies outside the face's prism: it is then beside R, not in it, and the
// face is not where the bodies overlap (an edge pair is; see collide).
PolyContact face_contact(const Placed& R, int f, const Placed& I, bool ref_b, double separation,
                         double alert, double L, const Vec3& origin, bool* beside = nullptr) {
  const Vec3& n = R.n[f];
  const double d = R.d[f];
  PolyContact c;
  c.separation = separation;
  c.axis = {ref_b ? PolyAxisKind::FaceB : PolyAxisKind::FaceA, f, 0};
  c.normal = ref_b ? Vec3(-n) : n;
  const int fi = incident_face(I, n);
  const std::vector<int>& loop = I.shape->faces()[fi].loop;
  const int m = static_cast<int>(loop.size());
  std::vector<ClipPoint> poly, next;
  poly.reserve(2 * m);
  for (int k = 0; k < m; ++k)
    poly.push_back({I.v[loop[k]], PolyKeyTag::Vertex, static_cast<std::uint32_t>(loop[k]), 0,
                    edge_index(*I.shape, loop[k], loop[(k + 1) % m])});
  const std::vector<int>& ref = R.shape->faces()[f].loop;
  const int r = static_cast<int>(ref.size());
  for (int k = 0; k < r && !poly.empty(); ++k) {
    const Vec3 s = side_normal(R, f, k);
    clip(poly, s, s.dot(R.v[ref[k]]), kSideSlack * L, k, next);
    std::swap(poly, next);
  }
  const std::uint32_t fr = static_cast<std::uint32_t>(f);
  std::vector<PolyContactPoint> cand;
  for (const ClipPoint& q : poly) {
    const double g = n.dot(q.x) - d;
    if (g <= alert) cand.push_back({q.x - 0.5 * g * n, g, poly_point_key(q.tag, ref_b, fr, q.a, q.b)});
  }
  // The incident body's vertices inside the reference body that the
  // clipping left out (outside the face's prism, or every clipped point
  // above alert): held by no row, each would sink on below the face. Seen
  // on irregular hulls: the deepest vertex outside the prism under the
  // previous step's hinted face (0.002 d a step), and an edge beside the
  // face whose two vertices took the one row in turn, the other sinking
  // meanwhile (0.03 d in 30 steps, 0.19 d over a shear). Each joins the
  // points, and the reduction keeps the deepest and the extent.
  std::vector<char> kept(I.v.size(), 0);  // the vertices the clipping kept (candidates or above alert)
  for (const ClipPoint& q : poly)
    if (q.tag == PolyKeyTag::Vertex) kept[q.a] = 1;
  auto add_vertex = [&](int k, double g) {
    cand.push_back({I.v[k] - 0.5 * g * n, g,
                    poly_point_key(PolyKeyTag::Vertex, ref_b, fr, static_cast<std::uint32_t>(k), 0)});
  };
  for (int k = 0; k < static_cast<int>(I.v.size()); ++k) {
    const double g = n.dot(I.v[k]) - d;
    if (!kept[k] && g < -kAbsoluteTol * L && inside(R, I.v[k])) add_vertex(k, g);
  }
  // With no point at all, the deepest vertex (the one that gives this axis
  // its separation). Not beside others: outside the reference body, its
  // row would hold the bodies apart where they are free (0.14 L outside it,
  // seen beside a vertex inside it).
  if (cand.empty()) {
    const int v = support_low_vertex(I, n);
    add_vertex(v, n.dot(I.v[v]) - d);
    if (beside) *beside = !in_prism(R, f, I.v[v], kSideSlack * L);
  }
  set_points(c, cand, n, kAbsoluteTol * L, origin);
  return c;
}

// The closest points of segments p + s u and q + t w (s, t in [0, 1];
// Ericson, Real-Time Collision Detection 5.1.9), not parallel.
std::pair<Vec3, Vec3> closest_points(const Vec3& p, const Vec3& u, const Vec3& q, const Vec3& w) {
  const Vec3 r = p - q;
  const double a = u.dot(u), e = w.dot(w), f = w.dot(r), c = u.dot(r), b = u.dot(w);
  const double den = a * e - b * b;
  double s = std::clamp((b * f - c * e) / den, 0.0, 1.0);
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {p + s * u, q + t * w};
}

PolyContact edge_contact(const Placed& A, int ea, const Placed& B, int eb, const Vec3& n,
                         const Vec3& origin) {
  const PolyEdge& E = A.shape->edges()[ea];
  const PolyEdge& F = B.shape->edges()[eb];
  const auto [pa, pb] =
      closest_points(A.v[E.v0], A.v[E.v1] - A.v[E.v0], B.v[F.v0], B.v[F.v1] - B.v[F.v0]);
  PolyContact c;
  c.kind = PolyContactKind::EdgeEdge;
  c.axis = {PolyAxisKind::EdgePair, ea, eb};
  c.normal = n;
  c.count = 1;
  c.point[0] = {0.5 * (pa + pb) + origin, n.dot(pb - pa),
                poly_point_key(PolyKeyTag::EdgePair, false, static_cast<std::uint32_t>(ea),
                               static_cast<std::uint32_t>(eb), 0)};
  c.separation = c.point[0].gap;
  return c;
}

void check_size(const ConvexPolyhedron& P, const char* name) {
  const std::size_t most = std::max({P.vertices().size(), P.faces().size(), P.edges().size()});
  if (most >= (std::size_t{1} << 20))
    throw std::invalid_argument(std::string("collide: polyhedron ") + name +
                                " has too many features for the point keys (2^20)");
}

// A sphere against a polyhedron, in the polyhedron's centroid frame. One
// point is wanted, so the sphere's centre is taken into that frame (one
// rotation) rather than the polyhedron placed in the world's (O(V + F)).

enum class Feature : std::uint8_t { Face, Edge, Vertex };

// The polyhedron's surface point nearest a point p: its feature (a face,
// an edge or a vertex by index), the outward unit normal there and p's
// signed distance along it (negative inside).
struct Nearest {
  Feature feature = Feature::Face;
  int index = 0;
  Vec3 n = Vec3::UnitZ();
  double distance = 0.0;
};

// Whether x, in face f's plane, lies in the face: no farther than slack
// outside any of its side planes.
bool in_face(const ConvexPolyhedron& P, int f, const Vec3& x, double slack) {
  const PolyFace& F = P.faces()[static_cast<std::size_t>(f)];
  const std::vector<Vec3>& V = P.vertices();
  const std::size_t m = F.loop.size();
  for (std::size_t k = 0; k < m; ++k) {
    const Vec3& a = V[static_cast<std::size_t>(F.loop[k])];
    const Vec3 side = (V[static_cast<std::size_t>(F.loop[(k + 1) % m])] - a).cross(F.normal).normalized();
    if (side.dot(x - a) > slack) return false;
  }
  return true;
}

// The nearest point of P's edges to p (outside P): the first edge at the
// least distance. An end point is the vertex itself (not v0 + 1 (v1 - v0),
// a round-off away), so that edges meeting at the nearest vertex tie
// exactly and the first of them is taken whatever the others give. Within
// slack of an end, the feature is that vertex, so that a sphere resting
// on a vertex keeps its key; the point stays the edge's.
Nearest nearest_on_edges(const ConvexPolyhedron& P, const Vec3& p, double slack) {
  const std::vector<Vec3>& V = P.vertices();
  double best = std::numeric_limits<double>::infinity();
  int e_best = 0;
  double along = 0.0, length = 0.0;
  Vec3 x_best = Vec3::Zero();
  for (int e = 0; e < static_cast<int>(P.edges().size()); ++e) {
    const PolyEdge& E = P.edges()[static_cast<std::size_t>(e)];
    const Vec3 &a = V[static_cast<std::size_t>(E.v0)], &b = V[static_cast<std::size_t>(E.v1)];
    const Vec3 u = b - a;
    const double t = (p - a).dot(u) / u.squaredNorm();
    const Vec3 x = t <= 0.0 ? a : t >= 1.0 ? b : Vec3(a + t * u);
    const double d2 = (p - x).squaredNorm();
    if (d2 < best) {
      best = d2;
      e_best = e;
      x_best = x;
      along = std::clamp(t, 0.0, 1.0);
      length = u.norm();
    }
  }
  const PolyEdge& E = P.edges()[static_cast<std::size_t>(e_best)];
  Nearest h;
  h.distance = std::sqrt(best);
  h.n = (p - x_best) / h.distance;
  if (along * length <= slack) {
    h.feature = Feature::Vertex;
    h.index = E.v0;
  } else if ((1.0 - along) * length <= slack) {
    h.feature = Feature::Vertex;
    h.index = E.v1;
  } else {
    h.feature = Feature::Edge;
    h.index = e_best;
  }
  return h;
}

// The contact of the sphere (c, r) with P at pose; the polyhedron is B if
// poly_b (the normal then from the sphere to it), else A.
std::optional<PolyContact> sphere_polyhedron(const ConvexPolyhedron& P, const Pose3& pose, const Vec3& c,
                                             double r, double alert, bool poly_b) {
  check_size(P, poly_b ? "B" : "A");
  const Eigen::Matrix3d R = pose.orientation.normalized().toRotationMatrix();
  const Vec3 p = R.transpose() * (c - pose.position);
  const double slack = kSideSlack * std::min(r, P.circumradius());
  // The face whose plane is farthest from p (the first on a tie): P lies
  // behind every face's plane, so no point of P is nearer than that.
  int f = 0;
  double s = -std::numeric_limits<double>::infinity();
  for (int g = 0; g < static_cast<int>(P.faces().size()); ++g) {
    const PolyFace& F = P.faces()[static_cast<std::size_t>(g)];
    const double sg = F.normal.dot(p) - F.offset;
    if (sg > s) {
      s = sg;
      f = g;
    }
  }
  if (s - r > alert) return std::nullopt;
  // Inside P the face of least penetration; outside, the face if p's
  // projection on it lies in it (then that is the nearest point: a face
  // holding the nearest point in its interior has the farthest plane),
  // else an edge or a vertex.
  const PolyFace& F = P.faces()[static_cast<std::size_t>(f)];
  Nearest h;
  if (s <= 0.0 || in_face(P, f, p - s * F.normal, slack)) {
    h.feature = Feature::Face;
    h.index = f;
    h.n = F.normal;
    h.distance = s;
  } else {
    h = nearest_on_edges(P, p, slack);
  }
  const double gap = h.distance - r;
  if (gap > alert) return std::nullopt;
  const Vec3 n = R * h.n;  // world, from the polyhedron to the sphere
  static constexpr PolyKeyTag kTag[3] = {PolyKeyTag::Vertex, PolyKeyTag::EdgePair, PolyKeyTag::Corner};
  static constexpr PolyContactKind kKind[3] = {PolyContactKind::VertexFace, PolyContactKind::SphereEdge,
                                               PolyContactKind::SphereVertex};
  const auto which = static_cast<std::size_t>(h.feature);
  PolyContact out;
  out.kind = kKind[which];
  out.axis = {poly_b ? PolyAxisKind::FaceB : PolyAxisKind::FaceA, f, 0};
  out.normal = poly_b ? Vec3(-n) : n;
  out.separation = gap;
  out.count = 1;
  out.point[0] = {c - (r + 0.5 * gap) * n, gap,
                  poly_point_key(kTag[which], poly_b, static_cast<std::uint32_t>(h.index), 0, 0)};
  return out;
}

}  // namespace

std::optional<PolyContact> collide_sphere(const ConvexPolyhedron& A, const Pose3& pose_a, const Vec3& c,
                                          double r, double alert) {
  return sphere_polyhedron(A, pose_a, c, r, alert, false);
}

std::optional<PolyContact> collide_sphere(const Vec3& c, double r, const ConvexPolyhedron& B,
                                          const Pose3& pose_b, double alert) {
  return sphere_polyhedron(B, pose_b, c, r, alert, true);
}

std::vector<int> reduce_points(std::span<const PolyContactPoint> pts, const Vec3& n, double band) {
  const int m = static_cast<int>(pts.size());
  std::vector<int> keep;
  if (m <= 4) {
    for (int i = 0; i < m; ++i) keep.push_back(i);
    return keep;
  }
  // The first index whose value is within tol of the largest.
  auto first_best = [m](auto&& value, double tol) {
    double best = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < m; ++i) best = std::max(best, value(i));
    for (int i = 0; i < m; ++i)
      if (value(i) >= best - tol) return i;
    return 0;
  };
  const int i1 = first_best([&](int i) { return -pts[i].gap; }, band);
  const Vec3 x1 = pts[i1].position;
  auto planar = [&](int i) {
    const Vec3 r = pts[i].position - x1;
    return Vec3(r - r.dot(n) * n);
  };
  const int i2 = first_best([&](int i) { return planar(i).norm(); }, band);
  const Vec3 x2 = pts[i2].position;
  // Twice the signed area of (a, b, x) about n.
  auto area = [&](const Vec3& a, const Vec3& b, int i) {
    return (b - a).cross(pts[i].position - a).dot(n);
  };
  const double atol = 2.0 * band * planar(i2).norm();
  const int i3 = first_best([&](int i) { return std::abs(area(x1, x2, i)); }, atol);
  // The triangle counter-clockwise about n; the fourth point adds the most
  // area outside one of its sides.
  std::array<Vec3, 3> t{x1, x2, pts[i3].position};
  if (area(x1, x2, i3) < 0) std::swap(t[0], t[1]);
  auto added = [&](int i) {
    double add = 0.0;
    for (int k = 0; k < 3; ++k) add = std::max(add, -area(t[k], t[(k + 1) % 3], i));
    return add;
  };
  const int i4 = first_best(added, atol);
  keep = {i1, i2, i3};
  if (added(i4) > atol) keep.push_back(i4);  // else every point is in the triangle
  std::sort(keep.begin(), keep.end());
  keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
  return keep;
}

std::optional<PolyContact> collide(const ConvexPolyhedron& A, const Pose3& pose_a,
                                   const ConvexPolyhedron& B, const Pose3& pose_b, double alert,
                                   const std::optional<PolyAxis>& hint, PolyContact* face_too) {
  if (face_too) face_too->count = 0;
  check_size(A, "A");
  check_size(B, "B");
  const Vec3 origin = pose_a.position;
  const Placed pa = place(A, pose_a, origin), pb = place(B, pose_b, origin);
  const double L = std::min(A.circumradius(), B.circumradius());

  const FaceQuery fa = best_face(pa, pb);
  if (fa.s > alert) return std::nullopt;
  const FaceQuery fb = best_face(pb, pa);
  if (fb.s > alert) return std::nullopt;
  const EdgeQuery ee = best_edges(pa, pb);
  if (ee.s > alert) return std::nullopt;

  // Faces: A's best, B's if it beats it; a hinted face unless that beats it.
  bool face_b = beats(fb.s, fa.s, L);
  int face = face_b ? fb.face : fa.face;
  double sf = face_b ? fb.s : fa.s;
  if (hint && hint->kind != PolyAxisKind::EdgePair) {
    const bool hb = hint->kind == PolyAxisKind::FaceB;
    const Placed &R = hb ? pb : pa, &I = hb ? pa : pb;
    if (hint->a >= 0 && hint->a < static_cast<int>(R.n.size())) {
      const double sh = face_separation(R, hint->a, I);
      if (!beats(sf, sh, L)) {
        face_b = hb;
        face = hint->a;
        sf = sh;
      }
    }
  }
  // Edge pairs: the best, or a hinted pair unless the best beats it.
  int ea = ee.ea, eb = ee.eb;
  double se = ee.s;
  Vec3 ne = ee.n;
  if (hint && hint->kind == PolyAxisKind::EdgePair && hint->a >= 0 &&
      hint->a < static_cast<int>(A.edges().size()) && hint->b >= 0 &&
      hint->b < static_cast<int>(B.edges().size())) {
    Vec3 nh;
    double sh;
    if (edge_axis(pa, hint->a, pb, hint->b, nh, sh) && !beats(se, sh, L)) {
      ea = hint->a;
      eb = hint->b;
      se = sh;
      ne = nh;
    }
  }
  // The contact on face f of B (on_b) or of A, the other body incident.
  auto on_face = [&](bool on_b, int f, double s, bool* beside = nullptr) {
    return on_b ? face_contact(pb, f, pa, true, s, alert, L, origin, beside)
                : face_contact(pa, f, pb, false, s, alert, L, origin, beside);
  };
  if (ea >= 0 && beats(se, sf, L)) {
    if (face_too) {
      // The face's points that are not deeper than the edge pair's own
      // separation (within its margin): those about to close. A deeper one
      // is beside the other body, not in it (below the face's plane, beyond
      // the edge), and would hold the bodies apart where they are free.
      const PolyContact f = on_face(face_b, face, sf);
      const double floor = se - margin(se, L);
      face_too->axis = f.axis;
      face_too->normal = f.normal;
      face_too->separation = f.separation;
      for (const PolyContactPoint& p : f.points())
        if (p.gap >= floor) face_too->point[static_cast<std::size_t>(face_too->count++)] = p;
      face_too->kind = face_too->count > 0 ? kind_of(face_too->count) : f.kind;
    }
    return edge_contact(pa, ea, pb, eb, ne, origin);
  }
  // A face that won only within the margin (or by its hint) and finds no
  // point of its own, only the deepest vertex beside the reference body:
  // the bodies overlap where an edge of one crosses the other's surface,
  // and the edge pair's point is there. Held by the vertex beside it
  // instead, an irregular hull's overlap grew 0.01 to 0.045 d in 180 steps
  // of shear, under a row at the axis' full separation.
  bool beside = false;
  PolyContact c = on_face(face_b, face, sf, &beside);
  if (!beside) return c;
  // Then the axis of least penetration, without margin or hint: the best
  // edge pair (the unhinted one) if no face beats it, else the best face.
  // At that axis the deepest point lies in its Minkowski face: the vertex
  // in the face's prism, the edges' closest points inside both segments.
  const bool fb_best = fb.s > fa.s;
  const FaceQuery& best = fb_best ? fb : fa;
  if (ee.ea >= 0 && ee.s >= best.s) return edge_contact(pa, ee.ea, pb, ee.eb, ee.n, origin);
  if (fb_best == face_b && best.face == face) return c;
  return on_face(fb_best, best.face, best.s);
}

std::optional<PolyContact> collide_plane(const Vec3& p0, const Vec3& n, const ConvexPolyhedron& B,
                                         const Pose3& pose_b, double alert) {
  check_size(B, "B");
  const Vec3 origin = pose_b.position;
  const Placed pb = place(B, pose_b, origin);
  const Vec3 q = p0 - origin;
  // The candidates: the vertices within alert of B's incident face (its
  // face most anti-parallel to n, the first on a tie) and B's deepest
  // vertex. Not every vertex within alert: on a body whose next ring of
  // vertices is within alert of the plane (an icosahedron resting on a
  // face, 0.3 d above it against an alert of d/3), the reduction to 4
  // points keeps the widest, and that dropped two of the three vertices
  // that bear, which then sank into the plane without a row (0.2 d in
  // 0.4 s of a single icosahedron at rest). The incident face's points are
  // coplanar, as a face pair's clipped points are; a body on an edge or a
  // vertex has them in its incident face or as its deepest vertex.
  const int nv = static_cast<int>(pb.v.size());
  std::vector<double> gap(static_cast<std::size_t>(nv));
  int deepest = 0;
  for (int k = 0; k < nv; ++k) {
    gap[k] = n.dot(pb.v[k] - q);
    if (gap[k] < gap[deepest]) deepest = k;
  }
  if (gap[deepest] > alert) return std::nullopt;
  const int fi = incident_face(pb, n);
  std::vector<char> take(static_cast<std::size_t>(nv), 0);
  for (const int k : B.faces()[fi].loop) take[k] = gap[k] <= alert;
  take[deepest] = 1;
  std::vector<PolyContactPoint> cand;
  for (int k = 0; k < nv; ++k)
    if (take[k])
      cand.push_back({pb.v[k] - 0.5 * gap[k] * n, gap[k],
                      poly_point_key(PolyKeyTag::Vertex, false, 0, static_cast<std::uint32_t>(k), 0)});
  if (cand.empty()) return std::nullopt;
  PolyContact c;
  c.axis = {PolyAxisKind::FaceA, 0, 0};
  c.normal = n;
  set_points(c, cand, n, kAbsoluteTol * B.circumradius(), origin);
  c.separation = c.point[0].gap;
  for (const PolyContactPoint& p : c.points()) c.separation = std::min(c.separation, p.gap);
  return c;
}

}  // namespace cd
