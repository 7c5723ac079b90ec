// The defaults that the scene (scene.hpp) shares with the engines' parameter
// structs (core/solver.hpp's SolverParams, 2d/world.hpp's WorldParams), so
// that a World built without a scene and one built from the default scene
// agree. They live here, at the bottom layer, because the scene may include
// nothing above it; every other default is a Scene member's initialiser.
#pragma once

namespace cd {
// The rows the stop test averages over (solver.stop_rows, SolverParams::stop_rows).
enum class StopRows { All, Loaded };
}  // namespace cd

namespace cd::defaults {

inline constexpr double dt = 1e-4;          // time step (s)
inline constexpr bool rotation = true;      // bodies rotate
inline constexpr double tol = 1e-4;         // NLGS eps_f on rms |dp| / mean |p|
inline constexpr int max_iter = 2000;       // NLGS sweep cap per step
inline constexpr double residual_tol = 0.0; // law-residual stop; 0: off
inline constexpr int subspace = 0;          // subspace correction: CG iterations; 0: off
inline constexpr int anderson = 0;          // Anderson acceleration memory; 0: off
inline constexpr StopRows stop_rows = StopRows::All;  // the stop test over every row

}  // namespace cd::defaults
