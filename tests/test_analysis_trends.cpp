// Fits across the runs of a campaign (analysis/src/trends.hpp) on synthetic
// runs whose answers are known: an angularity campaign with mu*(alpha) =
// mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)), nu*(alpha) linear, contact
// snapshots of known anisotropy, sliding and side-side shares; runs at
// several I with nu(I) = nu_max - b I; runs at several p with
// e = e0 - lambda ln(p/p0). Series noise is AR(1) (analysis_synth.hpp) of
// known size, so the steady error bars are tested through the 3-sigma
// recovery. Also: degenerate inputs are refused, and `cdanalysis report`
// on the angularity campaign writes the table, the fit and the plots.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "analysis/src/report.hpp"
#include "analysis/src/scene_info.hpp"
#include "analysis/src/snapshot.hpp"
#include "analysis/src/trends.hpp"
#include "config.hpp"
#include "analysis_synth.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

constexpr double kPi = std::numbers::pi;
const fs::path exe = fs::path(CDLAB_BINARY_DIR) / "analysis" / "cdanalysis";
fs::path scratch(const std::string& name) { return cdtest::scratch_dir("test_analysis_trends", name); }

// Truth of the angularity campaign.
constexpr double kMu0 = 0.28, kMu1 = 0.52, kAlphaC = 0.7;
double mu_true(double a) { return kMu0 + (kMu1 - kMu0) * (1 - std::exp(-a / kAlphaC)); }
double nu_true(double a) { return 0.82 - 0.04 * a; }
double ac_true(double a) { return 0.25 + 0.1 * a; }
constexpr double kAfn = 0.3, kAft = 0.08, kFriction = 0.4;

struct Series {
  double mu = 0.3, nu = 0.8, z = 3.5, p = 100, I = 0.01;
  double noise_mu = 0.02, noise_nu = 0.003, noise_z = 0.05, noise_p = 3;
  int rows = 400;
  std::uint64_t seed = 1;
};

// series.csv with AR(1) noise (a = 0.5: tau_int = 1.5 rows) on every column.
void write_series(const fs::path& dir, const Series& s) {
  fs::create_directories(dir);
  synth::Normal G(s.seed);
  const double a = 0.5, b = std::sqrt(1 - a * a);
  double e[4] = {G(), G(), G(), G()};
  std::ofstream csv(dir / "series.csv");
  csv << "step,time,strain,q_over_p,packing_fraction,z,p,inertial_number\n";
  for (int i = 0; i < s.rows; ++i) {
    const double g = 0.01 * i;
    csv << fmt::format("{},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", i, g, g, s.mu + s.noise_mu * e[0],
                       s.nu + s.noise_nu * e[1], s.z + s.noise_z * e[2], s.p + s.noise_p * e[3], s.I);
    for (double& x : e) x = a * x + b * G();
  }
}

void write_scene(const fs::path& dir, int nsides_in_scene, double I, double p) {
  std::ofstream(dir / "scene.toml") << fmt::format(
      "# synthetic (test_analysis_trends)\n[contact]\nmu = {}\ncohesion_number = 0\n\n[solver]\ntol = 1e-4\n\n"
      "[particles]\nnsides = [{}]\n\n[shear]\npressure = {}\ninertial_number = {}\n",
      kFriction, nsides_in_scene, p, I);
}

// K contact snapshots: M contacts at the quantiles of P(theta) = (1 + a_c
// cos 2(theta - th0))/2pi over [0, pi) (th0 = 135 deg), <fn> and <ft> of
// the harmonic forms; every 5th contact slides (|ft| = mu fn, status 2);
// for polygons every 3rd is side-side, the others side-vertex. A
// particles snapshot with the true nsides goes beside each.
void write_snapshots(const fs::path& dir, int nsides, double a_c, int K, std::uint64_t seed) {
  synth::Normal G(seed);
  const int M = 600;
  const double th0 = 0.75 * kPi;
  for (int s = 0; s < K; ++s) {
    const double ac = a_c + 0.01 * G();  // snapshot-to-snapshot scatter
    ContactSet cs;
    for (int k = 0; k < M; ++k) {
      const double u = (k + 0.5) / M * kPi;  // F(theta) pi = theta + (a/2)(sin 2(theta - th0) + sin 2 th0)
      double th = u;
      for (int it = 0; it < 50; ++it) {
        const double F = th + 0.5 * ac * (std::sin(2 * (th - th0)) + std::sin(2 * th0)) - u;
        th -= F / (1 + ac * std::cos(2 * (th - th0)));
      }
      Contact c;
      c.theta = th;
      c.lx = 1e-3 * std::cos(th);
      c.ly = 1e-3 * std::sin(th);
      c.fn = 1 + kAfn * std::cos(2 * (th - th0));
      c.ft = -kAft * std::sin(2 * (th - th0));
      c.status = 1;
      if (k % 5 == 0) {
        c.ft = (c.ft >= 0 ? 1 : -1) * kFriction * c.fn;
        c.status = 2;
      }
      c.type = nsides == 0 ? 0 : (k % 3 == 0 ? 2 : 1);
      c.b1 = k;
      c.b2 = M + k;
      cs.push_back(c);
    }
    write_contacts((dir / fmt::format("contacts_{:05d}.vtp", s)).string(), cs, {});
    ParticleSet ps;
    for (int i = 0; i < 2 * M; ++i) {
      Particle p;
      p.id = i;
      p.radius = 5e-4;
      p.nsides = nsides;
      ps.push_back(p);
    }
    write_particles((dir / fmt::format("particles_{:05d}.vtp", s)).string(), ps);
  }
}

