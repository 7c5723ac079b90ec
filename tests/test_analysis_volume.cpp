// Rheology from runs at imposed volume (shear.control = "volume"): the
// packing fraction is set, exact, and p and I are measured (the series'
// inertial_number). The same laws as at imposed pressure: mu(I) against the
// measured I, and nu = nu_max - a I, which at imposed volume is fitted in I,
// I = (nu_max - nu)/a, weighted by I's error bars (nu has none).
//   - the fit on synthetic points with a known law: nu_max and a recovered,
//     and their GSL errors right (the pulls over many replicas);
//   - synthetic run folders as cdsim writes them at imposed volume
//     (scene.toml with [shear] control = "volume", inertial_number 0; a
//     series whose I follows sigma_yy): the measured I is read, not the
//     scene's 0; `fit mu-i`, `fit nu-i` and `report` recover the law;
//   - runs at imposed volume and at imposed pressure are not fitted together.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "analysis/src/compare.hpp"
#include "analysis/src/fit.hpp"
#include "analysis/src/trends.hpp"
#include "analysis_synth.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

// The law: 2D disks as the reference campaign measured them
// (tests/data/regress: phi 0.8084 at I = 0.01, 0.7809 at 0.1; mu(I) of its
// stored fit).
constexpr double kPhiC = 0.812, kA = 0.30;
constexpr double kMu1 = 0.28, kMu2 = 0.89, kI0 = 0.34;
double I_of(double phi) { return (kPhiC - phi) / kA; }

// ---- the fit alone ------------------------------------------------------------

// 400 replicas of five runs at phi = 0.76 ... 0.80, each I drawn about the
// law with a 3 % error bar. For a model linear in its parameters the
// weighted least-squares pull (estimate - truth)/error is a unit normal
// when the error is the propagated one; the reported error is scaled up by
// max(1, chi2/dof) (fit.hpp), which with dof = 3 gives E[pull^2] =
// E[1/max(1, chi2_3/3)] = 0.858 (rms 0.926) and P(|pull| < 2) = 0.966
// (sampled numerically). I = (nu_max - nu)/a is linear in (nu_max/a, 1/a):
// at 3 % errors the linearisation is good to well below these bounds.
// Bounds at about 4 standard errors of the 400-replica estimates: mean pull
// within 0.2 (sd 0.046), mean pull^2 in [0.62, 1.1] (sd ~0.06), the share
// with |pull| < 2 at least 0.92 (sd 0.009).
TEST(VolumeFit, RecoversPhiCAndAWithinTheirErrors) {
  const std::vector<double> phi = {0.76, 0.77, 0.78, 0.79, 0.80};
  synth::Normal G(20261127);
  const int n = 400;
  double sum[2] = {0, 0}, sum2[2] = {0, 0};
  int within2[2] = {0, 0};
  for (int k = 0; k < n; ++k) {
    std::vector<double> I, sI;
    for (double f : phi) {
      const double s = 0.03 * I_of(f);
      sI.push_back(s);
      I.push_back(I_of(f) + s * G());
    }
    const cda::FitResult r = cda::fit_nu_I_volume(phi, I, sI);
    ASSERT_TRUE(r.converged) << k;
    ASSERT_EQ(r.model, "nu_I");
    const double pull[2] = {(r["nu_max"] - kPhiC) / r.err("nu_max"), (r["a"] - kA) / r.err("a")};
    for (int j = 0; j < 2; ++j) {
      sum[j] += pull[j];
      sum2[j] += pull[j] * pull[j];
      within2[j] += std::abs(pull[j]) < 2;
    }
  }
  for (int j = 0; j < 2; ++j) {
    const char* name = j ? "a" : "nu_max";
    EXPECT_LT(std::abs(sum[j] / n), 0.2) << name;
    EXPECT_GT(sum2[j] / n, 0.62) << name;
    EXPECT_LT(sum2[j] / n, 1.1) << name;
    EXPECT_GE(within2[j], 0.92 * n) << name;
  }
}

