// The parts of a run session (run_session.hpp), each one concern that can be
// read and tested alone: the output folder and its lock, the resume from a
// checkpoint, when outputs fall, series.csv and timings.csv, a stop asked
// by a signal, the --dump-problem steps, the cost record (summary.toml) and
// the progress lines.
#pragma once
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "checkpoint_io.hpp"
#include "files.hpp"
#include "run_loop.hpp"
#include "run_plan.hpp"
#include "stages.hpp"

namespace cd {

using RunClock = std::chrono::steady_clock;

// The output folder of a run: the paths of its files and its one-writer
// lock, taken at once if the folder exists (before its checkpoint is read),
// or as soon as make() makes it.
class RunFolder {
 public:
  explicit RunFolder(const std::string& out);
  const std::string& out() const { return out_; }
  // DIR/name.
  std::string file(const char* name) const { return (dir_ / name).string(); }
  std::string checkpoint() const { return file("checkpoint.bin"); }
  std::string series() const { return file("series.csv"); }
  // The stage timings, wall-clock seconds, apart from the physics so that
  // identical runs give byte-identical series (timings.csv: same rows).
  std::string timings() const { return file("timings.csv"); }

  // Makes the folder and locks it (if not yet locked), then checks that it
  // was not removed and made again since it was locked.
  void make();
  // Before every write: the folder must still be the one locked. A stopping
  // run whose folder was removed and made again by a new run (of the same
  // --out) would otherwise reopen the new series.csv by its path and append
  // its last row ahead of the new header; it writes nothing instead
  // (FolderGone). Each check is one stat, at most a few per series row.
  void check() const {
    if (lock_) lock_->check_unchanged();
  }

 private:
  std::string out_;
  std::filesystem::path dir_;
  std::optional<FolderLock> lock_;
};

// Removes the files an earlier run wrote in the folder, so that a shorter
// run does not leave stale snapshots behind.
void clear_previous(const std::filesystem::path& dir);

// Where a run starts: step 0, or the checkpoint it resumes from.
struct ResumePoint {
  bool resumed = false;
  std::int64_t step = 0;                    // the checkpoint's step; 0 for a fresh run
  std::vector<std::string> series_columns;  // of series.csv, cut back to the checkpoint
  std::vector<std::string> timing_columns;  // of timings.csv, likewise
  bool legacy_timings = false;              // timings in series.csv (a run begun before timings.csv)
  RunTotals totals;                         // the run's cost so far (summary.toml)
};

// Resumes from the folder's checkpoint unless `fresh` or there is none: the
// engine's state replaced by it, series.csv and timings.csv cut back to its
// step. A checkpoint of another scene (or dimension), or an unreadable
// one, throws CheckpointError saying how to start over, before anything is
// written.
ResumePoint resume_from_checkpoint(RunEngine& e, const RunPlan& plan, const RunFolder& folder, bool fresh);

// The snapshots a resumed run wrote up to its checkpoint at step k0, known
// by their steps (the time is computed as the step does, steps * dt).
Frames snapshots_up_to(const RunPlan& plan, std::int64_t k0);

// When a step's outputs fall (RunPlan's intervals, in steps): a series row
// every every_row steps and at the scene's last step; a snapshot every
// every_snap; a checkpoint by simulated time or strain (on rows: the plan
// rounds them up to whole rows), on the first row after ckpt_wall seconds
// of wall clock since the last one (or since start), and at the session's
// end when checkpoints are on. A resumed run keeps its checkpoint current
// even with checkpoints off.
class OutputCadence {
 public:
  OutputCadence(const RunPlan& plan, bool resumed)
      : nsteps_(plan.nsteps), every_row_(plan.every_row), every_snap_(plan.every_snap),
        every_ckpt_(plan.every_ckpt), every_ckpt_strain_(plan.every_ckpt_strain), ckpt_wall_(plan.ckpt_wall),
        checkpoint_at_end_(plan.checkpoints() || resumed) {}

  bool row_due(std::int64_t k) const { return k % every_row_ == 0 || k == nsteps_; }
  // The series row a stop asked at step k waits for.
  std::int64_t next_row(std::int64_t k) const { return std::min(nsteps_, (k / every_row_ + 1) * every_row_); }
  bool snapshot_due(std::int64_t k) const { return every_snap_ && k % every_snap_ == 0; }
  // `ending`: the session ends at step k (the scene's last step, a stop,
  // or a settled compaction).
  bool checkpoint_due(std::int64_t k, bool ending, RunClock::time_point now) const {
    const bool wall_due = ckpt_wall_ > 0 && k % every_row_ == 0 &&
                          std::chrono::duration<double>(now - last_checkpoint_).count() >= ckpt_wall_;
    return (every_ckpt_ && k % every_ckpt_ == 0) || (every_ckpt_strain_ && k % every_ckpt_strain_ == 0) ||
           wall_due || (ending && checkpoint_at_end_);
  }
  // The wall clock counts from the session's start, then from each checkpoint.
  void start(RunClock::time_point t) { last_checkpoint_ = t; }
  void checkpoint_written(RunClock::time_point t) { last_checkpoint_ = t; }

