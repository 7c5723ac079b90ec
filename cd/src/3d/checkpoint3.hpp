// 3D checkpoints: the whole state of a World3 between two steps (every
// Bodies3 array, time, step count, stage timers, warm-start memory), so that
// a run continued from one is bit-identical to a run never stopped.
//
// The file's frame is core/checkpoint_io.hpp's with dimension 3; between the
// timers and the totals it holds one array per Bodies3 member ("3d.vel",
// "3d.pos", ...), then "3d.warm.keys", "3d.warm.p" and "3d.cell": the
// periodic cell's state, {L_x, L_y, L_z, le_offset, periodic x, y, z (0/1),
// dL_x/dt, dL_y/dt, dL_z/dt, strain} (all 0 without a cell; a file of the
// first 7 only, written before the cell's lengths could move, is read with
// rates and strain 0). A 2D checkpoint is refused by its dimension tag,
// naming both dimensions.
#pragma once
#include <cstdint>
#include <string>

#include "checkpoint_io.hpp"
#include "world3.hpp"

namespace cd {

// Writes w's state and `scene_key` to path atomically.
void save_checkpoint3(const std::string& path, const World3& w, std::uint64_t scene_key,
                      const RunTotals& totals = {});

// Reads a checkpoint into w: its parameters are kept, its cell's state
// (CellState3: lengths, Lees-Edwards offset, rates, strain) is the
// checkpoint's; a checkpoint whose periodic axes differ from w's is refused. Returns the
// stored scene key; with `totals`, also the run's totals. w is changed only if the
// whole file is valid; otherwise throws CheckpointError naming the file.
//
// Polyhedra: the file stores the shape library's vertices besides its count
// and fingerprint. Shapes::Scene (a run's own restart) takes w's library,
// the scene's, and refuses a file whose fingerprint is not its; with
// Shapes::File (a started sample, shear.start) the library is the file's,
// rebuilt from its vertices (to round-off), each body checked against its
// shape's circumradius and moments.
enum class Shapes : std::uint8_t { Scene, File };
std::uint64_t load_checkpoint3(const std::string& path, World3& w, RunTotals* totals = nullptr,
                               Shapes shapes = Shapes::Scene);

}  // namespace cd
