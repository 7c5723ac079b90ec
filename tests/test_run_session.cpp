// The parts of a run session (core/run_session_parts.hpp), each alone: when
// outputs fall, the resume from a checkpoint, the output folder, a signal's
// notice, the --dump-problem steps, series rows, the cost record. The whole
// session is driven through run_loop by test_output_folder, test_checkpoint,
// test_cdsim_cli and the others that run cdsim.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "files.hpp"
#include "run_session_parts.hpp"

namespace fs = std::filesystem;

namespace {

// An engine that only counts steps: its load() takes the step count and
// key it is told to, as a checkpoint would hold them.
class Counter final : public cd::RunEngine {
 public:
  std::int64_t steps_ = 0;
  std::uint64_t stored_key = 1;
  std::int64_t stored_steps = 0;
  cd::StepStats last_;
  cd::StageTimes times_;
  mutable int energy_asked = 0;

  void step() override { ++steps_; }
  const cd::StepStats& last() const override { return last_; }
  std::int64_t steps() const override { return steps_; }
  double time() const override { return 1e-3 * double(steps_); }
  cd::StageTimes& times() override { return times_; }
  double kinetic_energy() const override {
    ++energy_asked;
    return 0.5;
  }
  std::string non_finite() const override { return ""; }
  void save(const std::string&, std::uint64_t, const cd::RunTotals&) const override {}
  std::uint64_t load(const std::string&, cd::RunTotals* t) override {
    steps_ = stored_steps;
    t->sweeps = 42;
    return stored_key;
  }
  void open_snapshots(const std::string&, cd::Frames) override {}
  void write_snapshot() override {}
};

cd::RunPlan plan(std::int64_t steps, std::int64_t every_row) {
  cd::RunPlan p;
  p.nsteps = steps;
  p.dt = 1e-3;
  p.every_row = every_row;
  p.key = 7;
  return p;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

cd::StepStats stats(int iterations, double residual, double overlap) {
  cd::StepStats s;
  s.solve.iterations = iterations;
  s.solve.residual_max = residual;
  s.solve.residual_mean = residual / 2;
  s.max_overlap = overlap;
  s.contacts = 3;
  return s;
}

double at(const cd::Columns& cols, const std::string& name) {
  for (const auto& [n, x] : cols)
    if (n == name) return x;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

TEST(OutputCadence, RowsAndSnapshotsFallOnTheirStepsAndTheLast) {
  cd::RunPlan p = plan(12, 5);
  p.every_snap = 10;
  const cd::OutputCadence c(p, false);
  for (std::int64_t k : {5, 10, 12}) EXPECT_TRUE(c.row_due(k)) << k;
  for (std::int64_t k : {1, 7, 11}) EXPECT_FALSE(c.row_due(k)) << k;
  EXPECT_EQ(c.next_row(7), 10);
  EXPECT_EQ(c.next_row(11), 12);  // the last step, not 15
  EXPECT_TRUE(c.snapshot_due(10));
  EXPECT_FALSE(c.snapshot_due(5));
  EXPECT_FALSE(cd::OutputCadence(plan(12, 5), false).snapshot_due(10));  // no snapshots
}

TEST(OutputCadence, CheckpointsBySimulatedTimeStrainAndAtTheEnd) {
  const auto now = cd::RunClock::now();
  cd::RunPlan p = plan(100, 5);
  EXPECT_FALSE(cd::OutputCadence(p, false).checkpoint_due(100, true, now)) << "checkpoints off";
  EXPECT_TRUE(cd::OutputCadence(p, true).checkpoint_due(100, true, now)) << "a resumed run keeps its checkpoint";
  p.every_ckpt = 20;
  p.every_ckpt_strain = 30;
  const cd::OutputCadence c(p, false);
  EXPECT_TRUE(c.checkpoint_due(20, false, now));
  EXPECT_TRUE(c.checkpoint_due(30, false, now));
  EXPECT_FALSE(c.checkpoint_due(25, false, now));
  EXPECT_TRUE(c.checkpoint_due(25, true, now)) << "a stop or a settled run ends with one";
}

TEST(OutputCadence, WallClockCheckpointsFallOnTheFirstRowAfterTheirInterval) {
  using std::chrono::seconds;
  cd::RunPlan p = plan(1000, 5);
  p.ckpt_wall = 60;
  cd::OutputCadence c(p, false);
  const auto t0 = cd::RunClock::now();
  c.start(t0);
  EXPECT_FALSE(c.checkpoint_due(5, false, t0 + seconds(59)));
  EXPECT_FALSE(c.checkpoint_due(7, false, t0 + seconds(61))) << "not between rows";
  EXPECT_TRUE(c.checkpoint_due(10, false, t0 + seconds(61)));
  c.checkpoint_written(t0 + seconds(61));
  EXPECT_FALSE(c.checkpoint_due(15, false, t0 + seconds(100)));
  EXPECT_TRUE(c.checkpoint_due(15, false, t0 + seconds(121)));
}

TEST(OutputCadence, AnIntervalNotShorterThanTheRunIsWarnedOf) {
  cd::RunPlan p = plan(200, 10);
  EXPECT_EQ(cd::long_interval_warnings(p), "");
  p.every_ckpt = 200;
  p.checkpoint_interval = 0.05;
  EXPECT_EQ(cd::long_interval_warnings(p),
            "cdsim: warning: output.checkpoint_interval = 0.05 s is 200 steps (rounded up to whole series rows), "
            "not shorter than the run's 200: it writes no checkpoint before the end, so a kill loses the whole "
            "run\n");
  p.every_ckpt = 0;
  p.every_ckpt_strain = 300;
  p.checkpoint_strain = 0.5;
  p.ckpt_wall = 60;
  EXPECT_EQ(cd::long_interval_warnings(p),
            "cdsim: warning: output.checkpoint_strain = 0.5 is 300 steps (rounded up to whole series rows), "
            "not shorter than the run's 200: it writes no checkpoint before the end (output.checkpoint_wall "
            "still does)\n");
}

TEST(StopNotice, SaysOnceWhichRowTheStopWaitsFor) {
  cd::StopNotice n;
  EXPECT_EQ(n.seen(15, false, 40, false),
            "cdsim: signal 15: stopping at the next series row (step 40); a second signal stops at once\n");
  EXPECT_EQ(n.seen(15, false, 40, false), "");
  cd::StopNotice after_progress;
  EXPECT_TRUE(after_progress.seen(2, false, 40, true).starts_with("\ncdsim: signal 2:"));
  cd::StopNotice at_row;
  EXPECT_EQ(at_row.seen(15, true, 40, false), "") << "the stop is at this very row";
  EXPECT_EQ(at_row.seen(15, false, 45, false), "") << "said (or not) once";
}

TEST(ProblemDumps, EveryStepMustBeReached) {
  EXPECT_NO_THROW(cd::ProblemDumps({1, 50}, 50));
  try {
    cd::ProblemDumps({10, 51}, 50);
    ADD_FAILURE() << "a step past the run's end accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--dump-problem 51: the run's last step is 50");
  }
  const cd::ProblemDumps d({3, 7}, 10);
  EXPECT_TRUE(d.at(7));
  EXPECT_FALSE(d.at(5));
  EXPECT_EQ(std::string(cd::ProblemDumps::failed(7, cd::WriteError("could not write 'x'")).what()),
            "--dump-problem 7: could not write 'x'");
}

TEST(RunFolder, ChecksItIsStillTheFolderItLocked) {
  const fs::path root = cdtest::scratch_dir("test_run_session", "folder");
  const fs::path d = root / "run";
  cd::RunFolder f(d.string());
  EXPECT_NO_THROW(f.check()) << "nothing to check before the folder is made";
  f.make();
  EXPECT_TRUE(fs::is_directory(d));
  EXPECT_TRUE(fs::exists(d / ".cdsim.lock"));
  EXPECT_EQ(f.series(), (d / "series.csv").string());
  EXPECT_NO_THROW(f.check());
  fs::remove_all(d);
  fs::create_directories(d);
  EXPECT_THROW(f.check(), cd::FolderGone);
}

TEST(RunFolder, ClearPreviousRemovesOnlyARunsOwnFiles) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "clear");
  for (const char* f : {"series.csv", "timings.csv", "scene.toml", "summary.toml", "checkpoint.bin",
                        "checkpoint.bin.tmp.12", "problem_5.cdp", "particles.pvd", "particles_00001.vtp",
                        "spheres_00002.vtp", "polyhedra_00003.vtp", "notes.txt", "mine.vtp", ".cdsim.lock"})
    write(d / f, "x");
  cd::clear_previous(d);
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(d)) left.insert(e.path().filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"notes.txt", "mine.vtp", ".cdsim.lock"}));
}

