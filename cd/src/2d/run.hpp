// A run: the time loop around World::step, writing series rows, VTK
// snapshots and a progress line.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "checkpoint.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace cd {

struct RunOptions {
  std::string out;          // output folder
  bool quiet = false;       // no progress line
  std::string scene_toml;   // resolved scene, written as scene.toml
  bool fresh = false;       // start over even if `out` holds a checkpoint
  // Steps whose contact problem is written into `out` before it is solved:
  // problem_STEP.cdp (exact, contact_problem.hpp; cdproblem replays it to
  // the same impulses), problem_STEP.dat (Siconos' matrix form; not for
  // cohesive steps) and, after the solve, problem_STEP.impulses (the
  // step's impulses, row order, hex floats).
  std::vector<std::int64_t> dump_steps;
  // > 0: stop after this many steps of this call (at a step boundary, with
  // a series row and, if checkpoints are on, a checkpoint to resume from).
  std::int64_t max_steps = 0;
};

// A run that produced a non-finite position, velocity, impulse, cell
// quantity or series value: the message names the step, the body or contact
// and the quantity. The series holds the rows before it; the last
// checkpoint written is intact (none is written after the bad step).
struct RunDiverged : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Set by SIGINT/SIGTERM (install_stop_handlers): the run stops at the next
// step boundary, writing a checkpoint if checkpoints are on.
void install_stop_handlers();

struct RunSummary {
  int stop_signal = 0;          // > 0: stopped early by this signal
  bool stopped_at_max_steps = false;
  std::int64_t total_steps = 0;  // the scene's steps
  std::int64_t first_step = 0;  // > 0: resumed from a checkpoint at this step
  std::int64_t steps = 0;       // steps run by this call
  double mean_iterations = 0;
  int max_iterations = 0;
  std::int64_t cap_hits = 0;
  double max_residual = 0;
  double max_overlap = 0;        // largest overlap / mean diameter
  double max_overlap_small = 0;  // largest overlap / the smaller grain's diameter
  double wall_time = 0;
  double kinetic_energy = 0;

  // The whole run, every session (what summary.toml holds).
  std::string status;           // "done", "stopped" (signal), "max-steps", "diverged"
  std::int64_t last_step = 0;   // the last step taken
  RunTotals totals;             // summed over sessions (checkpoint.hpp)
  int threads = 0;              // OpenMP threads of this session
  std::vector<double> load_start, load_end;  // /proc/loadavg (1, 5, 15 min) of this session; empty if unreadable
  double cap_share() const { return last_step ? totals.cap_steps / double(last_step) : 0.0; }
};

// summary.toml, written into the run folder at the end of every session
// (done, stopped by a signal or --max-steps, diverged): the cost of the whole
// run, documented in docs/outputs.md.
std::string summary_toml(const RunSummary& s);

// Runs the world for the scene's duration. The caller has validated the
// scene and checked the output folder; this creates it and writes into it.
// If the folder holds a checkpoint.bin (and not opt.fresh), the run resumes
// from it: w's state is replaced, series.csv is cut back to the checkpoint's
// step, and the run goes on as if never stopped. A checkpoint of another
// scene, or an unreadable one, throws before anything is written.
RunSummary run(World& w, const Scene& s, const RunOptions& opt);

}  // namespace cd
