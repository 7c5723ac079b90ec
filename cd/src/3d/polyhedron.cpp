// ConvexPolyhedron: the hull, its faces and edges, its mass properties.
//
// The hull is computed here rather than with Qhull (libqhull_r, in Debian):
// the shapes have tens to a few hundred vertices, for which a plain
// Quickhull is short and fast (3000 points in ~0.1 s); Qhull's triangulated
// or merged output would still have to be put in a canonical order, its
// coplanar merging and its notion of an interior point made to agree with
// the refusals below, and its errors (which exit or longjmp) turned into
// exceptions.
//
// Steps: (1) check the input and the tolerance; (2) the hull as triangles,
// points added in the order of Quickhull; (3) faces grown over the
// triangles that lie in one plane within the tolerance, the boundary of
// each its loop; a point is a vertex when it is a corner of at least three
// faces (one face: in its interior; two: inside an edge); (4) the canonical
// order; (5) volume, centroid and inertia from tetrahedra on the faces from
// an interior point; (6) the principal frame.
#include "polyhedron.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

namespace cd {

namespace {

// Relative tolerance of every geometric decision (times the input's size).
constexpr double kRelativeTolerance = 1e-10;
// Moments within this fraction of the largest one are equal (principal frame).
constexpr double kEqualMoments = 1e-9;

std::string point_text(const Vec3& p) { return fmt::format("({:.17g}, {:.17g}, {:.17g})", p.x(), p.y(), p.z()); }

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument("convex polyhedron: " + what); }
// A hull that fails its invariants: only inputs close to degenerate at the
// tolerance come here (see the header), refused as such.
[[noreturn]] void broken(const std::string& what) {
  throw std::invalid_argument("convex polyhedron: no consistent hull at the tolerance (" + what +
                              "): the points are too close to a degenerate configuration");
}

// An oriented hull triangle: vertices counter-clockwise seen from outside,
// unit outward normal n, plane n.x = d, twice its area.
struct Tri {
  std::array<int, 3> v;
  Vec3 n;
  double d, area2;
};

Tri make_tri(const std::vector<Vec3>& q, int a, int b, int c) {
  const Vec3 m = (q[b] - q[a]).cross(q[c] - q[a]);
  const double len = m.norm();
  if (!(len > 0.0)) broken(fmt::format("a degenerate triangle {} {} {}", a, b, c));
  const Vec3 n = m / len;
  return Tri{{a, b, c}, n, n.dot(q[a]), len};
}

double height(const Tri& t, const Vec3& p) { return t.n.dot(p) - t.d; }

// The first simplex: the lexicographically smallest point, the farthest
// from it, the farthest from their line, the farthest from their plane.
// Its degeneracies are the zero-volume refusals.
std::array<int, 4> first_simplex(const std::vector<Vec3>& q, const std::vector<int>& used, double eps) {
  int i0 = used[0];
  for (int k : used)
    if (std::lexicographical_compare(q[k].data(), q[k].data() + 3, q[i0].data(), q[i0].data() + 3)) i0 = k;
  const auto farthest = [&](auto dist) {
    int best = i0;
    double dbest = 0.0;
    for (int k : used)
      if (const double d = dist(q[k]); d > dbest) best = k, dbest = d;
    return std::pair{best, dbest};
  };
  const auto [i1, d1] = farthest([&](const Vec3& p) { return (p - q[i0]).norm(); });
  if (d1 <= eps) refuse("zero volume: all points coincide");
  const Vec3 u = (q[i1] - q[i0]) / d1;
  const auto [i2, d2] = farthest([&](const Vec3& p) { return (p - q[i0]).cross(u).norm(); });
  if (d2 <= eps) refuse("zero volume: all points are collinear");
  const Vec3 n = u.cross(q[i2] - q[i0]).normalized();
  const auto [i3, d3] = farthest([&](const Vec3& p) { return std::abs(n.dot(p - q[i0])); });
  if (d3 <= eps) refuse("zero volume: all points are coplanar");
  return {i0, i1, i2, i3};
}

// The hull's triangles over the points `used` (indices into q), in the
// order of Quickhull (Barber, Dobkin & Huhdanpaa 1996): each point outside
// the hull so far waits in the outside set of one triangle it is above (by
// more than eps); the farthest point of the first triangle with a
// non-empty set is added next, the triangles it sees (the connected region
// around that triangle) replaced by a fan over their horizon, and their
// points given to the first new triangle they are above (none: they are
// inside, never vertices). Adding extreme points first, and the visible
// region grown from one triangle, keep the hull a closed surface of
// triangles even where many points lie within eps of a plane.
std::vector<Tri> hull_triangles(const std::vector<Vec3>& q, const std::vector<int>& used, double eps) {
  std::vector<Tri> tris;
  std::vector<char> alive;
  std::vector<std::vector<int>> outside;
  std::map<std::pair<int, int>, int> owner;  // directed edge -> live triangle
  const auto add = [&](int a, int b, int c) {
    tris.push_back(make_tri(q, a, b, c));
    alive.push_back(1);
    outside.emplace_back();
    const int t = static_cast<int>(tris.size()) - 1;
    for (int e = 0; e < 3; ++e) owner[{tris[t].v[e], tris[t].v[(e + 1) % 3]}] = t;
  };
  const auto give = [&](int k, int first) {  // to the first triangle from `first` that k is above
    for (int t = first; t < static_cast<int>(tris.size()); ++t)
      if (alive[t] && height(tris[t], q[k]) > eps) {
        outside[t].push_back(k);
        return;
      }
  };

  const std::array<int, 4> s = first_simplex(q, used, eps);
  for (int k = 0; k < 4; ++k) {
    const int a = s[(k + 1) % 4], b = s[(k + 2) % 4], c = s[(k + 3) % 4];
    if (height(make_tri(q, a, b, c), q[s[k]]) > 0.0) add(a, c, b);  // the fourth point inside
    else add(a, b, c);
  }
  for (int k : used)
    if (std::find(s.begin(), s.end(), k) == s.end()) give(k, 0);

  std::vector<int> visible, stack;
  std::vector<char> seen;
  for (;;) {
    int t0 = 0;
    while (t0 < static_cast<int>(tris.size()) && (!alive[t0] || outside[t0].empty())) ++t0;
    if (t0 == static_cast<int>(tris.size())) break;
    int p = outside[t0][0];
    for (int k : outside[t0])
      if (height(tris[t0], q[k]) > height(tris[t0], q[p])) p = k;
    // The visible region: connected, grown from t0.
    visible.clear();
    seen.assign(tris.size(), 0);
    stack.assign(1, t0);
    seen[t0] = 1;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      visible.push_back(t);
      for (int e = 0; e < 3; ++e) {
        const auto it = owner.find({tris[t].v[(e + 1) % 3], tris[t].v[e]});
        if (it == owner.end()) broken("an open edge");
        const int u = it->second;
        if (!seen[u] && height(tris[u], q[p]) > eps) {
          seen[u] = 1;
          stack.push_back(u);
        }
      }
    }
    std::sort(visible.begin(), visible.end());
    std::vector<std::pair<int, int>> horizon;
    for (int t : visible)
      for (int e = 0; e < 3; ++e) {
        const int a = tris[t].v[e], b = tris[t].v[(e + 1) % 3];
        if (!seen[owner.at({b, a})]) horizon.emplace_back(a, b);
      }
    for (int t : visible) {
      alive[t] = 0;
      for (int e = 0; e < 3; ++e) owner.erase({tris[t].v[e], tris[t].v[(e + 1) % 3]});
    }
    const int first_new = static_cast<int>(tris.size());
    for (const auto& [a, b] : horizon) add(a, b, p);
    for (int t : visible)
      for (int k : outside[t])
        if (k != p) give(k, first_new);
    for (int t : visible) outside[t].clear();
  }
  std::vector<Tri> out;
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (alive[t]) out.push_back(tris[t]);
  return out;
}

