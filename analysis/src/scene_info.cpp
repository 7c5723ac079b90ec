#include "scene_info.hpp"

#include <fmt/core.h>

#include <filesystem>
#include <toml.hpp>

namespace fs = std::filesystem;

namespace cda {
namespace {

// A TOML number as a double: the resolved scene writes whole values such as
// `cohesion_number = 0` as integers as often as floats.
std::optional<double> number(const toml::value& root, const std::string& table, const std::string& key,
                             const std::string& file) {
  if (!root.is_table() || !root.contains(table)) return std::nullopt;
  const auto& t = root.at(table);
  if (!t.is_table() || !t.contains(key)) return std::nullopt;
  const auto& v = t.at(key);
  if (v.is_floating()) return v.as_floating();
  if (v.is_integer()) return static_cast<double>(v.as_integer());
  throw InputError(fmt::format("'{}': [{}] {} is not a number", file, table, key));
}

}  // namespace

SceneInfo read_scene_info(const std::string& run_dir) {
  SceneInfo s;
  s.file = (fs::path(run_dir) / "scene.toml").string();
  std::error_code ec;
  if (!fs::exists(s.file, ec))
    throw InputError(fmt::format("run folder '{}' has no scene.toml", run_dir));
  toml::value root;
  try {
    root = toml::parse(s.file);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("'{}' does not parse as TOML: {}", s.file, e.what()));
  }
  s.cohesion_number = number(root, "contact", "cohesion_number", s.file);
  s.inertial_number = number(root, "shear", "inertial_number", s.file);
  s.pressure = number(root, "shear", "pressure", s.file);
  return s;
}

double require(const SceneInfo& s, const std::optional<double>& v, const std::string& key) {
  if (!v) throw InputError(fmt::format("'{}' has no {}", s.file, key));
  return *v;
}

}  // namespace cda
