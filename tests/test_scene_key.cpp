// The scene key a checkpoint carries (core/run_plan.hpp) hashes the scene's
// values, not their documentation: a run in progress resumes after an
// upgrade that only rewords the parameters' docs. A checkpoint written by a
// cdsim whose key hashed the documented text too (any other key) is taken as
// this scene's when the run folder's scene.toml has this scene's values, and
// refused as before when it has others.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "checkpoint.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "run_plan.hpp"

namespace {

namespace fs = std::filesystem;

using cdtest::slurp;

TEST(SceneKey, HashesTheValuesNotTheirDocumentation) {
  const cd::Scene a = cd::parse_scene("[contact]\nmu = 0.3\n", "a.toml");
  EXPECT_EQ(cd::resolved_values(a).find('#'), std::string::npos);
  EXPECT_NE(cd::resolved_values(a).find("mu = 0.3\n"), std::string::npos);
  // The values read back from the documented text give the same key.
  EXPECT_EQ(cd::scene_key(cd::parse_scene(cd::resolved_toml(a), "scene.toml")), cd::scene_key(a));
  cd::Scene b = a;
  b.mu = 0.31;
  EXPECT_NE(cd::scene_key(a), cd::scene_key(b));
}

// A run stopped at step 20 with a checkpoint whose key is another cdsim's
// (re-saved with a foreign key), then resumed by the same command.
class ForeignKey : public ::testing::Test {
 protected:
  std::string cmd(const fs::path& out) const {
    return std::string("OMP_NUM_THREADS=1 ") + CDLAB_BINARY_DIR + "/cd/cdsim " + CDLAB_SOURCE_DIR +
           "/configs/default.toml --set particles.n=60 --set box.width=0.01 --set box.height=0.02 "
           "--set time.dt=5e-4 --set time.duration=0.03 --set output.series_interval=0.005 "
           "--set output.snapshot_interval=0 --set output.checkpoint_interval=0.01 --quiet --out " +
           out.string();
  }
  void stop_with_foreign_key(const fs::path& out) {
    ASSERT_EQ(cdtest::run_command(cmd(out) + " --max-steps 20").code, 0);
    cd::World w{cd::WorldParams{}};
    cd::RunTotals t;
    const std::string ckpt = (out / "checkpoint.bin").string();
    const std::uint64_t key = cd::load_checkpoint(ckpt, w, &t);
    cd::save_checkpoint(ckpt, w, key ^ 0x5a5a5a5aull, t);
  }
};

TEST_F(ForeignKey, ResumesWhenTheFoldersSceneHasTheSameValues) {
  const fs::path whole = cdtest::scratch_dir("test_scene_key", "whole");
  const fs::path cut = cdtest::scratch_dir("test_scene_key", "cut");
  ASSERT_EQ(cdtest::run_command(cmd(whole)).code, 0);
  stop_with_foreign_key(cut);
  // Its scene.toml as an older cdsim wrote it: other documentation.
  std::string toml = slurp(cut / "scene.toml");
  for (std::size_t k = 0; (k = toml.find("# ", k)) != std::string::npos; k += 6) toml.replace(k, 2, "# (v1) ");
  std::ofstream(cut / "scene.toml", std::ios::binary | std::ios::trunc) << toml;
  const auto r = cdtest::run_command(cmd(cut));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(whole / "series.csv"), slurp(cut / "series.csv"));
}

TEST_F(ForeignKey, IsRefusedWhenTheFoldersSceneHasOtherValues) {
  const fs::path cut = cdtest::scratch_dir("test_scene_key", "other");
  stop_with_foreign_key(cut);
  std::string toml = slurp(cut / "scene.toml");
  const std::size_t k = toml.find("\nmu = 0.4");
  ASSERT_NE(k, std::string::npos) << toml;
  toml.replace(k, 9, "\nmu = 0.5");
  std::ofstream(cut / "scene.toml", std::ios::binary | std::ios::trunc) << toml;
  const auto r = cdtest::run_command(cmd(cut));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("different scene"), std::string::npos) << r.out;
}

}  // namespace
