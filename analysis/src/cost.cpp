#include "cost.hpp"

#include <fmt/core.h>

#include <filesystem>
#include <sstream>
#include <toml.hpp>

#include "error.hpp"

namespace fs = std::filesystem;

namespace cda {

std::optional<RunCost> read_run_cost(const std::string& run_dir) {
  const std::string file = (fs::path(run_dir) / "summary.toml").string();
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  refuse_folder(file);
  std::istringstream text(toml_text(file));
  toml::value root;
  try {
    root = toml::parse(text, file);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("'{}' does not parse as TOML: {}", file, e.what()));
  }
  const auto number = [&](const char* key) {
    if (!root.is_table() || !root.contains(key))
      throw InputError(fmt::format("'{}' has no {}", file, key));
    const auto& v = root.at(key);
    if (v.is_floating()) return v.as_floating();
    if (v.is_integer()) return static_cast<double>(v.as_integer());
    throw InputError(fmt::format("'{}': {} is not a number", file, key));
  };
  RunCost c;
  c.wall_time = number("wall_time");
  c.cpu_time = number("cpu_time");
  c.steps = number("steps");
  c.sweeps_per_step = number("sweeps_mean");
  c.cap_share = number("cap_share");
  c.threads = number("threads");
  if (root.contains("status") && root.at("status").is_string()) c.status = root.at("status").as_string().str;
  return c;
}

}  // namespace cda
