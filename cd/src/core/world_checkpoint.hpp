// The checkpoint of a world, the walk the 2D and 3D checkpoints share
// (2d/checkpoint.cpp, 3d/checkpoint3.cpp) over core/checkpoint_io.hpp's
// frame: between the timers and the totals, every body array of the
// engine's table, the warm-start memory, then the engine's own arrays (its
// cell's state). A world is changed only if the whole file is valid.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "checkpoint_io.hpp"

namespace cd::ckpt {

// What differs between the engines' files besides their own arrays: the
// dimension tag and the warm-start arrays' names.
struct WorldFile {
  int dimension;
  std::string_view warm_keys, warm_p;
};

// Writes w (bodies by `table`, warm start, then write_own(Writer&)) and
// `key` to path atomically.
template <class World, class Table, class WriteOwn>
void save_world(const std::string& path, const World& w, const WorldFile& f, const Table& table,
                std::uint64_t key, const RunTotals& totals, WriteOwn&& write_own) {
  Writer o;
  begin(o, f.dimension, key, static_cast<std::int64_t>(w.steps), w.time, w.times);
  for_each_array(table, w.bodies, [&](std::string_view name, const auto& v) { o.array(name, v); });
  o.array(f.warm_keys, w.warm_start().keys);
  o.array(f.warm_p, w.warm_start().p);
  write_own(o);
  finish(o, totals, path);
}

// Reads a checkpoint into w: the bodies by `table`, checked by
// check_bodies(in, bodies); the warm start, checked; read_own(in, bodies)
// reads and checks the engine's own arrays (against the bodies: the cell
// holds them) and returns them; then the totals and
// the body count. Only then is w changed: bodies, clock, timers, warm
// start, and apply_own(w, own) (which must not throw). Returns the scene
// key; with `totals`, also the run's totals.
template <class World, class Table, class CheckBodies, class ReadOwn, class ApplyOwn>
std::uint64_t load_world(const std::string& path, World& w, const WorldFile& f, const Table& table,
                         RunTotals* totals, CheckBodies&& check_bodies, ReadOwn&& read_own,
                         ApplyOwn&& apply_own) {
  std::string data;
  Reader in{path, {}};
  const Header h = open(path, data, in, f.dimension, totals != nullptr);
  std::remove_cvref_t<decltype(w.bodies)> b;
  for_each_array(table, b, [&](std::string_view name, auto& v) { in.array(name, v); });
  check_bodies(in, b);
  typename World::WarmStart warm;
  in.array(f.warm_keys, warm.keys);
  in.array(f.warm_p, warm.p);
  check_warm(in, f.warm_keys, warm.keys, f.warm_p, warm.p);
  auto own = read_own(in, std::as_const(b));
  const RunTotals tot = close(in, h);
  check_count(in, b.size(), w.bodies.size());

  w.bodies = std::move(b);
  w.steps = h.steps;
  w.time = h.time;
  w.times = h.times;
  w.set_warm_start(std::move(warm));
  apply_own(w, std::move(own));
  if (totals) *totals = tot;
  return h.key;
}

// The largest overlap of the state when it was written (array `name`: one
// depth in m, written by write_overlap) against the one its bodies have as
// read, measure() (a struct with depth, b1, b2): a grain moved or resized
// since (damage the checksum does not see and the value rules pass)
// changes it, and is refused naming the pair. The depth is a function of
// the positions alone, so the two agree to round-off; 1e-9 d_ref leaves
// room for nothing else. A file without the array (an older build's, or a
// state the engine does not measure) is not checked.
template <class Measure>
void check_overlap(Reader& in, std::string_view name, double d_ref, Measure&& measure) {
  if (in.next_name(name) != name) return;
  std::vector<double> rec;
  in.array(name, rec);
  if (rec.size() != 1) in.fail(fmt::format("is corrupt: '{}' holds {} numbers (must be 1)", name, rec.size()));
  in.non_negative(name, 0, "", rec[0]);
  const auto now = [&] {
    try {
      return measure();
    } catch (const CheckpointError&) {
      throw;
    } catch (const std::exception& e) {
      in.fail(fmt::format("is corrupt: its bodies cannot be detected in its cell ({})", e.what()));
    }
  }();
  if (!(std::abs(now.depth - rec[0]) <= 1e-9 * d_ref))
    in.fail(fmt::format("is corrupt: its bodies overlap by {:.6g} m at most (bodies {} and {}), but '{}' recorded "
                        "{:.6g} m when it was written: a position or a size was changed since",
                        now.depth, now.b1, now.b2, name, rec[0]));
}

}  // namespace cd::ckpt
