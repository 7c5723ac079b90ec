// What several commands share: printing a fit, writing fit TOML, expanding
// campaign folders into runs.
#include <fmt/core.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
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

namespace {

// The option's text as a finite double, or the reason it is not one.
std::string read_finite(const std::string& text, double& v) {
  char* end = nullptr;
  errno = 0;
  v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') return fmt::format("'{}' is not a number", printable(text, 40));
  if (!std::isfinite(v) || (errno == ERANGE && std::abs(v) > 1))
    return fmt::format("'{}' is not a finite number", printable(text, 40));
  return {};
}

CLI::Validator number_check(const char* name, bool (*ok)(double), const char* rule) {
  return CLI::Validator(
      [ok, rule](std::string& text) -> std::string {
        double v = 0;
        if (auto why = read_finite(text, v); !why.empty()) return why;
        if (!ok(v)) return fmt::format("'{}' is not {}", printable(text, 40), rule);
        return {};
      },
      name);
}

}  // namespace

CLI::Validator finite_number() {
  return number_check("FINITE", [](double) { return true; }, "finite");
}
// A positive quantity of a physical size: the scenes' rule (magnitudes in
// [1e-100, 1e100]), so that a quotient by it stays finite (a volume of
// 4.9e-324 made the stress inf).
CLI::Validator positive_number() {
  return number_check("POSITIVE", [](double v) { return v >= 1e-100 && v <= 1e100; }, "> 0 (in [1e-100, 1e100])");
}
CLI::Validator non_negative_number() {
  return number_check("NONNEGATIVE", [](double v) { return v >= 0; }, ">= 0");
}

CLI::Validator writable_file() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        namespace fs = std::filesystem;
        std::error_code ec;
        if (path.empty()) return "an empty value";
        if (fs::is_directory(path, ec)) return fmt::format("'{}' is a folder, not a file", printable(path, 200));
        fs::path dir = fs::path(path).parent_path();
        if (dir.empty()) dir = ".";
        if (!fs::is_directory(dir, ec))
          return fmt::format("cannot write '{}': folder '{}' does not exist", printable(path, 200),
                             printable(dir.string(), 200));
        if (::access(dir.c_str(), W_OK) != 0)
          return fmt::format("cannot write '{}': folder '{}' is not writable", printable(path, 200),
                             printable(dir.string(), 200));
        return {};
      },
      "FILE");
}

CLI::Validator window_spec() {
  return CLI::Validator(
      [](std::string& spec) -> std::string {
        try {
          resolve_window(spec, std::vector<double>{0, 1});
        } catch (const AnalysisError& e) {
          return e.what();
        }
        return {};
      },
      "a:b|a%:b%");
}

CLI::Option* add_window_option(CLI::App& sub, std::string& window) {
  return sub
      .add_option("--window", window,
                  "steady window a:b of each run's abscissa (strain), or a%:b% of each run's span of it, e.g. "
                  "50%:100% the second half (default: detected per run)")
      ->check(window_spec());
}

CLI::Option* add_toml_option(CLI::App& sub, std::string& path) {
  return sub.add_option("--toml", path, "write the fit parameters to this TOML file")->check(writable_file());
}

void require_finite_numbers(CLI::App& app) {
  for (CLI::Option* o : app.get_options()) {
    if (o->get_type_name() == "FLOAT") o->check(finite_number());
    // An empty text (--column '') is refused: it meant the option's
    // default without a word (files: writable_file()).
    if (o->get_type_name() == "TEXT")
      o->check(CLI::Validator([](std::string& t) { return t.empty() ? std::string("an empty value") : ""; },
                              "NONEMPTY"));
  }
  for (CLI::App* sub : app.get_subcommands({})) require_finite_numbers(*sub);
}

void print_fit(const FitResult& r, const Model& m) {
  fmt::print("{}  ({})\n", r.model, m.formula);
  for (std::size_t i = 0; i < r.names.size(); ++i)
    fmt::print("  {:<10} {:.6g} +- {:.3g}\n", r.names[i], r.value[i], r.error[i]);
  fmt::print("  chi2/dof {:.3f} (dof {}), error scale {:.3g}, {}{}\n", r.chi2_dof, r.dof, r.scale,
             r.converged ? "converged" : "NOT converged: ", r.message);
}

void write_toml(const std::string& path, const std::vector<FitResult>& f, const std::vector<Model>& m,
                const std::vector<RefusedFit>& refused) {
  if (path.empty()) return;
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("cannot write '{}'", path));
  out << fits_to_toml(f, m, refused);
  fmt::print("wrote {}\n", path);
}

int with_reservations(const std::string& what, const std::vector<std::string>& left_out, const FitResult& r) {
  const auto u = undetermined_params(r);
  if (left_out.empty() && u.empty()) return 0;
  std::string msg;
  if (!left_out.empty()) msg = fmt::format("{} run{} left out (above)", left_out.size(), left_out.size() == 1 ? "" : "s");
  if (!u.empty())
    msg += fmt::format("{}undetermined: {} (error not below the value); what would determine {}: {}",
                       msg.empty() ? "" : "; ", fmt::join(u, ", "), u.size() == 1 ? "it" : "them",
                       what_would_determine(r.model));
  fmt::print(stderr, "cdanalysis {}: written with reservations (exit {}): {}\n", what, kExitPartial, msg);
  return kExitPartial;
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
