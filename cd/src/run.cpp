#include "run.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "output.hpp"

namespace cd {

namespace {

using Clock = std::chrono::steady_clock;

// Removes the files an earlier run wrote in the folder, so that a shorter
// run does not leave stale snapshots behind.
void clear_previous(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) return;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string f = e.path().filename().string();
    const bool ours = f == "series.csv" || f == "scene.toml" || e.path().extension() == ".pvd" ||
                      f.starts_with("checkpoint.bin") ||
                      (e.path().extension() == ".vtp" &&
                       (f.starts_with("particles_") || f.starts_with("contacts_") ||
                        f.starts_with("walls_") || f.starts_with("shapes_")));
    if (ours) fs::remove(e.path());
  }
}

// Accumulates step statistics over one series interval.
struct Interval {
  int steps = 0;
  long iter_sum = 0;
  int iter_max = 0;
  int cap_hits = 0;
  double res_max = 0, res_mean_sum = 0;
  double ov_max = 0;
  double corr_work = 0;
  StageTimes t0;

  void add(const StepStats& s) {
    ++steps;
    iter_sum += s.solve.iterations;
    iter_max = std::max(iter_max, s.solve.iterations);
    cap_hits += s.solve.cap_hit;
    res_max = std::max(res_max, s.solve.residual_max);
    res_mean_sum += s.solve.residual_mean;
    ov_max = std::max(ov_max, s.max_overlap);
    corr_work += s.correction_work;
  }
};

}  // namespace

RunSummary run(World& w, const Scene& s, const RunOptions& opt) {
  namespace fs = std::filesystem;
  const fs::path dir(opt.out);
  const std::string ckpt = (dir / "checkpoint.bin").string();
  const std::string series_path = (dir / "series.csv").string();
  const double dt = w.params().dt;
  const std::int64_t nsteps = std::llround(s.duration / dt);
  const std::int64_t every_row = std::max<std::int64_t>(1, std::llround(s.series_interval / dt));
  const std::int64_t every_snap =
      s.snapshot_interval > 0 ? std::max<std::int64_t>(1, std::llround(s.snapshot_interval / dt))
                              : 0;
  // Checkpoints fall on series rows, so that no row's interval spans a restart.
  const std::int64_t every_ckpt =
      s.checkpoint_interval > 0
          ? every_row * std::max<std::int64_t>(
                            1, (std::llround(s.checkpoint_interval / dt) + every_row - 1) / every_row)
          : 0;
  const bool progress = !opt.quiet && isatty(STDERR_FILENO);

  // Resume from a checkpoint of this scene; checked before anything is written.
  const std::uint64_t key = scene_key(s);
  const bool resume = !opt.fresh && fs::exists(ckpt);
  std::vector<std::string> columns;  // of series.csv, cut back to the checkpoint
  if (resume) {
    try {
      if (load_checkpoint(ckpt, w) != key || w.steps > nsteps)
        throw CheckpointError(fmt::format("checkpoint '{}' was written by a different scene "
                                          "(compare with {})", ckpt, (dir / "scene.toml").string()));
      columns = truncate_series(series_path, w.steps);
    } catch (const CheckpointError& e) {
      throw CheckpointError(std::string(e.what()) +
                            "; run with --fresh to discard the checkpoint and start over");
    }
  }
  const std::int64_t k0 = resume ? w.steps : 0;

  fs::create_directories(opt.out);
  if (!resume) clear_previous(opt.out);
  write_file_atomic((dir / "scene.toml").string(), opt.scene_toml);
  // On resume, the snapshots up to the checkpoint are known by their steps
  // (the time is computed as World::step does, steps * dt).
  std::vector<std::pair<double, std::string>> frames;
  for (std::int64_t j = 0; resume && every_snap && j * every_snap <= k0; ++j)
    frames.emplace_back(static_cast<double>(j * every_snap) * dt, fmt::format("{:05d}", j));
  Series series = resume ? Series(series_path, std::move(columns)) : Series(series_path);
  Snapshots snaps = resume ? Snapshots(opt.out, std::move(frames)) : Snapshots(opt.out);

  RunSummary sum;
  Interval iv;
  iv.t0 = w.times;  // restored on resume
  const auto start = Clock::now();
  auto last_print = start;
  long iter_total = 0;

  auto timed_output = [&](auto&& f) {
    const auto t = Clock::now();
    f();
    w.times.output += std::chrono::duration<double>(Clock::now() - t).count();
  };
  if (every_snap && !resume) timed_output([&] { snaps.write(w); });

  for (std::int64_t k = k0 + 1; k <= nsteps; ++k) {
    w.step();
    const StepStats& st = w.last();
    iv.add(st);
    iter_total += st.solve.iterations;
    sum.max_iterations = std::max(sum.max_iterations, st.solve.iterations);
    sum.cap_hits += st.solve.cap_hit;
    sum.max_residual = std::max(sum.max_residual, st.solve.residual_max);
    sum.max_overlap = std::max(sum.max_overlap, st.max_overlap);

    if (k % every_row == 0 || k == nsteps) {
      timed_output([&] {
        const StageTimes& t = w.times;
        series.row({{"step", double(k)},
                    {"time", w.time},
                    {"contacts", double(st.contacts)},
                    {"active", double(st.active)},
                    {"iterations", double(iv.iter_sum) / iv.steps},
                    {"iterations_max", double(iv.iter_max)},
                    {"residual", iv.res_max},
                    {"residual_mean", iv.res_mean_sum / iv.steps},
                    {"cap_hit", double(iv.cap_hits)},
                    {"max_overlap", iv.ov_max},
                    {"mean_overlap", st.mean_overlap},
                    {"kinetic_energy", w.kinetic_energy()},
                    {"correction_work", iv.corr_work},
                    {"t_detect", t.detect - iv.t0.detect},
                    {"t_solve", t.solve - iv.t0.solve},
                    {"t_integrate", t.integrate - iv.t0.integrate},
                    {"t_output", t.output - iv.t0.output}});
        series.flush();
      });
      iv = Interval{};
      iv.t0 = w.times;
    }
    if (every_snap && k % every_snap == 0) timed_output([&] { snaps.write(w); });
    // After this step's outputs, so that a restart has them all. A resumed
    // run keeps its checkpoint current even with checkpoints off.
    if ((every_ckpt && k % every_ckpt == 0) || (k == nsteps && (every_ckpt || resume)))
      timed_output([&] { save_checkpoint(ckpt, w, key); });

    if (progress) {
      const auto now = Clock::now();
      if (now - last_print > std::chrono::milliseconds(500) || k == nsteps) {
        last_print = now;
        const double el = std::chrono::duration<double>(now - start).count();
        const double eta = el / (k - k0) * (nsteps - k);
        std::fprintf(stderr, "\r%5.1f%%  ETA %6.1fs  step %lld/%lld  contacts %d  iterations %d   ",
                     100.0 * k / nsteps, eta, static_cast<long long>(k),
                     static_cast<long long>(nsteps), st.contacts, st.solve.iterations);
        std::fflush(stderr);
      }
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  sum.first_step = k0;
  sum.steps = nsteps - k0;
  sum.mean_iterations = sum.steps ? double(iter_total) / sum.steps : 0.0;
  sum.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
  sum.kinetic_energy = w.kinetic_energy();
  return sum;
}

}  // namespace cd