TEST(Resume, NoCheckpointOrFreshStartsAtStepZero) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "no_resume");
  Counter e;
  EXPECT_FALSE(cd::resume_from_checkpoint(e, plan(100, 10), cd::RunFolder(d.string()), false).resumed);
  write(d / "checkpoint.bin", "x");
  const cd::ResumePoint r = cd::resume_from_checkpoint(e, plan(100, 10), cd::RunFolder(d.string()), true);
  EXPECT_FALSE(r.resumed);
  EXPECT_EQ(r.step, 0);
}

TEST(Resume, CutsTheSeriesBackToTheCheckpoint) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "resume");
  write(d / "checkpoint.bin", "x");
  write(d / "series.csv", "step,time,a\n10,0.01,1\n20,0.02,2\n30,0.03,3\n");
  write(d / "timings.csv", "step,time,t_solve\n10,0.01,1\n20,0.02,2\n30,0.03,3\n");
  Counter e;
  e.stored_key = 7;
  e.stored_steps = 20;
  const cd::ResumePoint r = cd::resume_from_checkpoint(e, plan(100, 10), cd::RunFolder(d.string()), false);
  EXPECT_TRUE(r.resumed);
  EXPECT_EQ(r.step, 20);
  EXPECT_EQ(r.totals.sweeps, 42);
  EXPECT_FALSE(r.legacy_timings);
  EXPECT_EQ(r.series_columns, (std::vector<std::string>{"step", "time", "a"}));
  EXPECT_EQ(r.timing_columns, (std::vector<std::string>{"step", "time", "t_solve"}));
  EXPECT_EQ(cdtest::slurp(d / "series.csv"), "step,time,a\n10,0.01,1\n20,0.02,2\n");
  EXPECT_EQ(cdtest::slurp(d / "timings.csv"), "step,time,t_solve\n10,0.01,1\n20,0.02,2\n");
}

