#include "poly_rows3.hpp"

#include <algorithm>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace cd {

namespace {

// What a candidate becomes: kept as detect3 made it (no polyhedron), or
// the rows of a contact with a polyhedron, from the polyhedron narrow
// phase (with a polyhedron or a plane) or the sphere's.
enum class Candidate : std::uint8_t { Kept, Polyhedra, Sphere };

// The narrow phase of candidate (b1, b2) with body 2 at pos2 (its image
// when the pair meets across the cell): a sphere's with a polyhedron
// (either one body 1), a plane's, or two polyhedra's with the pair's
// remembered axis as the hint (face: an edge pair's face contact too).
std::optional<PolyContact> narrow_phase(const Bodies3& bodies, const std::vector<Vec3>& x,
                                        const std::vector<Quat>& q, double alert, const PolyMemory3& memory,
                                        std::uint64_t key, std::size_t b1, std::size_t b2, const Vec3& pos2,
                                        PolyContact& face) {
  const Shape3 s1 = bodies.shape[b1], s2 = bodies.shape[b2];
  const Pose3 pose2{pos2, q[b2]};
  if (s1 == Shape3::Sphere) return collide_sphere(x[b1], bodies.radius[b1], bodies.polyhedron(b2), pose2, alert);
  if (s2 == Shape3::Sphere)
    return collide_sphere(bodies.polyhedron(b1), Pose3{x[b1], q[b1]}, pos2, bodies.radius[b2], alert);
  if (s1 == Shape3::Plane) return collide_plane(x[b1], bodies.normal[b1], bodies.polyhedron(b2), pose2, alert);
  const PolyPairMemory3* m = memory.find(key);
  return collide(bodies.polyhedron(b1), Pose3{x[b1], q[b1]}, bodies.polyhedron(b2), pose2, alert,
                 m ? std::optional<PolyAxis>(m->axis) : std::nullopt, &face);
}

}  // namespace

void polyhedra_rows3(const Bodies3& bodies, const std::vector<Vec3>& x, const std::vector<Quat>& q,
                     double alert, const PolyMemory3& memory, std::vector<SphereRow>& rows,
                     std::vector<ContactInfo3>& info, std::vector<PolyPairAxis3>& axes, int min_parallel) {
  const int nc = static_cast<int>(rows.size());
  std::vector<Candidate> what(static_cast<std::size_t>(nc), Candidate::Kept);
  std::vector<std::optional<PolyContact>> hit(static_cast<std::size_t>(nc));
  std::vector<PolyContact> face(static_cast<std::size_t>(nc));  // an edge pair's face contact too
  std::vector<Vec3> pos2(static_cast<std::size_t>(nc));
  // The narrow phase, one slot per candidate.
#pragma omp parallel for schedule(static) if (nc >= min_parallel)
  for (int k = 0; k < nc; ++k) {
    const auto u = static_cast<std::size_t>(k);
    const auto b1 = static_cast<std::size_t>(rows[u].b1), b2 = static_cast<std::size_t>(rows[u].b2);
    const Shape3 s1 = bodies.shape[b1], s2 = bodies.shape[b2];
    if (s1 != Shape3::Polyhedron && s2 != Shape3::Polyhedron) continue;
    what[u] = s1 == Shape3::Sphere || s2 == Shape3::Sphere ? Candidate::Sphere : Candidate::Polyhedra;
    const ContactInfo3& f = info[u];
    // Body 2's image: its centre seen from body 1 (detect3's branch) when
    // the pair meets across the cell.
    const bool image = f.ix != 0 || f.iy != 0 || f.iz != 0;
    pos2[u] = image ? Vec3(x[b1] + f.branch) : x[b2];
    hit[u] = narrow_phase(bodies, x, q, alert, memory, f.key, b1, b2, pos2[u], face[u]);
  }
  // The rows, in the candidates' order.
  std::vector<SphereRow> out;
  std::vector<ContactInfo3> out_info;
  out.reserve(rows.size());
  out_info.reserve(rows.size());
  axes.clear();
  for (int k = 0; k < nc; ++k) {
    const auto u = static_cast<std::size_t>(k);
    if (what[u] == Candidate::Kept) {
      out.push_back(rows[u]);
      out_info.push_back(info[u]);
      continue;
    }
    if (!hit[u]) continue;
    const PolyContact& c = *hit[u];
    const auto b1 = static_cast<std::size_t>(rows[u].b1);
    const bool plane = bodies.shape[b1] == Shape3::Plane;
    // Only a pair of polyhedra takes its axis as the next step's hint.
    if (what[u] == Candidate::Polyhedra && !plane) axes.push_back({info[u].key, c.axis});
    // The contact's points, then (an edge pair's) its face's, each set with
    // its own normal.
    for (const PolyContact* cc : {&c, static_cast<const PolyContact*>(&face[u])}) {
      SphereRow row = rows[u];
      row.n = cc->normal;
      orthonormal_basis(cc->normal, row.t1, row.t2);
      row.wnn = row.wtt = row.bn = row.mu = row.adh = 0.0;
      ContactInfo3 f = info[u];
      // A plane's branch runs from the body's foot on the plane to its centre.
      if (plane) f.branch = (pos2[u] - x[b1]).dot(cc->normal) * cc->normal;
      f.kind = static_cast<std::uint8_t>(1 + static_cast<int>(cc->kind));
      for (const PolyContactPoint& p : cc->points()) {
        row.c1 = p.position - x[b1];
        row.c2 = p.position - pos2[u];
        row.r = Vec3::Zero();
        f.gap = p.gap;
        f.point = p.position;
        f.feature = p.key;
        out.push_back(row);
        out_info.push_back(f);
      }
    }
  }
  rows.swap(out);
  info.swap(out_info);
}

