#include "report_scan.hpp"

#include <fmt/core.h>

#include <filesystem>

#include "report.hpp"
#include "scene_info.hpp"
#include "snapshot.hpp"

namespace fs = std::filesystem;

namespace cda {
namespace {

// The shapes of a run: the nsides of its last particles snapshot when it
// has one shape there, else scene.toml's; -1 unknown or mixed.
int run_nsides(const std::string& run, const std::optional<SceneInfo>& scene) {
  try {
    const auto snaps = list_snapshots(run, "particles");
    if (!snaps.empty()) {
      int n = -2;
      for (const auto& q : read_particles(snaps.back())) {
        if (q.nsides < 0) break;
        if (n == -2) n = q.nsides;
        else if (n != q.nsides) return -1;
      }
      if (n >= 0) return n;
    }
  } catch (const AnalysisError&) {
  }
  return scene && scene->nsides ? *scene->nsides : -1;
}

// What the scene says of the campaign's kind, and whether the run is of
// the campaign's dimension. A run without a readable scene.toml is kept.
void read_scene(ReportRun& r, int dim) {
  std::optional<SceneInfo> scene;
  try {
    scene = read_scene_info(r.folder);
    if (scene->dimension != dim) {
      r.status = "skipped";
      r.skipped_why = fmt::format("{}: a {}D run in a {}D campaign (the first run's dimension): skipped", r.folder,
                                  scene->dimension, dim);
      r.problems.push_back(r.skipped_why);
    } else {  // a skipped run says nothing of the campaign's kind
      if (scene->cohesion_number) r.eta = *scene->cohesion_number;
      if (scene->inertial_number) r.I_imposed = *scene->inertial_number;
      if (scene->pressure) r.pressure = *scene->pressure;
      r.volume = scene->volume_control;
      if (scene->volume_fraction && *scene->volume_fraction > 0) r.volume_fraction = *scene->volume_fraction;
    }
  } catch (const AnalysisError&) {
  }
  r.nsides = run_nsides(r.folder, scene);
}

// The cost from summary.toml; a damaged one is a problem, and the cost
// columns say n/a as without one.
void read_cost(ReportRun& r) {
  try {
    r.cost = read_run_cost(r.folder);
  } catch (const AnalysisError& e) {
    r.problems.push_back(e.what());
  }
}

// The steady window of the main column and every mean over it, and the
// shear profile's rate_min there; over the given window if there is one
// (scan_campaign). Throws AnalysisError when one of them cannot be
// measured: the run is then not steady.
void measure_steady(ReportRun& r, const Table& series, int dim, const std::string& window) {
  const auto rs =
      run_steady(r.folder, series, r.main_column, r.x_column, window_range(window, series.column(r.x_column)));
  r.main_stats = rs.stats;
  const Window& w = rs.stats.window;
  const auto mean = [&](const std::string& q) {
    Val m;  // nan when the series has no such column
    if (q == "inertial_number" && series.has(q)) {
      const auto st = measured_inertial_number(series, r.x_column, w);  // from <sigma_yy>
      m = {st.mean, st.err};
    } else if (series.has(q)) {
      const auto st = stats_over(series, q, r.x_column, w);
      m = {st.mean, st.error()};
    }
    return m;
  };
  // In the order of steady.csv's columns: the first that fails is the one named.
  const Val mu = mean(mu_column(dim)), I = mean("inertial_number"), phi = mean("packing_fraction"),
            z = mean("z"), p = mean("p");
  // Is the shear homogeneous over the window? (run.hpp shear_profile; nan
  // for a run without particle snapshots or not a periodic shear)
  const Val rate_min = window_rate_min(r.folder, series, r.x_column, w);
  if (is_banded(rate_min.v)) {
    r.status = "banded";
    r.problems.push_back(fmt::format("{}: banded shear (rate_min {:.2f} < {}; cdanalysis profile)", r.folder,
                                     rate_min.v, kBandedRateMin));
  }
  r.mu = mu, r.I = I, r.phi = phi, r.z = z, r.p = p, r.rate_min = rate_min;
  r.measured = true;
  r.steady = series.has(mu_column(dim)) || series.has("packing_fraction");
}

// The main column against the abscissa, all rows, as the series plot draws
// it. Throws AnalysisError naming the column the series lacks.
Table series_curve(const Table& series, const std::string& x_column, const std::string& column) {
  Table t({x_column, column});
  const auto& x = series.column(x_column);
  const auto& y = series.column(column);
  for (std::size_t i = 0; i < x.size(); ++i) t.add_row({x[i], y[i]});
  return t;
}

// 3D: the fabric averaged over the contact snapshots in the steady window
// (the last snapshot alone without one); 2D: that of the last snapshot.
void measure_fabric(ReportRun& r, const Table& series, int dim, int bins) {
  if (list_snapshots(r.folder, "contacts").empty()) return;
  try {
    if (dim == 3) {
      auto fw = window_fabric3(r.folder, series, r.x_column, r.main_stats ? &r.main_stats->window : nullptr);
      r.problems.insert(r.problems.end(), fw.problems.begin(), fw.problems.end());
      r.fabric3 = std::move(fw);
    } else {
      r.fabric2 = run_fabric(r.folder, -1, bins, -1);
    }
  } catch (const AnalysisError& e) {
    r.fabric_why = e.what();
    r.problems.push_back(fmt::format("{}: {}", r.folder, e.what()));
  }
}

// One run: scene, cost, then what its series and snapshots give, each
// step's failure recorded and the next one tried where it still can be.
ReportRun scan_run(const std::string& folder, std::size_t index, int dim, int bins, const std::string& window) {
  ReportRun r;
  r.index = index;
  r.folder = folder;
  r.name = fs::path(folder).filename().string();
  read_scene(r, dim);
  read_cost(r);
  if (r.status == "skipped") return r;  // its series is not read
  try {
    const auto series = read_series(folder);
    r.x_column = default_x_column(series);
    r.main_column = series.has(mu_column(dim)) ? mu_column(dim) : "kinetic_energy";
    try {
      measure_steady(r, series, dim, window);
    } catch (const AnalysisError& e) {
      r.status = "not steady";
      r.not_steady_why = e.what();
      r.problems.push_back(fmt::format("{}: {}", folder, e.what()));
    }
    // Without its main column (neither mu nor kinetic_energy) a run has
    // nothing to draw: it is unreadable, after the steady attempt said why.
    r.curve = series_curve(series, r.x_column, r.main_column);
    measure_fabric(r, series, dim, bins);
  } catch (const AnalysisError& e) {
    r.status = "unreadable";
    r.unreadable_why = e.what();
    r.problems.push_back(e.what());
  }
  return r;
}

}  // namespace

std::string ReportRun::stem() const { return fmt::format("run{:03d}", index); }

ReportScan scan_campaign(const std::string& campaign, int bins, const std::string& window) {
  ReportScan scan;
  scan.campaign = campaign;
  const auto folders = campaign_runs(campaign);
  // The campaign's dimension: a run of the other one is listed and skipped.
  for (const auto& run : folders) {
    try {
      scan.dimension = run_dimension(run);
      break;
    } catch (const AnalysisError&) {
    }
  }
  for (std::size_t k = 0; k < folders.size(); ++k)
    scan.runs.push_back(scan_run(folders[k], k, scan.dimension, bins, window));
  return scan;
}

ReportSummary summarize(const ReportScan& scan) {
  ReportSummary sum;
  sum.runs = scan.runs.size();
  sum.dimension = scan.dimension;
  for (const ReportRun& r : scan.runs) {
    if (r.measured) ++sum.steady;
    if (r.fabric3 || r.fabric2) ++sum.fabric;
    if (r.left_out()) ++sum.left_out;
    if (r.cost) {
      ++sum.costed;
      sum.wall_time += r.cost->wall_time;
      sum.cpu_time += r.cost->cpu_time;
    }
    sum.problems.insert(sum.problems.end(), r.problems.begin(), r.problems.end());
  }
  return sum;
}

}  // namespace cda
