// A run session: one call of run_loop (run_loop.hpp), from the output
// folder's lock and the resume to summary.toml, as named steps over the
// parts of run_session_parts.hpp. A session opens (lock, resume, outputs,
// clocks), advances step by step (the engine's step, the watchdog, a
// stop, rows, snapshots, checkpoints) and closes (the cost record).
#pragma once
#include <cstdint>
#include <string>

#include "run_loop.hpp"
#include "run_plan.hpp"
#include "run_session_parts.hpp"
#include "settle.hpp"

namespace cd {

class RunSession {
 public:
  // Checks the --dump-problem steps, locks an existing folder and resumes
  // from its checkpoint (run_loop.hpp says when): of the outputs, only
  // series.csv and timings.csv are touched yet, cut back to the checkpoint.
  RunSession(RunEngine& e, const RunPlan& plan, const RunOptions& opt);
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  RunSummary run();

 private:
  void open();
  void open_outputs();
  // Step k and its outputs; false when the session ends at it.
  bool advance(std::int64_t k);
  void step_engine(std::int64_t k);
  // The watchdog (run_loop.hpp, RunDiverged): throws if step k left a bad state.
  void check_state(std::int64_t k, const StepStats& st);
  void after_step(std::int64_t k);
  void write_row(std::int64_t k, const StepStats& st);
  void write_snapshot();
  void write_checkpoint();
  RunSummary close();
  // summary.toml as the session ends at step `last`.
  void write_summary(const char* status, std::int64_t last);
  // A diverged run still says what it cost, up to `last`, the last step
  // counted; a failure to write that does not hide the divergence.
  RunDiverged diverged(std::int64_t last, const std::string& msg);
  // Runs an output write, timed as the Output stage.
  template <class Write>
  void timed_output(Write&& write);

  RunEngine& e_;
  const RunPlan& plan_;
  const RunOptions& opt_;
  // Initialised in this order: the dumps are checked before the folder is
  // locked, and the folder locked before the checkpoint is read.
  const ProblemDumps dumps_;
  RunFolder folder_;
  ResumePoint from_;
  SettleRule settle_;     // the compaction's stop rule, its rows read back on resume
  std::int64_t k0_;       // the first step is k0 + 1
  std::int64_t k_last_;   // the last step this session may take
  std::int64_t k_end_;    // the last step taken (earlier if stopped or settled)
  bool settled_;
  OutputCadence cadence_;
  SeriesFiles series_;
  SeriesInterval interval_;
  StopNotice stop_notice_;
  CostRecord cost_;
  ProgressLines progress_;
};

}  // namespace cd
