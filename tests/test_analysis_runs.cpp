// Fits from run folders: stress-dilatancy over the rows of shear runs and
// cohesion against an eta = 0 reference, on synthetic runs with known
// answers (analysis_synth.hpp), and the errors for missing input.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "analysis/src/cohesion.hpp"
#include "analysis/src/dilatancy.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/scene_info.hpp"
#include "analysis_synth.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

fs::path scratch(const std::string& name) { return cdtest::scratch_dir("test_analysis_runs", name); }

std::string message(const std::function<void()>& f) {
  try {
    f();
  } catch (const AnalysisError& e) {
    return e.what();
  }
  return "<no AnalysisError>";
}

const fs::path exe = fs::path(CDLAB_BINARY_DIR) / "analysis" / "cdanalysis";

}  // namespace

TEST(AnalysisRuns, SinPsiConvention) {
  EXPECT_DOUBLE_EQ(sin_psi(0, 1), 0);
  EXPECT_NEAR(sin_psi(1, 1), std::sqrt(0.5), 1e-15);   // dilation: positive
  EXPECT_NEAR(sin_psi(-1, 1), -std::sqrt(0.5), 1e-15);
  EXPECT_DOUBLE_EQ(sin_psi(0.3, -2), sin_psi(0.3, 2));  // shear direction does not matter
  // Inverse used by the generator: d = g s/sqrt(1 - s^2).
  const double s = 0.27, g = 3;
  EXPECT_NEAR(sin_psi(g * s / std::sqrt(1 - s * s), g), s, 1e-15);
}

// A dense run (dilating transient) and a loose one (contracting), sin phi_c
// = 0.3. The fixed-slope fit recovers it within 3 sigma, the free slope is 1
// within 3 sigma, and over 24 seeds the pulls (fit - truth)/error have an
// rms near 1: the error bars are honest despite AR(1)-correlated rows.
TEST(AnalysisRuns, DilatancyRecoversCriticalFrictionWithHonestErrors) {
  const auto d = scratch("dilatancy");
  double sum2 = 0, sum2b = 0;
  const int seeds = 24;
  for (int k = 0; k < seeds; ++k) {
    std::vector<RunDilatancy> runs;
    for (double psi0 : {0.25, -0.15}) {
      synth::RunSpec s;
      s.mu = 0.3;
      s.psi0 = psi0;
      s.gamma0 = 0.5;
      s.rows = 400;
      s.seed = 1000 + 2 * k + (psi0 > 0);
      const auto dir = d / fmt::format("s{}_{}", k, psi0 > 0 ? "dense" : "loose");
      synth::write_run(dir, s);
      runs.push_back(run_dilatancy(dir.string(), read_series(dir.string())));
      // The loose run's transient is small next to the noise: R ~ 0.6-0.9.
      EXPECT_GT(runs.back().reliability, 0.4);
      // tau_int 1.5 rows: ceil(4 tau) ~ 6, but Sokal's estimate over 200
      // rows scatters by ~40%.
      EXPECT_GE(runs.back().block_rows, 3u);
      EXPECT_LE(runs.back().block_rows, 16u);
    }
    const auto f = fit_dilatancy_runs(runs);
    ASSERT_TRUE(f.fixed.converged && f.free.converged);
    const double pull = (f.fixed["sin_phi_c"] - 0.3) / f.fixed.err("sin_phi_c");
    const double pullb = (f.free["b"] - 1) / f.free.err("b");
    if (k == 0) {
      EXPECT_LT(std::abs(pull), 3);
      EXPECT_LT(std::abs(pullb), 3);
      if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
        EXPECT_TRUE(plot_dilatancy((d / "plot").string(), f));
        EXPECT_TRUE(fs::exists(d / "plot" / "dilatancy.png"));
        EXPECT_TRUE(fs::exists(d / "plot" / "dilatancy.svg"));
      }
    }
    sum2 += pull * pull;
    sum2b += pullb * pullb;
  }
  // rms of 24 unit normals: 1 +- 0.15; [0.6, 1.5] allows ~3 sigma and
  // catches error bars off by the factor sqrt(2 tau) ~ 1.7 of ignoring
  // the correlation.
  const double rms = std::sqrt(sum2 / seeds), rmsb = std::sqrt(sum2b / seeds);
  std::printf("rms pull: sin_phi_c %.3f, b %.3f (%d seeds)\n", rms, rmsb, seeds);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.5);
  EXPECT_GT(rmsb, 0.6);
  EXPECT_LT(rmsb, 1.5);
}

