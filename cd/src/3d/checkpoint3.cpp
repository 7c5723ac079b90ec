#include "checkpoint3.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <utility>

#include "detect3.hpp"
#include "poly_rows3.hpp"
#include "world_checkpoint.hpp"

namespace cd {

namespace {

// Every Bodies3 array, listed once: the writer and the reader both walk
// this list, so a new Bodies3 member is one line here.
constexpr std::tuple kBodies3Arrays{
    std::pair{"3d.vel", &Bodies3::vel},
    std::pair{"3d.pos", &Bodies3::pos},
    std::pair{"3d.orient", &Bodies3::orient},
    std::pair{"3d.shape", &Bodies3::shape},
    std::pair{"3d.radius", &Bodies3::radius},
    std::pair{"3d.normal", &Bodies3::normal},
    std::pair{"3d.mass", &Bodies3::mass},
    std::pair{"3d.inertia", &Bodies3::inertia},
    std::pair{"3d.driven", &Bodies3::driven},
};
// Bodies3 holds only vectors, so a member left out of the list shows here.
// Three are not in the list: the polyhedra's shape_id and moments, written
// only when there are polyhedra (the "3d.poly" arrays below; spheres and
// planes have them from restore_derived), and the shapes, which are the
// scene's (checked by their fingerprint).
static_assert(sizeof(Bodies3) ==
                  (std::tuple_size_v<decltype(kBodies3Arrays)> + 3) * sizeof(std::vector<char>),
              "a Bodies3 member is missing from kBodies3Arrays (checkpoint3.cpp)");

void restore_derived(Bodies3& b) {
  b.shape_id.assign(b.size(), -1);
  b.moments.resize(b.size());
  for (std::size_t i = 0; i < b.size(); ++i)
    b.moments[i] = b.shape[i] == Shape3::Sphere ? Vec3::Constant(b.inertia[i]) : Vec3::Zero();
}

// The polyhedra of a checkpoint: each body's shape and moments, the count
// and fingerprint of the shape library they index (the scene's), and the
// pair memory as flat arrays (no struct padding in the file: identical
// runs write identical bytes).
struct PolyState3 {
  std::vector<std::uint64_t> shapes;  // count, fingerprint
  std::vector<std::int32_t> shape_id;
  std::vector<Vec3> moments;
  std::vector<std::uint64_t> keys;
  std::vector<std::int32_t> axis;     // per pair: kind, a, b, count
  std::vector<std::uint64_t> feature; // per pair: PolyPairMemory3::kMaxRows
  std::vector<Vec3> p;                // per pair: PolyPairMemory3::kMaxRows
  std::vector<std::int32_t> vertex_count;  // per shape (absent in files written before)
  std::vector<Vec3> vertices;              // the shapes' vertices, shape after shape
};

// FNV-1a over the library's vertices, faces and circumradii: two libraries
// with the same fingerprint are the same shapes in the same order.
std::uint64_t shapes_fingerprint(const std::vector<ConvexPolyhedron>& lib) {
  std::uint64_t h = fnv1a({});
  const auto bytes = [&](const void* d, std::size_t n) { h = fnv1a({static_cast<const char*>(d), n}, h); };
  for (const ConvexPolyhedron& c : lib) {
    bytes(c.vertices().data(), c.vertices().size() * sizeof(Vec3));
    for (const PolyFace& f : c.faces()) bytes(f.loop.data(), f.loop.size() * sizeof(int));
    const double r = c.circumradius();
    bytes(&r, sizeof r);
  }
  return h;
}

// A library as the file holds it: each shape's vertex count, then all
// the vertices, shape after shape.
struct FlatShapes3 {
  std::vector<std::int32_t> count;
  std::vector<Vec3> vertices;
};
FlatShapes3 flat_shapes(const std::vector<ConvexPolyhedron>& lib) {
  FlatShapes3 f;
  for (const ConvexPolyhedron& c : lib) {
    f.count.push_back(static_cast<std::int32_t>(c.vertices().size()));
    f.vertices.insert(f.vertices.end(), c.vertices().begin(), c.vertices().end());
  }
  return f;
}

void write_poly3(ckpt::Writer& o, const World3& w) {
  const Bodies3& b = w.bodies;
  if (!b.has_polyhedra()) return;
  o.array("3d.poly.shapes", std::vector<std::uint64_t>{b.polyhedra.size(), shapes_fingerprint(b.polyhedra)});
  o.array("3d.poly.shape_id", b.shape_id);
  o.array("3d.poly.moments", b.moments);
  const PolyMemory3& m = w.polyhedra_memory();
  std::vector<std::int32_t> axis;
  std::vector<std::uint64_t> feature;
  std::vector<Vec3> p;
  for (const PolyPairMemory3& e : m.p) {
    axis.insert(axis.end(), {static_cast<std::int32_t>(e.axis.kind), e.axis.a, e.axis.b, e.count});
    feature.insert(feature.end(), e.feature.begin(), e.feature.end());
    p.insert(p.end(), e.p.begin(), e.p.end());
  }
  o.array("3d.poly.memory.keys", m.keys);
  o.array("3d.poly.memory.axis", axis);
  o.array("3d.poly.memory.feature", feature);
  o.array("3d.poly.memory.p", p);
  const FlatShapes3 f = flat_shapes(b.polyhedra);
  o.array("3d.poly.vertex_count", f.count);
  o.array("3d.poly.vertices", f.vertices);
}

// The library a file's vertices give (Bodies3::add_shape's frames), or a
// failure naming the shape.
std::vector<ConvexPolyhedron> file_shapes(ckpt::Reader& in, const PolyState3& ps) {
  if (ps.vertex_count.empty() && ps.shapes.size() == 2 && ps.shapes[0] > 0)
    in.fail("holds polyhedra without their shapes' vertices (written before they were stored): it can resume its "
            "own run, not start another");
  if (ps.shapes.size() != 2 || ps.vertex_count.size() != ps.shapes[0])
    in.fail(fmt::format("is corrupt: '3d.poly.vertex_count' holds {} shapes, '3d.poly.shapes' says {}",
                        ps.vertex_count.size(), ps.shapes.size() == 2 ? ps.shapes[0] : 0));
  Bodies3 lib;
  std::size_t at = 0;
  for (std::size_t k = 0; k < ps.vertex_count.size(); ++k) {
    const std::int32_t m = ps.vertex_count[k];
    if (m < 4 || static_cast<std::size_t>(m) > ps.vertices.size() - at)
      in.bad("3d.poly.vertex_count", k, "", fmt::format("is {} (at least 4, and the vertices left: {})", m,
                                                        ps.vertices.size() - at));
    std::vector<Vec3> v(ps.vertices.begin() + static_cast<std::ptrdiff_t>(at),
                        ps.vertices.begin() + static_cast<std::ptrdiff_t>(at + static_cast<std::size_t>(m)));
    at += static_cast<std::size_t>(m);
    try {
      lib.add_shape(ConvexPolyhedron(v));
    } catch (const std::invalid_argument& e) {
      in.fail(fmt::format("is corrupt: shape {} of '3d.poly.vertices' is not a convex polyhedron ({})", k, e.what()));
    }
  }
  if (at != ps.vertices.size())
    in.fail(fmt::format("is corrupt: '3d.poly.vertices' holds {} vertices, the counts {}", ps.vertices.size(), at));
  return lib.polyhedra;
}

// The polyhedra section if the checkpoint has one, checked against the
// bodies and the scene's shape library `lib`.
PolyState3 read_poly3(ckpt::Reader& in, const Bodies3& b, std::vector<ConvexPolyhedron>& lib, Shapes shapes) {
  PolyState3 ps;
  const bool has = in.next_name("3d.poly.shapes") == "3d.poly.shapes";
  bool any_poly = false;
  for (std::size_t i = 0; i < b.size(); ++i) any_poly |= b.shape[i] == Shape3::Polyhedron;
  if (!has) {
    if (any_poly) in.fail("is corrupt: it has polyhedra (3d.shape 2) but no '3d.poly' arrays");
    if (!lib.empty() && shapes == Shapes::Scene)
      in.fail("holds spheres; this scene's grains are polyhedra (particles.shape)");
    if (shapes == Shapes::File) lib.clear();
    return ps;
  }
  in.array("3d.poly.shapes", ps.shapes);
  in.array("3d.poly.shape_id", ps.shape_id);
  in.array("3d.poly.moments", ps.moments);
  in.array("3d.poly.memory.keys", ps.keys);
  in.array("3d.poly.memory.axis", ps.axis);
  in.array("3d.poly.memory.feature", ps.feature);
  in.array("3d.poly.memory.p", ps.p);
  if (in.next_name("3d.poly.vertex_count") == "3d.poly.vertex_count") {
    in.array("3d.poly.vertex_count", ps.vertex_count);
    in.array("3d.poly.vertices", ps.vertices);
  }
  if (shapes == Shapes::File) {
    lib = file_shapes(in, ps);
  } else {
    if (ps.shapes.size() != 2 || ps.shapes[0] != lib.size() || ps.shapes[1] != shapes_fingerprint(lib))
      in.fail(fmt::format("holds polyhedra of other shapes than this scene's ('3d.poly.shapes' does not give its {} "
                          "shapes and their fingerprint; particles.shape and the sizes make them)", lib.size()));
    // The stored vertices, when there are, are the library's, bit for bit
    // (a sample started from this file takes its shapes from them).
    if (!ps.vertex_count.empty() || !ps.vertices.empty()) {
      const FlatShapes3 f = flat_shapes(lib);
      if (f.count != ps.vertex_count || f.vertices != ps.vertices)
        in.fail("is corrupt: '3d.poly.vertex_count' and '3d.poly.vertices' are not the vertices of the shapes "
                "'3d.poly.shapes' fingerprints");
    }
  }
  const std::size_t n = b.size(), np = ps.keys.size();
  if (ps.shape_id.size() != n || ps.moments.size() != n)
    in.fail(fmt::format("is corrupt: '3d.poly.shape_id' and '3d.poly.moments' hold {} and {} elements for {} bodies",
                        ps.shape_id.size(), ps.moments.size(), n));
  constexpr std::size_t R = PolyPairMemory3::kMaxRows;
  if (ps.axis.size() != 4 * np || ps.feature.size() != R * np || ps.p.size() != R * np)
    in.fail(fmt::format("is corrupt: '3d.poly.memory.keys' holds {} pairs, '3d.poly.memory.axis' {} values (4 a "
                        "pair), '3d.poly.memory.feature' and '3d.poly.memory.p' {} and {} ({} a pair)",
                        np, ps.axis.size(), ps.feature.size(), ps.p.size(), R));
  for (std::size_t i = 0; i < n; ++i) {
    const bool poly = b.shape[i] == Shape3::Polyhedron;
    const std::int32_t id = ps.shape_id[i];
    if (poly ? !(id >= 0 && static_cast<std::size_t>(id) < lib.size()) : id != -1)
      in.bad("3d.poly.shape_id", i, "", fmt::format("is {} ({})", id, poly ? fmt::format("a shape of the {} "
                                                    "of this scene", lib.size()) : "-1 for a sphere or a plane"));
    if (!poly) {
      // A sphere's moments are its scalar inertia, a plane's zero
      // (restore_derived).
      const Vec3 expect = b.shape[i] == Shape3::Sphere ? Vec3::Constant(b.inertia[i]) : Vec3::Zero();
      for (int k = 0; k < 3; ++k)
        if (!(ps.moments[i][k] == expect[k]))
          in.bad("3d.poly.moments", i, std::string(1, "xyz"[k]),
                 fmt::format("is {:.17g}, not {:.17g} (a sphere's inertia, a plane's 0)", ps.moments[i][k],
                             expect[k]));
      continue;
    }
    const ConvexPolyhedron& c = lib[static_cast<std::size_t>(id)];
    if (!(std::abs(b.radius[i] - c.circumradius()) <= 1e-12 * c.circumradius()))
      in.bad("3d.radius", i, "", fmt::format("is {:.17g}, but its shape's circumradius is {:.17g}", b.radius[i],
                                             c.circumradius()));
    // Moments: the body's density (mass / volume) times the shape's unit
    // moments, to round-off (a driven body keeps its mass).
    const Vec3 expect = b.mass[i] / c.volume() * c.unit_inertia().diagonal();
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(ps.moments[i][k] - expect[k]) <= 1e-9 * expect[k]))
        in.bad("3d.poly.moments", i, std::string(1, "xyz"[k]),
               fmt::format("is {:.17g}, but the mass and shape give {:.17g}", ps.moments[i][k], expect[k]));
  }
  for (std::size_t k = 0; k < np; ++k) {
    if (k > 0 && !(ps.keys[k] > ps.keys[k - 1]))
      in.bad("3d.poly.memory.keys", k, "", "is not above the one before (the keys are strictly increasing)");
    const std::int32_t kind = ps.axis[4 * k], count = ps.axis[4 * k + 3];
    if (kind < 0 || kind > 2) in.bad("3d.poly.memory.axis", k, "kind", fmt::format("is {} (0, 1 or 2)", kind));
    if (count < 0 || count > static_cast<int>(R))
      in.bad("3d.poly.memory.axis", k, "count", fmt::format("is {} (0 to {})", count, R));
    for (std::size_t j = 0; j < R; ++j)
      for (int c = 0; c < 3; ++c) in.finite("3d.poly.memory.p", R * k + j, std::string(1, "xyz"[c]), ps.p[R * k + j][c]);
  }
  return ps;
}

