// A run never writes into a folder that is no longer the one it opened. Its
// files are written by path (series.csv and timings.csv reopened at each
// row, the others renamed into place), so a run stopping (SIGTERM) while
// its folder was removed and made again by a new run of the same --out
// appended its last row to the new run's series.csv, ahead of the new
// header. The run session checks the folder's identity (RunFolder::check,
// core/run_session_parts.hpp; FolderLock::check_unchanged, core/files.hpp)
// before each write and stops
// with FolderGone, writing nothing. Reproduced here without signals: an
// engine that stands in for a world swaps the folder from inside the run,
// just before the write under test.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

#include <fmt/format.h>

#include "cli_util.hpp"
#include "files.hpp"
#include "run_loop.hpp"

namespace fs = std::filesystem;

namespace {

// An engine without physics: steps of 1 ms that change nothing, a checkpoint
// and snapshots as small files written as the real ones are (atomically, by
// path), and a hook called at the end of each step and at each kinetic
// energy asked (the run loop asks at each series row and once at the end,
// for the session's line, just before summary.toml).
class Idle final : public cd::RunEngine {
 public:
  std::function<void(std::int64_t)> after_step_taken, energy_asked;

  void step() override {
    ++steps_;
    if (after_step_taken) after_step_taken(steps_);
  }
  const cd::StepStats& last() const override { return last_; }
  std::int64_t steps() const override { return steps_; }
  double time() const override { return 1e-3 * double(steps_); }
  cd::StageTimes& times() override { return times_; }
  double kinetic_energy() const override {
    if (energy_asked) energy_asked(steps_);
    return 0;
  }
  std::string non_finite() const override { return ""; }
  void save(const std::string& path, std::uint64_t, const cd::RunTotals&) const override {
    cd::write_file_atomic(path, fmt::format("step {}\n", steps_));
  }
  std::uint64_t load(const std::string& path, cd::RunTotals*) override {
    throw cd::CheckpointError("no checkpoint expected: " + path);
  }
  void open_snapshots(const std::string& dir, cd::Frames) override { dir_ = dir; }
  void write_snapshot() override {
    cd::write_file_atomic((fs::path(dir_) / fmt::format("snapshot_{}.txt", steps_)).string(), "frame\n");
  }

 private:
  std::int64_t steps_ = 0;
  cd::StepStats last_;
  cd::StageTimes times_;
  std::string dir_;
};

// Every file of a folder (name -> bytes); empty if the folder is gone.
std::map<std::string, std::string> files_of(const fs::path& d) {
  std::map<std::string, std::string> f;
  if (!fs::is_directory(d)) return f;
  for (const auto& e : fs::directory_iterator(d)) f[e.path().filename().string()] = cdtest::slurp(e.path());
  return f;
}

// What a new run of the same --out has written when the old one writes
// again: the folder made anew, its series.csv a header and nothing else.
void make_new_run_folder(const fs::path& d) {
  fs::create_directories(d);
  std::ofstream(d / "series.csv") << "step,time,new_run\n";
  std::ofstream(d / "timings.csv") << "step,time,t_new\n";
}

cd::RunPlan plan(std::int64_t steps, std::int64_t every_row, std::int64_t every_snap, std::int64_t every_ckpt) {
  cd::RunPlan p;
  p.nsteps = steps;
  p.dt = 1e-3;
  p.every_row = every_row;
  p.every_snap = every_snap;
  p.every_ckpt = every_ckpt;
  p.key = 1;
  return p;
}

struct Swap {
  const char* name;
  cd::RunPlan plan;
  // How the folder changes: removed and made again, moved away and made
  // again, or removed.
  enum { Replaced, Moved, Removed } how;
  // When: just after this step is taken, or when the kinetic energy is
  // asked for the n-th time (energy > 0).
  std::int64_t step = 0;
  int energy = 0;
};

// The swap lands before a series row, before a snapshot (no row due), before
// a checkpoint (no row due: the snapshot-free plan writes one alone at step
// 4), and, after the last row and checkpoint, before summary.toml (the
// loop's last kinetic energy: the 5th, after the rows of steps 1-4).
TEST(OutputFolder, ARunWritesNothingIntoAFolderRemovedOrReplacedUnderIt) {
  const Swap cases[] = {
      {"row", plan(10, 1, 0, 0), Swap::Replaced, 3},
      {"row_removed", plan(10, 1, 0, 0), Swap::Removed, 3},
      {"snapshot_moved", plan(10, 5, 2, 0), Swap::Moved, 2},
      {"checkpoint", plan(10, 5, 0, 4), Swap::Replaced, 4},
      {"summary", plan(4, 1, 0, 0), Swap::Replaced, 0, 5},
  };
  const fs::path root = cdtest::scratch_dir("test_output_folder", "swap");
  for (const Swap& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path d = root / c.name, moved = root / (std::string(c.name) + ".old");
    Idle e;
    std::map<std::string, std::string> left;  // the new folder's files, as the swap left them
    int asked = 0;
    const auto swap = [&] {
      if (c.how == Swap::Moved) fs::rename(d, moved);
      else fs::remove_all(d);
      if (c.how != Swap::Removed) make_new_run_folder(d);
      left = files_of(d);
    };
    if (c.step > 0) e.after_step_taken = [&](std::int64_t k) { if (k == c.step) swap(); };
    if (c.energy > 0) e.energy_asked = [&](std::int64_t) { if (++asked == c.energy) swap(); };
    cd::RunOptions opt;
    opt.out = d.string();
    opt.quiet = true;
    opt.scene_toml = "name = \"idle\"\n";
    try {
      cd::run_loop(e, c.plan, opt);
      ADD_FAILURE() << "the run went on after its folder was swapped";
    } catch (const cd::FolderGone& g) {
      EXPECT_EQ(std::string(g.what()), "output folder '" + d.string() +
                                           "' was removed or replaced while the run was writing; nothing written");
    }
    EXPECT_EQ(files_of(d), left) << "the run wrote into the new folder";
    if (c.how == Swap::Removed) {
      EXPECT_FALSE(fs::exists(d)) << "the run made its folder again";
    }
    if (c.how == Swap::Moved) {
      // The folder moved away keeps what the run wrote before: rows up to
      // the step before the swap (rows every 5: none yet), no snapshot of
      // the swap's step.
      EXPECT_TRUE(fs::exists(moved / "scene.toml"));
      EXPECT_FALSE(fs::exists(moved / fmt::format("snapshot_{}.txt", c.step)));
    }
  }
}

// Untouched, the folder is the run's to the end: the same runs, no swap,
// write their rows, snapshots, checkpoint and summary.
TEST(OutputFolder, AFolderLeftAloneIsWrittenToTheEnd) {
  const fs::path d = cdtest::scratch_dir("test_output_folder", "alone");
  Idle e;
  cd::RunOptions opt;
  opt.out = d.string();
  opt.quiet = true;
  opt.scene_toml = "name = \"idle\"\n";
  const cd::RunSummary s = cd::run_loop(e, plan(10, 5, 2, 4), opt);
  EXPECT_EQ(s.status, "done");
  const auto f = files_of(d);
  for (const char* name : {"series.csv", "timings.csv", "summary.toml", "scene.toml", "checkpoint.bin",
                           "snapshot_10.txt"})
    EXPECT_TRUE(f.count(name)) << name;
  EXPECT_EQ(f.at("checkpoint.bin"), "step 10\n");
}

}  // namespace
