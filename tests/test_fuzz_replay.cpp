// The committed regression inputs of `make fuzz` (tests/data/fuzz/<target>/,
// each a minimised input that once crashed or broke a reader's contract),
// replayed through the same harness functions (tests/fuzz/fuzz_targets.hpp)
// compiled normally: each must now be accepted, or refused by the reader's
// documented error naming the file. A crash or any other exception fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_targets.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> inputs(const std::string& target) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(CDLAB_TEST_DATA) / "fuzz" / target;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

TEST(FuzzReplay, RegressionInputsAreReadOrRefusedCleanly) {
  int replayed = 0;
  for (const cdfuzz::Target& t : cdfuzz::targets()) {
    for (const fs::path& p : inputs(t.name)) {
      std::ifstream in(p, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      SCOPED_TRACE(p.string());
      EXPECT_NO_THROW(EXPECT_EQ(t.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0));
      ++replayed;
    }
  }
  // The folder exists in the tree: an empty replay would be a path gone wrong.
  EXPECT_GT(replayed, 0);
}

// Every folder of tests/data/fuzz/ is a target's (a misspelt one would never
// be replayed).
TEST(FuzzReplay, EveryCorpusFolderIsATarget) {
  for (const auto& e : fs::directory_iterator(fs::path(CDLAB_TEST_DATA) / "fuzz")) {
    if (!e.is_directory()) continue;
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(std::any_of(cdfuzz::targets().begin(), cdfuzz::targets().end(),
                            [&](const cdfuzz::Target& t) { return name == t.name; }))
        << name;
  }
}