// The campaign: shapes ns, each a run; the scene says nsides = 0 (as a
// shear run started from a checkpoint does): alpha must come from the
// particles snapshots.
fs::path angularity_campaign(const std::string& name, const std::vector<int>& shapes) {
  const auto dir = scratch(name);
  std::uint64_t seed = 11;
  int idx = 0;
  for (int n : shapes) {
    const auto run = dir / fmt::format("r{}_ns_{}", idx++, n);
    const double a = angularity_of(n);
    Series s;
    s.mu = mu_true(a);
    s.nu = nu_true(a);
    s.z = 3.2 + 0.5 * a;
    s.seed = seed++;
    write_series(run, s);
    write_scene(run, 0, 0.01, 100);
    write_snapshots(run, n, ac_true(a), 4, seed++);
  }
  return dir;
}

}  // namespace

TEST(AnalysisTrends, AngularityRecoversTheLawAndTheTable) {
  const auto dir = angularity_campaign("angularity", {0, 3, 4, 5, 6, 8, 10, 20});
  std::vector<AngularityPoint> pts;
  for (const auto& r : campaign_runs(dir.string())) pts.push_back(angularity_point(r));
  ASSERT_EQ(pts.size(), 8u);
  for (const auto& a : pts) {
    SCOPED_TRACE(a.run);
    EXPECT_EQ(a.alpha_source, "particles snapshot");
    EXPECT_NEAR(a.alpha, angularity_of(a.nsides), 1e-15);
    // Series means within 3 of their steady error bars; the error bars of
    // the right size (AR(1), tau 1.5 rows: sd sqrt(3/rows) over the window).
    EXPECT_NEAR(a.mu.v, mu_true(a.alpha), 3 * a.mu.err);
    EXPECT_NEAR(a.nu.v, nu_true(a.alpha), 3 * a.nu.err);
    EXPECT_GT(a.mu.err, 0.3 * 0.02 * std::sqrt(3.0 / 400));
    EXPECT_LT(a.mu.err, 3.0 * 0.02 * std::sqrt(3.0 / 80));
    // Fabric from the 4 snapshots (mean +- sem).
    EXPECT_EQ(a.snapshots, 4u);
    EXPECT_NEAR(a.a_c.v, ac_true(a.alpha), 0.02);
    EXPECT_GT(a.a_c.err, 0);
    EXPECT_NEAR(a.a_fn.v, kAfn, 0.03);
    EXPECT_NEAR(a.a_ln.v, 0, 0.01);  // every branch along n, of one length
    EXPECT_NEAR(a.a_lt.v, 0, 0.01);
    // The check q/p ~ (sum a)/2: both sums near the snapshots' q/p.
    EXPECT_NEAR(a.sum_half_tensor.v, a.q_over_p_snap.v, 0.03);
    EXPECT_NEAR(a.sum_half_fft.v, a.q_over_p_snap.v, 0.05);
    // Every 5th contact on the cone: the Coulomb test and the flag agree.
    EXPECT_NEAR(a.sliding.v, 0.2, 1e-9);
    EXPECT_NEAR(a.sliding_flag.v, 0.2, 1e-9);
    EXPECT_DOUBLE_EQ(a.sliding_tol, 1e-4);
    if (a.nsides == 0) {
      EXPECT_EQ(a.ss_share.v, 0);
      EXPECT_TRUE(std::isnan(a.q_sv.v));
      EXPECT_TRUE(std::isnan(a.q_ss.v));
    } else {
      EXPECT_NEAR(a.ss_share.v, 1.0 / 3, 0.002);
      EXPECT_GT(a.q_sv.v, a.q_ss.v);  // 2/3 of the contacts, same mobilisation
    }
  }
  const auto r = fit_angularity(pts);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r["mu0"], kMu0, 3 * r.err("mu0"));
  EXPECT_NEAR(r["mu1"], kMu1, 3 * r.err("mu1"));
  EXPECT_NEAR(r["alpha_c"], kAlphaC, 3 * r.err("alpha_c"));
  EXPECT_LT(r.err("alpha_c"), 0.5 * kAlphaC);  // determined, not just wide
  EXPECT_NEAR(r.chi2_dof, 1.0, 4 * std::sqrt(2.0 / r.dof));

  const auto t = angularity_table(pts);
  EXPECT_EQ(t.rows(), 8u);
  for (const char* c : {"alpha", "mu", "mu_err", "nu_err", "z", "a_c", "a_ft_err", "sliding", "ss_share",
                        "q_sv_over_p", "sum_half_fft", "sum_half_tensor"})
    EXPECT_TRUE(t.has(c)) << c;
}

