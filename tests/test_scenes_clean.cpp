// Shipped scenes run clean: every configs/*.toml runs,
// briefly, without a warning that the scene does not explain. A scene
// explains a warning it is known to give, at its own settings, by a comment
// line
//     # expected warning "<words of the warning>": why
// and a warning line of cdsim ("cdsim: warning: ...") that contains none of
// the scene's quoted words fails the test, naming scene and warning.
//
// Each scene runs a stretch that holds what its full run warns about where
// one is known (the piles: the first 0.1 s, the impact, where their sweep
// caps and overlaps came: series rows of the full runs), else its first
// steps (--max-steps), one thread; the shear scenes start from their
// preparation's short run, so that they need no outputs/ of a user.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const fs::path kConfigs = CDLAB_SOURCE_DIR "/configs";

// The short version of each shipped scene: its arguments after the scene
// and --out. $PREP / $PREP3 are the folders of the preparations' short runs.
const std::map<std::string, std::string> kShort = {
    {"default", "--set time.duration=0.1"},
    {"hexagons", "--set time.duration=0.1"},
    {"mixture", "--set time.duration=0.1"},
    {"pile3d", "--max-steps 40"},
    {"pile-polyhedra", "--max-steps 40"},
    // to its own stop (settled, ~1100 steps): the shear scenes start from a
    // jammed sample, as a user's do (from 300 steps, phi 0.49, the cohesive
    // shear compacted it further with the cell at its approach floor, and
    // 3 of its 100 steps stopped at the sweep cap)
    {"shear-prep", ""},
    {"shear-inertial", "--set 'shear.start=\"$PREP/checkpoint.bin\"' --max-steps 100"},
    {"shear-cohesive", "--set 'shear.start=\"$PREP/checkpoint.bin\"' --max-steps 100"},
    {"shear-walls", "--max-steps 300"},
    {"shear3-prep", "--max-steps 20"},
    {"shear3-inertial", "--set 'shear.start=\"$PREP3/checkpoint.bin\"' --max-steps 10"},
};
// The preparations first: the shear scenes start from them.
const std::vector<std::string> kFirst = {"shear-prep", "shear3-prep"};

// Warnings explained by the test, not by the scene, for a scene that cannot
// carry its own note yet (a note belongs in the scene). Empty: every scene
// explains its own warnings.
const std::map<std::string, std::vector<std::string>> kExplainedHere = {};

// The quoted words of the scene's `# expected warning "...": why` lines.
std::vector<std::string> expected_warnings(const fs::path& scene) {
  std::vector<std::string> out;
  std::istringstream in(cdtest::slurp(scene));
  const std::regex note(R"re(^#\s*expected warning\s+"([^"]+)"\s*:\s*\S.*)re");
  std::smatch m;
  for (std::string line; std::getline(in, line);)
    if (std::regex_match(line, m, note)) out.push_back(m[1]);
  return out;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t i = s.find(from); i != std::string::npos; i = s.find(from, i + to.size())) s.replace(i, from.size(), to);
  return s;
}

}  // namespace

TEST(ScenesClean, EveryShippedSceneRunsWithoutAnUnexplainedWarning) {
  const fs::path d = cdtest::scratch_dir("test_scenes_clean", "runs");
  std::vector<std::string> names = kFirst;
  for (const auto& e : fs::directory_iterator(kConfigs))
    if (e.path().extension() == ".toml") {
      const std::string n = e.path().stem().string();
      if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    }
  std::sort(names.begin() + kFirst.size(), names.end());
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const auto it = kShort.find(name);
    ASSERT_NE(it, kShort.end()) << "configs/" << name << ".toml: a new scene: give its short run in kShort";
    std::string args = replace_all(it->second, "$PREP3", (d / "shear3-prep").string());
    args = replace_all(args, "$PREP", (d / "shear-prep").string());
    const cdtest::CmdResult r = cdtest::run_command("OMP_WAIT_POLICY=passive " + kCdsim + " " +
                                                    (kConfigs / (name + ".toml")).string() + " --out " +
                                                    (d / name).string() + " --threads 1 -q " + args);
    ASSERT_EQ(r.code, 0) << r.out;
    std::vector<std::string> explained = expected_warnings(kConfigs / (name + ".toml"));
    if (const auto h = kExplainedHere.find(name); h != kExplainedHere.end())
      explained.insert(explained.end(), h->second.begin(), h->second.end());
    std::istringstream out(r.out);
    for (std::string line; std::getline(out, line);) {
      if (line.find("warning:") == std::string::npos) continue;
      bool ok = false;
      for (const std::string& words : explained) ok = ok || line.find(words) != std::string::npos;
      EXPECT_TRUE(ok) << "configs/" << name << ".toml gives a warning it does not explain (fix the setting, or "
                      << "add a line '# expected warning \"<words>\": why'):\n" << line;
    }
  }
}

// The check itself: a warning the scene explains passes, another fails.
TEST(ScenesClean, NoteFormatIsRead) {
  const fs::path d = cdtest::scratch_dir("test_scenes_clean", "note");
  std::ofstream(d / "s.toml") << "# expected warning \"stopped at the sweep cap\": measured, 3 % at impact\n"
                                 "# expected warning \"overlap\":\n"  // no reason: not a note
                                 "name = \"s\"\n";
  EXPECT_EQ(expected_warnings(d / "s.toml"), std::vector<std::string>{"stopped at the sweep cap"});
}