TEST(AnalysisRuns, DilatancyNamesMissingColumnsAndShortRuns) {
  const auto d = scratch("dilatancy_bad");
  synth::RunSpec s;
  s.rows = 20;
  synth::write_run(d / "short", s);
  EXPECT_NE(message([&] { run_dilatancy((d / "short").string(), read_series((d / "short").string())); })
                .find("20 rows with a shear rate, at least 32"),
            std::string::npos);
  fs::create_directories(d / "old");
  std::ofstream(d / "old" / "series.csv") << "step,time,q_over_p\n0,0,0.3\n1,1,0.3\n";
  EXPECT_NE(message([&] { run_dilatancy((d / "old").string(), read_series((d / "old").string())); })
                .find("no column 'volume_strain_rate'"),
            std::string::npos);
}

// eta = 0 runs on mu(I) and cohesive runs with q/p = sin phi + (c/p) cos phi,
// c/p from the model with known k0, beta, alpha: the command recovers them.
TEST(AnalysisRuns, CohesionFromRunsRecoversTheModel) {
  const auto d = scratch("cohesion");
  const double mu1 = 0.26, mu2 = 0.6, I0 = 0.08;
  const double k0 = 0.12, beta = 0.8, alpha = 0.5;
  std::uint64_t seed = 77;
  for (double I : {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3}) {
    synth::RunSpec s;
    s.I = I;
    s.mu = synth::mu_of_I(mu1, mu2, I0, I);
    s.seed = seed++;
    synth::write_run(d / fmt::format("eta_0_I_{:g}", I), s);
  }
  for (double eta : {1.0, 3.0, 10.0})
    for (double I : {2e-3, 2e-2, 0.1, 0.25}) {
      synth::RunSpec s;
      s.I = I;
      s.eta = eta;
      s.mu = synth::mu_of_I(mu1, mu2, I0, I);
      s.c_over_p = synth::cohesion_model(k0, beta, alpha, eta, I);
      s.seed = seed++;
      synth::write_run(d / fmt::format("eta_{:g}_I_{:g}", eta, I), s);
    }
  ASSERT_TRUE(fs::exists(exe)) << "cdanalysis not built: " << exe;
  const auto toml = (d / "fit.toml").string();
  auto r = cdtest::run_command(fmt::format("'{}' fit cohesion '{}' --toml '{}' --out '{}'", exe.string(),
                                           d.string(), toml, (d / "out").string()));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("sin phi(I) by the mu(I) fit"), std::string::npos) << r.out;
  // The library path, for the numbers.
  std::vector<SteadyPoint> ref, coh;
  for (const auto& e : fs::directory_iterator(d))
    if (fs::exists(e.path() / "series.csv")) {
      const auto p = steady_point(e.path().string());
      (p.eta == 0 ? ref : coh).push_back(p);
    }
  ASSERT_EQ(ref.size(), 6u);
  ASSERT_EQ(coh.size(), 12u);
  for (auto mode : {SinPhiReference::Mode::Auto, SinPhiReference::Mode::Interp}) {
    const SinPhiReference sr(ref, mode);
    std::vector<double> eta, I, c, ce;
    for (const auto& p : coh) {
      const auto cp = cohesion_point(p, sr);
      eta.push_back(p.eta);
      I.push_back(p.I);
      c.push_back(cp.c_over_p);
      ce.push_back(cp.c_over_p_err);
    }
    const auto f = fit_cohesion(eta, I, c, ce);
    ASSERT_TRUE(f.converged);
    if (mode == SinPhiReference::Mode::Auto) {
      EXPECT_TRUE(sr.uses_fit());
      EXPECT_NEAR(f["k0"], k0, 3 * f.err("k0"));
      EXPECT_NEAR(f["beta"], beta, 3 * f.err("beta"));
      EXPECT_NEAR(f["alpha"], alpha, 3 * f.err("alpha"));
    } else {
      // Interpolation in ln I between the reference runs is biased where
      // mu(I) curves; k0, fixed by the slow runs, is still recovered.
      EXPECT_FALSE(sr.uses_fit());
      EXPECT_NEAR(f["k0"], k0, 3 * f.err("k0"));
    }
  }
  if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(fs::exists(d / "out" / "cohesion.png")) << r.out;
  }
}

