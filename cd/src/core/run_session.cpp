#include "run_session.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "files.hpp"

namespace cd {

namespace {

// The watchdog's finite limit: a contact whose overlap reaches half the
// smaller grain's diameter (StepStats::max_overlap_small) is no rigid (or
// stiff) contact any more but a state gone bad that stays finite (a
// solve that took an impulse from a singular system, a step far too long
// for the grains' speeds); the run stops as diverged rather than going on
// to numbers that look like results. A run warns of overlaps from 0.01 of
// that diameter on (cdsim's closing warning), fifty times below this limit.
constexpr double kDivergedOverlap = 0.5;

// A resumed run reads its rows back, so that it stops where the run never
// stopped does, and one that had settled at its checkpoint takes no more
// steps.
SettleRule settle_rule(const RunPlan& plan, const ResumePoint& from, const RunFolder& folder) {
  SettleRule rule = plan.settle;
  if (from.resumed) rule.resume(folder.series());
  return rule;
}

}  // namespace

RunSession::RunSession(RunEngine& e, const RunPlan& plan, const RunOptions& opt)
    : e_(e),
      plan_(plan),
      opt_(opt),
      dumps_(opt.dump_steps, plan.nsteps),
      folder_(opt.out),
      from_(resume_from_checkpoint(e, plan, folder_, opt.fresh)),
      settle_(settle_rule(plan, from_, folder_)),
      k0_(from_.step),
      k_last_(from_.resumed && settle_.settled() ? k0_ : plan.nsteps),
      k_end_(k_last_),
      settled_(k_last_ < plan.nsteps),
      cadence_(plan, from_.resumed),
      progress_(opt, plan.nsteps) {}

template <class Write>
void RunSession::timed_output(Write&& write) {
  const auto t = RunClock::now();
  write();
  e_.times()[Stage::Output] += std::chrono::duration<double>(RunClock::now() - t).count();
}

RunSummary RunSession::run() {
  open();
  for (std::int64_t k = k0_ + 1; k <= k_last_; ++k)
    if (!advance(k)) break;
  return close();
}

void RunSession::open() {
  e_.start();
  std::fputs(long_interval_warnings(plan_).c_str(), stderr);
  open_outputs();
  // Said when it happens and flushed, so that a log has it even if the
  // resumed run is killed before it ends.
  if (from_.resumed) {
    std::printf("cdsim: resumed from %s/checkpoint.bin at step %lld of %lld\n", opt_.out.c_str(),
                static_cast<long long>(k0_), static_cast<long long>(plan_.nsteps));
    std::fflush(stdout);
  }
  interval_.t0 = e_.times();  // restored on resume
  // The session's cost counts the steps and their outputs, not the setup
  // before them (summary.toml: "in the run loop").
  const auto start = RunClock::now();
  cost_.start(from_.totals, start);
  progress_.start(k0_, start);
  cadence_.start(start);
  if (k0_ < k_last_) cost_.count_session();
  if (plan_.every_snap && !from_.resumed) write_snapshot();
}

void RunSession::open_outputs() {
  folder_.make();
  if (!from_.resumed) clear_previous(opt_.out);
  write_file_atomic(folder_.file("scene.toml"), opt_.scene_toml);
  Frames frames = from_.resumed ? snapshots_up_to(plan_, k0_) : Frames{};
  series_.open(folder_, from_);
  if (plan_.every_snap) e_.open_snapshots(opt_.out, std::move(frames));
}

bool RunSession::advance(std::int64_t k) {
  step_engine(k);
  const StepStats& st = e_.last();
  check_state(k, st);
  const bool row_due = cadence_.row_due(k);
  if (const int sig = stop_signal(); sig != 0)
    std::fputs(stop_notice_.seen(sig, row_due, cadence_.next_row(k), progress_.on_terminal()).c_str(), stderr);
  // --max-steps stops after exactly N steps (to try a scene), with a row
  // for the partial interval there.
  const bool at_limit = opt_.max_steps > 0 && k - k0_ >= opt_.max_steps && k < plan_.nsteps;
  // A signal's stop waits for a series row (StopNotice says why).
  const bool stopping = (stop_signal() != 0 && row_due && k < plan_.nsteps) || at_limit;
  if (stopping) k_end_ = k;
  after_step(k);
  interval_.add(st);
  cost_.add(st);
  if (row_due || stopping) write_row(k, st);
  if (cadence_.snapshot_due(k)) write_snapshot();
  // After this step's outputs, so that a restart has them all.
  if (cadence_.checkpoint_due(k, k == plan_.nsteps || stopping || settled_, RunClock::now())) write_checkpoint();
  if (stopping) {
    RunSummary& s = cost_.summary();
    s.stop_signal = stop_signal();
    s.stopped_at_max_steps = at_limit && !stop_signal();
    return false;
  }
  if (settled_) return false;
  progress_.after_step(k, st);
  return true;
}

void RunSession::step_engine(std::int64_t k) {
  if (dumps_.at(k)) folder_.check();  // the step writes its problem before its solve
  try {
    e_.step();
  } catch (const FolderGone&) {
    throw;
  } catch (const WriteError& e) {
    // Inside a step, only --dump-problem writes (its hook, before the
    // solve): a write that failed, not a state that went bad.
    throw ProblemDumps::failed(k, e);
  } catch (const std::runtime_error& e) {
    // A step that cannot go on (e.g. a periodic cell shrunk below what
    // detection needs): the run stops as a diverged one, its outputs kept.
    throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): {}; series.csv holds the rows before it", k,
                                      e_.time(), e.what()));
  }
}