void apply_poly3(World3& w, const PolyState3& ps, std::vector<ConvexPolyhedron> lib) {
  Bodies3& b = w.bodies;
  restore_derived(b);
  PolyMemory3 m;
  if (!ps.shapes.empty()) {
    b.polyhedra = std::move(lib);
    b.shape_id = ps.shape_id;
    b.moments = ps.moments;
    m.keys = ps.keys;
    m.p.resize(ps.keys.size());
    for (std::size_t k = 0; k < ps.keys.size(); ++k) {
      PolyPairMemory3& e = m.p[k];
      e.axis = {static_cast<PolyAxisKind>(ps.axis[4 * k]), ps.axis[4 * k + 1], ps.axis[4 * k + 2]};
      e.count = ps.axis[4 * k + 3];
      for (std::size_t j = 0; j < PolyPairMemory3::kMaxRows; ++j) {
        e.feature[j] = ps.feature[PolyPairMemory3::kMaxRows * k + j];
        e.p[j] = ps.p[PolyPairMemory3::kMaxRows * k + j];
      }
    }
  }
  w.set_polyhedra_memory(std::move(m));
}

// Every body's arrays, checked as a scene's bodies are: the shape tag,
// planes driven with a unit normal, spheres of positive radius, masses and
// inertias of the right sign, orientations unit quaternions, every number
// finite.
void check_bodies3(const ckpt::Reader& in, const Bodies3& b) {
  const std::size_t n = ckpt::same_lengths(kBodies3Arrays, b, in);
  const auto vec = [&](std::string_view array, std::size_t i, const Vec3& v) {
    for (int c = 0; c < 3; ++c) in.finite(array, i, std::string(1, "xyz"[c]), v[c]);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const auto shape = static_cast<unsigned>(b.shape[i]);
    if (shape > static_cast<unsigned>(Shape3::Polyhedron))
      in.bad("3d.shape", i, "", fmt::format("is {} (0 sphere, 1 plane, 2 polyhedron)", shape));
    // A polyhedron's inertia is its moments (3d.poly.moments): no scalar.
    const bool poly = b.shape[i] == Shape3::Polyhedron;
    if (poly && b.inertia[i] != 0)
      in.bad("3d.inertia", i, "", "is not 0 for a polyhedron (its inertia is its principal moments)");
    if (poly && b.vel[i].inv_I != 0)
      in.bad("3d.vel", i, "inv_I", "is not 0 for a polyhedron (its inertia is its principal moments)");
    if (b.driven[i] > 1) in.bad("3d.driven", i, "", fmt::format("is {} (0 or 1)", b.driven[i]));
    const bool plane = b.shape[i] == Shape3::Plane;
    if (plane && !b.driven[i]) in.bad("3d.driven", i, "", "is 0 for a plane (planes are driven)");
    in.non_negative("3d.radius", i, "", b.radius[i], !plane);
    in.non_negative("3d.mass", i, "", b.mass[i], !b.driven[i]);
    in.non_negative("3d.inertia", i, "", b.inertia[i], !b.driven[i] && !poly);
    vec("3d.normal", i, b.normal[i]);
    if (plane && !(std::abs(b.normal[i].norm() - 1) < 1e-9))
      in.bad("3d.normal", i, "", fmt::format("has norm {:.6g} (a plane's normal is a unit vector)", b.normal[i].norm()));
    const BodyVel3& v = b.vel[i];
    vec("3d.vel", i, v.v);
    vec("3d.vel", i, v.w);
    in.non_negative("3d.vel", i, "inv_m", v.inv_m, !b.driven[i]);
    in.non_negative("3d.vel", i, "inv_I", v.inv_I, !b.driven[i] && !poly);
    if (b.driven[i] && (v.inv_m != 0 || v.inv_I != 0))
      in.bad("3d.vel", i, "inv_m", "is not 0 for a driven body");
    if (!b.driven[i]) {
      in.inverse("3d.vel", i, "inv_m", v.inv_m, b.mass[i], "mass");
      if (!poly) in.inverse("3d.vel", i, "inv_I", v.inv_I, b.inertia[i], "inertia");
    }
    vec("3d.pos", i, b.pos[i]);
    const Quat& q = b.orient[i];
    for (int c = 0; c < 4; ++c) in.finite("3d.orient", i, std::string(1, "xyzw"[c]), q.coeffs()[c]);
    // Renormalised every step (world3.cpp): round-off away from 1 only.
    if (!(std::abs(q.norm() - 1) < 1e-9))
      in.bad("3d.orient", i, "", fmt::format("has norm {:.6g} (an orientation is a unit quaternion)", q.norm()));
  }
}

