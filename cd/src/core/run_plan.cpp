#include "run_plan.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "checkpoint_io.hpp"
#include "config.hpp"
#include "derived.hpp"

namespace cd {

RunPlan plan_of(const Scene& s, double dt) {
  RunPlan p;
  p.dt = dt;
  p.nsteps = std::llround(run_duration(s) / dt);
  const std::int64_t nsteps = p.nsteps;
  // An interval in steps, >= 1; one longer than the run is the run (no
  // overflow for huge intervals).
  const auto steps_of = [&](double interval) {
    const double k = interval / dt;
    return k >= double(nsteps) ? std::max<std::int64_t>(1, nsteps)
                               : std::max<std::int64_t>(1, std::llround(k));
  };
  // Rows and snapshots by simulated time, or by shear strain (the strain
  // keys need a rate: scene/protocol.cpp).
  const double rate = shear_rate(s);
  p.every_row = steps_of(s.series_strain > 0 && rate > 0 ? s.series_strain / rate : s.series_interval);
  p.every_snap = s.snapshot_strain > 0 && rate > 0 ? steps_of(s.snapshot_strain / rate)
                 : s.snapshot_interval > 0        ? steps_of(s.snapshot_interval)
                                                  : 0;
  // Checkpoints fall on series rows, so that no row's interval spans a
  // restart: every so much simulated time, or shear strain, rounded up to
  // whole rows; or at the first row after checkpoint_wall seconds of wall
  // clock. Writing one only reads the state, so when they fall (even by the
  // clock) changes no result.
  const auto on_rows = [&](std::int64_t k) {
    return p.every_row * std::max<std::int64_t>(1, (k + p.every_row - 1) / p.every_row);
  };
  p.every_ckpt = s.checkpoint_interval > 0 ? on_rows(steps_of(s.checkpoint_interval)) : 0;
  p.every_ckpt_strain =
      s.checkpoint_strain > 0 && rate > 0 ? on_rows(steps_of(s.checkpoint_strain / rate)) : 0;
  p.ckpt_wall = s.checkpoint_wall;
  p.checkpoint_interval = s.checkpoint_interval;
  p.checkpoint_strain = s.checkpoint_strain;
  p.key = scene_key(s);
  p.settle = SettleRule(s);
  return p;
}

std::uint64_t scene_key(const Scene& scene) {
  Scene s = scene;
  s.source.clear();
  s.threads = 0;
  s.quiet = false;
  s.checkpoint_interval = 0;
  s.checkpoint_strain = 0;
  s.checkpoint_wall = 0;
  return fnv1a(resolved_values(s));
}

bool folder_scene_is(const std::string& scene_toml, std::uint64_t key) {
  try {
    return scene_key(load_scene(scene_toml)) == key;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace cd
