// Identical runs give identical files: the same scene run
// twice, each into its own folder, gives byte-identical series.csv and VTK
// snapshots, and a summary.toml that differs only in its cost record (wall
// and CPU time, load average). Wall-clock stage timings, which differ from
// run to run, are in timings.csv, whose rows are the series' rows (same
// steps); so a user who diffs two runs, or a regression that compares files,
// sees only what the physics changed.
//
// Scenes: a 2D pile in a box (walls, gravity), a 2D periodic compaction at
// imposed pressure (the shear protocol's columns), and a 3D pile of spheres.
// Each runs on two threads with the parallel sweep forced on, so that the
// coloured path is the one compared (results do not depend on the thread
// count: test_state_hash).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace {

namespace fs = std::filesystem;

using cdtest::slurp;

// The files of a run folder, by name (no subfolders are written).
std::set<std::string> names(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

// summary.toml without its cost lines: what the run computed.
std::string summary_physics(const fs::path& p) {
  std::istringstream in(slurp(p));
  std::string out;
  for (std::string line; std::getline(in, line);) {
    const std::string key = line.substr(0, line.find(' '));
    if (key == "wall_time" || key == "cpu_time" || key == "load_start" || key == "load_end") continue;
    out += line + '\n';
  }
  return out;
}

struct Case {
  const char* name;
  const char* scene;
  const char* sets;
};

class Reproducible : public ::testing::TestWithParam<Case> {};

TEST_P(Reproducible, TwoIdenticalRunsGiveIdenticalFiles) {
  const Case& c = GetParam();
  std::vector<fs::path> dirs;
  for (const char* run : {"a", "b"}) {
    const fs::path out = cdtest::scratch_dir("test_reproducible", std::string(c.name) + "_" + run);
    const auto r = cdtest::run_command(
        std::string("OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive ") + CDLAB_BINARY_DIR + "/cd/cdsim " +
        CDLAB_SOURCE_DIR + "/configs/" + c.scene + " " + c.sets + " --quiet --out " + out.string());
    ASSERT_EQ(r.code, 0) << r.out;
    dirs.push_back(out);
  }
  const std::set<std::string> files = names(dirs[0]);
  ASSERT_EQ(files, names(dirs[1]));
  // Every file the run writes is here: a new output must be added to one
  // of the lists below (compared, or the cost record), never left unchecked.
  int snapshots = 0;
  for (const std::string& f : files) {
    if (f == "summary.toml") {
      EXPECT_EQ(summary_physics(dirs[0] / f), summary_physics(dirs[1] / f));
      EXPECT_NE(slurp(dirs[0] / f).find("wall_time"), std::string::npos);
    } else if (f == "checkpoint.bin") {
      ADD_FAILURE() << "checkpoints are off in these scenes (a checkpoint holds the stage timers)";
    } else if (f == "timings.csv") {
      // Wall-clock seconds: the same rows (steps) and columns, other values.
      std::istringstream a(slurp(dirs[0] / f)), b(slurp(dirs[1] / f));
      std::string la, lb;
      std::getline(a, la), std::getline(b, lb);
      EXPECT_EQ(la, lb) << "timings.csv header";
      EXPECT_EQ(la.rfind("step,", 0), 0u) << la;
      while (std::getline(a, la) && std::getline(b, lb))
        EXPECT_EQ(la.substr(0, la.find(',')), lb.substr(0, lb.find(','))) << "timings.csv steps";
    } else {
      // series.csv, scene.toml, the .pvd collections and the .vtp snapshots.
      EXPECT_TRUE(slurp(dirs[0] / f) == slurp(dirs[1] / f)) << f << " differs between two identical runs";
      snapshots += f.ends_with(".vtp");
    }
  }
  EXPECT_TRUE(files.count("series.csv") && files.count("timings.csv") && files.count("scene.toml"));
  EXPECT_GE(snapshots, 4) << "the runs wrote too few snapshots to compare";
  // No wall-clock column in the series.
  const std::string header = slurp(dirs[0] / "series.csv").substr(0, slurp(dirs[0] / "series.csv").find('\n'));
  EXPECT_EQ(header.find(",t_"), std::string::npos) << header;
}

// A run begun by a cdsim that wrote the timings into series.csv (before
// timings.csv) and resumed by this one goes on in its own layout: the
// timings stay in its series, no timings.csv appears, and its physics
// columns are those of a run never stopped.
std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

TEST(Reproducible, ARunWithTimingsInItsSeriesResumesInItsLayout) {
  const std::string cmd = std::string("OMP_NUM_THREADS=1 ") + CDLAB_BINARY_DIR + "/cd/cdsim " + CDLAB_SOURCE_DIR +
                          "/configs/default.toml --set particles.n=60 --set box.width=0.01 --set box.height=0.02 "
                          "--set time.dt=5e-4 --set time.duration=0.03 --set output.series_interval=0.005 "
                          "--set output.snapshot_interval=0 --set output.checkpoint_interval=0.01 --quiet --out ";
  const fs::path whole = cdtest::scratch_dir("test_reproducible", "legacy_whole");
  const fs::path cut = cdtest::scratch_dir("test_reproducible", "legacy_cut");
  ASSERT_EQ(cdtest::run_command(cmd + whole.string()).code, 0);
  const auto first = cdtest::run_command(cmd + cut.string() + " --max-steps 20");
  ASSERT_EQ(first.code, 0) << first.out;
  // The old layout: the t_* columns after the series' own, no timings.csv.
  const std::vector<std::string> s = lines(slurp(cut / "series.csv")), t = lines(slurp(cut / "timings.csv"));
  ASSERT_EQ(s.size(), t.size());
  ASSERT_EQ(s.size(), 3u);  // header, rows at steps 10 and 20
  std::string old;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::string tail = t[i].substr(t[i].find(',', t[i].find(',') + 1));  // after step,time
    old += s[i] + tail + '\n';
  }
  {
    std::ofstream f(cut / "series.csv", std::ios::binary | std::ios::trunc);
    f << old;
  }
  fs::remove(cut / "timings.csv");

  const auto second = cdtest::run_command(cmd + cut.string());
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("resumed from"), std::string::npos) << second.out;
  EXPECT_FALSE(fs::exists(cut / "timings.csv"));
  const std::vector<std::string> a = lines(slurp(whole / "series.csv")), b = lines(slurp(cut / "series.csv"));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_NE(b[0].find(",t_predict,"), std::string::npos) << b[0];
  const std::size_t ncols = std::count(a[0].begin(), a[0].end(), ',') + 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    // The first ncols columns of the old layout are the series' own.
    std::size_t cut_at = 0;
    for (std::size_t c = 0; c < ncols; ++c) cut_at = b[i].find(',', cut_at) + 1;
    EXPECT_EQ(a[i] + ',', b[i].substr(0, cut_at)) << "row " << i;
    EXPECT_EQ(std::count(b[i].begin(), b[i].end(), ','), std::count(b[0].begin(), b[0].end(), ',')) << "row " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Runs, Reproducible,
    ::testing::Values(
        Case{"pile2d", "default.toml",
             "--set particles.n=120 --set box.width=0.012 --set box.height=0.03 --set time.dt=5e-4 "
             "--set time.duration=0.05 --set output.series_interval=0.005 "
             "--set output.snapshot_interval=0.02 --set solver.threads=2"},
        Case{"compaction2d", "shear-prep.toml",
             "--set particles.n=100 --max-steps 120 --set output.series_interval=1e-4 "
             "--set output.snapshot_interval=5e-4 --set output.checkpoint_wall=0"},
        Case{"pile3d", "pile3d.toml",
             "--set particles.n=100 --max-steps 60 --set output.series_interval=0.005 "
             "--set output.snapshot_interval=0.02 --set output.checkpoint_wall=0"}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
