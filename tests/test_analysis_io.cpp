// Reading runs (series.csv, contact and particle snapshots), the run-level
// measurements, and the messages for bad input, through the library and
// through the cdanalysis command when it is built.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>

#include "analysis/src/compare.hpp"
#include "analysis/src/cost.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/snapshot.hpp"
#include "cli_util.hpp"
#include "run.hpp"  // cdsim's summary.toml writer (cd/src/2d/run.hpp)

namespace fs = std::filesystem;
using namespace cda;

namespace {

fs::path scratch(const std::string& name) { return cdtest::scratch_dir("test_analysis_io", name); }

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string message(const std::function<void()>& f) {
  try {
    f();
  } catch (const AnalysisError& e) {
    return e.what();
  }
  return "<no AnalysisError>";
}

// A steady shear-like run: q_over_p = 0.3 + AR(1) noise, I = 0.01 + noise,
// after a transient; a square lattice of 16 particles with contacts along x
// (fn = 2) and y (fn = 1), written without the branch array.
void make_run(const fs::path& dir, double mu, double I, unsigned seed) {
  fs::create_directories(dir);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> G(0, 1);
  std::string csv = "step,time,contacts,strain,q_over_p,inertial_number\n";
  double e = 0;
  for (int i = 0; i < 600; ++i) {
    e = 0.7 * e + 0.01 * G(rng);
    const double strain = 0.01 * i;
    csv += fmt::format("{},{},{},{},{},{}\n", i, 0.1 * i, 24, strain,
                       mu + 0.3 * std::exp(-strain / 0.3) + e, I * (1 + 0.05 * G(rng)));
  }
  write(dir / "series.csv", csv);
  ParticleSet ps;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      Particle p;
      p.id = 4 * j + i;
      p.x = i;
      p.y = j;
      p.radius = 0.5;
      ps.push_back(p);
    }
  ContactSet cs;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      Contact c;
      c.status = 1;
      if (i < 3) {
        c.b1 = 4 * j + i, c.b2 = c.b1 + 1, c.theta = 0, c.lx = 1, c.ly = 0, c.fn = 2;
        cs.push_back(c);
      }
      if (j < 3) {
        c.b1 = 4 * j + i, c.b2 = c.b1 + 4, c.theta = std::numbers::pi / 2, c.lx = 0, c.ly = 1, c.fn = 1;
        cs.push_back(c);
      }
    }
  write_particles((dir / "particles_00000.vtp").string(), ps);
  write_contacts((dir / "contacts_00000.vtp").string(), cs, ps, false);
}

}  // namespace