// The cell against the spheres it holds, as the scene's cell is checked:
// every periodic length at least 2 x 2 r_max (the detection's grid needs
// the alert distance on top: the least any scene asks), the spheres inside the periodic lengths (a step ends with them
// wrapped in), the Lees-Edwards offset within L_x.
void check_cell3(const ckpt::Reader& in, const CellState3& c, const Bodies3& b, const WorldParams3& p) {
  double r_max = 0.0;
  for (std::size_t i = 0; i < b.size(); ++i)
    if (b.shape[i] == Shape3::Sphere) r_max = std::max(r_max, b.radius[i]);
  const double lmin = 2 * (2 * r_max);
  for (int a = 0; a < 3; ++a) {
    if (!p.periodic[a]) continue;
    if (!(c.size[a] >= lmin))
      in.bad("3d.cell", a, std::string(1, "xyz"[a]),
             fmt::format("is {:.6g} m: a periodic length must be at least 2 x 2 r_max = {:.6g} m for these spheres",
                         c.size[a], lmin));
    const double tol = 1e-9 * c.size[a];
    for (std::size_t i = 0; i < b.size(); ++i)
      if (b.shape[i] == Shape3::Sphere && !b.driven[i] && !(b.pos[i][a] >= -tol && b.pos[i][a] <= c.size[a] + tol))
        in.bad("3d.pos", i, std::string(1, "xyz"[a]),
               fmt::format("is {:.6g} m, outside the periodic length [0, {:.6g}]", b.pos[i][a], c.size[a]));
  }
  if (p.periodic[0] && !(c.le_offset >= 0 && c.le_offset <= c.size.x()))
    in.bad("3d.cell", 3, "", fmt::format("is {:.6g} m (the Lees-Edwards offset is within [0, L_x = {:.6g}])",
                                        c.le_offset, c.size.x()));
}

