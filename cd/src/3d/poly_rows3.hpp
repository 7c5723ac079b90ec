// The contact rows of a scene with polyhedra: the broad phase's candidates
// (detect3.hpp: bounding spheres of circumradius, in the cell grid, and
// planes) replaced by the points of the narrow phase (polyhedron_contact.hpp),
// and the memory that carries each point's impulse and each pair's axis
// from one step to the next.
//
// A candidate pair of polyhedra (or a plane and a polyhedron) becomes 0 to
// 4 rows, one per contact point, which share the contact's frame (n from
// body 1 to body 2, t1 and t2 from n as for spheres), and on an edge pair's
// axis the points of the best face axis as well, with that face's normal
// (collide's face_too: 5 rows at most); a point's lever arms
// run from each body's centroid (a plane's: from its point) to the point,
// its gap is the point's, its ContactInfo3 key the pair's and its feature
// the point's key. A candidate pair of a sphere and a polyhedron (either
// body 1) becomes 0 or 1 row, the sphere's narrow phase's point
// (collide_sphere), set as a polyhedron's: its lever arms run from the
// centroid and from the sphere's centre to the point, the latter along n,
// so that the sphere's rotation enters through friction alone. Candidates
// without a polyhedron stay as detect3 made them.
//
// Memory: one entry per pair that had rows (keyed by contact_key3(b1, b2)),
// holding the axis of a polyhedra pair's contact (the next narrow phase's
// hint: the same face or edge pair unless another beats it by the margin;
// a plane's or a sphere's pair needs none) and each row's
// impulse in the world frame on body 2 by its feature key (a row of two
// spheres or of a sphere and a plane: feature 0, one per pair). A row of the new step takes the
// impulse remembered under its pair and feature (remembered_impulse),
// projected on its frame by World3's build as spheres' warm start is; a
// new point starts from zero.
//
// Order: rows in the candidates' order, a pair's points in the narrow
// phase's order, whatever the thread count (the narrow phase runs on
// threads into per-candidate slots; the rows are put together on one).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "bodies3.hpp"
#include "contact3.hpp"
#include "detect3.hpp"
#include "polyhedron_contact.hpp"
#include "warm_start.hpp"

namespace cd {

struct PolyPairMemory3 {
  // A contact's points (up to 4) and, on an edge pair's axis, the edge
  // point with the face's (up to 4 more, as the narrow phase gives them).
  static constexpr int kMaxRows = 5;
  PolyAxis axis;
  int count = 0;
  std::array<std::uint64_t, kMaxRows> feature{};
  std::array<Vec3, kMaxRows> p{};  // world frame, on body 2
};
using PolyMemory3 = WarmStart<PolyPairMemory3>;

// A pair's axis found by this step's narrow phase (for the memory).
struct PolyPairAxis3 {
  std::uint64_t key;
  PolyAxis axis;
};

// Replaces the candidate rows (x, q: the bodies' midpoint positions and
// orientations) as above, with no impulse; axes receives the axis of every
// pair of polyhedra with rows (a plane's or a sphere's is not kept); memory
// gives the hints.
void polyhedra_rows3(const Bodies3& bodies, const std::vector<Vec3>& x, const std::vector<Quat>& q,
                     double alert, const PolyMemory3& memory, std::vector<SphereRow>& rows,
                     std::vector<ContactInfo3>& info, std::vector<PolyPairAxis3>& axes, int min_parallel);

// The largest overlap of any world (the depth of its deepest contact
// point; 0 if none) and a pair that has it, through the periodic cell (if
// cell.any()): detect3's largest_overlap3 for spheres and planes; with
// polyhedra, detect3's bounding-sphere candidates at alert 0, then the
// narrow phase at the bodies' own positions and orientations.
Overlap3 deepest_overlap3(const Bodies3& bodies, const PeriodicCell3& cell, int min_parallel);

// The impulse remembered for a row (its pair's key and its feature), world
// frame, or null.
inline const Vec3* remembered_impulse(const PolyMemory3& memory, const ContactInfo3& f) {
  const PolyPairMemory3* m = memory.find(f.key);
  if (!m) return nullptr;
  for (int j = 0; j < m->count; ++j)
    if (m->feature[static_cast<std::size_t>(j)] == f.feature) return &m->p[static_cast<std::size_t>(j)];
  return nullptr;
}

// The memory of the step just solved: the rows' impulses (world frame, on
// body 2) by pair and feature, the pairs' axes.
void keep_polyhedra_memory3(const std::vector<SphereRow>& rows, const std::vector<ContactInfo3>& info,
                            const std::vector<PolyPairAxis3>& axes, PolyMemory3& memory);

}  // namespace cd
