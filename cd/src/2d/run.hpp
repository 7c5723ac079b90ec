// A 2D run: World in the shared run loop (core/run_loop.hpp), with its
// checkpoints, snapshots, --dump-problem files and shear columns.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "run_loop.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace cd {

// Runs the world for the scene's duration. The caller has validated the
// scene and checked the output folder; this creates it and writes into it.
// If the folder holds a checkpoint.bin (and not opt.fresh), the run resumes
// from it: w's state is replaced, series.csv is cut back to the checkpoint's
// step, and the run goes on as if never stopped. A checkpoint of another
// scene, or an unreadable one, throws before anything is written.
RunSummary run(World& w, const Scene& s, const RunOptions& opt);

}  // namespace cd
