// The report's parts alone (analysis/src/report_*.hpp): the scan of a
// campaign folder into one record per run, what each step of a run gave or
// why it failed; the summary's counts and the tables made from the
// records; and the campaign's kind, from what the scenes vary. The whole
// report is tested through write_report in test_analysis_io and
// test_analysis_trends.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "analysis/src/report_scan.hpp"
#include "analysis/src/report_sections.hpp"
#include "analysis/src/report_tables.hpp"
#include "analysis_synth.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

fs::path scratch(const std::string& name) { return cdtest::scratch_dir("test_analysis_report", name); }

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// A campaign of six runs, sorted by name as campaign_runs sorts them: two
// cohesionless steady runs at imposed I = 0.01 and 0.1, a cohesive one
// (eta = 1), a damaged series, a run still drifting at its end, and a 3D
// run in this 2D campaign.
fs::path six_runs(const std::string& name) {
  const auto d = scratch(name);
  synth::RunSpec s;
  s.mu = 0.3;
  s.I = 0.01;
  s.seed = 3;
  synth::write_run(d / "I_0.01", s);
  s.I = 0.1;
  s.seed = 4;
  synth::write_run(d / "I_0.1", s);
  fs::create_directories(d / "bad");
  write(d / "bad" / "series.csv", "step,time,strain,q_over_p\n0,0,0,0.3\n1,0.1,0.01,x\n");
  fs::create_directories(d / "drift");
  std::string csv = "step,time,strain,q_over_p,inertial_number\n";
  for (int i = 0; i < 300; ++i) csv += fmt::format("{},{},{},{},0.05\n", i, i / 10.0, i / 100.0, 0.2 + 0.001 * i);
  write(d / "drift" / "series.csv", csv);
  s.I = 0.01;
  s.eta = 1;
  s.c_over_p = 0.1;
  s.seed = 5;
  synth::write_run(d / "eta_1", s);
  synth::write_run(d / "three_d", s);
  write(d / "three_d" / "scene.toml", "dimension = 3\n");
  return d;
}

const ReportRun& run_named(const ReportScan& scan, const std::string& name) {
  const auto it = std::find_if(scan.runs.begin(), scan.runs.end(), [&](const ReportRun& r) { return r.name == name; });
  if (it == scan.runs.end()) throw std::runtime_error("no run " + name);
  return *it;
}

}  // namespace

TEST(AnalysisReport, ScanRecordsWhatEachRunGaveAndWhyNot) {
  const auto d = six_runs("scan");
  const ReportScan scan = scan_campaign(d.string());
  EXPECT_EQ(scan.dimension, 2);  // the first run's
  ASSERT_EQ(scan.runs.size(), 6u);
  for (std::size_t k = 0; k < scan.runs.size(); ++k) EXPECT_EQ(scan.runs[k].index, k);
  EXPECT_EQ(scan.runs[0].name, "I_0.01");
  EXPECT_EQ(scan.runs[0].stem(), "run000");

  for (const char* name : {"I_0.01", "I_0.1", "eta_1"}) {
    SCOPED_TRACE(name);
    const ReportRun& r = run_named(scan, name);
    EXPECT_EQ(r.status, "ok");
    EXPECT_TRUE(r.measured);
    EXPECT_TRUE(r.steady);
    EXPECT_EQ(r.problems.size(), 0u);
    EXPECT_EQ(r.x_column, "strain");
    EXPECT_EQ(r.main_column, "q_over_p");
    ASSERT_TRUE(r.curve);
    EXPECT_EQ(r.curve->rows(), 300u);  // every row, the transient too
    ASSERT_TRUE(r.main_stats);
    EXPECT_GT(r.main_stats->window.x_begin, 0.0);  // after the transient
    // sin psi decays with gamma0 = 0.2 and the noise has sd 0.02.
    const double mu = 0.3 + (r.eta > 0 ? 0.1 * std::sqrt(1 - 0.3 * 0.3) : 0);
    EXPECT_NEAR(r.mu.v, mu, 5 * r.mu.err);
    EXPECT_LT(r.mu.err, 0.01);
    EXPECT_TRUE(std::isfinite(r.I.v));
    EXPECT_TRUE(std::isnan(r.phi.v));  // no packing_fraction column
    EXPECT_TRUE(std::isnan(r.rate_min.v));  // no particle snapshots
    EXPECT_EQ(r.pressure, 1000.0);
    EXPECT_EQ(r.nsides, -1);
    EXPECT_FALSE(r.cost);
  }
  EXPECT_EQ(run_named(scan, "I_0.1").I_imposed, 0.1);
  EXPECT_EQ(run_named(scan, "eta_1").eta, 1.0);
  EXPECT_EQ(run_named(scan, "I_0.01").eta, 0.0);

  const ReportRun& bad = run_named(scan, "bad");
  EXPECT_EQ(bad.status, "unreadable");
  EXPECT_FALSE(bad.curve);
  EXPECT_FALSE(bad.measured);
  EXPECT_NE(bad.unreadable_why.find("series.csv"), std::string::npos) << bad.unreadable_why;
  ASSERT_EQ(bad.problems.size(), 1u);
  EXPECT_TRUE(std::isnan(bad.eta));  // no scene.toml

  const ReportRun& drift = run_named(scan, "drift");
  EXPECT_EQ(drift.status, "not steady");
  EXPECT_FALSE(drift.measured);
  EXPECT_FALSE(drift.steady);
  EXPECT_TRUE(drift.curve);  // drawn all the same
  EXPECT_FALSE(drift.not_steady_why.empty());
  ASSERT_EQ(drift.problems.size(), 1u);
  EXPECT_EQ(drift.problems[0].rfind(drift.folder + ": ", 0), 0u) << drift.problems[0];

  const ReportRun& three = run_named(scan, "three_d");
  EXPECT_EQ(three.status, "skipped");
  EXPECT_NE(three.skipped_why.find("a 3D run in a 2D campaign"), std::string::npos) << three.skipped_why;
  EXPECT_FALSE(three.curve);  // its series is not read
  EXPECT_TRUE(std::isnan(three.eta));  // says nothing of the campaign's kind
}

