// 3D checkpoints: the whole state of a World3 between two steps (every
// Bodies3 array, time, step count, stage timers, warm-start memory), so that
// a run continued from one is bit-identical to a run never stopped.
//
// The file's frame is core/checkpoint_io.hpp's with dimension 3; between the
// timers and the totals it holds one array per Bodies3 member ("3d.vel",
// "3d.pos", ...), then "3d.warm.keys" and "3d.warm.p". A 2D checkpoint is
// refused by its dimension tag, naming both dimensions.
#pragma once
#include <cstdint>
#include <string>

#include "checkpoint_io.hpp"
#include "world3.hpp"

namespace cd {

// Writes w's state and `scene_key` to path atomically.
void save_checkpoint3(const std::string& path, const World3& w, std::uint64_t scene_key,
                      const RunTotals& totals = {});

// Reads a checkpoint into w (its parameters are kept) and returns the stored
// scene key; with `totals`, also the run's totals. w is changed only if the
// whole file is valid; otherwise throws CheckpointError naming the file.
std::uint64_t load_checkpoint3(const std::string& path, World3& w, RunTotals* totals = nullptr);

}  // namespace cd