 private:
  std::int64_t nsteps_, every_row_, every_snap_, every_ckpt_, every_ckpt_strain_;
  double ckpt_wall_;
  bool checkpoint_at_end_;
  RunClock::time_point last_checkpoint_{};
};

// The warnings (whole lines, "" if none) for a checkpoint interval, by
// simulated time or by strain, not shorter than the run: it writes no
// checkpoint before the end.
std::string long_interval_warnings(const RunPlan& plan);

// Step statistics over one series interval (the row's solver, overlap and
// work columns); t0: the stage timers at its start.
struct SeriesInterval {
  int steps = 0;
  long iter_sum = 0;
  int iter_max = 0;
  int cap_hits = 0;
  double res_max = 0, res_mean_sum = 0;
  double ov_max = 0, ov_small = 0;
  double corr_work = 0, proj_work = 0;
  StageTimes t0;

  void add(const StepStats& s);
};

// A series row at step k: the step's and the interval's columns, before
// the engine's protocol columns (RunEngine::add_columns). Asks the engine
// for its time and kinetic energy.
Columns series_row(std::int64_t k, RunEngine& e, const StepStats& st, const SeriesInterval& iv);
// A timings row: step, time, and each stage's wall-clock seconds over the
// interval (`now` less the timers at its start).
Columns timings_row(std::int64_t k, double time, const StageTimes& now, const StageTimes& t0);

// series.csv and timings.csv: made new for a fresh run, continued after a
// resume. Rows are written whole, the folder checked before each write.
class SeriesFiles {
 public:
  // Takes the resume's column names; a fresh run's files are made empty.
  void open(const RunFolder& folder, ResumePoint& from);
  // A run begun before timings.csv existed: the timings go on in series.csv.
  bool legacy_timings() const { return !timings_; }
  void write_series(const Columns& row, const RunFolder& folder);
  void write_timings(const Columns& row, const RunFolder& folder);  // nothing if legacy

 private:
  std::optional<Series> series_, timings_;
};

// The signal that asked the run to stop (SIGINT, SIGTERM or SIGHUP, caught
// since install_stop_handlers), 0 if none: set once, by the first of them.
int stop_signal();

// What the run says when it first sees a signal's stop: that the stop waits
// for the next series row (rows are whole intervals, and a checkpoint there
// resumes to the same series), unless one falls at this very step.
class StopNotice {
 public:
  // The line to print ("" if none) at a step where `signal` is set; `row`
  // is the row the stop waits for, `after_progress` whether a progress line
  // is on the terminal (the notice then starts a line of its own).
  std::string seen(int signal, bool row_due, std::int64_t row, bool after_progress);

 private:
  bool announced_ = false;
};

// The --dump-problem steps: each step's contact problem is written into the
// folder by the engine (before its solve, and after it its impulses).
class ProblemDumps {
 public:
  // Throws std::invalid_argument for a step past the run's last, nsteps: a
  // dump the run never reaches would be silently missing.
  ProblemDumps(const std::vector<std::int64_t>& steps, std::int64_t nsteps);
  bool at(std::int64_t k) const { return std::find(steps_.begin(), steps_.end(), k) != steps_.end(); }
  // A dump file that could not be written (a WriteError from the engine's
  // step or after_step): that failure, naming the option and the step
  // (cdsim exits 4).
  static WriteError failed(std::int64_t k, const WriteError& e);

 private:
  std::vector<std::int64_t> steps_;
};

// The cost record of a session: its statistics (RunSummary, cdsim's closing
// lines) and the run's totals over every session (summary.toml), counted
// step by step, with the session's wall and CPU time.
class CostRecord {
 public:
  // The session starts at `t`: its CPU clock and the machine's load are
  // read now. `so_far`: the run's totals at the checkpoint it resumes from
  // (zero for a fresh run).
  void start(const RunTotals& so_far, RunClock::time_point t);
  // A session that takes steps is one more of the run's.
  void count_session() { totals_.sessions += 1; }
  void add(const StepStats& st);
  // The totals as they stand now: the wall and CPU time of this session added.
  RunTotals totals_now() const;
  // The session's closing figures: it took steps k0+1 .. k_end of nsteps.
  void end_session(std::int64_t k0, std::int64_t k_end, std::int64_t nsteps);
  RunSummary& summary() { return sum_; }
  // summary.toml, at the end of the session however it ends; `last` is the
  // last step taken (counted).
  void write_summary(const char* status, std::int64_t last, std::int64_t nsteps, const RunFolder& folder);

 private:
  RunSummary sum_;
  RunTotals totals_;
  RunClock::time_point start_{};
  double cpu0_ = 0;
  long iterations_ = 0;  // the session's sweeps, for its mean
};

// How a session ended, as summary.toml's status says (a divergence aside).
const char* session_status(const RunSummary& s);

// The progress of a session: on a terminal (unless quiet), a line on stderr
// rewritten every half second; with --progress, a whole line on stdout
// every so many seconds of wall clock, quiet or not, terminal or log.
class ProgressLines {
 public:
  ProgressLines(const RunOptions& opt, std::int64_t nsteps);
  bool on_terminal() const { return terminal_; }
  // The session runs steps k0+1 .. nsteps from `t`.
  void start(std::int64_t k0, RunClock::time_point t);
  void after_step(std::int64_t k, const StepStats& st);
  // Ends the terminal's line.
  void end() const;

 private:
  std::string out_;
  double every_;  // s between the stdout lines; 0: none
  bool terminal_;
  std::int64_t nsteps_, k0_ = 0;
  RunClock::time_point start_{}, last_terminal_{}, last_line_{};
};

}  // namespace cd