// The faces of the hull: each a loop of point indices (counter-clockwise
// from outside) and the normal of its largest triangle, over the hull's
// triangles merged where coplanar.
std::vector<PolyFace> merged_faces(const std::vector<Vec3>& q, const std::vector<Tri>& tris, double eps) {
  const int nt = static_cast<int>(tris.size());
  std::map<std::pair<int, int>, int> owner;  // directed edge -> triangle
  for (int t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e)
      if (!owner.emplace(std::pair{tris[t].v[e], tris[t].v[(e + 1) % 3]}, t).second)
        broken("an edge used twice in one direction");
  const auto twin = [&](int a, int b) {
    const auto it = owner.find({b, a});
    if (it == owner.end()) broken("an open edge");
    return it->second;
  };
  // Faces grown from the largest triangles (whose planes are the best
  // determined): a neighbour joins when its three points are within eps of
  // the seed's plane. Measuring against one plane, not neighbour against
  // neighbour, keeps a face planar where many points lie a few eps apart.
  std::vector<int> order(nt), group(nt, -1), stack;
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return tris[a].area2 > tris[b].area2; });
  for (int seed : order) {
    if (group[seed] >= 0) continue;
    const Tri& plane = tris[seed];
    group[seed] = seed;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        const int u = twin(tris[t].v[e], tris[t].v[(e + 1) % 3]);
        if (group[u] >= 0) continue;
        const auto near = [&](int x) { return std::abs(height(plane, q[x])) <= eps; };
        if (near(tris[u].v[0]) && near(tris[u].v[1]) && near(tris[u].v[2])) {
          group[u] = seed;
          stack.push_back(u);
        }
      }
    }
  }
  // Each group's boundary (edges whose twin is in another group) is its loop.
  std::map<int, std::map<int, int>> next_of;  // group -> (point -> next point)
  for (int t = 0; t < nt; ++t) {
    const int r = group[t];
    auto& next = next_of[r];
    for (int e = 0; e < 3; ++e) {
      const int a = tris[t].v[e], b = tris[t].v[(e + 1) % 3];
      if (group[twin(a, b)] == r) continue;
      if (!next.emplace(a, b).second) broken("a face whose boundary is not a simple loop");
    }
  }
  std::vector<PolyFace> faces;
  for (const auto& [g, next] : next_of) {
    std::vector<int> loop{next.begin()->first};
    for (int x = next.begin()->second; x != loop.front();) {
      loop.push_back(x);
      const auto it = next.find(x);
      if (it == next.end() || loop.size() > next.size()) broken("a face boundary that does not close");
      x = it->second;
    }
    if (loop.size() != next.size()) broken("a face with two boundaries");
    faces.push_back(PolyFace{std::move(loop), tris[g].n, 0.0});
  }
  return faces;
}