TEST(AnalysisIo, SeriesCsvAndItsErrors) {
  const auto d = scratch("csv");
  write(d / "ok.csv", "step, time ,q\n0,0.0,1e-3\n1,0.5,nan\n\n");
  // nan is a missing value in cdanalysis' own tables only; in a series it is bad input.
  EXPECT_NE(message([&] { Table::read_csv((d / "ok.csv").string()); })
                .find("ok.csv' line 3, column 'q': 'nan' is not a finite number"),
            std::string::npos);
  write(d / "inf.csv", "a,b\n1,inf\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "inf.csv").string(), true); })
                .find("line 2, column 'b': 'inf' is not a finite number"),
            std::string::npos);
  const auto t = Table::read_csv((d / "ok.csv").string(), true);
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.column("time")[1], 0.5);
  EXPECT_TRUE(std::isnan(t.column("q")[1]));
  EXPECT_NE(message([&] { t.column("p"); }).find("has no column 'p' (columns: step,time,q)"), std::string::npos);
  EXPECT_NE(message([&] { Table::read_csv((d / "none.csv").string()); }).find("cannot open"), std::string::npos);
  write(d / "empty.csv", "");
  EXPECT_NE(message([&] { Table::read_csv((d / "empty.csv").string()); }).find("empty.csv' is empty"), std::string::npos);
  write(d / "header.csv", "a,b\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "header.csv").string()); }).find("no data rows"), std::string::npos);
  write(d / "short.csv", "a,b\n1,2\n3\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "short.csv").string()); }).find("line 3: 1 fields"), std::string::npos);
  write(d / "text.csv", "a,b\n1,x\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "text.csv").string()); }).find("column 'b': 'x' is not a number"),
            std::string::npos);
  // Columns declared as words are skipped and left out; the others are still read and checked.
  write(d / "words.csv", "protocol,x,build\nwalls,0.5,515852b\nperiodic,0.25,1d6d952-dirty\n");
  const auto words = Table::read_csv((d / "words.csv").string(), false, {"protocol", "build"});
  EXPECT_EQ(words.names(), std::vector<std::string>{"x"});
  EXPECT_EQ(words.column("x")[1], 0.25);
  EXPECT_EQ(words.line(1), 3u);
  EXPECT_NE(message([&] { Table::read_csv((d / "words.csv").string(), false, {"protocol"}); })
                .find("line 2, column 'build': '515852b' is not a number"),
            std::string::npos);
  write(d / "words-short.csv", "protocol,x\nwalls\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "words-short.csv").string(), false, {"protocol"}); })
                .find("line 2: 1 fields, the header has 2"),
            std::string::npos);
  // A column named twice: which of the two a reader meant is unknown.
  write(d / "twice.csv", "step,q,q\n0,1,2\n");
  EXPECT_NE(message([&] { Table::read_csv((d / "twice.csv").string()); }).find("column 'q' appears twice"),
            std::string::npos);
  // A NUL byte inside a number: the field is not a number (it read as 0.).
  write(d / "nul.csv", std::string("a,b\n1,0.\0" "403\n", 13));
  EXPECT_NE(message([&] { Table::read_csv((d / "nul.csv").string()); }).find("column 'b'"), std::string::npos);
  // Round trip at full precision.
  Table w({"x"});
  w.add_row({0.1 + 0.2});
  w.write_csv((d / "rt.csv").string());
  EXPECT_EQ(Table::read_csv((d / "rt.csv").string()).column("x")[0], 0.1 + 0.2);
}

TEST(AnalysisIo, ContactSnapshotRoundTripWithAndWithoutBranch) {
  const auto d = scratch("vtp");
  ParticleSet ps(2);
  ps[0].id = 7, ps[0].x = 1, ps[0].y = 2, ps[0].radius = 0.5;
  ps[1].id = 9, ps[1].x = 1.6, ps[1].y = 2.8, ps[1].radius = 0.5;
  Contact c;
  c.b1 = 7, c.b2 = 9, c.theta = std::atan2(0.8, 0.6), c.lx = 0.6, c.ly = 0.8, c.fn = 3, c.ft = -0.5;
  c.status = 2, c.type = 1;
  Contact periodic = c;
  periodic.lx = -9.4;  // image across a periodic boundary: not centre to centre
  for (bool with_branch : {true, false}) {
    const auto f = (d / (with_branch ? "b.vtp" : "nb.vtp")).string();
    write_contacts(f, {c, periodic}, ps, with_branch);
    const auto r = read_contacts(f);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_NEAR(r[0].theta, c.theta, 1e-15);
    EXPECT_NEAR(r[0].lx, 0.6, 1e-12);
    EXPECT_NEAR(r[0].ly, 0.8, 1e-12);
    EXPECT_EQ(r[0].fn, 3);
    EXPECT_EQ(r[0].ft, -0.5);
    EXPECT_EQ(r[0].status, 2);
    EXPECT_EQ(r[0].type, 1);
    EXPECT_EQ(r[0].b1, 7);
    EXPECT_EQ(r[0].b2, 9);
    EXPECT_NEAR(r[1].lx, -9.4, 1e-12);  // from the branch array, or from the line's points
  }
  write_particles((d / "p.vtp").string(), ps);
  const auto rp = read_particles((d / "p.vtp").string());
  ASSERT_EQ(rp.size(), 2u);
  EXPECT_EQ(rp[1].id, 9);
  EXPECT_DOUBLE_EQ(rp[1].y, 2.8);
  EXPECT_NE(message([&] { read_contacts((d / "missing.vtp").string()); }).find("missing.vtp' does not exist"),
            std::string::npos);
  write(d / "junk.vtp", "not xml");
  EXPECT_NE(message([&] { read_contacts((d / "junk.vtp").string()); }).find("junk.vtp"), std::string::npos);
  // A particles file read as contacts lacks the contact arrays.
  write_contacts((d / "c.vtp").string(), {c}, ps);
  EXPECT_NE(message([&] { read_particles((d / "c.vtp").string()); }).find("has no array 'id'"), std::string::npos);
}

TEST(AnalysisIo, RunFolderSteadyAndFabric) {
  const auto d = scratch("campaign");
  make_run(d / "a", 0.3, 0.01, 1);
  const auto series = read_series((d / "a").string());
  EXPECT_EQ(default_x_column(series), "strain");
  const auto r = run_steady((d / "a").string(), series, "q_over_p", "strain", std::nullopt);
  EXPECT_TRUE(r.detected);
  EXPECT_NEAR(r.stats.mean, 0.3, 4 * r.stats.error() + 0.002);
  const auto given = run_steady((d / "a").string(), series, "q_over_p", "strain", parse_range("3:5"));
  EXPECT_EQ(given.stats.window.end - given.stats.window.begin, 201u);
  // Lattice: 12 x-contacts (fn 2, l 1) and 12 y-contacts (fn 1): sigma V =
  // diag(24, 12); with V = 12: p = 1.5, q = 0.5; a_c = 0 (as many x as y).
  const auto f = run_fabric((d / "a").string(), -1, 36, 12.0);
  EXPECT_NEAR(f.stress.p(), 1.5, 1e-12);
  EXPECT_NEAR(f.stress.q(), 0.5, 1e-12);
  EXPECT_NEAR(f.tensor.c.a(), 0.0, 1e-12);
  // Tensor: 2(24 - 12)/36 = 2/3 (see the lattice limit in anisotropy.hpp);
  // the binned profile holds the exact bin means at 0 and 90 degrees.
  EXPECT_NEAR(f.tensor.fn.a(), 2.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(f.profile.fn[0], 2.0);
  EXPECT_DOUBLE_EQ(f.profile.fn[18], 1.0);
  EXPECT_EQ(f.profile.empty_bins, 34u);
  ASSERT_TRUE(f.connectivity.has_value());
  // Corner particles have 2 contacts, edges 3, inner 4: z = (4*2 + 8*3 + 4*4)/16 = 3.
  EXPECT_DOUBLE_EQ(f.connectivity->z, 3.0);
  EXPECT_EQ(f.connectivity->rattlers, 0u);
  EXPECT_NE(message([&] { run_fabric((d / "a").string(), 3, 36, 1); }).find("has 1 contacts snapshots; snapshot 3"),
            std::string::npos);
  EXPECT_NE(message([&] { read_series((d / "nope").string()); }).find("run folder"), std::string::npos);
  EXPECT_NE(message([&] { parse_range("5:3"); }).find("a < b"), std::string::npos);
  // --window in percent of a run's own span of x: x from 1 to 5 here, so
  // 50%:100% is 3:5 and gives the window "3:5" gives; absolute specs pass
  // through; mixed or out-of-range percentages are refused by name.
  const std::vector<double> x = {1, 2, 3, 4, 5};
  EXPECT_EQ(resolve_window("50%:100%", x), (std::pair<double, double>{3.0, 5.0}));
  EXPECT_EQ(resolve_window("25%:75%", x), (std::pair<double, double>{2.0, 4.0}));
  EXPECT_EQ(resolve_window("1.5:2", x), (std::pair<double, double>{1.5, 2.0}));
  for (const char* bad : {"50%:4", "3:100%", "50%:120%", "60%:50%", "%:50%", "a%:50%"})
    EXPECT_NE(message([&] { resolve_window(bad, x); }).find("a%:b%"), std::string::npos) << bad;
  const auto& xs = series.column("strain");
  const double span = xs.back() - xs.front();
  const auto half = run_steady((d / "a").string(), series, "q_over_p", "strain",
                               resolve_window("50%:100%", xs));
  EXPECT_DOUBLE_EQ(half.stats.window.x_begin, xs[std::lower_bound(xs.begin(), xs.end(), xs.front() + span / 2) - xs.begin()]);
  EXPECT_DOUBLE_EQ(half.stats.window.x_end, xs.back());
  fs::create_directories(d / "empty_run");
  EXPECT_NE(message([&] { read_series((d / "empty_run").string()); }).find("has no series.csv"), std::string::npos);
}

TEST(AnalysisIo, ReportOfACampaign) {
  const auto d = scratch("report");
  const double I[] = {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3};
  for (int k = 0; k < 6; ++k)
    make_run(d / fmt::format("r{}", k), 0.28 + 0.34 / (1 + 0.05 / I[k]), I[k], 10 + k);
  const auto s = write_report(d.string(), (d / "out").string());
  EXPECT_EQ(s.runs, 6u);
  EXPECT_EQ(s.steady, 6u);
  EXPECT_EQ(s.fabric, 6u);
  for (const char* f : {"index.html", "steady.csv", "fabric.csv", "runs.csv", "fits.toml"})
    EXPECT_TRUE(fs::exists(d / "out" / f)) << f;
  const auto t = Table::read_csv((d / "out" / "steady.csv").string(), true);
  EXPECT_EQ(t.rows(), 6u);
  std::ifstream toml(d / "out" / "fits.toml");
  const std::string text((std::istreambuf_iterator<char>(toml)), {});
  EXPECT_NE(text.find("[mu_I.params.mu1]"), std::string::npos);
  if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(s.plots_ok);
    EXPECT_TRUE(fs::exists(d / "out" / "mu_I.png"));
    EXPECT_TRUE(fs::exists(d / "out" / "mu_I.svg"));
    EXPECT_TRUE(fs::exists(d / "out" / "run000_polar_P.png"));
  }
  EXPECT_NE(message([&] { campaign_runs((d / "out").string()); }).find("holds no run"), std::string::npos);
}

// A run's summary.toml as cdsim writes it (cd::summary_toml).
void write_summary(const fs::path& dir, double wall, double steps, double sweeps_mean, double cap_share) {
  cd::RunSummary s;
  s.status = "done";
  s.last_step = static_cast<std::int64_t>(steps);
  s.total_steps = s.last_step;
  s.threads = 2;
  s.totals.wall = wall;
  s.totals.cpu = 2 * wall;
  s.totals.sweeps = sweeps_mean * steps;
  s.totals.cap_steps = cap_share * steps;
  s.totals.sessions = 1;
  write(dir / "summary.toml", cd::summary_toml(s));
}

// A tiny inertial campaign: four points, three with their cost in
// summary.toml, one without (older cdsim, or killed before its first
// session ended), and one more whose summary is damaged. Every table has
// the cost columns beside the physics; a missing or damaged summary reads
// n/a (nan in the numeric tables) and never stops the report; the total is
// over the runs that have one.
TEST(AnalysisIo, ReportShowsTheCostOfEachPoint) {
  const auto d = scratch("report_cost");
  const double I[] = {1e-3, 1e-2, 0.1, 0.3, 0.03};
  for (int k = 0; k < 5; ++k)
    make_run(d / fmt::format("I_{}", I[k]), 0.28 + 0.34 / (1 + 0.05 / I[k]), I[k], 20 + k);
  write_summary(d / "I_0.001", 100.5, 4000, 250.25, 0.375);
  write_summary(d / "I_0.01", 20.25, 2000, 120, 0.02);
  write_summary(d / "I_0.1", 5, 400, 60.5, 0);
  write(d / "I_0.03" / "summary.toml", "wall_time = \"soon\"\n");  // damaged
  EXPECT_EQ(read_run_cost((d / "I_0.3").string()), std::nullopt);
  const auto c = read_run_cost((d / "I_0.01").string());
  ASSERT_TRUE(c);
  EXPECT_EQ(c->wall_time, 20.25);
  EXPECT_EQ(c->cpu_time, 40.5);
  EXPECT_EQ(c->steps, 2000);
  EXPECT_EQ(c->sweeps_per_step, 120);
  EXPECT_EQ(c->cap_share, 0.02);
  EXPECT_EQ(c->threads, 2);
  EXPECT_NE(message([&] { read_run_cost((d / "I_0.03").string()); }).find("is not a number"), std::string::npos);

  const auto s = write_report(d.string(), (d / "out").string());
  EXPECT_EQ(s.runs, 5u);
  EXPECT_EQ(s.steady, 5u);
  EXPECT_EQ(s.costed, 3u);
  EXPECT_DOUBLE_EQ(s.wall_time, 100.5 + 20.25 + 5);
  EXPECT_DOUBLE_EQ(s.cpu_time, 2 * (100.5 + 20.25 + 5));
  EXPECT_TRUE(std::any_of(s.problems.begin(), s.problems.end(),
                          [](const std::string& p) { return p.find("summary.toml") != std::string::npos; }));

  // steady.csv and fabric.csv: the cost columns, nan without a summary.
  // Runs are sorted by folder name: I_0.001, I_0.01, I_0.03, I_0.1, I_0.3.
  for (const char* f : {"steady.csv", "fabric.csv"}) {
    SCOPED_TRACE(f);
    const auto t = Table::read_csv((d / "out" / f).string(), true);
    ASSERT_EQ(t.rows(), 5u);
    const std::vector<double> wall = {100.5, 20.25, NAN, 5, NAN}, steps = {4000, 2000, NAN, 400, NAN},
                              sweeps = {250.25, 120, NAN, 60.5, NAN}, cap = {0.375, 0.02, NAN, 0, NAN};
    for (std::size_t i = 0; i < 5; ++i) {
      const auto eq = [&](const char* col, double want) {
        const double got = t.column(col)[i];
        if (std::isnan(want)) EXPECT_TRUE(std::isnan(got)) << col << " row " << i;
        else EXPECT_EQ(got, want) << col << " row " << i;
      };
      eq("wall_time", wall[i]);
      eq("steps", steps[i]);
      eq("sweeps_per_step", sweeps[i]);
      eq("cap_share", cap[i]);
    }
  }
  // runs.csv and index.html say n/a; the page gives the campaign's total.
  std::ifstream runs(d / "out" / "runs.csv");
  const std::string rtext((std::istreambuf_iterator<char>(runs)), {});
  EXPECT_NE(rtext.find("run,folder,status,wall_time,cpu_time,steps,sweeps_per_step,cap_share,threads\n"),
            std::string::npos) << rtext;
  EXPECT_NE(rtext.find("I_0.3\",ok,n/a,n/a,n/a,n/a,n/a,n/a\n"), std::string::npos) << rtext;
  EXPECT_NE(rtext.find("I_0.01\",ok,20.25,40.5,2000,120,0.02,2\n"), std::string::npos) << rtext;
  std::ifstream html(d / "out" / "index.html");
  const std::string h((std::istreambuf_iterator<char>(html)), {});
  EXPECT_NE(h.find("125.8 s of wall time"), std::string::npos) << h;
  EXPECT_NE(h.find("2 without one are not counted"), std::string::npos) << h;
  EXPECT_NE(h.find("<td>37.5 %</td>"), std::string::npos) << h;
  EXPECT_NE(h.find("<td>n/a</td>"), std::string::npos) << h;
  // Cost against I: the three points with a cost, by measured I.
  EXPECT_TRUE(s.cost_plot);
  const auto ci = Table::read_csv((d / "out" / "cost_I.csv").string());
  ASSERT_EQ(ci.rows(), 3u);
  EXPECT_EQ(ci.column("wall_time")[0], 100.5);
  EXPECT_NEAR(ci.column("I")[0], 1e-3, 1e-4);
  if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(s.plots_ok);
    EXPECT_TRUE(fs::exists(d / "out" / "cost_I.png"));
  }
}

