// The run plan: when a run's series rows, snapshots and checkpoints fall, in
// steps of dt, and the key its checkpoints carry. It depends only on the
// scene's keys (scene/derived.hpp's duration and shear rate), so both
// engines' runs (2d/run.cpp, 3d/run3.cpp) take it from here.
#pragma once
#include <cstdint>

#include "scene.hpp"
#include "settle.hpp"

namespace cd {

struct RunPlan {
  std::int64_t nsteps = 0;
  double dt = 0;
  std::int64_t every_row = 1;
  std::int64_t every_snap = 0;         // 0: no snapshots
  std::int64_t every_ckpt = 0;         // 0: none by simulated time
  std::int64_t every_ckpt_strain = 0;  // 0: none by strain
  double ckpt_wall = 0;                // s of wall clock; 0: none
  double checkpoint_interval = 0, checkpoint_strain = 0;  // as given (for messages)
  std::uint64_t key = 0;               // scene key a checkpoint must match
  SettleRule settle;                   // the compaction's stop rule (off unless shear.settle_*)
  bool checkpoints() const { return every_ckpt || every_ckpt_strain || ckpt_wall > 0; }
};

// The plan of scene s run at time step dt (the world's, after the scene's
// [shear] overrides).
RunPlan plan_of(const Scene& s, double dt);

// What a checkpoint must match: a hash of the resolved scene without the keys
// that change neither the results nor the outputs, so that a restart may
// change them: solver.threads (results are bit-identical for any thread
// count), output.quiet, output.checkpoint_interval, output.checkpoint_strain,
// output.checkpoint_wall, and the scene's file name. It hashes the values
// alone (config.hpp's resolved_values), not their documentation.
std::uint64_t scene_key(const Scene& s);

// Whether the scene.toml in a run folder is the scene of `key`: how a
// checkpoint whose key hashed the documentation too (written by a cdsim
// before scene_key hashed the values alone) is recognised as this scene's.
// False if the file is missing or unreadable.
bool folder_scene_is(const std::string& scene_toml, std::uint64_t key);

}  // namespace cd