TEST(Resume, ARunBegunBeforeTimingsCsvKeepsItsTimingsInTheSeries) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "legacy");
  write(d / "checkpoint.bin", "x");
  write(d / "series.csv", "step,time,t_solve\n10,0.01,1\n");
  Counter e;
  e.stored_key = 7;
  e.stored_steps = 10;
  const cd::ResumePoint r = cd::resume_from_checkpoint(e, plan(100, 10), cd::RunFolder(d.string()), false);
  EXPECT_TRUE(r.legacy_timings);
  EXPECT_TRUE(r.timing_columns.empty());
  EXPECT_FALSE(fs::exists(d / "timings.csv"));
}

TEST(Resume, AnotherScenesCheckpointIsRefusedWithTheWayOut) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "other_scene");
  write(d / "checkpoint.bin", "x");
  write(d / "series.csv", "step,time\n10,0.01\n");
  Counter e;
  e.stored_key = 8;  // the plan's is 7
  e.stored_steps = 10;
  try {
    cd::resume_from_checkpoint(e, plan(100, 10), cd::RunFolder(d.string()), false);
    ADD_FAILURE() << "another scene's checkpoint accepted";
  } catch (const cd::CheckpointError& err) {
    EXPECT_EQ(std::string(err.what()),
              "checkpoint '" + (d / "checkpoint.bin").string() + "' was written by a different scene (compare with " +
                  (d / "scene.toml").string() + "); run with --fresh to discard the checkpoint and start over");
  }
  EXPECT_EQ(cdtest::slurp(d / "series.csv"), "step,time\n10,0.01\n") << "nothing written";
}

TEST(Resume, TheSnapshotsUpToTheCheckpointAreKnownByTheirSteps) {
  cd::RunPlan p = plan(100, 5);
  p.every_snap = 5;
  const cd::Frames f = cd::snapshots_up_to(p, 12);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[2].second, "00002");
  EXPECT_EQ(f[2].first, 10 * 1e-3);
  EXPECT_TRUE(cd::snapshots_up_to(plan(100, 5), 12).empty()) << "no snapshots";
}

TEST(SeriesRows, AnIntervalsStatisticsMakeItsRow) {
  cd::SeriesInterval iv;
  iv.add(stats(10, 1e-3, 0.01));
  iv.add(stats(30, 4e-3, 0.02));
  Counter e;
  e.steps_ = 20;
  const cd::Columns row = cd::series_row(20, e, stats(30, 4e-3, 0.02), iv);
  EXPECT_EQ(row.front().first, "step");
  EXPECT_EQ(at(row, "step"), 20);
  EXPECT_EQ(at(row, "time"), 0.02);
  EXPECT_EQ(at(row, "contacts"), 3);
  EXPECT_EQ(at(row, "iterations"), 20);
  EXPECT_EQ(at(row, "iterations_max"), 30);
  EXPECT_EQ(at(row, "residual"), 4e-3);
  EXPECT_EQ(at(row, "residual_mean"), (0.5e-3 + 2e-3) / 2);
  EXPECT_EQ(at(row, "max_overlap"), 0.02);
  EXPECT_EQ(at(row, "kinetic_energy"), 0.5);
  EXPECT_EQ(e.energy_asked, 1) << "the kinetic energy is asked once a row";

  cd::StageTimes t0, now;
  t0[cd::Stage::Solve] = 1.0;
  now[cd::Stage::Solve] = 3.5;
  const cd::Columns t = cd::timings_row(20, 0.02, now, t0);
  ASSERT_EQ(t.size(), 2u + cd::kStages);
  EXPECT_EQ(at(t, "t_solve"), 2.5);
  EXPECT_EQ(at(t, "t_output"), 0);
}

