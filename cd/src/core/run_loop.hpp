// The run loop both dimensions share: the time loop around an engine's
// step, with resume from a checkpoint, series rows, VTK snapshots, periodic
// checkpoints, the watchdog, signals, --max-steps, the progress line and
// summary.toml. What depends on the dimension (the world, its checkpoint,
// its snapshots, its protocol columns) is behind RunEngine; 2d/run.cpp and
// 3d/run3.cpp each wrap their world in one. The loop's steps are
// RunSession's (run_session.hpp), over parts each testable alone
// (run_session_parts.hpp).
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "checkpoint_io.hpp"
#include "run_plan.hpp"
#include "stages.hpp"

namespace cd {

struct RunOptions {
  std::string out;          // output folder
  bool quiet = false;       // no progress line
  std::string scene_toml;   // resolved scene, written as scene.toml
  bool fresh = false;       // start over even if `out` holds a checkpoint
  // Steps whose contact problem is written into `out` before it is solved:
  // 2D problem_STEP.cdp (exact, contact_problem.hpp; cdproblem replays it
  // to the same impulses), problem_STEP.dat (Siconos' matrix form; not for
  // cohesive steps); 3D problem_STEP.cdp3 and .hdf5 (FCLib; 3d/dump3.hpp);
  // and, after the solve, problem_STEP.impulses (the step's impulses, row
  // order, hex floats).
  std::vector<std::int64_t> dump_steps;
  // > 0: stop after this many steps of this call (at a step boundary, with
  // a series row and, if checkpoints are on, a checkpoint to resume from).
  std::int64_t max_steps = 0;
  // > 0: a whole progress line on stdout every this many wall-clock seconds
  // (folder, step, share done, ETA), quiet or not, terminal or log: what a
  // campaign of hours shows while its runs go (cdsim --progress).
  double progress_every = 0;
};

// A run that produced a non-finite position, velocity, impulse, cell
// quantity or series value, or two grains sunk into each other by
// half the smaller one's diameter (run_session.cpp): the message names the
// step, the body or contact and the quantity. The series holds the rows
// before it; the last checkpoint written is intact (none is written after
// the bad step).
struct RunDiverged : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Set by SIGINT/SIGTERM (install_stop_handlers): the run stops at the next
// step boundary, writing a checkpoint if checkpoints are on.
void install_stop_handlers();

struct RunSummary {
  int stop_signal = 0;          // > 0: stopped early by this signal
  bool stopped_at_max_steps = false;
  // The stop rule (shear.settle_*, core/settle.hpp): on, met (the run ended
  // at the row that met it), and what the last window measured.
  bool settle_on = false, settled = false;
  double settle_stress_dev = 0, settle_phi_range = 0;
  std::int64_t total_steps = 0;  // the scene's steps
  std::int64_t first_step = 0;  // > 0: resumed from a checkpoint at this step
  std::int64_t steps = 0;       // steps run by this call
  double mean_iterations = 0;
  int max_iterations = 0;
  std::int64_t cap_hits = 0;
  std::int64_t anderson_off = 0;  // steps whose Anderson mixing stalled and went off (SolveStats::anderson_off)
  // Steps at the sweep cap whose Anderson mixing had stalled and gone off:
  // their last sweeps were plain NLGS's.
  std::int64_t cap_anderson_off = 0;
  std::int64_t subspace_off = 0;  // steps whose subspace corrections stalled and stopped (SolveStats::subspace_off)
  std::int64_t subspace_iterations = 0;  // conjugate-gradient iterations of the subspace corrections, all steps
  // Steps on which a pressure-driven length was held at its approach floor
  // by a load past it (StepStats::floor_held): the imposed pressure not
  // fully applied on them.
  std::int64_t floor_steps = 0;
  double max_residual = 0;
  double max_overlap = 0;        // largest overlap / mean diameter
  double max_overlap_small = 0;  // largest overlap / the smaller grain's diameter
  double wall_time = 0;
  double kinetic_energy = 0;

  // The whole run, every session (what summary.toml holds).
  std::string status;           // "done", "settled", "stopped" (signal), "max-steps", "diverged"
  std::int64_t last_step = 0;   // the last step taken
  RunTotals totals;             // summed over sessions (checkpoint_io.hpp)
  int threads = 0;              // OpenMP threads of this session
  std::vector<double> load_start, load_end;  // /proc/loadavg (1, 5, 15 min) of this session; empty if unreadable
  double cap_share() const { return last_step ? totals.cap_steps / double(last_step) : 0.0; }
};

// summary.toml, written into the run folder at the end of every session
// (done, stopped by a signal or --max-steps, diverged): the cost of the whole
// run, documented in docs/outputs.md.
std::string summary_toml(const RunSummary& s);

using Columns = std::vector<std::pair<std::string, double>>;
using Frames = std::vector<std::pair<double, std::string>>;  // (time, number) of written snapshots

// What the run loop needs of a world.
class RunEngine {
 public:
  virtual ~RunEngine() = default;
  virtual void step() = 0;
  virtual const StepStats& last() const = 0;
  virtual std::int64_t steps() const = 0;
  virtual double time() const = 0;
  virtual StageTimes& times() = 0;
  virtual double kinetic_energy() const = 0;
  // The watchdog: the first non-finite quantity of the state, or "".
  virtual std::string non_finite() const = 0;
  virtual void save(const std::string& path, std::uint64_t key, const RunTotals& t) const = 0;
  // Replaces the state; returns the stored scene key (throws CheckpointError).
  virtual std::uint64_t load(const std::string& path, RunTotals* t) = 0;
  // Snapshots into `dir`, continuing after `frames` (empty: a fresh run).
  virtual void open_snapshots(const std::string& dir, Frames frames) = 0;
  virtual void write_snapshot() = 0;
  // Once the state is the run's start (after a resume, before step 1).
  virtual void start() {}
  // After each step k (before its series row): dumps, interval sums.
  virtual void after_step(std::int64_t /*k*/) {}
  // Protocol columns appended to a series row (and their interval reset).
  virtual void add_columns(Columns& /*cols*/) {}
};

// Runs the engine to plan.nsteps. The caller has validated the scene and
// checked the output folder; this creates it and writes into it. If the
// folder holds a checkpoint.bin (and not opt.fresh), the run resumes from
// it: the engine's state is replaced, series.csv is cut back to the
// checkpoint's step, and the run goes on as if never stopped. A checkpoint
// of another scene (or dimension), or an unreadable one, throws before
// anything is written.
RunSummary run_loop(RunEngine& e, const RunPlan& plan, const RunOptions& opt);

}  // namespace cd
