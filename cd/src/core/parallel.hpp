// The code's parallel thresholds, in one place: a loop over fewer rows, or
// fewer bodies, runs on one thread, since waking a team and the barriers
// cost more than the work (measured: a 600-row pile ran 3x slower on 2
// threads than on 1; much worse on a loaded machine). The solver's own
// threshold is SolverParams::min_parallel (default kMinParallelRows; tests
// set 0 to force the parallel paths); loops over bodies (predict,
// integrate) use half of it, detection kMinParallelBodies.
#pragma once

namespace cd {

inline constexpr int kMinParallelRows = 4096;
inline constexpr int kMinParallelBodies = kMinParallelRows / 2;

}  // namespace cd
