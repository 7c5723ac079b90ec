// cdsim as a user meets it: bad input gets one clear message, a non-zero
// exit, and nothing written; a good run writes what docs/outputs.md promises.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "cli_util.hpp"
#include "config.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";

using Result = cdtest::CmdResult;
Result run(const std::string& args) { return cdtest::run_command(kCdsim + " " + args); }

// In the build folder (cdtest::scratch_dir), not /tmp, where each run of the
// suite left seven cdsim_cli_* folders behind.
fs::path temp_dir(const std::string& name) { return cdtest::scratch_dir("test_cdsim_cli", name); }

fs::path write(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// A tiny valid scene: two disks on a floor, a few steps.
const std::string kScene = R"(name = "tiny"
[time]
dt = 1e-3
duration = 0.01
[gravity]
g = [0.0, -9.81]
[[disk]]
pos = [0.0, 0.5]
radius = 0.5
[[disk]]
pos = [1.0, 0.5]
radius = 0.5
[[wall]]
a = [-5.0, 0.0]
b = [5.0, 0.0]
[output]
series_interval = 1e-3
snapshot_interval = 5e-3
)";

}  // namespace

TEST(CdsimCli, UnknownKeyNamesKeyPositionAndSuggestion) {
  const fs::path d = temp_dir("unknown");
  const fs::path scene = write(d, "s.toml", "[contact]\nmuu = 0.3\n");
  const Result r = run(scene.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("s.toml:2:1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("contact.muu"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("did you mean 'contact.mu'"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "out"));
}

TEST(CdsimCli, NegativeRadiusIsRejected) {
  const fs::path d = temp_dir("radius");
  const fs::path scene = write(d, "s.toml", "[[disk]]\npos = [0.0, 0.0]\nradius = -1.0\n");
  const Result r = run(scene.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("disk[0].radius"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("must be > 0"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "out"));
}

TEST(CdsimCli, OverlappingInitialParticlesAreNamed) {
  const fs::path d = temp_dir("overlap");
  const fs::path scene = write(d, "s.toml",
                               "[[disk]]\npos = [0.0, 0.0]\nradius = 0.5\n"
                               "[[disk]]\npos = [2.0, 0.0]\nradius = 0.5\n"
                               "[[disk]]\npos = [2.8, 0.0]\nradius = 0.5\n");
  const Result r = run(scene.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("initial overlap"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("disk[1]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("disk[2]"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "out"));
}

TEST(CdsimCli, UnwritableOutputFolderIsRejectedBeforeRunning) {
  // Tests run as root, which bypasses permission bits: put the output folder
  // below a regular file, which nobody can create.
  const fs::path d = temp_dir("unwritable");
  const fs::path scene = write(d, "s.toml", kScene);
  write(d, "afile", "x");
  const Result r = run(scene.string() + " --out " + (d / "afile" / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("output folder"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("afile"), std::string::npos) << r.out;
}

TEST(CdsimCli, MalformedSceneAndBadOverride) {
  const fs::path d = temp_dir("malformed");
  const fs::path scene = write(d, "s.toml", "[time\ndt = 1\n");
  Result r = run(scene.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("s.toml"), std::string::npos) << r.out;
  const fs::path good = write(d, "g.toml", kScene);
  r = run(good.string() + " --set time.dt=-1 --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("time.dt"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "out"));
  r = run((d / "missing.toml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("missing.toml"), std::string::npos) << r.out;
}

// A folder or a binary file given as the scene is named as such; the
// binary's bytes are not echoed to the terminal.
TEST(CdsimCli, FolderOrBinaryGivenAsTheSceneIsNamed) {
  const fs::path d = temp_dir("binary");
  Result r = run(d.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("'" + d.string() + "' is a folder, not a scene file"), std::string::npos) << r.out;
  const fs::path bin = write(d, "b.toml", std::string("name = 1\n\x1b[31m\x01\x02red", 19));
  r = run(bin.string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("is not a scene file (TOML text): control byte 0x1b at line 2"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << "echoed an escape sequence";
  EXPECT_FALSE(fs::exists(d / "out"));
}

TEST(CdsimCli, GoodRunWritesSeriesSceneAndCollections) {
  const fs::path d = temp_dir("good");
  const fs::path scene = write(d, "s.toml", kScene);
  const Result r = run(scene.string() + " --quiet --out " + (d / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"series.csv", "scene.toml", "particles.pvd", "contacts.pvd", "walls.pvd",
                        "particles_00000.vtp", "particles_00002.vtp"})
    EXPECT_TRUE(fs::exists(d / "out" / f)) << f;
  // series: the documented columns, one row per output interval (10 steps).
  std::ifstream in(d / "out" / "series.csv");
  std::string header, line;
  std::getline(in, header);
  for (const char* c : {"step", "time", "contacts", "iterations", "residual", "cap_hit",
                        "max_overlap", "mean_overlap", "kinetic_energy"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + c + ","), std::string::npos) << c;
  // The wall-clock stage timings are in timings.csv, on the series' steps.
  EXPECT_EQ(header.find(",t_"), std::string::npos) << header;
  {
    std::ifstream t(d / "out" / "timings.csv");
    std::string th;
    std::getline(t, th);
    for (const char* c : {"step", "time", "t_predict", "t_detect", "t_build", "t_colour", "t_solve",
                          "t_integrate", "t_observe", "t_output"})
      EXPECT_NE(("," + th + ",").find(std::string(",") + c + ","), std::string::npos) << c;
  }
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 10);
  // The resolved scene reads back to the scene that ran.
  const cd::Scene a = cd::load_scene(scene.string());
  const cd::Scene b = cd::load_scene((d / "out" / "scene.toml").string());
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.disks.size(), b.disks.size());
  EXPECT_EQ(b.mu, cd::Scene{}.mu);  // defaults are written out too
}