constexpr ckpt::WorldFile kFile{3, "3d.warm.keys", "3d.warm.p"};

// The largest overlap of bodies b in cell c (polyhedra: by the narrow
// phase, their bounding spheres are not their shapes).
Overlap3 overlap_of3(const Bodies3& b, const CellState3& c, const WorldParams3& p) {
  const PeriodicCell3 cell = periodic_cell3(p, c.le_offset, c.size);
  return deepest_overlap3(b, cell, p.solver.min_parallel);
}

}  // namespace

void save_checkpoint3(const std::string& path, const World3& w, std::uint64_t scene_key,
                      const RunTotals& totals) {
  ckpt::save_world(path, w, kFile, kBodies3Arrays, scene_key, totals, [&](ckpt::Writer& o) {
    const WorldParams3& p = w.params();
    const CellState3& c = w.cell();
    o.array("3d.cell", std::vector<double>{c.size.x(), c.size.y(), c.size.z(), c.le_offset, double(p.periodic[0]),
                                           double(p.periodic[1]), double(p.periodic[2]), c.rate.x(), c.rate.y(),
                                           c.rate.z(), c.strain});
    write_poly3(o, w);
    o.array("3d.overlap", std::vector<double>{overlap_of3(w.bodies, c, p).depth});
  });
}

