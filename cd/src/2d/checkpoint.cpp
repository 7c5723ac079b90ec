#include "checkpoint.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <tuple>
#include <type_traits>

#include <fmt/format.h>

#include "detect.hpp"
#include "output.hpp"
#include "world_checkpoint.hpp"

namespace cd {

namespace {

static_assert(std::endian::native == std::endian::little,
              "checkpoints store raw little-endian values");

// Every Bodies array, listed once: the writer and the reader both walk this
// list, so a new Bodies member is one line here.
constexpr std::tuple kBodiesArrays{
    std::pair{"vel", &Bodies::vel},
    std::pair{"pos", &Bodies::pos},
    std::pair{"angle", &Bodies::angle},
    std::pair{"shape", &Bodies::shape},
    std::pair{"radius", &Bodies::radius},
    std::pair{"nsides", &Bodies::nsides},
    std::pair{"mass", &Bodies::mass},
    std::pair{"inertia", &Bodies::inertia},
    std::pair{"driven", &Bodies::driven},
    std::pair{"force", &Bodies::force},
};
// Bodies holds only vectors, so a member left out of the list shows here.
static_assert(sizeof(Bodies) ==
                  std::tuple_size_v<decltype(kBodiesArrays)> * sizeof(std::vector<char>),
              "a Bodies member is missing from kBodiesArrays (checkpoint.cpp)");

// Every body's arrays, checked as a scene's bodies are: the shape tag, the
// sides (a polygon's in [3, 60], else 0), the walls driven, sizes, masses
// and inertias of the right sign, every number finite: the step then never
// reads out of bounds nor starts from a non-finite state.
void check_bodies(const ckpt::Reader& in, const Bodies& b) {
  const std::size_t n = ckpt::same_lengths(kBodiesArrays, b, in);
  for (std::size_t i = 0; i < n; ++i) {
    const auto shape = static_cast<unsigned>(b.shape[i]);
    if (shape > static_cast<unsigned>(Shape::Polygon))
      in.bad("shape", i, "", fmt::format("is {} (0 disk, 1 wall segment, 2 polygon)", shape));
    if (b.driven[i] > 1) in.bad("driven", i, "", fmt::format("is {} (0 or 1)", b.driven[i]));
    const bool polygon = b.shape[i] == Shape::Polygon, wall = b.shape[i] == Shape::Segment;
    if (polygon ? b.nsides[i] < 3 || b.nsides[i] > 60 : b.nsides[i] != 0)
      in.bad("nsides", i, "", fmt::format("is {} (a polygon has 3 to 60 sides, a disk or wall 0)", b.nsides[i]));
    if (wall && !b.driven[i]) in.bad("driven", i, "", "is 0 for a wall segment (walls are driven)");
    in.non_negative("radius", i, "", b.radius[i], !wall);
    in.non_negative("mass", i, "", b.mass[i], !b.driven[i]);
    in.non_negative("inertia", i, "", b.inertia[i], !b.driven[i]);
    const BodyVel& v = b.vel[i];
    in.finite("vel", i, "vx", v.vx);
    in.finite("vel", i, "vy", v.vy);
    in.finite("vel", i, "w", v.w);
    in.non_negative("vel", i, "inv_m", v.inv_m, !b.driven[i]);
    in.non_negative("vel", i, "inv_I", v.inv_I, !b.driven[i]);
    if (b.driven[i] && (v.inv_m != 0 || v.inv_I != 0))
      in.bad("vel", i, "inv_m", "is not 0 for a driven body");
    if (!b.driven[i]) {
      in.inverse("vel", i, "inv_m", v.inv_m, b.mass[i], "mass");
      in.inverse("vel", i, "inv_I", v.inv_I, b.inertia[i], "inertia");
    }
    in.finite("pos", i, "x", b.pos[i].x());
    in.finite("pos", i, "y", b.pos[i].y());
    in.finite("angle", i, "", b.angle[i]);
    in.finite("force", i, "x", b.force[i].x());
    in.finite("force", i, "y", b.force[i].y());
  }
}

// The cell's numbers, and the cell against the grains it holds, as the
// scene's cell is checked (the state a run left: lengths that the detection
// can grid, the grains inside the periodic lengths, the Lees-Edwards offset
// within the width).
void check_cell(const ckpt::Reader& in, const CellState& c, const Bodies& b, const WorldParams& p) {
  in.non_negative("cell", 0, "width", c.width);
  in.non_negative("cell", 0, "height", c.height);
  in.finite("cell", 0, "offset", c.offset);
  in.finite("cell", 0, "hdot", c.hdot);
  in.finite("cell", 0, "wdot", c.wdot);
  in.finite("cell", 0, "strain", c.strain);
  const CellParams::Mode mode = p.cell.mode;
  if (mode == CellParams::Mode::None) return;
  const bool le = mode == CellParams::Mode::LeesEdwards;
  double r_max = 0.0;
  for (std::size_t i = 0; i < b.size(); ++i)
    if (b.shape[i] != Shape::Segment) r_max = std::max(r_max, b.radius[i]);
  // The detection's grid needs 4 (x) and 3 (y, Lees-Edwards) times 2 r_max
  // plus the alert distance; without it (the least any scene asks):
  const double h = 2 * r_max;
  if (!(c.width >= 4 * h))
    in.bad("cell", 0, "width", fmt::format("is {:.6g} m: the periodic width must be at least 4 x 2 r_max = {:.6g} m "
                                          "for these grains", c.width, 4 * h));
  if (le && !(c.height >= 3 * h))
    in.bad("cell", 0, "height", fmt::format("is {:.6g} m: the periodic height must be at least 3 x 2 r_max = {:.6g} m "
                                           "for these grains", c.height, 3 * h));
  if (!(c.offset >= 0 && c.offset <= c.width))
    in.bad("cell", 0, "offset", fmt::format("is {:.6g} m (the Lees-Edwards offset is within [0, width = {:.6g}])",
                                           c.offset, c.width));
  // A step ends with every grain wrapped into the periodic lengths.
  const double tol = 1e-9 * std::max(c.width, c.height);
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.shape[i] == Shape::Segment || b.driven[i]) continue;
    if (!(b.pos[i].x() >= -tol && b.pos[i].x() <= c.width + tol))
      in.bad("pos", i, "x", fmt::format("is {:.6g} m, outside the periodic width [0, {:.6g}]", b.pos[i].x(), c.width));
    if (le && !(b.pos[i].y() >= -tol && b.pos[i].y() <= c.height + tol))
      in.bad("pos", i, "y",
             fmt::format("is {:.6g} m, outside the periodic height [0, {:.6g}]", b.pos[i].y(), c.height));
  }
}

