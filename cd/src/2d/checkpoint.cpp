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

}  // namespace

void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals) {
  ckpt::Writer o;
  ckpt::begin(o, 2, scene_key, static_cast<std::int64_t>(w.steps), w.time, w.times);
  ckpt::for_each_array(kBodiesArrays, w.bodies, [&](std::string_view name, const auto& v) { o.array(name, v); });
  o.array("warm.keys", w.warm_start().keys);
  o.array("warm.p", w.warm_start().p);
  o.array("cell", std::vector<CellState>{w.cell});
  ckpt::finish(o, totals, path);
}

std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals) {
  std::string data;
  ckpt::Reader in{path, {}};
  const ckpt::Header h = ckpt::open(path, data, in, 2, totals != nullptr);
  Bodies b;
  ckpt::for_each_array(kBodiesArrays, b, [&](std::string_view name, auto& v) { in.array(name, v); });
  World::WarmStart warm;
  in.array("warm.keys", warm.keys);
  in.array("warm.p", warm.p);
  if (warm.keys.size() != warm.p.size()) in.fail("is corrupt (warm-start sizes differ)");
  std::vector<CellState> cell;
  in.array("cell", cell);
  if (cell.size() != 1) in.fail("is corrupt (cell state)");
  const RunTotals tot = ckpt::close(in, h);

  w.bodies = std::move(b);
  w.steps = h.steps;
  w.time = h.time;
  w.times = h.times;
  w.set_warm_start(std::move(warm));
  w.cell = cell[0];
  if (totals) *totals = tot;
  return h.key;
}

}  // namespace cd
