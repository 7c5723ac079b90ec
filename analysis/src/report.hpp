// Campaign report: a folder of tables (CSV), fit parameters (TOML), plots
// (gnuplot, pngcairo and svg) and an index.html that links them.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "fit.hpp"
#include "plot.hpp"
#include "run.hpp"

namespace cda {

// Fit results as TOML: one table per fit,
//   [mu_I]  formula, chi2, dof, chi2_dof, error_scale, converged
//   [mu_I.params.mu1]  value, error
// plus the covariance as an array of rows, and `undetermined` listing the
// parameters whose error is not below their value (undetermined_params).
// A fit the data did not determine at all (refused: a singular Jacobian,
// too few points) is written as its own table without params:
//   [mu_I]  formula, determined = false, reason
// which compare-fits reads as the model missing.
struct RefusedFit {
  std::string model, formula, reason;
};
std::string fits_to_toml(const std::vector<FitResult>& fits, const std::vector<Model>& models,
                         const std::vector<RefusedFit>& refused = {});

// Polar diagrams of P(theta), <fn>(theta), <ft>(theta) with their Fourier
// (second-harmonic) fits; 3 plots named <stem>_P, <stem>_fn, <stem>_ft.
bool plot_polar(const std::string& dir, const std::string& stem, const RunFabric& f);
// mu(I) points with error bars, the fit and its 1-sigma band (r null: the
// fit was refused, points alone), undetermined parameters flagged in the
// legend: dir/mu_I.{png,svg}
// (with mu_I_data.csv, mu_I_fit.csv). ylabel: what mu is (2D q/p, 3D -sxy/syy).
bool plot_mu_I(const std::string& dir, std::span<const double> I, std::span<const double> mu,
               std::span<const double> mu_err, const FitResult* r, const std::string& ylabel = "μ* = q/p");

// Runs of a campaign folder: its subfolders holding series.csv, sorted; the
// folder itself if it holds series.csv. Throws AnalysisError naming the
// folder when there is none.
std::vector<std::string> campaign_runs(const std::string& campaign);

struct ReportSummary {
  std::size_t runs = 0, steady = 0, fabric = 0;
  // Runs left out of every table and fit (not steady, unreadable, of the
  // other dimension): each named in problems and on the page.
  std::size_t left_out = 0;
  // Fits written as undetermined (refused, or a parameter whose error
  // exceeds its value), with the reason: "mu_I: ...".
  std::vector<std::string> undetermined;
  // Cost: runs with a summary.toml, and their wall and CPU time summed (s).
  std::size_t costed = 0;
  double wall_time = 0, cpu_time = 0;
  bool cost_plot = false;  // cost_I.{png,svg} drawn (an inertial campaign)
  std::vector<std::string> problems;  // one line per run or step that failed
  bool plots_ok = true;
  std::vector<std::string> kinds;  // what the runs vary (inertial, cohesive, angularity, pressure)
  std::vector<std::string> fits;   // models fitted into fits.toml
  std::size_t angularity = 0;      // runs in angularity.csv
  int dimension = 2;               // the campaign's (its first run's scene.toml)
};

// The whole report of a campaign into out_dir (created): runs.csv, steady.csv
// and fabric.csv (each with the cost columns wall_time, cpu_time, steps,
// sweeps_per_step, cap_share from the run's summary.toml: nan in steady.csv
// and fabric.csv, which are read back as numbers, "n/a" in runs.csv, when a
// run has none), fits.toml, plots, cost_I.{csv,png,svg} for a campaign over
// I, and index.html with a table of points (physics and cost) and the
// campaign's total wall and CPU time. A 3D campaign (dimension = 3 in the
// first run's scene.toml) takes mu = shear_stress_ratio and writes the 3D
// anisotropies into fabric.csv, each the mean ± sem over the contact
// snapshots in the run's steady window, else of the last snapshot alone
// (docs/analysis.md, "Commands in 3D"); runs of the other dimension are
// listed under problems and skipped. window: every run's steady window,
// as scan_campaign's ("": each run's detected one).
ReportSummary write_report(const std::string& campaign, const std::string& out_dir, int bins = 36,
                           const std::string& window = "");

}  // namespace cda