std::uint64_t load_checkpoint3(const std::string& path, World3& w, RunTotals* totals, Shapes shapes) {
  // The shapes are the scene's, those of the world built from it, or the
  // file's (read_poly3 replaces them).
  std::vector<ConvexPolyhedron> lib = w.bodies.polyhedra;
  return ckpt::load_world(
      path, w, kFile, kBodies3Arrays, totals, check_bodies3,
      [&](ckpt::Reader& in, const Bodies3& b) {
        std::vector<double> cell;
        in.array("3d.cell", cell);
        // 7 numbers: written before the cell had rates and a strain (both 0).
        if (cell.size() != 7 && cell.size() != 11)
          in.fail(fmt::format("is corrupt: '3d.cell' holds {} numbers (must be 7 or 11)", cell.size()));
        for (std::size_t c = 0; c < cell.size(); ++c) in.finite("3d.cell", c, "", cell[c]);
        const WorldParams3& p = w.params();
        for (int a = 0; a < 3; ++a)
          if ((cell[4 + a] != 0.0) != p.periodic[a])
            in.fail(fmt::format("holds a cell periodic along (x, y, z) = ({:d}, {:d}, {:d}); this scene's is "
                                "({:d}, {:d}, {:d})", cell[4] != 0.0, cell[5] != 0.0, cell[6] != 0.0,
                                p.periodic[0], p.periodic[1], p.periodic[2]));
        CellState3 c;
        c.size = Vec3(cell[0], cell[1], cell[2]);
        c.le_offset = cell[3];
        c.rate = cell.size() == 11 ? Vec3(cell[7], cell[8], cell[9]) : Vec3::Zero();
        c.strain = cell.size() == 11 ? cell[10] : 0.0;
        check_cell3(in, c, b, p);
        try {
          World3 probe(p);  // checks the cell without touching w
          probe.set_cell(c);
        } catch (const std::invalid_argument& e) {
          in.fail(fmt::format("is corrupt: '3d.cell' holds a cell this scene cannot take ({})", e.what()));
        }
        PolyState3 poly = read_poly3(in, b, lib, shapes);
        ckpt::check_overlap(in, "3d.overlap", p.d_ref, [&] {
          if (poly.shapes.empty()) return overlap_of3(b, c, p);
          Bodies3 shaped = b;  // the polyhedra as the world will hold them
          shaped.polyhedra = lib;
          shaped.shape_id = poly.shape_id;
          return overlap_of3(shaped, c, p);
        });
        return std::pair{c, std::move(poly)};
      },
      [&](World3& w, const std::pair<CellState3, PolyState3>& own) {
        apply_poly3(w, own.second, std::move(lib));
        w.set_cell(own.first);
      });
}

}  // namespace cd
