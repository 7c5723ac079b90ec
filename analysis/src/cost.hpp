// What a run cost, read from the summary.toml cdsim writes into every run
// folder (docs/outputs.md, "summary.toml"). The report puts it beside the
// physics of each point.
#pragma once
#include <optional>
#include <string>

namespace cda {

struct RunCost {
  double wall_time = 0;        // s, summed over the run's sessions
  double cpu_time = 0;         // s
  double steps = 0;            // the last step taken
  double sweeps_per_step = 0;  // mean NLGS sweeps per step
  double cap_share = 0;        // share of steps at the sweep cap
  double threads = 0;          // of the last session
  std::string status;          // done, stopped, max-steps, diverged
};

// The cost of the run in run_dir: nullopt when it has no summary.toml (a
// run from an older cdsim, or one killed before its first session ended).
// Throws InputError naming the file when it exists but does not parse or a
// field is missing or not a number.
std::optional<RunCost> read_run_cost(const std::string& run_dir);

}  // namespace cda