// Volume, centroid (about the point g) and second moment C = integral of
// x x^T dV about the centroid, from the tetrahedra (g, fan triangles of the
// faces). A tetrahedron with a vertex at 0 and the others a, b, c has
// volume a.(b x c)/6 (positive: faces counter-clockwise from outside, g
// inside), first moment V (a + b + c)/4 and second moment V/20 (a a^T +
// b b^T + c c^T + s s^T), s = a + b + c (Tonon 2004, J. Math. Stat. 1:8;
// Mirtich 1996, J. Graphics Tools 1:31).
struct Moments {
  double volume = 0.0;
  Vec3 centroid = Vec3::Zero();  // relative to g
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
};

Moments moments(const std::vector<Vec3>& x, const std::vector<PolyFace>& faces, const Vec3& g) {
  Moments m;
  Vec3 first = Vec3::Zero();
  for (const PolyFace& f : faces) {
    const Vec3 a = x[f.loop[0]] - g;
    for (std::size_t i = 1; i + 1 < f.loop.size(); ++i) {
      const Vec3 b = x[f.loop[i]] - g, c = x[f.loop[i + 1]] - g;
      const double v = a.dot(b.cross(c)) / 6.0;
      const Vec3 s = a + b + c;
      m.volume += v;
      first += v / 4.0 * s;
      m.second += v / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
    }
  }
  m.centroid = first / m.volume;
  m.second -= m.volume * m.centroid * m.centroid.transpose();  // parallel axes: about the centroid
  return m;
}

// The first index of the component of largest magnitude (ties within 1e-9).
int dominant(const Vec3& v) {
  const double top = v.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i)
    if (std::abs(v[i]) >= top - 1e-9) return i;
  return 0;
}

Vec3 signed_axis(const Vec3& v) { return v[dominant(v)] < 0.0 ? Vec3(-v) : v; }

