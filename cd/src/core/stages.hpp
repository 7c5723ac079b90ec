// The stage table of a time step: names, order and wall-clock timers. The
// step of any engine (2D today) runs these stages; their names are the
// series columns t_<name> and the checkpoint's record of the timers.
#pragma once
#include <array>

namespace cd {

// The stages of a step, in the order they run, and `output` (timed by the
// run loop). Their names are the series columns t_<name> and the
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

}  // namespace cd
