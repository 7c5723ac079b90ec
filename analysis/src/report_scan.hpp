// The report's reading of a campaign: every run of the folder as one plain
// record (what its scene says, its steady means, its fabric, its cost and
// what went wrong with it), before anything is fitted, drawn or written.
// The tables, the fit sections and the page are made from it alone.
#pragma once
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cost.hpp"
#include "report.hpp"
#include "run.hpp"
#include "steady.hpp"
#include "table.hpp"
#include "trends.hpp"

namespace cda {

// One run of a campaign as the report reads it.
struct ReportRun {
  std::size_t index = 0;  // its place among the campaign's sorted runs
  std::string folder;     // as campaign_runs gives it
  std::string name;       // the folder's last component
  // ok, banded, not steady, unreadable, skipped (of the other dimension).
  std::string status = "ok";

  // From scene.toml, nan when absent (and for a skipped run, which says
  // nothing of the campaign's kind); nsides from the particles snapshots,
  // else scene.toml, -1 unknown or mixed.
  double eta = std::nan(""), I_imposed = std::nan(""), pressure = std::nan("");
  int nsides = -1;
  // Imposed volume ([shear] control = "volume"): no I imposed, phi exact;
  // its volume_fraction (nan: absent or 0, the sample's own).
  bool volume = false;
  double volume_fraction = std::nan("");

  std::optional<RunCost> cost;  // none without a summary.toml

  // The series' abscissa and main column (the dimension's mu, else
  // kinetic_energy), and the main column over the whole run for its plot;
  // no curve when the series is unreadable or the run skipped.
  std::string x_column, main_column;
  std::optional<Table> curve;

  // The steady window of the main column: set as soon as it is found, even
  // when a mean over it then fails (the plot still shades it).
  std::optional<SteadyStats> main_stats;
  // Every steady mean measured: the run has its row in steady.csv.
  bool measured = false;
  // A point for the fits: measured, and the series has mu or packing_fraction.
  bool steady = false;
  // Steady means ± error (nan when the series has no such column): mu
  // (q_over_p in 2D, shear_stress_ratio in 3D), the measured inertial
  // number, packing fraction, coordination, pressure; and the shear
  // profile's slowest gap over the window (nan without particle snapshots).
  Val mu, I, phi, z, p, rate_min;

  // The fabric, when the run has contact snapshots: 3D over the steady
  // window, 2D of the last snapshot.
  std::optional<WindowFabric3> fabric3;
  std::optional<RunFabric> fabric2;

  // Why a step failed, each said on the page where the step stands.
  std::string skipped_why, not_steady_why, fabric_why, unreadable_why;
  // Every problem of the run, in the order met.
  std::vector<std::string> problems;

  std::string stem() const;  // run000, run001...: its plots' names
  bool left_out() const { return status == "skipped" || status == "not steady" || status == "unreadable"; }
};

struct ReportScan {
  std::string campaign;
  // The campaign's: its first run whose scene.toml reads (2 when none does).
  int dimension = 2;
  std::vector<ReportRun> runs;
};

// Reads every run of the campaign (campaign_runs; throws as it does when
// there is none). A run of the other dimension is recorded as skipped, a
// failing step as a problem of its run: the scan itself never stops. bins:
// the angular bins of the 2D fabric. window: "a:b" of the strain, or
// "a%:b%" of each run's span of it (steady's --window): every run's steady
// means (and its 3D fabric) over that window instead of its detected one;
// "": detected.
ReportScan scan_campaign(const std::string& campaign, int bins = 36, const std::string& window = "");

// The summary's counts (runs, steady, with fabric, left out, costed and
// their summed cost), the dimension, and every run's problems in the
// campaign's order; the fits, kinds and plots are the report's to add.
ReportSummary summarize(const ReportScan& scan);

}  // namespace cda
