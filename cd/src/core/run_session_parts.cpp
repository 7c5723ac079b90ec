#include "run_session_parts.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

namespace cd {

void RunFolder::lock_if_present() {
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
                        f.starts_with("spheres_")));
    if (ours) fs::remove(e.path());
  }
}

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

namespace {

std::string long_interval_warning(const RunPlan& plan, std::int64_t every, const std::string& what) {
  if (!every || every < plan.nsteps) return "";
  return fmt::format("cdsim: warning: {} is {} steps (rounded up to whole series rows), not shorter than the "
                     "run's {}: it writes no checkpoint before the end{}\n",
                     what, every, plan.nsteps,
                     plan.ckpt_wall > 0 ? " (output.checkpoint_wall still does)" : ", so a kill loses the whole run");
}

}  // namespace

std::string long_interval_warnings(const RunPlan& plan) {
  return long_interval_warning(plan, plan.every_ckpt,
                               fmt::format("output.checkpoint_interval = {} s", plan.checkpoint_interval)) +
         long_interval_warning(plan, plan.every_ckpt_strain,
                               fmt::format("output.checkpoint_strain = {}", plan.checkpoint_strain));
}

}  // namespace cd
