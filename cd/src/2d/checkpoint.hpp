// Checkpoints: the whole state of a World between two steps (every Bodies
// array, time, step count, stage timers, warm-start memory), so that a run
// continued from one is bit-identical to a run never stopped.
//
// The file's frame (version 5: magic, version, dimension 2, scene key,
// steps, time, stage timers, ..., run totals, checksum) is
// core/checkpoint_io.hpp's; between the timers and the totals, a 2D file holds
// one array per Bodies member, then "warm.keys", "warm.p" and "cell" (one
// CellState). Version 4 files (no dimension tag) are read as 2D.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "checkpoint_io.hpp"
#include "world.hpp"

namespace cd {

// Writes w's state and `scene_key` to path atomically (temporary file, then
// rename): a killed writer leaves the previous checkpoint intact.
void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals = {});

// Reads a checkpoint into w (its parameters are kept) and returns the stored
// scene key. Every array is checked as a scene is (lengths, shape tags,
// sides, signs, finiteness) and, if w already holds bodies (a resume into
// the world built from the scene), their count must be w's; with `totals`, also the run's totals. w (and *totals) are
// changed only if the whole file is valid; otherwise throws CheckpointError
// naming the file and what is wrong. Without `totals` (a start sample,
// shear.start) a version 3 file is read too: it differs only by having no
// totals; to resume a run, it is refused.
std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals = nullptr);

}  // namespace cd
