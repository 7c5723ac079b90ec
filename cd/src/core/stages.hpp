// The stage table of a time step: names, order and wall-clock timers. The
// step of either engine (2D and 3D) runs these stages; their names are the
// columns of the run's timings.csv and the checkpoint's record of the timers.
#pragma once
#include <array>
#include <chrono>
#include <cstddef>
#include <utility>

#include "solver.hpp"

namespace cd {

// The stages of a step, in the order they run, and `output` (timed by the
// run loop). Their names are the columns of timings.csv and the
// checkpoint's record of the timers.
enum class Stage : int { Predict, Detect, Build, Colour, Solve, Integrate, Observe, Output };
inline constexpr int kStages = 8;
inline constexpr std::array<const char*, kStages> kStageNames = {
    "predict", "detect", "build", "colour", "solve", "integrate", "observe", "output"};

struct StageTimes {  // wall-clock seconds, accumulated, per stage
  std::array<double, kStages> t{};
  double& operator[](Stage s) { return t[static_cast<int>(s)]; }
  double operator[](Stage s) const { return t[static_cast<int>(s)]; }
};

// What one step reports, in 2D and 3D (max_overlap_small: 2D only so far).
struct StepStats {
  SolveStats solve;
  int contacts = 0;        // rows handed to the solver
  int active = 0;          // rows carrying a force (p_n + a > 0)
  double max_overlap = 0;  // max over contacts of -gap / d_ref (midpoint configuration)
  double mean_overlap = 0; // mean of -gap / d_ref over overlapping contacts
  double max_overlap_small = 0;  // max over contacts of -gap / (the smaller grain's diameter)
  double correction_work = 0;  // sum of p_n x bias velocity of the overlap correction (J)
  double projection_work = 0;  // overlap projection: sum of f_n x the separation it added (J)
  // A pressure-driven length's free velocity was held at the approach floor
  // by a load the floor does not let through even from rest
  // (core/cell_dof.hpp, load_past_floor): the imposed stress was not fully
  // applied on this step. Always false without such a length.
  bool floor_held = false;
};

// The stages of a world's step W, in order, each a member function.
template <class W>
using StageTable = std::array<std::pair<Stage, void (W::*)()>, kStages - 1>;  // Output: the run loop's

// Runs a step's stages in order, each timed into its slot of `times`.
template <class W>
void run_stages(W& w, const StageTable<W>& table, StageTimes& times) {
  using Clock = std::chrono::steady_clock;
  for (const auto& [stage, run] : table) {
    const auto t0 = Clock::now();
    (w.*run)();
    times[stage] += std::chrono::duration<double>(Clock::now() - t0).count();
  }
}

}  // namespace cd
