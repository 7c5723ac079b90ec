#include "start_hint.hpp"

#include <algorithm>
#include <filesystem>
#include <vector>

#include <fmt/format.h>

#include "config.hpp"

namespace cd {

std::string missing_start_hint(const Scene& s) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (s.start.empty() || fs::exists(s.start, ec)) return "";
  const fs::path want = fs::path(s.start).lexically_normal();
  std::vector<fs::path> scenes;
  const fs::path dir = s.source.empty() ? fs::path(".") : fs::path(s.source).parent_path();
  for (const auto& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, ec))
    if (e.path().extension() == ".toml" && !fs::equivalent(e.path(), s.source, ec)) scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());  // the same answer on every file system
  for (const fs::path& p : scenes) {
    try {
      const Scene other = load_scene(p.string());
      if ((fs::path("outputs") / other.name / "checkpoint.bin").lexically_normal() == want)
        return fmt::format("; no such file: {} makes it (run `cdsim {}` first)", p.string(), p.string());
    } catch (const std::exception&) {
      // Not a scene this build reads: not the one that makes the sample.
    }
  }
  return "; no such file: it is the checkpoint.bin of a preparation run (e.g. configs/shear-prep.toml "
         "run with --out into that folder): run it first";
}

}  // namespace cd
