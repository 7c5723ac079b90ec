// docs/scene-parameters.md is generated from `cdsim --help-scene=md` (make
// scene-doc). This test fails when the two drift apart, so that a new or
// changed scene parameter cannot reach main with stale documentation.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "cli_util.hpp"

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kDoc = CDLAB_SOURCE_DIR "/docs/scene-parameters.md";
// The Makefile's scene-doc target writes a short header ending with this
// line, then the output of cdsim --help-scene verbatim.
const std::string kMarker = "<!-- cdsim --help-scene -->\n";

std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream ia(a), ib(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(ia, la));
    const bool gb = static_cast<bool>(std::getline(ib, lb));
    if (!ga && !gb) return "(they differ only in the final newline)";
    if (!ga || !gb || la != lb)
      return "first difference at table line " + std::to_string(line) + ":\n  docs:  " +
             (ga ? la : "<end of file>") + "\n  cdsim: " + (gb ? lb : "<end of output>");
  }
}

TEST(HelpScene, DocsSceneParametersIsWhatCdsimPrints) {
  const cdtest::CmdResult r = cdtest::run_command(kCdsim + " --help-scene=md");
  ASSERT_EQ(r.code, 0) << r.out;
  ASSERT_FALSE(r.out.empty());

  std::ifstream in(kDoc, std::ios::binary);
  ASSERT_TRUE(in) << kDoc << " is missing: run `make scene-doc` and commit it";
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::size_t at = doc.find(kMarker);
  ASSERT_NE(at, std::string::npos)
      << kDoc << " has no line '" << kMarker.substr(0, kMarker.size() - 1)
      << "': regenerate it with `make scene-doc` and commit it";
  const std::string table = doc.substr(at + kMarker.size());
  EXPECT_TRUE(table == r.out)
      << "docs/scene-parameters.md is out of date with `cdsim --help-scene`: run `make scene-doc` "
         "and commit docs/scene-parameters.md.\n"
      << first_difference(table, r.out);
}

}  // namespace
