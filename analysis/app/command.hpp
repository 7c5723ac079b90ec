// The subcommands of cdanalysis as a table of name -> handler (as git's
// builtin/ and LAMMPS' command styles): each subcommand is one file in
// commands/ that declares its options on its CLI11 subcommand and returns
// the handler main runs once that subcommand was parsed. Adding a command
// is one file and one row in cdanalysis.cpp's table.
#pragma once
#include <CLI/CLI.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/src/fit.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/run.hpp"

namespace cda::cli {

// Runs the parsed subcommand; returns the exit code (error.hpp). Failures
// are thrown (AnalysisError: 1, InputError: 2) and reported by main.
using Handler = std::function<int()>;
// Declares the options of a subcommand on `sub` (bound to state the handler
// owns) and returns its handler.
using Declare = Handler (*)(CLI::App& sub);

struct Command {
  const char* name;
  const char* help;
  Declare declare;
};

// The commands, each defined in commands/<name>.cpp.
Handler steady(CLI::App& sub);
Handler fabric(CLI::App& sub);
Handler profile(CLI::App& sub);
Handler fit_mu_i(CLI::App& sub);
Handler fit_cohesion(CLI::App& sub);
Handler fit_dilatancy(CLI::App& sub);
Handler fit_angularity(CLI::App& sub);
Handler fit_nu_i(CLI::App& sub);
Handler fit_compaction(CLI::App& sub);
Handler fit_fabric_bounds(CLI::App& sub);
Handler compare_fits(CLI::App& sub);
Handler report(CLI::App& sub);
Handler draw(CLI::App& sub);

// ---- Shared by the commands (common.cpp) ----

// Option validators. CLI11's own let NaN through (every comparison with NaN
// is false, so NaN "passes" a range and then means "not given") and print
// their bounds with %f (DBL_MAX as 309 digits). main adds finite_number()
// to every floating-point option of every command (declare_all), so a range
// below only has to say its range.
CLI::Validator finite_number();
CLI::Validator positive_number();      // in [1e-100, 1e100]
CLI::Validator non_negative_number();  // >= 0 (and finite)
// A file the command will write: its folder exists and is writable, and the
// path is not a folder; checked before any work is done.
CLI::Validator writable_file();
// A --window spec, a:b or a%:b% (run.hpp resolve_window), checked before any run is read.
CLI::Validator window_spec();
// The options every fit shares, one text and one check each: --window (the
// steady window of each run, window_spec) and --toml (writable_file).
CLI::Option* add_window_option(CLI::App& sub, std::string& window);
CLI::Option* add_toml_option(CLI::App& sub, std::string& path);
// Adds finite_number() to every floating-point option of app and of its
// subcommands, recursively, and refuses an empty value of a text option.
void require_finite_numbers(CLI::App& app);

// The command as typed, for the plots' "made by" line (set once by main).
void set_command_line(int argc, char** argv);
const std::string& command_line();

void print_fit(const FitResult& r, const Model& m);
// Writes the fits as TOML to path (nothing when path is empty).
void write_toml(const std::string& path, const std::vector<FitResult>& f, const std::vector<Model>& m,
                const std::vector<RefusedFit>& refused = {});
// The exit code of a fit that was written: kExitPartial (with a line on
// stderr naming them) when runs were left out or parameters are
// undetermined (with what would determine them), else 0.
int with_reservations(const std::string& what, const std::vector<std::string>& left_out, const FitResult& r);
// Run folders from the arguments: a folder holding series.csv is a run, any
// other folder a campaign whose subfolders are runs (report.hpp).
std::vector<std::string> expand_runs(const std::vector<std::string>& args);
// The dimension shared by the runs of one fit (run_dimension); runs of
// different dimensions are refused: one fit mixes no dimensions.
int common_dimension(const std::vector<std::string>& runs, const std::string& what);
std::vector<double> col_or_empty(const Table& t, const std::string& name);

// fit nu-i and fit compaction: one steady state (packing fraction) against
// I or p, over runs or a table (state_fit.cpp).
struct StateFitOptions {
  std::vector<std::string> runs;
  std::string table, toml_out, out, window;
  double p0 = 0;  // compaction: reference pressure, 0: the geometric mean of the p's
};
int run_state_fit(const StateFitOptions& o, bool is_nu);

}  // namespace cda::cli
