#include "run_loop.hpp"

#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <ctime>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "files.hpp"
#include "load.hpp"
#include "run_session_parts.hpp"
#include "version.hpp"

namespace cd {

namespace {

using Clock = std::chrono::steady_clock;

// A TOML float: shortest text that reads back exactly, with a '.' or exponent.
std::string toml_float(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::string t = fmt::format("{}", x);
  if (t.find_first_of(".e") == std::string::npos) t += ".0";
  return t;
}

}  // namespace

std::string summary_toml(const RunSummary& s) {
  const RunTotals& t = s.totals;
  const auto load = [](const std::vector<double>& l) {
    std::string o = "[";
    for (std::size_t i = 0; i < l.size(); ++i) o += (i ? ", " : "") + toml_float(l[i]);
    return o + "]";
  };
  const auto line = [](const std::string& kv, const char* doc) {
    return fmt::format("{:<32} # {}\n", kv, doc);
  };
  std::string o =
      "# The cost of this run, over every session (cdsim call) that ran it: docs/outputs.md\n";
  o += line(fmt::format("cdlab_version = \"{}\"", version()), "git describe of the build; \"unknown\" outside a clone");
  o += line(fmt::format("status = \"{}\"", s.status), "done, settled (shear.settle_*), stopped (signal), max-steps, diverged");
  o += line(fmt::format("steps = {}", s.last_step), "the last step taken (series.csv's last row)");
  o += line(fmt::format("total_steps = {}", s.total_steps), "the scene's steps");
  o += line(fmt::format("sessions = {}", std::llround(t.sessions)), "cdsim calls that took steps (1 + resumes)");
  o += line("wall_time = " + toml_float(t.wall), "s, in the run loop, summed over sessions up to the last checkpoint or the end");
  o += line("cpu_time = " + toml_float(t.cpu), "s, user + system of every thread, likewise");
  o += line(fmt::format("threads = {}", s.threads), "OpenMP threads of the last session");
  o += line("load_start = " + load(s.load_start), "/proc/loadavg (1, 5, 15 min) when the last session started");
  o += line("load_end = " + load(s.load_end), "and when it ended");
  o += line("sweeps_mean = " + toml_float(s.last_step ? t.sweeps / double(s.last_step) : 0.0), "NLGS sweeps per step, mean over the steps");
  o += line(fmt::format("sweeps_max = {}", std::llround(t.sweeps_max)), "most sweeps of one step");
  // The accelerations' cost (0 when off). A CG iteration of the subspace
  // correction is one product W p through the bodies of the closed rows,
  // about half a sweep's cost (docs/accuracy.md): sweeps_mean leaves it out.
  o += line(fmt::format("cg_iterations = {}", std::llround(t.cg_iterations)),
            "CG iterations of the subspace corrections (solver.subspace), all steps");
  o += line("cg_iterations_mean = " + toml_float(s.last_step ? t.cg_iterations / double(s.last_step) : 0.0),
            "per step, mean over the steps; one costs about half a sweep");
  o += line(fmt::format("anderson_off_steps = {}", std::llround(t.anderson_off_steps)),
            "steps whose Anderson mixing (solver.anderson) stalled and went off");
  o += line(fmt::format("subspace_off_steps = {}", std::llround(t.subspace_off_steps)),
            "steps whose subspace corrections stalled and stopped");
  o += line(fmt::format("cap_steps = {}", std::llround(t.cap_steps)), "steps stopped at solver.max_iter");
  o += line("cap_share = " + toml_float(s.cap_share()), "cap_steps / steps");
  o += line("residual_final = " + toml_float(t.residual_last), "law residual of the last step");
  o += line("residual_max = " + toml_float(t.residual_max), "largest law residual of any step");
  o += line("overlap_max = " + toml_float(t.overlap_max), "largest overlap, in mean diameters");
  o += line(fmt::format("floor_steps = {}", std::llround(t.floor_steps)),
            "steps on which the cell's compaction was held at its floor (a quarter of contact.alert a "
            "step): the imposed pressure was not fully applied on them");
  return o;
}


RunSummary run_loop(RunEngine& w, const RunPlan& plan, const RunOptions& opt) {
  const std::int64_t nsteps = plan.nsteps;
  const std::int64_t every_snap = plan.every_snap;
  const bool checkpoints = plan.checkpoints();

  const std::uint64_t key = plan.key;
  const ProblemDumps dumps(opt.dump_steps, nsteps);
  RunFolder folder(opt.out);
  folder.lock_if_present();
  const auto still_ours = [&] { folder.check(); };
  ResumePoint from = resume_from_checkpoint(w, plan, folder, opt.fresh);
  const bool resume = from.resumed;
  const bool legacy = from.legacy_timings;
  const std::string ckpt = folder.checkpoint();
  const std::string series_path = folder.series(), timings_path = folder.timings();
  const std::int64_t k0 = from.step;
  // The compaction's stop rule; a resumed run reads its rows back, and one
  // that had settled at its checkpoint takes no more steps.
  SettleRule settle = plan.settle;
  if (resume) settle.resume(series_path);
  const std::int64_t k_last = resume && settle.settled() ? k0 : nsteps;
  w.start();

  std::fputs(long_interval_warnings(plan).c_str(), stderr);

  folder.make();
  if (!resume) clear_previous(opt.out);
  write_file_atomic(folder.file("scene.toml"), opt.scene_toml);
  Frames frames = resume ? snapshots_up_to(plan, k0) : Frames{};
  Series series = resume ? Series(series_path, std::move(from.series_columns)) : Series(series_path);
  std::optional<Series> timings;
  if (!legacy)
    timings.emplace(resume ? Series(timings_path, std::move(from.timing_columns)) : Series(timings_path));
  if (every_snap) w.open_snapshots(opt.out, std::move(frames));

  SeriesInterval iv;
  iv.t0 = w.times();  // restored on resume
  const auto start = Clock::now();
  CostRecord cost(from.totals, start);
  RunSummary& sum = cost.summary();
  ProgressLines progress(opt, nsteps, k0, start);
  OutputCadence cadence(plan, resume);
  cadence.start(start);
  if (k0 < k_last) cost.count_session();
  const auto write_summary = [&](const char* status, std::int64_t last) {
    cost.write_summary(status, last, nsteps, folder);
  };
  // A diverged run still says what it cost, up to `last`, the last step
  // counted; a failure to write that does not hide the divergence.
  const auto diverged = [&](std::int64_t last, const std::string& msg) {
    try {
      write_summary("diverged", last);
    } catch (const std::exception&) {
    }
    return RunDiverged(msg);
  };

  auto timed_output = [&](auto&& f) {
    const auto t = Clock::now();
    f();
    w.times()[Stage::Output] += std::chrono::duration<double>(Clock::now() - t).count();
  };
  if (every_snap && !resume) timed_output([&] {
    still_ours();
    w.write_snapshot();
  });

  std::int64_t k_end = k_last;  // the last step taken (earlier if stopped by a signal or settled)
  StopNotice stop_notice;
  bool settled = k_last < nsteps;
  for (std::int64_t k = k0 + 1; k <= k_last; ++k) {
    if (dumps.at(k)) still_ours();  // the step writes its problem before its solve
    try {
      w.step();
    } catch (const FolderGone&) {
      throw;
    } catch (const WriteError& e) {
      // Inside a step, only --dump-problem writes (its hook, before the
      // solve): a write that failed, not a state that went bad.
      throw ProblemDumps::failed(k, e);
    } catch (const std::runtime_error& e) {
      // A step that cannot go on (e.g. a periodic cell shrunk below what
      // detection needs): the run stops as a diverged one, its outputs kept.
      throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): {}; series.csv holds the rows before it",
                                    k, w.time(), e.what()));
    }
    const StepStats& st = w.last();
    if (const std::string bad = w.non_finite(); !bad.empty())
      throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): non-finite state: {}; series.csv "
                                    "holds the rows before it{}", k, w.time(), bad,
                                    checkpoints ? ", checkpoint.bin (if written) the last good state" : ""));
    // The step's statistics go into the run's totals (summary.toml, which
    // must never hold inf or nan): a non-finite one is a divergence, caught
    // before it is counted.
    for (const auto& [name, x] : {std::pair{"law residual", st.solve.residual_max},
                                  std::pair{"mean law residual", st.solve.residual_mean},
                                  std::pair{"largest overlap", st.max_overlap},
                                  std::pair{"largest overlap of the smaller grain", st.max_overlap_small}})
      if (!std::isfinite(x))
        throw diverged(k - 1, fmt::format("step {} (t = {:.6g} s): the step's {} is {}; series.csv holds the "
                                          "rows before it", k, w.time(), name, x));
    // A signal's stop waits for the next series row: rows are whole
    // intervals, and a checkpoint there resumes to the same series.
    const bool row_due = cadence.row_due(k);
    if (const int sig = stop_signal(); sig != 0)
      std::fputs(stop_notice.seen(sig, row_due, cadence.next_row(k), progress.on_terminal()).c_str(), stderr);
    // --max-steps stops after exactly N steps (to try a scene), with a row
    // for the partial interval there.
    const bool at_limit = opt.max_steps > 0 && k - k0 >= opt.max_steps && k < nsteps;
    const bool stopping = (stop_signal() != 0 && row_due && k < nsteps) || at_limit;
    if (stopping) k_end = k;
    if (dumps.at(k)) still_ours();
    try {
      w.after_step(k);  // writes the rest of a --dump-problem step
    } catch (const FolderGone&) {
      throw;
    } catch (const WriteError& e) {
      throw ProblemDumps::failed(k, e);
    }
    iv.add(st);
    cost.add(st);

    if (row_due || stopping) {
      timed_output([&] {
        const StageTimes& t = w.times();
        Columns cols = {{"step", double(k)},
                    {"time", w.time()},
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
                    {"kinetic_energy", w.kinetic_energy()},
                    {"correction_work", iv.corr_work},
                    {"projection_work", iv.proj_work}};
        Columns tcols = {{"step", double(k)}, {"time", w.time()}};
        for (int s = 0; s < kStages; ++s)
          tcols.emplace_back(std::string("t_") + kStageNames[s], t.t[s] - iv.t0.t[s]);
        if (legacy) cols.insert(cols.end(), tcols.begin() + 2, tcols.end());
        w.add_columns(cols);
        for (const auto& [name, x] : cols)
          if (!std::isfinite(x))
            throw diverged(k, fmt::format("step {} (t = {:.6g} s): series column {} is {}; "
                                          "series.csv holds the rows before it", k, w.time(), name, x));
        series.row(cols);
        still_ours();
        series.flush();
        settle.add(cols);
        if (timings) {
          timings->row(tcols);
          still_ours();
          timings->flush();
        }
      });
      iv = SeriesInterval{};
      iv.t0 = w.times();
      if (settle.settled() && k < nsteps) {
        settled = true;
        k_end = k;
      }
    }
    if (cadence.snapshot_due(k)) timed_output([&] {
      still_ours();
      w.write_snapshot();
    });
    // After this step's outputs, so that a restart has them all.
    if (cadence.checkpoint_due(k, k == nsteps || stopping || settled, Clock::now())) {
      timed_output([&] {
        still_ours();
        w.save(ckpt, key, cost.totals_now());
      });
      cadence.checkpoint_written(Clock::now());
    }
    if (stopping) {
      sum.stop_signal = stop_signal();
      sum.stopped_at_max_steps = at_limit && !stop_signal();
      break;
    }
    if (settled) break;

    progress.after_step(k, st);
  }
  progress.end();
  cost.end_session(k0, k_end, nsteps);
  sum.kinetic_energy = w.kinetic_energy();
  sum.settled = settled;
  sum.settle_on = settle.on();
  sum.settle_stress_dev = settle.stress_dev();
  sum.settle_phi_range = settle.phi_range();
  write_summary(sum.stop_signal              ? "stopped"
                : sum.stopped_at_max_steps ? "max-steps"
                : settled                  ? "settled"
                                           : "done",
                k_end);
  return sum;
}

}  // namespace cd
