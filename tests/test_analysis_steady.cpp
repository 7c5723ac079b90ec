// Steady-state statistics on AR(1) series, whose time correlation is known:
// x_t = phi x_{t-1} + e_t, Var x = s^2, rho(t) = phi^t,
//   Var(mean of N) -> s^2/N (1 + phi)/(1 - phi),   tau_int = (1 + phi)/(2(1 - phi)).
// For blocks of B samples the exact variance of a block mean is
//   s^2/B [(1 + phi)/(1 - phi) - 2 phi (1 - phi^B)/(B (1 - phi)^2)],
// so the blocking estimate at the chosen B can be compared both with that
// exact value (scatter only) and with the asymptotic value (plus its bias).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/src/steady.hpp"

using namespace cda;

namespace {
std::vector<double> ar1(std::size_t n, double phi, double s, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> G(0, 1);
  const double se = s * std::sqrt(1 - phi * phi);
  std::vector<double> x(n);
  x[0] = s * G(rng);  // start in the stationary distribution
  for (std::size_t i = 1; i < n; ++i) x[i] = phi * x[i - 1] + se * G(rng);
  return x;
}
}  // namespace

TEST(AnalysisSteady, BlockingErrorOfAr1MatchesAnalytic) {
  const std::size_t n = 1 << 17;
  const double s = 2.0;
  for (double phi : {0.0, 0.5, 0.9}) {
    const auto x = ar1(n, phi, s, 2024);
    const auto b = block_average(x);
    ASSERT_TRUE(b.converged) << phi;
    const double N = static_cast<double>(n), B = static_cast<double>(b.block_size);
    const double asym = std::sqrt(s * s / N * (1 + phi) / (1 - phi));
    const double exact_B = std::sqrt(
        s * s / N * ((1 + phi) / (1 - phi) - 2 * phi * (1 - std::pow(phi, B)) / (B * (1 - phi) * (1 - phi))));
    // 3 of the reported error of the error (relative 1/sqrt(2(n_B - 1))).
    EXPECT_NEAR(b.sem, exact_B, 3 * b.sem_err) << "phi " << phi << " B " << B;
    EXPECT_NEAR(b.sem, asym, 3 * b.sem_err + (asym - exact_B)) << "phi " << phi;
    // Mean of a zero-mean series: within 4 analytic sem.
    EXPECT_NEAR(b.mean, 0.0, 4 * asym);
  }
}

TEST(AnalysisSteady, IntegratedAutocorrelationTimeOfAr1) {
  const std::size_t n = 1 << 17;
  for (double phi : {0.0, 0.5, 0.9}) {
    const auto x = ar1(n, phi, 1.0, 7);
    const auto a = autocorrelation_time(x);
    ASSERT_TRUE(a.converged);
    const double tau = (1 + phi) / (2 * (1 - phi));
    // Sokal's window truncates at W ~ 5 tau, a bias of phi^W/(1-phi) relative
    // (< 1% for phi <= 0.9), inside 3 of the Madras-Sokal error.
    EXPECT_NEAR(a.tau, tau, 3 * a.tau_err + 0.01 * tau) << phi;
    EXPECT_NEAR(a.n_eff, static_cast<double>(n) / (2 * tau), 0.1 * static_cast<double>(n) / (2 * tau));
  }
  // rho of the direct (non-circular) sum: rho(1) of 0 1 0 1 ... (mean 1/2)
  // is -(n-1)/n exactly.
  std::vector<double> alt(64);
  for (std::size_t i = 0; i < alt.size(); ++i) alt[i] = static_cast<double>(i % 2);
  EXPECT_NEAR(autocorrelation(alt)[1], -63.0 / 64.0, 1e-12);
}

TEST(AnalysisSteady, DetectsWindowAfterTransient) {
  // q/p-like series: 0.3 + 0.5 exp(-x/0.5) + AR(1) noise (sd 0.02, phi 0.8)
  // over x in [0, 10). What matters is that the transient left inside the
  // window biases its mean by less than 2 of its error bars; the bias is
  // known exactly here.
  const std::size_t n = 4000;
  const auto noise = ar1(n, 0.8, 0.02, 11);
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 10.0 * static_cast<double>(i) / static_cast<double>(n);
    y[i] = 0.3 + 0.5 * std::exp(-x[i] / 0.5) + noise[i];
  }
  const auto w = detect_steady_window(x, y);
  EXPECT_LE(w.x_begin, 8.0);  // at most the shortest candidate (last 20%)
  EXPECT_GT(w.x_begin, 0.5);  // not the whole run
  EXPECT_EQ(w.end, n);
  const auto st = steady_stats(x, y, w);
  double bias = 0;
  for (std::size_t i = w.begin; i < w.end; ++i) bias += 0.5 * std::exp(-x[i] / 0.5);
  bias /= static_cast<double>(w.end - w.begin);
  EXPECT_LT(bias, 2 * st.error()) << "window from " << w.x_begin;
  EXPECT_NEAR(st.mean, 0.3 + bias, 4 * st.error());
  // A stationary series keeps (almost) all of its length: the first
  // candidate start (row 0) passes.
  std::vector<double> flat(noise.begin(), noise.end());
  EXPECT_EQ(detect_steady_window(x, flat).begin, 0u);
}

TEST(AnalysisSteady, DriftingSeriesAndShortWindowsAreRejected) {
  std::vector<double> x(200), y(200);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = static_cast<double>(i);
    y[i] = 0.01 * x[i] + 1e-3 * std::sin(static_cast<double>(i));
  }
  try {
    detect_steady_window(x, y, {}, "q_over_p");
    FAIL() << "no throw";
  } catch (const AnalysisError& e) {
    EXPECT_NE(std::string(e.what()).find("q_over_p: no steady window"), std::string::npos) << e.what();
  }
  // 10 rows: too few for any window.
  std::vector<double> xs(x.begin(), x.begin() + 10), ys(10, 1.0);
  EXPECT_THROW(detect_steady_window(xs, ys), AnalysisError);
  // A strongly correlated but flat series: too few independent samples.
  const auto slow = ar1(200, 0.995, 1.0, 3);
  try {
    detect_steady_window(x, slow, {}, "z");
    FAIL() << "no throw";
  } catch (const AnalysisError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(m.find("too short") != std::string::npos || m.find("no steady window") != std::string::npos) << m;
  }
  // A given window of fewer than 16 rows cannot carry an error bar.
  const auto w = window_from_range(x, 10, 20);
  EXPECT_EQ(w.end - w.begin, 11u);
  EXPECT_THROW(steady_stats(x, y, w, "q_over_p"), AnalysisError);
  EXPECT_THROW(window_from_range(x, 500, 600), AnalysisError);
}
