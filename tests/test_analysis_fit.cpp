// Each fit recovers known parameters from noisy synthetic data (fixed seed)
// within 3 of its reported uncertainties (a 3-sigma test: for a correct
// error estimate one parameter out of ~370 fails by chance), and its
// chi2/dof is compatible with 1 (within 4 sqrt(2/dof)).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/src/fabric_bounds.hpp"
#include "analysis/src/fit.hpp"

using namespace cda;

namespace {
void expect_recovered(const FitResult& r, const std::vector<double>& truth) {
  ASSERT_TRUE(r.converged) << r.model << ": " << r.message;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_GT(r.error[i], 0) << r.model << " " << r.names[i];
    EXPECT_NEAR(r.value[i], truth[i], 3 * r.error[i]) << r.model << " " << r.names[i];
  }
  EXPECT_NEAR(r.chi2_dof, 1.0, 4 * std::sqrt(2.0 / r.dof)) << r.model;
}
}  // namespace

TEST(AnalysisFit, MuOfI) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> G(0, 1);
  const std::vector<double> truth = {0.28, 0.62, 0.05};
  std::vector<double> I, mu, s;
  for (int k = 0; k < 20; ++k) {
    const double i = 1e-4 * std::pow(10.0, 3.5 * k / 19.0);  // 1e-4 .. 0.3
    const double sig = 0.004 + 0.02 * i;                      // faster runs are noisier
    I.push_back(i);
    s.push_back(sig);
    mu.push_back(truth[0] + (truth[1] - truth[0]) / (1 + truth[2] / i) + sig * G(rng));
  }
  const auto r = fit_mu_I(I, mu, s);
  expect_recovered(r, truth);
  EXPECT_GE(r.scale, 1.0);
  // The band: predict_error at the data is below the data's own error bars
  // (20 points constrain 3 parameters).
  for (std::size_t k = 0; k < I.size(); ++k) EXPECT_LT(predict_error(mu_of_I(), r, &I[k]), s[k]);
}

TEST(AnalysisFit, NuOfIAndVoidRatioUnweighted) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> G(0, 1);
  std::vector<double> I, nu, p, e;
  for (int k = 0; k < 15; ++k) {
    I.push_back(0.01 + 0.02 * k);
    nu.push_back(0.82 - 0.3 * I.back() + 0.002 * G(rng));
    p.push_back(std::pow(10.0, -1 + 0.25 * k));
    e.push_back(0.25 - 0.03 * std::log(p.back() / 1.0) + 0.003 * G(rng));
  }
  // Without error bars the errors come from the residuals (scale = chi2/dof),
  // so chi2/dof is not a test; only the parameters are.
  const auto a = fit_nu_I(I, nu, {});
  EXPECT_NEAR(a["nu_max"], 0.82, 3 * a.err("nu_max"));
  EXPECT_NEAR(a["a"], 0.3, 3 * a.err("a"));
  EXPECT_DOUBLE_EQ(a.scale, a.chi2_dof);
  const auto b = fit_void_ratio(p, e, {}, 1.0);
  EXPECT_NEAR(b["e0"], 0.25, 3 * b.err("e0"));
  EXPECT_NEAR(b["lambda"], 0.03, 3 * b.err("lambda"));
  // Residual-based errors agree with the noise: sd 0.003 over 15 points.
  EXPECT_NEAR(std::sqrt(b.chi2 / b.dof), 0.003, 0.0015);
}

TEST(AnalysisFit, Cohesion) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> G(0, 1);
  const std::vector<double> truth = {0.12, 0.8, 0.5};  // k0, beta, alpha
  std::vector<double> eta, I, c, s;
  for (double et : {0.5, 1.0, 2.0, 5.0, 10.0, 20.0})
    for (double i : {1e-3, 1e-2, 0.05, 0.1, 0.2, 0.4}) {
      const double Ic = i / std::sqrt(1 + truth[2] * et);
      const double v = truth[0] * et / (1 - truth[1] * std::log(1 - Ic));
      const double sig = 0.02 * v + 0.002;
      eta.push_back(et);
      I.push_back(i);
      s.push_back(sig);
      c.push_back(v + sig * G(rng));
    }
  expect_recovered(fit_cohesion(eta, I, c, s), truth);
}