TEST(AnalysisIo, CommandLineExitsNonZeroNamingTheFile) {
  const fs::path exe = fs::path(CDLAB_BINARY_DIR) / "analysis" / "cdanalysis";
  // make test builds every target first: a missing binary is a failure, not a skip.
  ASSERT_TRUE(fs::exists(exe)) << "cdanalysis not built: " << exe;
  const auto d = scratch("cli");
  make_run(d / "a", 0.3, 0.01, 3);
  const auto err = d / "err.txt";
  auto run = [&](const std::string& args) {
    const int rc = std::system(fmt::format("{} {} > /dev/null 2> {}", exe.string(), args, err.string()).c_str());
    std::ifstream in(err);
    return std::make_pair(rc, std::string((std::istreambuf_iterator<char>(in)), {}));
  };
  auto [rc, msg] = run(fmt::format("steady {}", (d / "missing").string()));
  EXPECT_NE(rc, 0);
  EXPECT_NE(msg.find("missing' does not exist"), std::string::npos) << msg;
  std::tie(rc, msg) = run(fmt::format("steady {} --column pressure", (d / "a").string()));
  EXPECT_NE(rc, 0);
  EXPECT_NE(msg.find("has no column 'pressure'"), std::string::npos) << msg;
  std::tie(rc, msg) = run(fmt::format("steady {} --window 1:1.05", (d / "a").string()));
  EXPECT_NE(rc, 0);
  EXPECT_NE(msg.find("at least 16"), std::string::npos) << msg;
  std::tie(rc, msg) = run(fmt::format("fabric {} --snapshot 4", (d / "a").string()));
  EXPECT_NE(rc, 0);
  EXPECT_NE(msg.find("snapshot 4 does not exist"), std::string::npos) << msg;
  std::tie(rc, msg) = run(fmt::format("steady {}", (d / "a").string()));
  EXPECT_EQ(rc, 0) << msg;
  std::tie(rc, msg) = run(fmt::format("fabric {} --volume 12", (d / "a").string()));
  EXPECT_EQ(rc, 0) << msg;
}

