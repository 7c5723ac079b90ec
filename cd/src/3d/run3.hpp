// A 3D run: World3 in the shared run loop (core/run_loop.hpp), with its
// checkpoints (checkpoint3.hpp), snapshots (output3.hpp) and watchdog. The
// plan (series rows, snapshots, checkpoints, scene key) is 2D's plan_of.
#pragma once
#include "run_loop.hpp"
#include "scene.hpp"
#include "world3.hpp"

namespace cd {

// The watchdog: the first non-finite position, orientation, velocity or
// impulse of w, or "".
std::string non_finite3(const World3& w);

// Largest overlap of the last step's contacts over the smaller grain's
// diameter (a wall contact: the sphere's), as 2D's max_overlap_small.
double max_overlap_small3(const World3& w);

// As 2D's run (run.hpp): resumes from out/checkpoint.bin if there is one.
RunSummary run3(World3& w, const Scene& s, const RunOptions& opt);

}  // namespace cd