// Reference runs all in the linear part of mu(I) (I << I0: mu = 0.36 +
// 0.6 I exactly, as 3D runs up to I = 0.3 nearly are) do not determine mu2
// and I0: --reference mu-i refuses, and auto falls back to the
// interpolation in ln I instead of refusing the whole cohesion fit.
TEST(AnalysisRuns, CohesionReferenceAutoFallsBackWhenTheMuIFitIsUndetermined) {
  std::vector<SteadyPoint> ref;
  for (double I : {0.01, 0.03, 0.1, 0.3}) {
    SteadyPoint p;
    p.run = fmt::format("I_{:g}", I);
    p.dim = 3;
    p.I = I;
    p.I_err = 1e-4 * I;
    p.mu = 0.36 + 0.6 * I;
    p.mu_err = 0.005;
    ref.push_back(p);
  }
  EXPECT_THROW(SinPhiReference(ref, SinPhiReference::Mode::MuI), AnalysisError);
  const SinPhiReference sr(ref, SinPhiReference::Mode::Auto);
  EXPECT_FALSE(sr.uses_fit());
  // Linear in ln I between the runs at 0.03 and 0.1.
  const double I = 0.05, t = std::log(I / 0.03) / std::log(0.1 / 0.03);
  EXPECT_NEAR(sr.at(I, 0).sin_phi, (1 - t) * (0.36 + 0.6 * 0.03) + t * (0.36 + 0.6 * 0.1), 1e-12);
}

// When the runs do not determine the model (here two cohesive runs, one I,
// for three parameters) the command still writes the c/p points and their
// plot with --out, then refuses the fit (exit 1).
TEST(AnalysisRuns, CohesionPointsAreWrittenWhenTheModelIsRefused) {
  const auto d = scratch("cohesion_points");
  std::uint64_t seed = 5;
  for (double I : {0.005, 0.02, 0.08}) {
    synth::RunSpec s;
    s.I = I;
    s.mu = synth::mu_of_I(0.26, 0.6, 0.08, I);
    s.seed = seed++;
    synth::write_run(d / fmt::format("eta_0_I_{:g}", I), s);
  }
  for (double eta : {1.0, 3.0}) {
    synth::RunSpec s;
    s.I = 0.02;
    s.eta = eta;
    s.mu = synth::mu_of_I(0.26, 0.6, 0.08, 0.02);
    s.c_over_p = 0.1 * eta;
    s.seed = seed++;
    synth::write_run(d / fmt::format("eta_{:g}_I_0.02", eta), s);
  }
  ASSERT_TRUE(fs::exists(exe)) << "cdanalysis not built: " << exe;
  const auto out = d / "out";
  auto r = cdtest::run_command(fmt::format("'{}' fit cohesion '{}' --out '{}'", exe.string(), d.string(), out.string()));
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("refused"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(out / "cohesion_data.csv")) << r.out;
  const auto t = Table::read_csv((out / "cohesion_data.csv").string(), true);
  ASSERT_EQ(t.rows(), 2u);
  for (std::size_t i = 0; i < 2; ++i)  // c/p = 0.1 eta within the synthetic noise (4 error bars)
    EXPECT_NEAR(t.column("c_over_p")[i], 0.1 * t.column("eta")[i], 4 * t.column("c_over_p_err")[i]);
}

TEST(AnalysisRuns, CohesionWithoutReferenceOrSceneIsAClearError) {
  const auto d = scratch("cohesion_bad");
  synth::RunSpec s;
  s.eta = 2;
  s.c_over_p = 0.2;
  synth::write_run(d / "eta_2", s);
  ASSERT_TRUE(fs::exists(exe)) << "cdanalysis not built: " << exe;
  auto r = cdtest::run_command(fmt::format("'{}' fit cohesion '{}'", exe.string(), (d / "eta_2").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("no eta = 0 run among the given runs"), std::string::npos) << r.out;
  fs::remove(d / "eta_2" / "scene.toml");
  EXPECT_NE(message([&] { steady_point((d / "eta_2").string()); }).find("has no scene.toml"), std::string::npos);
  std::ofstream(d / "eta_2" / "scene.toml") << "[shear]\ninertial_number = 0.01\n";
  EXPECT_NE(message([&] { steady_point((d / "eta_2").string()); }).find("has no [contact] cohesion_number"),
            std::string::npos);
  std::ofstream(d / "eta_2" / "scene.toml") << "[contact]\ncohesion_number = 'x'\n";
  EXPECT_NE(message([&] { read_scene_info((d / "eta_2").string()); }).find("is not a number"), std::string::npos);
  std::ofstream(d / "eta_2" / "scene.toml") << "[contact\n";
  EXPECT_NE(message([&] { read_scene_info((d / "eta_2").string()); }).find("does not parse as TOML"),
            std::string::npos);
  // Integers are numbers: cohesion_number = 0 as written by hand.
  std::ofstream(d / "eta_2" / "scene.toml") << "[contact]\ncohesion_number = 0\n";
  EXPECT_EQ(*read_scene_info((d / "eta_2").string()).cohesion_number, 0.0);
}
