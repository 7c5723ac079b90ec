#include "scene_info.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <vector>
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
  refuse_folder(s.file);
  std::istringstream text(toml_text(s.file));
  toml::value root;
  try {
    root = toml::parse(text, s.file);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("'{}' does not parse as TOML: {}", s.file, e.what()));
  }
  if (root.is_table() && root.contains("dimension")) {
    const auto& d = root.at("dimension");
    const bool whole = d.is_integer() || (d.is_floating() && std::isfinite(d.as_floating()) &&
                                               d.as_floating() == std::floor(d.as_floating()) &&
                                               std::abs(d.as_floating()) < 1e9);
    const long long v = d.is_integer() ? d.as_integer() : whole ? static_cast<long long>(d.as_floating()) : 0;
    if (!whole || (v != 2 && v != 3))
      throw InputError(fmt::format("'{}': dimension is {} (2 or 3 expected)", s.file,
                                   toml::format(d)));
    s.dimension = static_cast<int>(v);
  }
  s.cohesion_number = number(root, "contact", "cohesion_number", s.file);
  s.inertial_number = number(root, "shear", "inertial_number", s.file);
  s.pressure = number(root, "shear", "pressure", s.file);
  s.friction = number(root, "contact", "mu", s.file);
  s.solver_tol = number(root, "solver", "tol", s.file);
  if (root.is_table() && root.contains("shear") && root.at("shear").is_table() && root.at("shear").contains("mode")) {
    const auto& m = root.at("shear").at("mode");
    if (!m.is_string()) throw InputError(fmt::format("'{}': [shear] mode is not a string", s.file));
    s.shear_mode = m.as_string();
  }
  if (root.is_table() && root.contains("shear") && root.at("shear").is_table() &&
      root.at("shear").contains("control")) {
    const auto& c = root.at("shear").at("control");
    if (!c.is_string()) throw InputError(fmt::format("'{}': [shear] control is not a string", s.file));
    s.volume_control = c.as_string() == "volume";
  }
  if (s.volume_control) {
    s.inertial_number.reset();  // not imposed: measured
    s.volume_fraction = number(root, "shear", "volume_fraction", s.file);
  }
  if (root.is_table() && root.contains("particles") && root.at("particles").is_table() &&
      root.at("particles").contains("nsides")) {
    const auto& v = root.at("particles").at("nsides");
    std::vector<long long> ns;
    // cdsim's resolved scene.toml writes the list as floats (nsides = [6.0]):
    // a float with an integer value counts as that integer.
    const auto side_count = [&](const toml::value& e) -> long long {
      if (e.is_integer()) return e.as_integer();
      if (e.is_floating() && std::isfinite(e.as_floating()) && e.as_floating() == std::floor(e.as_floating()) &&
          std::abs(e.as_floating()) < 1e9)
        return static_cast<long long>(e.as_floating());
      throw InputError(fmt::format("'{}': [particles] nsides holds a non-integer", s.file));
    };
    if (v.is_integer() || v.is_floating()) {
      ns.push_back(side_count(v));
    } else if (v.is_array()) {
      for (const auto& e : v.as_array()) ns.push_back(side_count(e));
    } else {
      throw InputError(fmt::format("'{}': [particles] nsides is neither an integer nor an array", s.file));
    }
    for (long long n : ns)
      if (n != 0 && n < 3)
        throw InputError(fmt::format("'{}': [particles] nsides holds {} (0 for disks or 3 and more)", s.file, n));
    std::sort(ns.begin(), ns.end());
    ns.erase(std::unique(ns.begin(), ns.end()), ns.end());
    if (ns.size() == 1) s.nsides = static_cast<int>(ns[0]);
    else if (ns.size() > 1) s.nsides_mixed = true;
  }
  return s;
}

double angularity_of(int nsides) { return nsides == 0 ? 0.0 : 2 * std::numbers::pi / nsides; }

int run_dimension(const std::string& run_dir) {
  std::error_code ec;
  if (!fs::exists(fs::path(run_dir) / "scene.toml", ec)) return 2;
  return read_scene_info(run_dir).dimension;
}

void refuse_3d(const std::string& run_dir, const std::string& what) {
  if (run_dimension(run_dir) == 3)
    throw AnalysisError(fmt::format("{} is 2D only: '{}' is a 3D run (dimension = 3 in its scene.toml)",
                                    what, run_dir));
}

double require(const SceneInfo& s, const std::optional<double>& v, const std::string& key) {
  if (!v) throw InputError(fmt::format("'{}' has no {}", s.file, key));
  return *v;
}

}  // namespace cda