// The principal frame of J under the convention of principal_axes().
void principal_frame(const Eigen::Matrix3d& J, Vec3& moments, Eigen::Matrix3d& R) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(J);
  if (es.info() != Eigen::Success) broken("the inertia tensor does not diagonalise");
  moments = es.eigenvalues();  // ascending
  const Eigen::Matrix3d& E = es.eigenvectors();
  const double tol = kEqualMoments * moments[2];
  const bool eq01 = moments[1] - moments[0] <= tol, eq12 = moments[2] - moments[1] <= tol;
  // The input axis least aligned with the distinct axis a, projected off it.
  const auto across = [](const Vec3& a) {
    const Vec3 c = a.cwiseAbs();
    const double low = c.minCoeff();
    int j = 0;
    while (c[j] > low + 1e-9) ++j;
    const Vec3 e = Vec3::Unit(j);
    return Vec3((e - a.dot(e) * a).normalized());
  };
  if (eq01 && eq12) {
    R.setIdentity();
  } else if (eq12) {  // one small moment, two equal large ones
    const Vec3 a = signed_axis(E.col(0)), u = across(a);
    R << a, u, a.cross(u);
  } else if (eq01) {  // two equal small moments, one large
    const Vec3 a = signed_axis(E.col(2)), u = across(a);
    R << u, a.cross(u), a;
  } else {
    const Vec3 a = signed_axis(E.col(0)), b = signed_axis(E.col(1));
    R << a, b, a.cross(b);
  }
}

}  // namespace