void keep_polyhedra_memory3(const std::vector<SphereRow>& rows, const std::vector<ContactInfo3>& info,
                            const std::vector<PolyPairAxis3>& axes, PolyMemory3& memory) {
  const std::size_t n = rows.size();
  std::vector<std::size_t> idx(n);
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return info[a].key != info[b].key ? info[a].key < info[b].key : info[a].feature < info[b].feature;
  });
  std::vector<PolyPairAxis3> ax = axes;
  std::sort(ax.begin(), ax.end(), [](const PolyPairAxis3& a, const PolyPairAxis3& b) { return a.key < b.key; });
  memory.keys.clear();
  memory.p.clear();
  for (std::size_t i = 0; i < n;) {
    const std::uint64_t key = info[idx[i]].key;
    PolyPairMemory3 m;
    const auto a = std::lower_bound(ax.begin(), ax.end(), key,
                                    [](const PolyPairAxis3& e, std::uint64_t k) { return e.key < k; });
    if (a != ax.end() && a->key == key) m.axis = a->axis;
    for (; i < n && info[idx[i]].key == key; ++i) {
      if (m.count == PolyPairMemory3::kMaxRows)
        throw std::logic_error("keep_polyhedra_memory3: more rows in one pair than the memory holds");
      const auto j = static_cast<std::size_t>(m.count++);
      m.feature[j] = info[idx[i]].feature;
      m.p[j] = rows[idx[i]].to_world(rows[idx[i]].r);
    }
    memory.keys.push_back(key);
    memory.p.push_back(m);
  }
}

Overlap3 deepest_overlap3(const Bodies3& bodies, const PeriodicCell3& cell, int min_parallel) {
  if (!bodies.has_polyhedra()) return largest_overlap3(bodies, cell, min_parallel);
  CellGrid3 grid;
  std::vector<SphereRow> rows;
  std::vector<ContactInfo3> info;
  std::vector<PolyPairAxis3> axes;
  if (cell.any()) detect3(bodies, bodies.pos, 0.0, cell, grid, rows, info, min_parallel);
  else detect3(bodies, bodies.pos, 0.0, grid, rows, info, min_parallel);
  polyhedra_rows3(bodies, bodies.pos, bodies.orient, 0.0, PolyMemory3{}, rows, info, axes, min_parallel);
  Overlap3 o;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (-info[k].gap > o.depth) o = {-info[k].gap, rows[k].b1, rows[k].b2};
  return o;
}

}  // namespace cd