// The same law fitted in nu at imposed pressure (I exact, nu's error a
// times I's) and in I at imposed volume gives the same parameters: on
// noiseless points both are exact.
TEST(VolumeFit, TheSameLawAsAtImposedPressure) {
  const std::vector<double> phi = {0.74, 0.77, 0.80};
  std::vector<double> I, sI, snu;
  for (double f : phi) I.push_back(I_of(f)), sI.push_back(0.01), snu.push_back(kA * 0.01);
  const cda::FitResult v = cda::fit_nu_I_volume(phi, I, sI);
  const cda::FitResult p = cda::fit_nu_I(I, phi, snu);
  EXPECT_NEAR(v["nu_max"], kPhiC, 1e-9);
  EXPECT_NEAR(v["a"], kA, 1e-8);
  EXPECT_NEAR(p["nu_max"], kPhiC, 1e-9);
  EXPECT_NEAR(p["a"], kA, 1e-8);
  EXPECT_EQ(v.model, p.model);
  EXPECT_EQ(v.names, p.names);
}

// ---- run folders at imposed volume ------------------------------------------------

// 2D disks of d = 1 mm, rho = 2.6 kg/m^2, sheared at rate_tp = 0.03 at the
// pressure scale 100 N/m (make campaign-volume's units): gamma-dot = 0.03 /
// t_p, t_p = d sqrt(rho/p).
constexpr double kD = 1e-3, kRho = 2.6, kP = 100.0, kRateTp = 0.03;
const double kTp = kD * std::sqrt(kRho / kP), kGd = kRateTp / kTp;

// A run at phi: sigma_yy + K_yy = rho d^2 gd^2 / I^2 (the Bagnold scaling
// that defines the measured I), with 10 % AR(1) noise (a = 0.5, tau = 1.5
// rows) shared by syy and the kinetic kyy (1 % of it); every row's
// inertial_number computed from that row's stress as cdsim does
// (gd d sqrt(rho/(syy + kyy))); q_over_p = mu(I) + 0.01 noise; the packing
// fraction constant (the cell held).
void write_volume_run(const fs::path& dir, double phi, std::uint64_t seed, bool volume = true) {
  fs::create_directories(dir);
  synth::Normal G(seed);
  const double I = I_of(phi), sigma = kRho * kD * kD * kGd * kGd / (I * I);
  const double mu = synth::mu_of_I(kMu1, kMu2, kI0, I);
  const double a = 0.5, b = std::sqrt(1 - a * a);
  double es = G(), em = G();
  std::ofstream csv(dir / "series.csv");
  csv << "step,time,strain,shear_rate,syy,kyy,p,q_over_p,inertial_number,packing_fraction\n";
  for (int i = 0; i < 300; ++i) {
    const double gamma = 0.01 * i, total = sigma * (1 + 0.1 * es);
    csv << fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", i, gamma / kGd, gamma,
                       kGd, 0.99 * total, 0.01 * total, 0.99 * total, mu + 0.01 * em,
                       kGd * kD * std::sqrt(kRho / total), phi);
    es = a * es + b * G();
    em = a * em + b * G();
  }
  std::ofstream(dir / "scene.toml") << fmt::format(
      "# Synthetic run (tests/test_analysis_volume.cpp): the keys the analysis reads.\n"
      "[contact]\ncohesion_number = 0.0\n\n[particles]\nd_mean = {}\ndensity = {}\n\n"
      "[shear]\nmode = \"periodic\"\ncontrol = \"{}\"\npressure = {}\ninertial_number = {}\nrate_tp = {}\n"
      "volume_fraction = {}\n",
      kD, kRho, volume ? "volume" : "pressure", kP, volume ? 0.0 : I, volume ? kRateTp : 0.0, volume ? phi : 0.0);
}

const std::vector<double> kPhis = {0.70, 0.72, 0.74, 0.76, 0.78, 0.80, 0.805};

fs::path volume_campaign(const std::string& name) {
  const fs::path c = cdtest::scratch_dir("test_analysis_volume", name) / "volume";
  for (std::size_t k = 0; k < kPhis.size(); ++k)
    write_volume_run(c / fmt::format("phi_{}", kPhis[k]), kPhis[k], 100 + k);
  return c;
}

const fs::path kExe = fs::path(CDLAB_BINARY_DIR) / "analysis" / "cdanalysis";

// A fit's parameter (value and error) from a fits TOML.
cda::FitParam param(const fs::path& file, const std::string& model, const std::string& name) {
  const cda::FitFile f = cda::read_fit_toml(file.string());
  return f.models.at(model).params.at(name);
}