TEST(AnalysisTrends, AngularityRefusesDegenerateInput) {
  // Two shapes: 2 distinct alpha for 3 parameters.
  const auto two = angularity_campaign("two_shapes", {0, 6, 6});
  std::vector<AngularityPoint> pts;
  for (const auto& r : campaign_runs(two.string())) pts.push_back(angularity_point(r));
  EXPECT_THROW(fit_angularity(pts), AnalysisError);
  const auto res = cdtest::run_command(fmt::format("'{}' fit angularity '{}'", exe.string(), two.string()));
  EXPECT_EQ(res.code, 1) << res.out;
  EXPECT_NE(res.out.find("distinct"), std::string::npos) << res.out;

  // A run mixing shapes has no single angularity.
  const auto mixed = scratch("mixed") / "run";
  write_series(mixed, {});
  write_scene(mixed, 6, 0.01, 100);
  write_snapshots(mixed, 6, 0.3, 1, 3);
  auto ps = read_particles((mixed / "particles_00000.vtp").string());
  ps[0].nsides = 3;
  write_particles((mixed / "particles_00000.vtp").string(), ps);
  EXPECT_THROW(angularity_point(mixed.string()), AnalysisError);
  // No snapshots and no nsides in the scene: unknown angularity.
  const auto bare = scratch("bare") / "run";
  write_series(bare, {});
  std::ofstream(bare / "scene.toml") << "[contact]\nmu = 0.4\n";
  EXPECT_THROW(angularity_point(bare.string()), AnalysisError);
}

TEST(AnalysisTrends, NuOfIAndCompactionFromRuns) {
  const auto dir = scratch("nu_i");
  const double nu_max = 0.815, b = 0.35;
  std::uint64_t seed = 101;
  for (double I : {0.001, 0.003, 0.01, 0.03, 0.1, 0.2}) {
    Series s;
    s.I = I;
    s.nu = nu_max - b * I;
    s.seed = seed++;
    const auto run = dir / fmt::format("I_{}", I);
    write_series(run, s);
    write_scene(run, 0, I, 100);
  }
  std::vector<StatePoint> pts;
  for (const auto& r : campaign_runs(dir.string())) pts.push_back(state_point(r));
  const auto r = fit_nu_I_points(pts);
  EXPECT_NEAR(r["nu_max"], nu_max, 3 * r.err("nu_max"));
  EXPECT_NEAR(r["a"], b, 3 * r.err("a"));
  EXPECT_LT(r.err("a"), 0.1 * b);

  // Compaction: e = e0 - lambda ln(p/p0) at p = 10 .. 1000.
  const auto cdir = scratch("compaction");
  const double e0 = 0.24, lambda = 0.012, p0 = 100;
  for (double p : {10.0, 30.0, 100.0, 300.0, 1000.0}) {
    Series s;
    s.p = p;
    s.noise_p = 0.02 * p;
    s.nu = 1 / (1 + e0 - lambda * std::log(p / p0));
    s.seed = seed++;
    const auto run = cdir / fmt::format("p_{}", p);
    write_series(run, s);
    write_scene(run, 0, 0.001, p);
  }
  std::vector<StatePoint> cp;
  for (const auto& run : campaign_runs(cdir.string())) cp.push_back(state_point(run));
  const auto c = fit_compaction_points(cp, p0);
  EXPECT_NEAR(c["e0"], e0, 3 * c.err("e0"));
  EXPECT_NEAR(c["lambda"], lambda, 3 * c.err("lambda"));
  EXPECT_LT(c.err("lambda"), 0.2 * lambda);
  // One pressure only: refused.
  std::vector<StatePoint> one(cp.begin(), cp.begin() + 1);
  one.push_back(cp[0]);
  EXPECT_THROW(fit_compaction_points(one, p0), AnalysisError);

  // The command line: exit 0 and the parameters printed; plots written.
  const auto out = scratch("compaction_out");
  auto res = cdtest::run_command(fmt::format("'{}' fit compaction '{}' --p0 100 --out '{}' --toml '{}'", exe.string(),
                                             cdir.string(), out.string(), (out / "c.toml").string()));
  EXPECT_EQ(res.code, 0) << res.out;
  EXPECT_NE(res.out.find("lambda"), std::string::npos) << res.out;
  EXPECT_TRUE(fs::exists(out / "compaction.gp"));
  EXPECT_TRUE(fs::exists(out / "c.toml"));
  res = cdtest::run_command(fmt::format("'{}' fit nu-i '{}' --out '{}'", exe.string(), dir.string(), out.string()));
  EXPECT_EQ(res.code, 0) << res.out;
  EXPECT_TRUE(fs::exists(out / "nu_I.gp"));
  const std::string one_run = (dir / "I_0.01").string();
  res = cdtest::run_command(fmt::format("'{}' fit nu-i '{}' '{}'", exe.string(), one_run, one_run));
  EXPECT_EQ(res.code, 1) << res.out;  // one distinct I for two parameters
}