TEST(SeriesRows, SeriesFilesWriteWholeRowsAndSkipTimingsOfALegacyRun) {
  const fs::path d = cdtest::scratch_dir("test_run_session", "series");
  cd::RunFolder f(d.string());
  cd::ResumePoint fresh;
  cd::SeriesFiles s;
  s.open(f, fresh);
  EXPECT_FALSE(s.legacy_timings());
  s.write_series({{"step", 5}, {"time", 0.005}}, f);
  s.write_timings({{"step", 5}, {"time", 0.005}, {"t_solve", 0.25}}, f);
  EXPECT_EQ(cdtest::slurp(d / "series.csv"), "step,time\n5,0.005\n");
  EXPECT_EQ(cdtest::slurp(d / "timings.csv"), "step,time,t_solve\n5,0.005,0.25\n");

  const fs::path l = cdtest::scratch_dir("test_run_session", "series_legacy");
  write(l / "series.csv", "step,time,t_solve\n5,0.005,0.25\n");
  cd::RunFolder lf(l.string());
  cd::ResumePoint legacy;
  legacy.resumed = true;
  legacy.legacy_timings = true;
  legacy.series_columns = {"step", "time", "t_solve"};
  cd::SeriesFiles ls;
  ls.open(lf, legacy);
  EXPECT_TRUE(ls.legacy_timings());
  ls.write_series({{"step", 10}, {"time", 0.01}, {"t_solve", 0.5}}, lf);
  ls.write_timings({{"step", 10}, {"time", 0.01}}, lf);
  EXPECT_EQ(cdtest::slurp(l / "series.csv"), "step,time,t_solve\n5,0.005,0.25\n10,0.01,0.5\n");
  EXPECT_FALSE(fs::exists(l / "timings.csv"));
}

TEST(CostRecord, CountsEachStepIntoTheSessionAndTheRun) {
  cd::RunTotals so_far;
  so_far.sweeps = 100;
  so_far.sweeps_max = 50;
  so_far.sessions = 1;
  cd::CostRecord c;
  c.start(so_far, cd::RunClock::now());
  c.count_session();
  cd::StepStats a = stats(10, 1e-3, 0.01), b = stats(40, 5e-4, 0.03);
  b.solve.cap_hit = true;
  b.solve.anderson_off = 3;
  b.floor_held = true;
  c.add(a);
  c.add(b);
  // A capped step whose mixing ran to the cap, and one whose mixing stalled
  // without a cap: neither is a capped step that ended as plain NLGS.
  cd::StepStats on = stats(40, 5e-4, 0.03), off = stats(40, 5e-4, 0.03);
  on.solve.cap_hit = true;
  off.solve.anderson_off = 7;
  c.add(on);
  c.add(off);
  const cd::RunTotals t = c.totals_now();
  EXPECT_EQ(t.sweeps, 230);
  EXPECT_EQ(t.sweeps_max, 50) << "the earlier sessions' most";
  EXPECT_EQ(t.cap_steps, 2);
  EXPECT_EQ(t.residual_max, 1e-3);
  EXPECT_EQ(t.residual_last, 5e-4);
  EXPECT_EQ(t.overlap_max, 0.03);
  EXPECT_EQ(t.sessions, 2);
  EXPECT_EQ(t.anderson_off_steps, 2);
  EXPECT_EQ(t.floor_steps, 1);
  EXPECT_GE(t.wall, 0);
  c.end_session(100, 104, 200);
  const cd::RunSummary& s = c.summary();
  EXPECT_EQ(s.first_step, 100);
  EXPECT_EQ(s.steps, 4);
  EXPECT_EQ(s.mean_iterations, 32.5);
  EXPECT_EQ(s.max_iterations, 40);
  EXPECT_EQ(s.cap_hits, 2);
  EXPECT_EQ(s.anderson_off, 2);
  EXPECT_EQ(s.cap_anderson_off, 1) << "b alone: at the cap, its mixing off";
  EXPECT_EQ(s.max_overlap, 0.03);
}

TEST(CostRecord, TheStatusNamesHowTheSessionEnded) {
  cd::RunSummary s;
  EXPECT_STREQ(cd::session_status(s), "done");
  s.settled = true;
  EXPECT_STREQ(cd::session_status(s), "settled");
  s.stopped_at_max_steps = true;
  EXPECT_STREQ(cd::session_status(s), "max-steps");
  s.stop_signal = 15;
  EXPECT_STREQ(cd::session_status(s), "stopped");
}

}  // namespace
