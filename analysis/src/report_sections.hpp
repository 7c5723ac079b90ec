// The report's fits, by campaign kind. The kind comes from the runs, not a
// flag: what their scene.toml (and, for shapes, particles snapshots) vary.
// Several kinds may hold at once; each has its section, which fits, draws
// and writes its part of the page, in this order:
//   inertial    I varies: mu(I) (4 runs or more) and nu(I) (3 or more),
//               over the cohesionless runs of the first steady run's shape
//               (at imposed volume, where no scene imposes I, the measured
//               I: the volume kind; nu(I) is then fitted in I);
//   pressure    pressure varies: the compaction e(p);
//   cohesive    cohesion_number varies: c/p against the eta = 0 runs;
//   angularity  nsides varies: the table against alpha and mu*(alpha).
#pragma once
#include <string>
#include <vector>

#include "fit.hpp"
#include "report.hpp"
#include "report_scan.hpp"

namespace cda {

struct CampaignKind {
  bool inertial = false, cohesive = false, angularity = false, pressure = false, volume = false;
  // What the runs vary, as the summary and the page say it.
  std::vector<std::string> names() const;
};
// I varies when two scenes impose different I's; when no scene imposes one
// (as at imposed volume), when the measured I's span a factor 1.5. Volume
// when runs at imposed volume differ in volume_fraction. The others when two
// scenes differ.
CampaignKind campaign_kind(const ReportScan& scan);

// What the sections write, in order: fits.toml's fits (with their models)
// and refusals, the page's Fits section, and into the summary the fits
// made, the problems met and the fits left undetermined.
struct ReportFits {
  ReportFits(const std::string& campaign, const std::string& out_dir, ReportSummary& sum);
  std::string campaign, out_dir;
  std::string report_cmd;  // the command that made the report: on the page and in each plot
  ReportSummary& sum;
  std::vector<FitResult> fits;
  std::vector<Model> models;
  std::vector<RefusedFit> refused;
  std::string html;

  // Never a dead end: a fit the data do not determine is written (fits.toml:
  // determined = false and the reason, or the undetermined parameters) and
  // drawn (the points alone, or the curve with the parameters flagged), with
  // what would determine it. Both record it in the summary and return the
  // page's paragraph (flagged: empty when every parameter is determined).
  std::string undetermined(const std::string& model, const std::string& why);
  std::string flagged(const FitResult& r, const std::string& model);
  // The page's line under a fit: the report's command and the fit's own.
  std::string made_by(const std::string& fit_cmd) const;
};

// The Fits section's head: the kind, or why there is no fit across runs.
std::string kind_html(const CampaignKind& kind);

void inertial_section(const ReportScan& scan, const CampaignKind& kind, ReportFits& out);
void pressure_section(const ReportScan& scan, ReportFits& out);
void cohesive_section(const ReportScan& scan, ReportFits& out);
// bins: the angular bins of each run's fabric.
void angularity_section(const ReportScan& scan, int bins, ReportFits& out);

}  // namespace cda
