#include "checkpoint3.hpp"

#include <cmath>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <utility>

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
static_assert(sizeof(Bodies3) ==
                  std::tuple_size_v<decltype(kBodies3Arrays)> * sizeof(std::vector<char>),
              "a Bodies3 member is missing from kBodies3Arrays (checkpoint3.cpp)");

}  // namespace

void save_checkpoint3(const std::string& path, const World3& w, std::uint64_t scene_key,
                      const RunTotals& totals) {
  ckpt::Writer o;
  ckpt::begin(o, 3, scene_key, static_cast<std::int64_t>(w.steps), w.time, w.times);
  ckpt::for_each_array(kBodies3Arrays, w.bodies, [&](std::string_view name, const auto& v) { o.array(name, v); });
  o.array("3d.warm.keys", w.warm_start().keys);
  o.array("3d.warm.p", w.warm_start().p);
  const WorldParams3& p = w.params();
  o.array("3d.cell", std::vector<double>{p.cell.x(), p.cell.y(), p.cell.z(), p.le_offset, double(p.periodic[0]),
                                         double(p.periodic[1]), double(p.periodic[2]), p.cell_rate.x(),
                                         p.cell_rate.y(), p.cell_rate.z(), p.strain});
  ckpt::finish(o, totals, path);
}

std::uint64_t load_checkpoint3(const std::string& path, World3& w, RunTotals* totals) {
  std::string data;
  ckpt::Reader in{path, {}};
  const ckpt::Header h = ckpt::open(path, data, in, 3, totals != nullptr);
  Bodies3 b;
  ckpt::for_each_array(kBodies3Arrays, b, [&](std::string_view name, auto& v) { in.array(name, v); });
  const std::size_t n = b.pos.size();
  bool same = true;
  ckpt::for_each_array(kBodies3Arrays, b, [&](std::string_view, const auto& v) { same = same && v.size() == n; });
  if (!same) in.fail("is corrupt (body arrays of different lengths)");
  World3::WarmStart warm;
  in.array("3d.warm.keys", warm.keys);
  in.array("3d.warm.p", warm.p);
  if (warm.keys.size() != warm.p.size()) in.fail("is corrupt (warm-start sizes differ)");
  std::vector<double> cell;
  in.array("3d.cell", cell);
  // 7 numbers: written before the cell had rates and a strain (both 0).
  if (cell.size() != 7 && cell.size() != 11) in.fail("is corrupt (the cell's state is not 7 or 11 numbers)");
  for (const double x : cell)
    if (!std::isfinite(x)) in.fail("is corrupt (a non-finite number in the cell's state)");
  WorldParams3 p = w.params();
  for (int a = 0; a < 3; ++a)
    if ((cell[4 + a] != 0.0) != p.periodic[a])
      in.fail(fmt::format("holds a cell periodic along (x, y, z) = ({:d}, {:d}, {:d}); this scene's is ({:d}, "
                          "{:d}, {:d})", cell[4] != 0.0, cell[5] != 0.0, cell[6] != 0.0, p.periodic[0],
                          p.periodic[1], p.periodic[2]));
  const RunTotals tot = ckpt::close(in, h);

  p.cell = Vec3(cell[0], cell[1], cell[2]);
  p.le_offset = cell[3];
  p.cell_rate = cell.size() == 11 ? Vec3(cell[7], cell[8], cell[9]) : Vec3::Zero();
  p.strain = cell.size() == 11 ? cell[10] : 0.0;
  try {
    World3 probe(p);  // checks the cell without touching w
  } catch (const std::invalid_argument& e) {
    in.fail(fmt::format("holds a cell this scene cannot take ({})", e.what()));
  }
  w.set_params(p);
  w.bodies = std::move(b);
  w.steps = h.steps;
  w.time = h.time;
  w.times = h.times;
  w.set_warm_start(std::move(warm));
  if (totals) *totals = tot;
  return h.key;
}

}  // namespace cd
