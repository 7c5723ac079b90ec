// Checkpoints: the whole state of a World between two steps (every Bodies
// array, time, step count, stage timers, warm-start memory), so that a run
// continued from one is bit-identical to a run never stopped.
//
// File format (version 4), little-endian, no padding:
//   "CDLABCKP"                      8-byte magic
//   u32 version
//   u64 scene key                   opaque to this file (run.cpp: hash of the scene)
//   i64 steps, f64 time
//   arrays, each: u32 name length, name, u64 count, u32 element size, raw elements
//     first the stage timers, one f64 per stage of world.hpp's stage table, in
//     an array named "times:" + the stage names joined by ':' (a build with
//     other stages refuses the file); then one per Bodies member, then
//     "warm.keys", "warm.p", "cell" (one CellState) and the run's totals (one
//     f64 per RunTotals field, in an array named "totals:" + the field names
//     joined by ':')
//   u64 FNV-1a of every byte before it
// A reader checks every size against the file and the checksum, and names the
// file in any error.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scene.hpp"
#include "world.hpp"

namespace cd {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The cost of a run so far, carried by its checkpoint so that a resumed run's
// summary.toml (run.cpp) covers every session. Wall and CPU time count what
// was spent up to the checkpoint: the work a kill loses after it is not
// counted (the session that redoes it counts it).
struct RunTotals {
  double wall = 0;           // s of wall-clock time in the run loop, summed over sessions
  double cpu = 0;            // s of CPU time of the process (user + system) in the run loop
  double sweeps = 0;         // NLGS sweeps summed over the steps (exact below 2^53)
  double sweeps_max = 0;     // most sweeps of one step
  double cap_steps = 0;      // steps that stopped at solver.max_iter
  double residual_max = 0;   // largest law residual of any step
  double residual_last = 0;  // the last step's law residual
  double overlap_max = 0;    // largest overlap, in mean diameters
  double sessions = 0;       // cdsim calls that took steps of this run
};

// 64-bit FNV-1a (the checksum; also used for the scene key).
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 1469598103934665603ull);

// Writes w's state and `scene_key` to path atomically (temporary file, then
// rename): a killed writer leaves the previous checkpoint intact.
void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals = {});

// Reads a checkpoint into w (its parameters are kept) and returns the stored
// scene key; with `totals`, also the run's totals. w (and *totals) are
// changed only if the whole file is valid; otherwise throws CheckpointError
// naming the file and what is wrong. Without `totals` (a start sample,
// shear.start) a version 3 file is read too: it differs only by having no
// totals; to resume a run, it is refused.
std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals = nullptr);

// ---- restarting a run (run.cpp) ----

// What a checkpoint must match: a hash of the resolved scene without the keys
// that change neither the results nor the outputs, so that a restart may
// change them: solver.threads (results are bit-identical for any thread
// count), output.quiet, output.checkpoint_interval, output.checkpoint_strain,
// output.checkpoint_wall, and the scene's file name.
std::uint64_t scene_key(const Scene& s);

// Cuts series.csv back to its header and the rows up to `step` (a killed run
// may have written rows after its last checkpoint) and returns the column
// names. Throws CheckpointError if the file does not reach `step`.
std::vector<std::string> truncate_series(const std::string& path, std::int64_t step);

}  // namespace cd
