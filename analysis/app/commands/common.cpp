// What several commands share: printing a fit, writing fit TOML, expanding
// campaign folders into runs.
#include <fmt/core.h>

#include <fstream>

#include "analysis/app/command.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {
namespace {
std::string g_command_line = "cdanalysis";
}

void set_command_line(int argc, char** argv) {
  g_command_line = "cdanalysis";
  for (int i = 1; i < argc; ++i) g_command_line += std::string(" ") + argv[i];
}

const std::string& command_line() { return g_command_line; }

void print_fit(const FitResult& r, const Model& m) {
  fmt::print("{}  ({})\n", r.model, m.formula);
  for (std::size_t i = 0; i < r.names.size(); ++i)
    fmt::print("  {:<10} {:.6g} +- {:.3g}\n", r.names[i], r.value[i], r.error[i]);
  fmt::print("  chi2/dof {:.3f} (dof {}), error scale {:.3g}, {}{}\n", r.chi2_dof, r.dof, r.scale,
             r.converged ? "converged" : "NOT converged: ", r.message);
}

void write_toml(const std::string& path, const std::vector<FitResult>& f, const std::vector<Model>& m) {
  if (path.empty()) return;
  std::ofstream out(path);
  if (!out) throw AnalysisError(fmt::format("cannot write '{}'", path));
  out << fits_to_toml(f, m);
  fmt::print("wrote {}\n", path);
}

std::vector<std::string> expand_runs(const std::vector<std::string>& args) {
  std::vector<std::string> runs;
  for (const auto& a : args) {
    const auto r = campaign_runs(a);
    runs.insert(runs.end(), r.begin(), r.end());
  }
  return runs;
}

int common_dimension(const std::vector<std::string>& runs, const std::string& what) {
  if (runs.empty()) return 2;
  const int dim = run_dimension(runs.front());
  for (const auto& r : runs)
    if (const int d = run_dimension(r); d != dim)
      throw AnalysisError(fmt::format("{}: '{}' is a {}D run and '{}' a {}D run: one fit mixes no dimensions",
                                      what, runs.front(), dim, r, d));
  return dim;
}

std::vector<double> col_or_empty(const Table& t, const std::string& name) {
  return t.has(name) ? t.column(name) : std::vector<double>{};
}

}  // namespace cda::cli