ConvexPolyhedron::ConvexPolyhedron(const std::vector<Vec3>& points, RedundantPoints redundant) {
  const int n = static_cast<int>(points.size());
  if (n < 4) refuse(fmt::format("needs at least 4 points, got {}", n));
  for (int k = 0; k < n; ++k)
    if (!points[k].allFinite())
      refuse(fmt::format("point {} {} has a non-finite coordinate", k, point_text(points[k])));

  // (1) Size and tolerance; coordinates about the bounding box's centre.
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 centre = 0.5 * (lo + hi);
  const double eps = kRelativeTolerance * (hi - lo).maxCoeff();
  if (!(eps > 0.0)) refuse("zero volume: all points coincide");
  std::vector<Vec3> q(n);
  for (int k = 0; k < n; ++k) q[k] = points[k] - centre;
  std::vector<int> used;
  for (int k = 0; k < n; ++k) {
    int same = -1;
    for (int j : used)
      if ((q[k] - q[j]).norm() <= eps) {
        same = j;
        break;
      }
    if (same < 0) {
      used.push_back(k);
    } else if (redundant == RedundantPoints::Refuse) {
      refuse(fmt::format("duplicate points: point {} {} coincides with point {} (within {:.3g})", k,
                         point_text(points[k]), same, eps));
    }
  }
  if (used.size() < 4) refuse("zero volume: all points coincide");

  // (2), (3) The hull and its faces; vertices are corners of >= 3 faces.
  const std::vector<Tri> tris = hull_triangles(q, used, eps);
  const std::vector<PolyFace> merged = merged_faces(q, tris, eps);
  std::vector<int> corners(n, 0);
  for (const PolyFace& f : merged)
    for (int x : f.loop) ++corners[x];
  if (redundant == RedundantPoints::Refuse)
    for (int k = 0; k < n; ++k) {
      if (corners[k] >= 3) continue;
      double above = -INFINITY;
      for (const Tri& t : tris) above = std::max(above, height(t, q[k]));
      refuse(fmt::format("non-convex or redundant input: point {} {} {}", k, point_text(points[k]),
                         above < -eps ? "is inside the hull"
                                      : "lies on the hull's surface (in a face or on an edge) but is not a vertex"));
    }

  // (4) Canonical order: vertices in input order; loops from their smallest
  // vertex; faces by loop; edges by vertex pair.
  std::vector<int> index(n, -1);
  for (int k = 0; k < n; ++k)
    if (corners[k] >= 3) {
      index[k] = static_cast<int>(input_index_.size());
      input_index_.push_back(k);
    }
  for (const PolyFace& m : merged) {
    PolyFace f;
    f.normal = m.normal;
    for (int x : m.loop)
      if (index[x] >= 0) f.loop.push_back(index[x]);
    if (f.loop.size() < 3) broken("a face with fewer than 3 corners");
    std::rotate(f.loop.begin(), std::min_element(f.loop.begin(), f.loop.end()), f.loop.end());
    faces_.push_back(std::move(f));
  }
  std::sort(faces_.begin(), faces_.end(), [](const PolyFace& a, const PolyFace& b) { return a.loop < b.loop; });
  std::map<std::pair<int, int>, PolyEdge> edges;
  std::set<std::pair<int, int>> directed;
  for (int fi = 0; fi < static_cast<int>(faces_.size()); ++fi) {
    const std::vector<int>& l = faces_[fi].loop;
    for (std::size_t i = 0; i < l.size(); ++i) {
      const int a = l[i], b = l[(i + 1) % l.size()];
      if (!directed.emplace(a, b).second) broken("an edge used twice in one direction");
      PolyEdge& e = edges[{std::min(a, b), std::max(a, b)}];
      e.v0 = std::min(a, b);
      e.v1 = std::max(a, b);
      (a < b ? e.f0 : e.f1) = fi;
    }
  }
  for (const auto& [key, e] : edges) {
    if (!directed.contains({key.second, key.first})) broken("an edge with one face");
    edges_.push_back(e);
  }

  // (5) Mass properties, about the mean of the vertices (strictly inside).
  std::vector<Vec3> x(input_index_.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = q[input_index_[i]];
  Vec3 g = Vec3::Zero();
  for (const Vec3& p : x) g += p;
  g /= static_cast<double>(x.size());
  const Moments m = moments(x, faces_, g);
  volume_ = m.volume;
  const Vec3 c = g + m.centroid;  // centroid about the bounding box's centre
  origin_ = centre + c;
  unit_inertia_ = m.second.trace() * Eigen::Matrix3d::Identity() - m.second;
  for (Vec3& p : x) p -= c;
  vertices_ = x;
  tolerance_ = eps;
  for (const Vec3& p : vertices_) circumradius_ = std::max(circumradius_, p.norm());

  // Face planes: the normal of the face's largest hull triangle (every
  // point of the face is within eps of its plane), the offset the mean over
  // the loop.
  for (PolyFace& f : faces_) {
    f.offset = 0.0;
    for (int v : f.loop) f.offset += f.normal.dot(vertices_[v]);
    f.offset /= static_cast<double>(f.loop.size());
  }

  // The hull's invariants, checked on every result so that none is wrong
  // beyond the tolerance: Euler's formula, every face planar, every input
  // point inside every face's plane, the centroid strictly inside.
  const std::size_t nv = vertices_.size(), ne = edges_.size(), nf = faces_.size();
  if (nv + nf != ne + 2) broken(fmt::format("V - E + F = {} - {} + {} != 2", nv, ne, nf));
  if (!(volume_ > 0.0)) broken("a volume that is not positive");
  for (const PolyFace& f : faces_) {
    if (!(f.offset > eps)) broken("the centroid is not inside a face");
    for (int v : f.loop)
      if (std::abs(f.normal.dot(vertices_[v]) - f.offset) > 2.0 * eps) broken("a face that is not planar");
    for (int k : used)
      if (const double out = f.normal.dot(q[k] - c) - f.offset; out > 2.0 * eps)
        broken(fmt::format("point {} lies {:.3g} tolerances outside a face", k, out / eps));
  }

  // (6) The principal frame.
  principal_frame(unit_inertia_, unit_principal_, principal_axes_);
}

ConvexPolyhedron ConvexPolyhedron::scaled(double s) const {
  if (!(s > 0.0) || !std::isfinite(s)) refuse(fmt::format("scale factor {} is not a positive finite number", s));
  ConvexPolyhedron p = *this;
  for (Vec3& v : p.vertices_) v *= s;
  for (PolyFace& f : p.faces_) f.offset *= s;
  p.origin_ *= s;
  p.circumradius_ *= s;
  p.tolerance_ *= s;
  p.volume_ *= s * s * s;
  const double s5 = s * s * s * s * s;
  p.unit_inertia_ *= s5;
  p.unit_principal_ *= s5;
  return p;
}

}  // namespace cd
