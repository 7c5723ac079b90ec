#include "checkpoint3.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <utility>

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
// Three are not written: the polyhedra's shape_id, moments and shapes
// (save_checkpoint3 refuses polyhedra; a checkpoint's bodies are spheres
// and planes, whose shape_id and moments restore_derived gives).
static_assert(sizeof(Bodies3) ==
                  (std::tuple_size_v<decltype(kBodies3Arrays)> + 3) * sizeof(std::vector<char>),
              "a Bodies3 member is missing from kBodies3Arrays (checkpoint3.cpp)");

void restore_derived(Bodies3& b) {
  b.shape_id.assign(b.size(), -1);
  b.moments.resize(b.size());
  for (std::size_t i = 0; i < b.size(); ++i)
    b.moments[i] = b.shape[i] == Shape3::Sphere ? Vec3::Constant(b.inertia[i]) : Vec3::Zero();
  b.polyhedra.clear();
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
    if (shape > static_cast<unsigned>(Shape3::Plane))
      in.bad("3d.shape", i, "", fmt::format("is {} (0 sphere, 1 plane)", shape));
    if (b.driven[i] > 1) in.bad("3d.driven", i, "", fmt::format("is {} (0 or 1)", b.driven[i]));
    const bool plane = b.shape[i] == Shape3::Plane;
    if (plane && !b.driven[i]) in.bad("3d.driven", i, "", "is 0 for a plane (planes are driven)");
    in.non_negative("3d.radius", i, "", b.radius[i], !plane);
    in.non_negative("3d.mass", i, "", b.mass[i], !b.driven[i]);
    in.non_negative("3d.inertia", i, "", b.inertia[i], !b.driven[i]);
    vec("3d.normal", i, b.normal[i]);
    if (plane && !(std::abs(b.normal[i].norm() - 1) < 1e-9))
      in.bad("3d.normal", i, "", fmt::format("has norm {:.6g} (a plane's normal is a unit vector)", b.normal[i].norm()));
    const BodyVel3& v = b.vel[i];
    vec("3d.vel", i, v.v);
    vec("3d.vel", i, v.w);
    in.non_negative("3d.vel", i, "inv_m", v.inv_m, !b.driven[i]);
    in.non_negative("3d.vel", i, "inv_I", v.inv_I, !b.driven[i]);
    if (b.driven[i] && (v.inv_m != 0 || v.inv_I != 0))
      in.bad("3d.vel", i, "inv_m", "is not 0 for a driven body");
    if (!b.driven[i]) {
      in.inverse("3d.vel", i, "inv_m", v.inv_m, b.mass[i], "mass");
      in.inverse("3d.vel", i, "inv_I", v.inv_I, b.inertia[i], "inertia");
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

}  // namespace

void save_checkpoint3(const std::string& path, const World3& w, std::uint64_t scene_key,
                      const RunTotals& totals) {
  if (w.bodies.has_polyhedra())
    throw std::invalid_argument("checkpoint: a world of polyhedra is not written to checkpoints yet");
  ckpt::save_world(path, w, kFile, kBodies3Arrays, scene_key, totals, [&](ckpt::Writer& o) {
    const WorldParams3& p = w.params();
    const CellState3& c = w.cell();
    o.array("3d.cell", std::vector<double>{c.size.x(), c.size.y(), c.size.z(), c.le_offset, double(p.periodic[0]),
                                           double(p.periodic[1]), double(p.periodic[2]), c.rate.x(), c.rate.y(),
                                           c.rate.z(), c.strain});
  });
}

std::uint64_t load_checkpoint3(const std::string& path, World3& w, RunTotals* totals) {
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
        return c;
      },
      [](World3& w, const CellState3& c) {
        restore_derived(w.bodies);
        w.set_cell(c);
      });
}

}  // namespace cd