TEST(AnalysisReport, AGivenWindowReplacesEachRunsDetectedOne) {
  // The drifting run (q/p = 0.2 + 0.1 strain) has no steady window of its
  // own; over a given strain window 1:2 its mean is 0.2 + 0.1 x 1.5 = 0.35
  // (the rows at strain 1.00 to 2.00, one row either end making 5e-4), and
  // every run's window is that one. A window outside a run's strain makes
  // it not steady, naming the window.
  const auto d = six_runs("window");
  const ReportScan scan = scan_campaign(d.string(), 36, "1:2");
  const ReportRun& drift = run_named(scan, "drift");
  EXPECT_EQ(drift.status, "ok");
  ASSERT_TRUE(drift.main_stats.has_value());
  EXPECT_NEAR(drift.mu.v, 0.35, 6e-4);
  for (const char* name : {"drift", "I_0.01", "I_0.1"}) {
    const ReportRun& r = run_named(scan, name);
    ASSERT_TRUE(r.main_stats.has_value()) << name;
    EXPECT_NEAR(r.main_stats->window.x_begin, 1.0, 0.011) << name;
    EXPECT_NEAR(r.main_stats->window.x_end, 2.0, 0.011) << name;
  }
  const ReportScan detected = scan_campaign(d.string());
  EXPECT_EQ(run_named(detected, "drift").status, "not steady");

  const ReportScan beyond = scan_campaign(d.string(), 36, "5:6");
  EXPECT_EQ(run_named(beyond, "drift").status, "not steady");
  EXPECT_NE(run_named(beyond, "drift").not_steady_why.find("window 5:6"), std::string::npos)
      << run_named(beyond, "drift").not_steady_why;
}

TEST(AnalysisReport, SummaryAndTablesFromTheScan) {
  const auto d = six_runs("tables");
  const ReportScan scan = scan_campaign(d.string());
  const ReportSummary sum = summarize(scan);
  EXPECT_EQ(sum.runs, 6u);
  EXPECT_EQ(sum.steady, 3u);
  EXPECT_EQ(sum.fabric, 0u);
  EXPECT_EQ(sum.left_out, 3u);
  EXPECT_EQ(sum.costed, 0u);
  ASSERT_EQ(sum.problems.size(), 3u);  // in the campaign's order: bad, drift, three_d
  EXPECT_NE(sum.problems[0].find("bad"), std::string::npos);
  EXPECT_NE(sum.problems[1].find("drift"), std::string::npos);
  EXPECT_NE(sum.problems[2].find("three_d"), std::string::npos);

  const Table st = steady_table(scan);
  ASSERT_EQ(st.rows(), 3u);
  EXPECT_EQ(st.column("run"), (std::vector<double>{0, 1, 4}));  // the measured runs' indices
  EXPECT_EQ(st.column("q_over_p")[2], run_named(scan, "eta_1").mu.v);
  EXPECT_TRUE(std::isnan(st.column("wall_time")[0]));
  EXPECT_EQ(fabric_table(scan).rows(), 0u);
  const std::string runs = runs_csv(scan);
  EXPECT_EQ(runs.rfind("run,folder,status,wall_time,cpu_time,steps,sweeps_per_step,cap_share,threads\n", 0), 0u);
  EXPECT_NE(runs.find("bad\",unreadable,n/a,n/a,n/a,n/a,n/a,n/a\n"), std::string::npos) << runs;
  EXPECT_NE(runs.find("drift\",not steady,"), std::string::npos) << runs;
  EXPECT_NE(runs.find("three_d\",skipped,"), std::string::npos) << runs;
}

TEST(AnalysisReport, KindFromWhatTheScenesVary) {
  const auto d = six_runs("kind");
  const ReportScan scan = scan_campaign(d.string());
  const CampaignKind k = campaign_kind(scan);
  EXPECT_TRUE(k.inertial);   // imposed I 0.01 and 0.1
  EXPECT_TRUE(k.cohesive);   // eta 0 and 1
  EXPECT_FALSE(k.pressure);  // 1000 in every scene
  EXPECT_FALSE(k.angularity);
  EXPECT_EQ(k.names(), (std::vector<std::string>{"inertial (I varies)", "cohesive (cohesion_number varies)"}));

  // No scene imposes I: the measured I's must span a factor 1.5.
  ReportScan measured = scan;
  for (ReportRun& r : measured.runs) r.I_imposed = std::nan(""), r.eta = 0;
  for (ReportRun& r : measured.runs) r.I.v = r.measured ? 0.01 : std::nan("");
  EXPECT_FALSE(campaign_kind(measured).inertial);
  measured.runs[1].I.v = 0.014;
  EXPECT_FALSE(campaign_kind(measured).inertial);
  measured.runs[1].I.v = 0.02;
  EXPECT_TRUE(campaign_kind(measured).inertial);
  EXPECT_EQ(campaign_kind(measured).names(), std::vector<std::string>{"inertial (I varies)"});
}