// Each run's state point: the measured I (from <sigma_yy + K_yy>), within
// 4 error bars of the law's (the error bar, from block averaging over ~20
// blocks, is itself uncertain by ~15 %), not the scene's 0; no imposed I;
// phi exact (its block error is round-off, 1e-17, not a weight).
TEST(VolumeRuns, TheMeasuredInertialNumberIsRead) {
  const fs::path c = volume_campaign("points");
  for (double phi : kPhis) {
    const cda::StatePoint s = cda::state_point((c / fmt::format("phi_{}", phi)).string());
    EXPECT_TRUE(s.volume) << phi;
    EXPECT_TRUE(std::isnan(s.I_imposed)) << phi << ": the scene's inertial_number 0 is not an imposed I";
    EXPECT_GT(s.I.err, 0) << phi;
    EXPECT_NEAR(s.I.v, I_of(phi), 4 * s.I.err) << phi;
    EXPECT_NEAR(s.nu.v, phi, 1e-12);
    EXPECT_LT(s.nu.err, 1e-12) << phi << ": constant to round-off, no weight";
  }
}

// fit nu-i and fit mu-i on the campaign folder: the law back within 3
// sigma (nu_max, a: of nu(I); mu1, mu2, I0: of mu(I), over I = 0.02-0.37,
// which determines them, as the reference campaign's 0.01-0.4 does).
TEST(VolumeRuns, FitsRecoverTheLaw) {
  const fs::path c = volume_campaign("fits");
  const fs::path out = c.parent_path();
  const auto nu = cdtest::run_command(kExe.string() + " fit nu-i " + c.string() + " --toml " +
                                      (out / "nu_i.toml").string());
  ASSERT_EQ(nu.code, 0) << nu.out;
  EXPECT_NE(nu.out.find("imposed volume"), std::string::npos) << nu.out;
  const cda::FitParam nm = param(out / "nu_i.toml", "nu_I", "nu_max"), a = param(out / "nu_i.toml", "nu_I", "a");
  EXPECT_NEAR(nm.value, kPhiC, 3 * nm.error) << nu.out;
  EXPECT_NEAR(a.value, kA, 3 * a.error) << nu.out;
  EXPECT_LT(nm.error, 0.01) << nu.out;
  EXPECT_LT(a.error, 0.1 * kA) << nu.out;

  const auto mu = cdtest::run_command(kExe.string() + " fit mu-i " + c.string() + " --toml " +
                                      (out / "mu_i.toml").string());
  ASSERT_EQ(mu.code, 0) << mu.out;
  for (const auto& [name, truth] : {std::pair{"mu1", kMu1}, std::pair{"mu2", kMu2}, std::pair{"I0", kI0}}) {
    const cda::FitParam p = param(out / "mu_i.toml", "mu_I", name);
    EXPECT_NEAR(p.value, truth, 3 * p.error) << name << "\n" << mu.out;
  }
}

// The report finds the campaign's kind from the runs (volume_fraction
// varies, no imposed I: the measured I spans a factor 16) and fits both
// laws into fits.toml, nu(I) in I.
TEST(VolumeRuns, TheReportFitsTheVolumeSeries) {
  const fs::path c = volume_campaign("report");
  const fs::path out = c.parent_path() / "analysis";
  const auto r = cdtest::run_command(kExe.string() + " report " + c.string() + " --out " + out.string());
  ASSERT_TRUE(r.code == 0 || r.code == 5) << r.out;
  EXPECT_NE(r.out.find("volume series"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("pressure series"), std::string::npos) << r.out;
  const cda::FitParam nm = param(out / "fits.toml", "nu_I", "nu_max");
  EXPECT_NEAR(nm.value, kPhiC, 3 * nm.error);
  EXPECT_NE(cdtest::slurp(out / "fits.toml").find("formula = \"nu = nu_max - a I, fitted as I"), std::string::npos);
  const cda::FitParam mu1 = param(out / "fits.toml", "mu_I", "mu1");
  EXPECT_NEAR(mu1.value, kMu1, 3 * mu1.error);
}

// A run at imposed pressure among runs at imposed volume: the two fits of
// nu(I) differ (which variable carries the error), so they are refused
// together, naming a run of each.
TEST(VolumeRuns, PressureAndVolumeRunsAreNotFittedTogether) {
  const fs::path c = volume_campaign("mixed");
  write_volume_run(c / "pressure_run", 0.78, 7, false);
  const auto nu = cdtest::run_command(kExe.string() + " fit nu-i " + c.string());
  EXPECT_EQ(nu.code, 1) << nu.out;
  EXPECT_NE(nu.out.find("pressure_run' at imposed pressure"), std::string::npos) << nu.out;
  EXPECT_NE(nu.out.find("fit them apart"), std::string::npos) << nu.out;
}

}  // namespace