// ---- Bad input to the command line ------------------------------------------

namespace {

const fs::path& cda_exe() {
  static const fs::path exe = fs::path(CDLAB_BINARY_DIR) / "analysis" / "cdanalysis";
  return exe;
}

cdtest::CmdResult run_cda(const std::string& args) {
  return cdtest::run_command(fmt::format("'{}' {}", cda_exe().string(), args));
}

// A small fit table for the commands that take --table.
fs::path mu_table(const fs::path& dir) {
  const auto t = dir / "mu.csv";
  write(t, "I,mu,mu_err\n0.001,0.26,0.01\n0.01,0.3,0.01\n0.03,0.35,0.01\n0.1,0.42,0.01\n0.3,0.52,0.01\n");
  return t;
}

}  // namespace

// Every floating-point option of every subcommand refuses NaN and infinity
// by name with exit 2. CLI11's ranges let NaN through (every comparison with
// it is false), after which NaN meant "not given": --tol-sigma nan made
// compare-fits pass any change. The options are read from each command's
// --help, so an option added later is covered without editing this test.
TEST(AnalysisIo, EveryNumericOptionRefusesNanAndInfinity) {
  ASSERT_TRUE(fs::exists(cda_exe())) << "cdanalysis not built: " << cda_exe();
  const std::vector<std::string> commands = {"steady", "fabric", "profile", "report", "compare-fits",
                                             "fit mu-i", "fit cohesion", "fit dilatancy", "fit angularity",
                                             "fit nu-i", "fit compaction", "fit fabric-bounds"};
  std::size_t options = 0;
  for (const auto& c : commands) {
    const auto help = run_cda(c + " --help");
    ASSERT_EQ(help.code, 0) << c << ": " << help.out;
    std::istringstream lines(help.out);
    std::string line;
    while (std::getline(lines, line)) {
      std::istringstream words(line);
      std::string name, type;
      words >> name >> type;
      if (name.rfind("--", 0) != 0 || type.rfind("FLOAT", 0) != 0) continue;
      ++options;
      for (const char* bad : {"nan", "-nan", "inf", "1.8e308"}) {
        // Positionals given, so that only the option can be at fault.
        const auto r = run_cda(fmt::format("{} a b {} {}", c, name, bad));
        EXPECT_EQ(r.code, 2) << c << " " << name << " " << bad << ": " << r.out;
        EXPECT_NE(r.out.find(name), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("is not a finite number"), std::string::npos) << r.out;
        EXPECT_LT(r.out.size(), 400u) << "no 309-digit bound in the message: " << r.out;
      }
    }
  }
  // fabric --volume, fit compaction --p0, fit fabric-bounds --k,
  // compare-fits --tol-sigma and --tol-rel at least.
  EXPECT_GE(options, 5u);
}

