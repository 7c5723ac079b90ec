#include "run_session_parts.hpp"

#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "load.hpp"

namespace cd {

namespace {

// CPU time of the process, user + system (s): every thread's.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The first SIGINT, SIGTERM or SIGHUP asks the run to stop at its next series
// row, where a checkpoint falls as it always does, so that the resumed run is
// the one never stopped; a second one of them, a second or more later, ends
// the process at once, as a kill would (the resume then starts from the last
// checkpoint). One within that second is the same request delivered twice:
// `timeout` signals the command and then its whole process group, and a
// shell's job control may do the same, so a single stop asked that way
// arrives twice within microseconds; before this rule it killed the run.
volatile std::sig_atomic_t g_stop = 0;
std::atomic<std::int64_t> g_stop_ns{0};  // CLOCK_MONOTONIC of the first signal
static_assert(std::atomic<std::int64_t>::is_always_lock_free);  // safe in a handler
constexpr std::int64_t kRepeatNs = 1'000'000'000;

std::int64_t monotonic_ns() {  // clock_gettime is async-signal-safe (POSIX)
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return std::int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

extern "C" void on_stop(int sig) {
  if (g_stop != 0) {
    if (monotonic_ns() - g_stop_ns.load() < kRepeatNs) return;  // the same request
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  g_stop_ns.store(monotonic_ns());
  g_stop = sig;
}

std::string long_interval_warning(const RunPlan& plan, std::int64_t every, const std::string& what) {
  if (!every || every < plan.nsteps) return "";
  return fmt::format("cdsim: warning: {} is {} steps (rounded up to whole series rows), not shorter than the "
                     "run's {}: it writes no checkpoint before the end{}\n",
                     what, every, plan.nsteps,
                     plan.ckpt_wall > 0 ? " (output.checkpoint_wall still does)" : ", so a kill loses the whole run");
}

}  // namespace

// The output folder

RunFolder::RunFolder(const std::string& out) : out_(out), dir_(out) {
  if (std::filesystem::is_directory(dir_)) lock_.emplace(out_);
}

void RunFolder::make() {
  std::filesystem::create_directories(out_);
  if (!lock_) lock_.emplace(out_);
  check();  // not removed (and made again above) since it was locked
}

void clear_previous(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) return;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string f = e.path().filename().string();
    const bool ours = f == "series.csv" || f == "timings.csv" || f == "scene.toml" || f == "view.py" ||
                      e.path().extension() == ".pvd" || f.starts_with("checkpoint.bin") ||
                      f.starts_with("problem_") || f.starts_with("summary.toml") ||
                      (e.path().extension() == ".vtp" &&
                       (f.starts_with("particles_") || f.starts_with("contacts_") ||
                        f.starts_with("walls_") || f.starts_with("shapes_") ||
                        f.starts_with("spheres_") || f.starts_with("polyhedra_")));
    if (ours) fs::remove(e.path());
  }
}

// The resume

ResumePoint resume_from_checkpoint(RunEngine& e, const RunPlan& plan, const RunFolder& folder, bool fresh) {
  ResumePoint r;
  const std::string ckpt = folder.checkpoint();
  if (fresh || !std::filesystem::exists(ckpt)) return r;
  r.resumed = true;
  const std::string scene_toml = folder.file("scene.toml");
  try {
    const std::uint64_t stored = e.load(ckpt, &r.totals);
    if ((stored != plan.key && !folder_scene_is(scene_toml, plan.key)) || e.steps() > plan.nsteps)
      throw CheckpointError(fmt::format("checkpoint '{}' was written by a different scene "
                                        "(compare with {})", ckpt, scene_toml));
    folder.check();
    r.series_columns = truncate_series(folder.series(), e.steps());
    // A run begun before timings.csv existed has the timings in its
    // series: it goes on so, to its end.
    r.legacy_timings = !std::filesystem::exists(folder.timings()) &&
                       std::any_of(r.series_columns.begin(), r.series_columns.end(),
                                   [](const std::string& c) { return c.starts_with("t_"); });
    if (!r.legacy_timings) r.timing_columns = truncate_series(folder.timings(), e.steps());
  } catch (const CheckpointError& err) {
    throw CheckpointError(std::string(err.what()) +
                          "; run with --fresh to discard the checkpoint and start over");
  }
  r.step = e.steps();
  return r;
}

Frames snapshots_up_to(const RunPlan& plan, std::int64_t k0) {
  Frames frames;
  for (std::int64_t j = 0; plan.every_snap && j * plan.every_snap <= k0; ++j)
    frames.emplace_back(static_cast<double>(j * plan.every_snap) * plan.dt, fmt::format("{:05d}", j));
  return frames;
}

// The cadence's warnings

std::string long_interval_warnings(const RunPlan& plan) {
  return long_interval_warning(plan, plan.every_ckpt,
                               fmt::format("output.checkpoint_interval = {} s", plan.checkpoint_interval)) +
         long_interval_warning(plan, plan.every_ckpt_strain,
                               fmt::format("output.checkpoint_strain = {}", plan.checkpoint_strain));
}

// Series rows

void SeriesInterval::add(const StepStats& s) {
  ++steps;
  iter_sum += s.solve.iterations;
  iter_max = std::max(iter_max, s.solve.iterations);
  cap_hits += s.solve.cap_hit;
  res_max = std::max(res_max, s.solve.residual_max);
  res_mean_sum += s.solve.residual_mean;
  ov_max = std::max(ov_max, s.max_overlap);
  ov_small = std::max(ov_small, s.max_overlap_small);
  corr_work += s.correction_work;
  proj_work += s.projection_work;
}

Columns series_row(std::int64_t k, RunEngine& e, const StepStats& st, const SeriesInterval& iv) {
  return {{"step", double(k)},
          {"time", e.time()},
          {"contacts", double(st.contacts)},
          {"active", double(st.active)},
          {"iterations", double(iv.iter_sum) / iv.steps},
          {"iterations_max", double(iv.iter_max)},
          {"residual", iv.res_max},
          {"residual_mean", iv.res_mean_sum / iv.steps},
          {"cap_hit", double(iv.cap_hits)},
          {"max_overlap", iv.ov_max},
          {"mean_overlap", st.mean_overlap},
          {"max_overlap_small", iv.ov_small},
          {"kinetic_energy", e.kinetic_energy()},
          {"correction_work", iv.corr_work},
          {"projection_work", iv.proj_work}};
}

Columns timings_row(std::int64_t k, double time, const StageTimes& now, const StageTimes& t0) {
  Columns cols = {{"step", double(k)}, {"time", time}};
  for (int s = 0; s < kStages; ++s) cols.emplace_back(std::string("t_") + kStageNames[s], now.t[s] - t0.t[s]);
  return cols;
}

void SeriesFiles::open(const RunFolder& folder, ResumePoint& from) {
  if (from.resumed) series_.emplace(folder.series(), std::move(from.series_columns));
  else series_.emplace(folder.series());
  if (from.legacy_timings) return;
  if (from.resumed) timings_.emplace(folder.timings(), std::move(from.timing_columns));
  else timings_.emplace(folder.timings());
}

void SeriesFiles::write_series(const Columns& row, const RunFolder& folder) {
  series_->row(row);
  folder.check();
  series_->flush();
}

void SeriesFiles::write_timings(const Columns& row, const RunFolder& folder) {
  if (!timings_) return;
  timings_->row(row);
  folder.check();
  timings_->flush();
}

// Signals

void install_stop_handlers() {
  std::signal(SIGINT, on_stop);
  std::signal(SIGTERM, on_stop);
  std::signal(SIGHUP, on_stop);
}

int stop_signal() { return g_stop; }

std::string StopNotice::seen(int signal, bool row_due, std::int64_t row, bool after_progress) {
  if (announced_) return "";
  announced_ = true;
  if (row_due) return "";
  return fmt::format("{}cdsim: signal {}: stopping at the next series row (step {}); a second signal stops at once\n",
                     after_progress ? "\n" : "", signal, row);
}

// Dumps

ProblemDumps::ProblemDumps(const std::vector<std::int64_t>& steps, std::int64_t nsteps) : steps_(steps) {
  for (const std::int64_t k : steps_)
    if (k > nsteps)
      throw std::invalid_argument(fmt::format("--dump-problem {}: the run's last step is {}", k, nsteps));
}

WriteError ProblemDumps::failed(std::int64_t k, const WriteError& e) {
  return WriteError(fmt::format("--dump-problem {}: {}", k, e.what()));
}

// The cost record

void CostRecord::start(const RunTotals& so_far, RunClock::time_point t) {
  totals_ = so_far;
  start_ = t;
  cpu0_ = cpu_seconds();
  sum_.load_start = load_average();
}

void CostRecord::add(const StepStats& st) {
  iterations_ += st.solve.iterations;
  sum_.max_iterations = std::max(sum_.max_iterations, st.solve.iterations);
  sum_.cap_hits += st.solve.cap_hit;
  sum_.anderson_off += st.solve.anderson_off > 0;
  sum_.cap_anderson_off += st.solve.cap_hit && st.solve.anderson_off > 0;
  sum_.subspace_off += st.solve.subspace_off > 0;
  sum_.subspace_iterations += st.solve.subspace_iterations;
  sum_.floor_steps += st.floor_held;
  sum_.max_residual = std::max(sum_.max_residual, st.solve.residual_max);
  sum_.max_overlap = std::max(sum_.max_overlap, st.max_overlap);
  sum_.max_overlap_small = std::max(sum_.max_overlap_small, st.max_overlap_small);
  totals_.sweeps += st.solve.iterations;
  totals_.sweeps_max = std::max(totals_.sweeps_max, double(st.solve.iterations));
  totals_.cap_steps += st.solve.cap_hit;
  totals_.residual_max = std::max(totals_.residual_max, st.solve.residual_max);
  totals_.residual_last = st.solve.residual_max;
  totals_.overlap_max = std::max(totals_.overlap_max, st.max_overlap);
  totals_.cg_iterations += st.solve.subspace_iterations;
  totals_.anderson_off_steps += st.solve.anderson_off > 0;
  totals_.subspace_off_steps += st.solve.subspace_off > 0;
  totals_.floor_steps += st.floor_held;
}

RunTotals CostRecord::totals_now() const {
  RunTotals t = totals_;
  t.wall += std::chrono::duration<double>(RunClock::now() - start_).count();
  t.cpu += cpu_seconds() - cpu0_;
  return t;
}

void CostRecord::end_session(std::int64_t k0, std::int64_t k_end, std::int64_t nsteps) {
  sum_.first_step = k0;
  sum_.steps = k_end - k0;
  sum_.total_steps = nsteps;
  sum_.mean_iterations = sum_.steps ? double(iterations_) / sum_.steps : 0.0;
  sum_.wall_time = std::chrono::duration<double>(RunClock::now() - start_).count();
}

void CostRecord::write_summary(const char* status, std::int64_t last, std::int64_t nsteps, const RunFolder& folder) {
  sum_.status = status;
  sum_.last_step = last;
  sum_.total_steps = nsteps;
  sum_.totals = totals_now();
  sum_.threads = omp_get_max_threads();
  sum_.load_end = load_average();
  folder.check();
  write_file_atomic(folder.file("summary.toml"), summary_toml(sum_));
}

const char* session_status(const RunSummary& s) {
  return s.stop_signal            ? "stopped"
         : s.stopped_at_max_steps ? "max-steps"
         : s.settled              ? "settled"
                                  : "done";
}

// Progress

ProgressLines::ProgressLines(const RunOptions& opt, std::int64_t nsteps)
    : out_(opt.out), every_(opt.progress_every), terminal_(!opt.quiet && isatty(STDERR_FILENO)), nsteps_(nsteps) {}

void ProgressLines::start(std::int64_t k0, RunClock::time_point t) {
  k0_ = k0;
  start_ = last_terminal_ = last_line_ = t;
}

void ProgressLines::after_step(std::int64_t k, const StepStats& st) {
  if (every_ > 0 && k < nsteps_) {
    const auto now = RunClock::now();
    if (now - last_line_ >= std::chrono::duration<double>(every_)) {
      last_line_ = now;
      const double el = std::chrono::duration<double>(now - start_).count();
      std::printf("cdsim: %s: %.1f %% (step %lld of %lld), %.0f s in this session, ETA %.0f s\n",
                  out_.c_str(), 100.0 * double(k) / double(nsteps_), static_cast<long long>(k),
                  static_cast<long long>(nsteps_), el, el / double(k - k0_) * double(nsteps_ - k));
      std::fflush(stdout);
    }
  }
  if (terminal_) {
    const auto now = RunClock::now();
    if (now - last_terminal_ > std::chrono::milliseconds(500) || k == nsteps_) {
      last_terminal_ = now;
      const double el = std::chrono::duration<double>(now - start_).count();
      const double eta = el / (k - k0_) * (nsteps_ - k);
      std::fprintf(stderr, "\r%5.1f%%  ETA %6.1fs  step %lld/%lld  contacts %d  iterations %d   ",
                   100.0 * k / nsteps_, eta, static_cast<long long>(k), static_cast<long long>(nsteps_),
                   st.contacts, st.solve.iterations);
      std::fflush(stderr);
    }
  }
}

void ProgressLines::end() const {
  if (terminal_) std::fprintf(stderr, "\n");
}

}  // namespace cd