TEST(AnalysisFit, DilatancyAndMuOfAlpha) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> G(0, 1);
  std::vector<double> sp, sf, s1, al, mu, s2;
  for (int k = 0; k < 12; ++k) {
    sp.push_back(-0.1 + 0.02 * k);
    s1.push_back(0.01);
    sf.push_back(0.35 + sp.back() + 0.01 * G(rng));
    al.push_back(0.05 * k);
    s2.push_back(0.005);
    mu.push_back(0.25 + (0.45 - 0.25) * (1 - std::exp(-al.back() / 0.15)) + 0.005 * G(rng));
  }
  expect_recovered(fit_dilatancy(sp, sf, s1), {0.35});
  expect_recovered(fit_dilatancy(sp, sf, s1, true), {0.35, 1.0});
  expect_recovered(fit_mu_alpha(al, mu, s2), {0.25, 0.45, 0.15});
}

TEST(AnalysisFit, BadInputIsRejected) {
  const std::vector<double> x = {1, 2}, y = {1, 2};
  EXPECT_THROW(fit_mu_I(x, y, {}), AnalysisError);  // 2 points, 3 parameters
  const std::vector<double> x3 = {0.1, 0.2, 0.3}, y3 = {1, 2, 3}, bad = {0.1, 0.0, 0.1};
  EXPECT_THROW(fit_mu_I(x3, y3, bad), AnalysisError);  // zero error bar
  const std::vector<double> neg = {-0.1, 0.2, 0.3};
  EXPECT_THROW(fit_mu_I(neg, y3, {}), AnalysisError);
}

TEST(AnalysisFabricBounds, EnvelopeIsTightAndClosedForm) {
  // Points drawn strictly inside the envelope of z_min = 3, z_max = 5 (k = 1),
  // plus one point on each branch: the envelope is recovered exactly.
  const double zmin = 3, zmax = 5;
  FabricBounds truth;
  truth.z_min = zmin;
  truth.z_max = zmax;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<double> z, a;
  for (int k = 0; k < 200; ++k) {
    const double zz = zmin + (zmax - zmin) * U(rng);
    z.push_back(zz);
    a.push_back(0.95 * truth.a_max(zz) * U(rng));
  }
  z.push_back(3.5);
  a.push_back(1 - zmin / 3.5);  // on the left branch
  z.push_back(4.6);
  a.push_back(zmax / 4.6 - 1);  // on the right branch
  const auto b = fabric_bounds(z, a);
  EXPECT_NEAR(b.z_min, zmin, 1e-12);
  EXPECT_NEAR(b.z_max, zmax, 1e-12);
  EXPECT_EQ(b.i_min, 200u);
  EXPECT_EQ(b.i_max, 201u);
  EXPECT_NEAR(b.z_star(), 4.0, 1e-12);
  EXPECT_NEAR(b.a_star(), 0.25, 1e-12);
  EXPECT_NEAR(b.a_max(4.0), 0.25, 1e-12);
  for (std::size_t i = 0; i < z.size(); ++i) EXPECT_LE(a[i], b.a_max(z[i]) + 1e-12);
  // k = 2 normalisation: same points give z_min = min z (1 - a/2).
  const auto b2 = fabric_bounds(z, a, {}, {}, 2.0);
  EXPECT_GT(b2.z_min, b.z_min);
  for (std::size_t i = 0; i < z.size(); ++i) EXPECT_LE(a[i], b2.a_max(z[i]) + 1e-12);
  // Error propagation from the extremal point: dz_min = hypot((1-a) dz, z da).
  const std::vector<double> ze(z.size(), 0.1), ae(z.size(), 0.01);
  const auto be = fabric_bounds(z, a, ze, ae);
  EXPECT_NEAR(be.z_min_err, std::hypot((1 - a[200]) * 0.1, 3.5 * 0.01), 1e-12);
  EXPECT_THROW(fabric_bounds({}, {}), AnalysisError);
}