void RunSession::check_state(std::int64_t k, const StepStats& st) {
  if (const std::string bad = e_.non_finite(); !bad.empty())
    throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): non-finite state: {}; series.csv "
                                      "holds the rows before it{}", k, e_.time(), bad,
                                      plan_.checkpoints() ? ", checkpoint.bin (if written) the last good state" : ""));
  // The step's statistics go into the run's totals (summary.toml, which
  // must never hold inf or nan): a non-finite one is a divergence, caught
  // before it is counted.
  for (const auto& [name, x] : {std::pair{"law residual", st.solve.residual_max},
                                std::pair{"mean law residual", st.solve.residual_mean},
                                std::pair{"largest overlap", st.max_overlap},
                                std::pair{"largest overlap of the smaller grain", st.max_overlap_small}})
    if (!std::isfinite(x))
      throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): the step's {} is {}; series.csv holds the "
                                        "rows before it", k, e_.time(), name, x));
  if (st.max_overlap_small >= kDivergedOverlap)
    throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): two grains overlap by {:.3g} of the smaller one's "
                                      "diameter, past the limit of {} (a time step too long for the grains' "
                                      "speeds, or a solve gone wrong); series.csv holds the rows before it{}", k, e_.time(), st.max_overlap_small, kDivergedOverlap,
                                      plan_.checkpoints() ? ", checkpoint.bin (if written) the last good state" : ""));
}

void RunSession::after_step(std::int64_t k) {
  if (dumps_.at(k)) folder_.check();
  try {
    e_.after_step(k);  // writes the rest of a --dump-problem step
  } catch (const FolderGone&) {
    throw;
  } catch (const WriteError& e) {
    throw ProblemDumps::failed(k, e);
  }
}

void RunSession::write_row(std::int64_t k, const StepStats& st) {
  timed_output([&] {
    Columns cols = series_row(k, e_, st, interval_);
    const Columns tcols = timings_row(k, e_.time(), e_.times(), interval_.t0);
    if (series_.legacy_timings()) cols.insert(cols.end(), tcols.begin() + 2, tcols.end());
    e_.add_columns(cols);
    for (const auto& [name, x] : cols)
      if (!std::isfinite(x))
        throw diverged(k, fmt::format("step {} (t = {:.6g} s): series column {} is {}; "
                                      "series.csv holds the rows before it", k, e_.time(), name, x));
    series_.write_series(cols, folder_);
    settle_.add(cols);
    series_.write_timings(tcols, folder_);
  });
  interval_ = SeriesInterval{};
  interval_.t0 = e_.times();
  if (settle_.settled() && k < plan_.nsteps) {
    settled_ = true;
    k_end_ = k;
  }
}

void RunSession::write_snapshot() {
  timed_output([&] {
    folder_.check();
    e_.write_snapshot();
  });
}

void RunSession::write_checkpoint() {
  timed_output([&] {
    folder_.check();
    e_.save(folder_.checkpoint(), plan_.key, cost_.totals_now());
  });
  cadence_.checkpoint_written(RunClock::now());
}

RunSummary RunSession::close() {
  progress_.end();
  cost_.end_session(k0_, k_end_, plan_.nsteps);
  RunSummary& s = cost_.summary();
  s.kinetic_energy = e_.kinetic_energy();
  s.settled = settled_;
  s.settle_on = settle_.on();
  s.settle_stress_dev = settle_.stress_dev();
  s.settle_phi_range = settle_.phi_range();
  write_summary(session_status(s), k_end_);
  return s;
}

void RunSession::write_summary(const char* status, std::int64_t last) {
  cost_.write_summary(status, last, plan_.nsteps, folder_);
}

RunDiverged RunSession::diverged(std::int64_t last, const std::string& msg) {
  try {
    write_summary("diverged", last);
  } catch (const std::exception&) {
  }
  return RunDiverged(msg);
}

}  // namespace cd