TEST(AnalysisIo, CompareFitsWithNanToleranceIsRefusedNotPassed) {
  const auto d = scratch("cmp_nan");
  const auto t = mu_table(d);
  ASSERT_EQ(run_cda(fmt::format("fit mu-i --table {} --toml {}", t.string(), (d / "a.toml").string())).code, 0);
  // The same fit with mu1 moved by 41 of its sigmas.
  auto fa = read_fit_toml((d / "a.toml").string());
  std::ifstream in(d / "a.toml");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto& mu1 = fa.models.at("mu_I").params.at("mu1");
  const std::string from = fmt::format("value = {}", toml_num(mu1.value));
  ASSERT_NE(text.find(from), std::string::npos) << text;
  text.replace(text.find(from), from.size(), fmt::format("value = {}", toml_num(mu1.value + 41 * mu1.error)));
  write(d / "b.toml", text);
  const std::string ab = fmt::format("compare-fits {} {}", (d / "a.toml").string(), (d / "b.toml").string());
  EXPECT_EQ(run_cda(ab).code, 1);  // the shift FAILs
  for (const char* opt : {"--tol-sigma nan", "--tol-rel nan", "--tol-sigma -1"})
    EXPECT_EQ(run_cda(ab + " " + opt).code, 2) << opt;
}