constexpr ckpt::WorldFile kFile{2, "warm.keys", "warm.p"};

// The largest overlap of bodies b in cell c (its periodic view as the
// world's: both axes for the Lees-Edwards cell, x between walls).
Overlap overlap_of(const Bodies& b, const CellState& c, const WorldParams& p) {
  const CellParams::Mode mode = p.cell.mode;
  const PeriodicCell pc{mode != CellParams::Mode::None, mode == CellParams::Mode::LeesEdwards, c.width, c.height,
                        c.offset};
  return largest_overlap(b, mode == CellParams::Mode::None ? nullptr : &pc);
}

}  // namespace

void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals) {
  ckpt::save_world(path, w, kFile, kBodiesArrays, scene_key, totals,
                   [&](ckpt::Writer& o) {
                     o.array("cell", std::vector<CellState>{w.cell});
                     o.array("overlap", std::vector<double>{overlap_of(w.bodies, w.cell, w.params()).depth});
                   });
}

std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals) {
  return ckpt::load_world(
      path, w, kFile, kBodiesArrays, totals, check_bodies,
      [&](ckpt::Reader& in, const Bodies& b) {
        std::vector<CellState> cell;
        in.array("cell", cell);
        if (cell.size() != 1) in.fail(fmt::format("is corrupt: 'cell' holds {} elements (must be 1)", cell.size()));
        check_cell(in, cell[0], b, w.params());
        ckpt::check_overlap(in, "overlap", w.params().d_ref, [&] { return overlap_of(b, cell[0], w.params()); });
        return cell[0];
      },
      [](World& w, const CellState& c) { w.cell = c; });
}

}  // namespace cd
