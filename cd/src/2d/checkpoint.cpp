#include "checkpoint.hpp"

#include <bit>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <tuple>
#include <type_traits>

#include <fmt/format.h>

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
    in.finite("pos", i, "x", b.pos[i].x());
    in.finite("pos", i, "y", b.pos[i].y());
    in.finite("angle", i, "", b.angle[i]);
    in.finite("force", i, "x", b.force[i].x());
    in.finite("force", i, "y", b.force[i].y());
  }
}

void check_cell(const ckpt::Reader& in, const CellState& c) {
  in.non_negative("cell", 0, "width", c.width);
  in.non_negative("cell", 0, "height", c.height);
  in.finite("cell", 0, "offset", c.offset);
  in.finite("cell", 0, "hdot", c.hdot);
  in.finite("cell", 0, "wdot", c.wdot);
  in.finite("cell", 0, "strain", c.strain);
}

constexpr ckpt::WorldFile kFile{2, "warm.keys", "warm.p"};

}  // namespace

void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals) {
  ckpt::save_world(path, w, kFile, kBodiesArrays, scene_key, totals,
                   [&](ckpt::Writer& o) { o.array("cell", std::vector<CellState>{w.cell}); });
}

std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals) {
  return ckpt::load_world(
      path, w, kFile, kBodiesArrays, totals, check_bodies,
      [](ckpt::Reader& in) {
        std::vector<CellState> cell;
        in.array("cell", cell);
        if (cell.size() != 1) in.fail(fmt::format("is corrupt: 'cell' holds {} elements (must be 1)", cell.size()));
        check_cell(in, cell[0]);
        return cell[0];
      },
      [](World& w, const CellState& c) { w.cell = c; });
}

}  // namespace cd