// A TOML file that is not UTF-8 (fits, a run's scene.toml or summary.toml)
// is refused by file, line and byte before toml11 parses it (which read
// outside its buffer reporting such a string; tests/data/fuzz/fit/).
TEST(AnalysisIo, TomlThatIsNotUtf8IsRefusedByPosition) {
  const auto d = scratch("toml_utf8");
  write(d / "fits.toml", "[mu_I]\nnote = 'a\xA9'\n");
  try {
    read_fit_toml((d / "fits.toml").string());
    ADD_FAILURE() << "no InputError";
  } catch (const cda::InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("'{}' is not TOML text: invalid UTF-8 byte 0xa9 at line 2, byte 17",
                                                 (d / "fits.toml").string()));
  }
  write(d / "ok.toml", "# \xC3\xA9t\xC3\xA9\n[mu_I]\nformula = 'gr\xC3\xA4in'\nnames = [\"mu1\"]\n"
                       "[mu_I.params.mu1]\nvalue = 0.26\nerror = 0.002\n");
  EXPECT_EQ(read_fit_toml((d / "ok.toml").string()).models.at("mu_I").params.at("mu1").value, 0.26);
}

// Exit 2 (bad input), not 1 (refused), for what is the input's fault; a
// folder where a file should be is named as a folder; file content in a
// message never carries control bytes to the terminal.
TEST(AnalysisIo, BadInputExitsTwoWithAClearMessage) {
  const auto d = scratch("bad_cli");
  make_run(d / "a", 0.3, 0.01, 3);
  const auto t = mu_table(d);
  for (const char* w : {"1:x", "2:1", "50%:1", "nan:1", ":"}) {
    const auto r = run_cda(fmt::format("steady {} --window '{}'", (d / "a").string(), w));
    EXPECT_EQ(r.code, 2) << w << ": " << r.out;
    EXPECT_NE(r.out.find("window"), std::string::npos) << r.out;
  }
  // An unwritable --toml is refused before anything is done or written.
  const auto r = run_cda(fmt::format("fit mu-i --table {} --toml {} --out {}", t.string(),
                                 (d / "no" / "such" / "x.toml").string(), (d / "plot").string()));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("does not exist"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "plot"));
  // Folders given as files.
  fs::create_directories(d / "dir.csv");
  auto f = run_cda(fmt::format("fit mu-i --table {}", (d / "dir.csv").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("is a folder, not a file"), std::string::npos) << f.out;
  f = run_cda(fmt::format("compare-fits {} {}", (d / "dir.csv").string(), (d / "dir.csv").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("is a folder, not a file"), std::string::npos) << f.out;
  fs::create_directories(d / "b" / "series.csv");
  f = run_cda(fmt::format("steady {}", (d / "b").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("is a folder, not a file"), std::string::npos) << f.out;
  // Binary junk in a table: shown escaped.
  write(d / "junk.csv", std::string("I,mu\n0.1,\x1b[2J\x07\xff\xfe\n"));
  f = run_cda(fmt::format("fit mu-i --table {}", (d / "junk.csv").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  for (const char c : f.out)
    EXPECT_TRUE(c == '\n' || (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f)) << "byte " << int(c);
  EXPECT_NE(f.out.find("\\x1B[2J\\x07\\xFF\\xFE"), std::string::npos) << f.out;
  // An empty text value is refused, not taken for the default (--column '' was q_over_p).
  f = run_cda(fmt::format("steady {} --column ''", (d / "a").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("--column: an empty value"), std::string::npos) << f.out;
  f = run_cda(fmt::format("fit mu-i --table {} --toml ''", t.string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("--toml: an empty value"), std::string::npos) << f.out;
  // A volume so small that the stress is inf: refused, as the scenes' +-1e100 rule refuses it.
  f = run_cda(fmt::format("fabric {} --volume 4.9e-324", (d / "a").string()));
  EXPECT_EQ(f.code, 2) << f.out;
  EXPECT_NE(f.out.find("--volume"), std::string::npos) << f.out;
}

// A series whose last row is cut, which repeats a step or whose time runs
// backwards is refused with file and line: rows of a cut file or of two
// runs mixed would bias every window average.
TEST(AnalysisIo, SeriesRowsMustBeWholeAndGoForward) {
  const auto d = scratch("series_rows");
  const std::string head = "step,time,strain,q_over_p\n";
  std::string good = head;
  for (int i = 0; i < 50; ++i) good += fmt::format("{},{},{},0.3\n", 10 * i, i / 10.0, i / 100.0);
  const auto expect_refused = [&](const std::string& name, const std::string& text, const std::string& what) {
    fs::create_directories(d / name);
    write(d / name / "series.csv", text);
    const std::string m = message([&] { read_series((d / name).string()); });
    EXPECT_NE(m.find(what), std::string::npos) << name << ": " << m;
    const auto r = run_cda(fmt::format("steady {} --column q_over_p", (d / name).string()));
    EXPECT_EQ(r.code, 2) << name << ": " << r.out;
  };
  fs::create_directories(d / "ok");
  write(d / "ok" / "series.csv", good);
  EXPECT_EQ(read_series((d / "ok").string()).rows(), 50u);
  expect_refused("cut", good + "500,5,0.5,0.2", "series.csv' line 52: the last row is cut");
  expect_refused("repeated", good + "490,5.0,0.5,0.3\n", "line 52: step 490 repeats the previous row's 490 (line 51)");
  expect_refused("backwards", good + "500,4.8,0.5,0.3\n", "line 52: time 4.8 is before the previous row's 4.9");
}

// Analyses never dead-end: over a campaign with a run that
// has no steady window and one whose series is damaged, the report is
// written with both listed and exits 5 (kExitPartial: written with
// reservations), fit mu-i leaves them out by name and fits the others
// (exit 5), and the same campaign without them exits 0. A fit the data do
// not determine is written and flagged: the undetermined parameters in the
// TOML, the page and the legend, or, refused, the reason in the TOML.
TEST(AnalysisIo, ReportAndFitsNeverDeadEnd) {
  const auto d = scratch("never_dead_end");
  const double I[] = {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3};
  for (int k = 0; k < 6; ++k)
    make_run(d / "camp" / fmt::format("I_{}", I[k]), 0.28 + 0.34 / (1 + 0.05 / I[k]), I[k], 40 + k);
  EXPECT_EQ(run_cda(fmt::format("report {} --out {}", (d / "camp").string(), (d / "r0").string())).code, 0);
  // A run still drifting at its end, and a run whose series is damaged.
  fs::create_directories(d / "camp" / "I_drift");
  std::string csv = "step,time,strain,q_over_p,inertial_number\n";
  for (int i = 0; i < 300; ++i) csv += fmt::format("{},{},{},{},0.05\n", i, i / 10.0, i / 100.0, 0.2 + 0.001 * i);
  write(d / "camp" / "I_drift" / "series.csv", csv);
  fs::create_directories(d / "camp" / "I_bad");
  write(d / "camp" / "I_bad" / "series.csv", "step,time,strain,q_over_p\n0,0,0,0.3\n1,0.1,0.01,x\n");

  const auto rep = run_cda(fmt::format("report {} --out {}", (d / "camp").string(), (d / "r").string()));
  EXPECT_EQ(rep.code, kExitPartial) << rep.out;
  EXPECT_NE(rep.out.find("2 of 8 runs left out"), std::string::npos) << rep.out;
  std::ifstream runs(d / "r" / "runs.csv");
  const std::string rtext((std::istreambuf_iterator<char>(runs)), {});
  EXPECT_NE(rtext.find("I_drift\",not steady"), std::string::npos) << rtext;
  EXPECT_NE(rtext.find("I_bad\",unreadable"), std::string::npos) << rtext;
  EXPECT_TRUE(fs::exists(d / "r" / "fits.toml"));
  EXPECT_NE(read_fit_toml((d / "r" / "fits.toml").string()).models.count("mu_I"), 0u);

  const auto fit = run_cda(fmt::format("fit mu-i {} --toml {}", (d / "camp").string(), (d / "mu.toml").string()));
  EXPECT_EQ(fit.code, kExitPartial) << fit.out;
  EXPECT_NE(fit.out.find("I_drift: left out: "), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("2 runs left out"), std::string::npos) << fit.out;
  const auto mu = read_fit_toml((d / "mu.toml").string());
  // The six good runs alone give the same fit as the report's.
  EXPECT_EQ(mu.models.at("mu_I").params.at("mu1").value,
            read_fit_toml((d / "r" / "fits.toml").string()).models.at("mu_I").params.at("mu1").value);

  // Undetermined: four points at small I, flat within their errors, say
  // nothing of where mu(I) bends (I0).
  write(d / "flat.csv", "I,mu,mu_err\n0.001,0.30,0.01\n0.002,0.31,0.01\n0.003,0.30,0.01\n0.004,0.31,0.01\n");
  const auto flat = run_cda(fmt::format("fit mu-i --table {} --toml {} --out {}", (d / "flat.csv").string(),
                                    (d / "flat.toml").string(), (d / "flat").string()));
  std::ifstream ft(d / "flat.toml");
  const std::string ftext((std::istreambuf_iterator<char>(ft)), {});
  if (flat.code == kExitPartial) {  // fitted, parameters flagged
    EXPECT_NE(ftext.find("undetermined = ["), std::string::npos) << ftext;
    EXPECT_NE(ftext.find("\"I0\"]"), std::string::npos) << ftext;
    EXPECT_NE(flat.out.find("what would determine them"), std::string::npos) << flat.out;
  } else {  // refused: the reason in the TOML, the points drawn
    EXPECT_EQ(flat.code, 1) << flat.out;
    EXPECT_NE(ftext.find("determined = false"), std::string::npos) << ftext;
    EXPECT_NE(flat.out.find("what would determine it"), std::string::npos) << flat.out;
  }
  EXPECT_TRUE(fs::exists(d / "flat" / "mu_I_data.csv"));
}