TEST(AnalysisTrends, ReportOnAnAngularityCampaign) {
  const auto dir = angularity_campaign("report", {0, 3, 4, 6, 10, 20});
  const auto out = dir / "report";
  const auto s = write_report(dir.string(), out.string());
  ASSERT_EQ(s.kinds.size(), 1u);
  EXPECT_NE(s.kinds[0].find("angularity"), std::string::npos);
  EXPECT_EQ(s.angularity, 6u);
  ASSERT_EQ(s.fits, std::vector<std::string>{"mu_alpha"});  // no mu(I): one I
  const auto t = Table::read_csv((out / "angularity.csv").string(), true);
  EXPECT_EQ(t.rows(), 6u);
  std::ifstream f(out / "fits.toml");
  const std::string toml((std::istreambuf_iterator<char>(f)), {});
  EXPECT_NE(toml.find("[mu_alpha]"), std::string::npos);
  EXPECT_EQ(toml.find("[mu_I]"), std::string::npos);
  for (const auto& stem : kAngularityPlots) {
    EXPECT_TRUE(fs::exists(out / (stem + ".gp"))) << stem;
    EXPECT_TRUE(fs::exists(out / (stem + ".png"))) << stem << " (gnuplot: " << s.plots_ok << ")";
    std::ifstream g(out / (stem + ".gp"));
    const std::string gp((std::istreambuf_iterator<char>(g)), {});
    EXPECT_NE(gp.find("# made by: cdanalysis report"), std::string::npos) << stem;
  }
  EXPECT_TRUE(fs::exists(out / "angularity_mu_fit.csv"));
  std::ifstream h(out / "index.html");
  const std::string html((std::istreambuf_iterator<char>(h)), {});
  EXPECT_NE(html.find("<h3>Angularity</h3>"), std::string::npos);
  EXPECT_NE(html.find("angularity_mu.png"), std::string::npos);
  EXPECT_NE(html.find("cdanalysis fit angularity"), std::string::npos);
}

// The shape as cdsim records it: the resolved scene.toml that cdsim writes
// (cd::resolved_toml) lists particles.nsides as floats ([6.0]); the analysis
// must read it as 6 (a real campaign's runs were all skipped otherwise).
TEST(AnalysisTrends, ReadsTheShapeFromCdsimsResolvedScene) {
  const fs::path d = cdtest::scratch_dir("analysis_trends", "resolved");
  for (const double n : {0.0, 6.0, 20.0}) {
    cd::Scene s;
    s.nsides = {n};
    std::ofstream(d / "scene.toml") << cd::resolved_toml(s);
    EXPECT_EQ(cda::read_scene_info(d.string()).nsides, static_cast<int>(n));
  }
  cd::Scene mixed;
  mixed.nsides = {0.0, 6.0};
  std::ofstream(d / "scene.toml") << cd::resolved_toml(mixed);
  EXPECT_TRUE(cda::read_scene_info(d.string()).nsides_mixed);
}
