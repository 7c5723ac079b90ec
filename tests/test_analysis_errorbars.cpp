// Error bars of steady means and of the quantities derived from them,
// against synthetic series whose standard error is known in closed form.
//
// Noise: stationary AR(1) series of unit variance, u_t = a u_{t-1} +
// sqrt(1 - a^2) n_t, n_t from synth::Normal (mt19937_64 through Box-Muller,
// the same numbers on every platform). The exact variance of the mean of
// N consecutive values, rho(t) = a^|t|:
//   V(N) = (1/N) [(1 + a)/(1 - a) - 2 a (1 - a^N)/(N (1 - a)^2)].
// A sum of independent AR(1) series with the same a is again one, so a
// linear combination of such series has the same V(N) per unit variance.
//
// Each test draws M independent realisations (fixed seeds) and checks:
//   - the mean of the reported variance err^2 against the exact variance
//     of the estimate. The blocking estimate at block size B (n = N/B
//     blocks) has the exact expectation E[sem_B^2] = (V(B) - V(N))/(n - 1),
//     which at a = 0.8, N = 4096 is 0.93 V(N) (B = 64), 0.965 V(N) (128, the
//     size chosen here) and 0.98 V(N) (256): the blocks' own correlation
//     makes it read low by up to 7 %. One err^2 scatters by sqrt(2/(n - 1))
//     = 0.25 relative at n = 32, so the mean over M = 1000 by 0.8 %, and 3
//     of that is 2.4 %. Accepted: 0.90 <= <err^2>/V <= 1.03.
//   - the coverage: the share of realisations with |estimate - truth| <
//     k err, k = 1 and 2, against the normal's 0.683 and 0.954. A binomial
//     share of M = 1000 scatters by sqrt(c(1 - c)/M) (0.015, 0.0066); the
//     estimated error (n - 1 = 31 degrees of freedom, Student) and its
//     3.5-7 % low variance lower the coverage by at most 0.03 (k = 1) and
//     0.02 (k = 2). Accepted: within 3 binomial sigma plus that allowance.
// Measured: <err^2>/V 0.96-0.97, coverages 0.66-0.68 and 0.94-0.95.
// An error bar off by sqrt 2 (twice the variance) or one that ignores the
// time correlation (the rows taken as independent: 1/9 of the variance at
// a = 0.8) fails both checks by far (<err^2>/V 1.95 and 0.11, coverage at
// 1 error bar 0.26 for the latter).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "analysis/src/cohesion.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/table.hpp"
#include "analysis_synth.hpp"

using namespace cda;

namespace {

constexpr std::size_t kRows = 4096;
constexpr int kRealisations = 1000;
constexpr double kA = 0.8;  // tau_int = (1 + a)/(2(1 - a)) = 4.5 rows

// Variance of the mean of n values of a unit-variance AR(1) series.
double ar1_mean_variance(double a, double n) {
  return ((1 + a) / (1 - a) - 2 * a * (1 - std::pow(a, n)) / (n * (1 - a) * (1 - a))) / n;
}

// A stationary AR(1) series of unit variance.
class Ar1 {
 public:
  Ar1(double a, synth::Normal& g) : a_(a), b_(std::sqrt(1 - a * a)), g_(g), u_(g()) {}
  double next() {
    const double u = u_;
    u_ = a_ * u_ + b_ * g_();
    return u;
  }

 private:
  double a_, b_;
  synth::Normal& g_;
  double u_;
};

// The reported estimates of one quantity over M realisations, against its
// true value and the true standard error of its estimate.
struct Coverage {
  std::vector<double> z;     // (estimate - truth)/err
  std::vector<double> err2;  // err^2
  void add(double estimate, double truth, double err) {
    ASSERT_GT(err, 0);
    z.push_back((estimate - truth) / err);
    err2.push_back(err * err);
  }
  // The checks of the file's header, for an estimate of standard error se.
  void check(double se, const std::string& what) const {
    const double m = static_cast<double>(z.size());
    double mean_err2 = 0;
    for (double e : err2) mean_err2 += e / m;
    const double ratio = mean_err2 / (se * se);
    EXPECT_GE(ratio, 0.90) << what << ": mean reported variance / exact variance";
    EXPECT_LE(ratio, 1.03) << what << ": mean reported variance / exact variance";
    std::printf("[ %s ] <err^2>/V = %.4f", what.c_str(), ratio);
    for (const auto& [k, allowance] : {std::pair{1.0, 0.03}, std::pair{2.0, 0.02}}) {
      double inside = 0;
      for (double v : z) inside += std::abs(v) < k;
      const double share = inside / m, nominal = std::erf(k / std::sqrt(2.0));
      const double sigma = std::sqrt(nominal * (1 - nominal) / m);
      EXPECT_NEAR(share, nominal, 3 * sigma + allowance) << what << ": coverage at " << k << " error bars";
      std::printf(", coverage at %g: %.3f (normal %.3f)", k, share, nominal);
    }
    std::printf("\n");
  }
};

// x (strain, 0.001 a row) and the named columns.
Table series_of(const std::vector<std::string>& names, std::vector<std::vector<double>> cols) {
  std::vector<double> x(cols.front().size());
  for (std::size_t r = 0; r < x.size(); ++r) x[r] = 0.001 * static_cast<double>(r);
  Table t;
  t.add_column("strain", std::move(x));
  for (std::size_t j = 0; j < names.size(); ++j) t.add_column(names[j], std::move(cols[j]));
  return t;
}

// The steady mean of `column` over the whole series (a given window, as
// --window 0:x_last).
SteadyStats whole(const Table& t, const std::string& column) {
  const auto& x = t.column("strain");
  return run_steady("synthetic", t, column, "strain", std::pair{x.front(), x.back()}).stats;
}

// M realisations, each of two independent AR(1) series u and v (seed
// seed0 + k): `one` makes a run of them and returns its estimate and error
// bar, gathered against the truth.
template <class F>
Coverage realisations(std::uint64_t seed0, double truth, F&& one) {
  Coverage c;
  for (int k = 0; k < kRealisations; ++k) {
    synth::Normal g(seed0 + static_cast<std::uint64_t>(k));
    Ar1 u(kA, g), v(kA, g);
    const auto [estimate, err] = one(u, v);
    c.add(estimate, truth, err);
  }
  return c;
}

}  // namespace

// The steady mean of a series: its error bar against the exact standard
// error of the mean of correlated rows, sqrt(V(N)) s.
TEST(AnalysisErrorBars, SteadyMeanOfCorrelatedRows) {
  const double mu = 0.3, s = 0.02;
  const Coverage c = realisations(1000, mu, [&](Ar1& u, Ar1&) {
    std::vector<double> y(kRows);
    for (double& x : y) x = mu + s * u.next();
    const SteadyStats st = whole(series_of({"q_over_p"}, {y}), "q_over_p");
    return std::pair{st.mean, st.error()};
  });
  c.check(s * std::sqrt(ar1_mean_variance(kA, kRows)), "mean");
}

// mu* = <q/p>, the mean of the rows' ratio, q and p correlated with each
// other and in time: q = Q (1 + c_q w), p = P (1 + c_p u), u and w
// unit-variance AR(1) series with corr(u_t, w_t) = rho (w = rho u +
// sqrt(1 - rho^2) v, v independent). To first order (the delta method)
// q/p = R (1 + c_q w - c_p u), R = Q/P, an AR(1) series of variance
// R^2 (c_q^2 + c_p^2 - 2 rho c_q c_p), so the standard error of <q/p> is
// R sqrt((c_q^2 + c_p^2 - 2 rho c_q c_p) V(N)). The second-order terms add
// 2 c_p^4 to the rows' relative variance (0.4 % of it here, inside the
// tolerance). The true mean, to fourth order in the c's (the rest is 1e-6 of
// R, 1e-3 of an error bar): E[q/p] = R (1 + c_p^2 + 3 c_p^4 - rho c_q c_p
// (1 + 3 c_p^2)). An error propagated from q's and p's own error bars as
// if independent would take c_q^2 + c_p^2, 3.2 times the variance here.
TEST(AnalysisErrorBars, RatioOfCorrelatedSeries) {
  const double Q = 30, P = 100, cq = 0.05, cp = 0.04, rho = 0.7;
  const double R = Q / P;
  const double truth = R * (1 + cp * cp + 3 * std::pow(cp, 4) - rho * cq * cp * (1 + 3 * cp * cp));
  const Coverage c = realisations(5000, truth, [&](Ar1& u, Ar1& v) {
    std::vector<double> q(kRows), p(kRows), r(kRows);
    for (std::size_t i = 0; i < kRows; ++i) {
      const double ui = u.next(), wi = rho * ui + std::sqrt(1 - rho * rho) * v.next();
      q[i] = Q * (1 + cq * wi);
      p[i] = P * (1 + cp * ui);
      r[i] = q[i] / p[i];
    }
    const SteadyStats st = whole(series_of({"q", "p", "q_over_p"}, {q, p, r}), "q_over_p");
    return std::pair{st.mean, st.error()};
  });
  c.check(R * std::sqrt((cq * cq + cp * cp - 2 * rho * cq * cp) * ar1_mean_variance(kA, kRows)), "q/p");
}

// The measured inertial number I = gamma-dot d sqrt(rho/<sigma_yy>),
// sigma_yy = syy + kyy (run.hpp): a nonlinear function of a correlated
// mean. syy = S (1 + c_s u), kyy = K (1 + c_k v), u and v independent
// AR(1): <sigma_yy> has the standard error sqrt((S^2 c_s^2 + K^2 c_k^2)
// V(N)), and I = k <sigma_yy>^(-1/2) that times I/(2 (S + K)) (delta
// method; the curvature's bias, (3/8) I Var/(S + K)^2, is 1e-8 of I). The
// true I is k/sqrt(S + K); the series' inertial_number column is each
// row's k/sqrt(sigma_yy), whose mean is biased (run.hpp) by (3/8) I
// Var(sigma_yy)/(S + K)^2, 1.6 error bars here: taking it instead drops the
// coverage at 1 error bar to 0.27.
TEST(AnalysisErrorBars, MeasuredInertialNumber) {
  const double S = 100, K = 5, cs = 0.1, ck = 0.5, kI = 0.1;  // kI = gamma-dot d sqrt(rho)
  const double truth = kI / std::sqrt(S + K);
  const Coverage c = realisations(9000, truth, [&](Ar1& u, Ar1& v) {
    std::vector<double> syy(kRows), kyy(kRows), I(kRows);
    for (std::size_t i = 0; i < kRows; ++i) {
      syy[i] = S * (1 + cs * u.next());
      kyy[i] = K * (1 + ck * v.next());
      I[i] = kI / std::sqrt(syy[i] + kyy[i]);
    }
    const Table t = series_of({"syy", "kyy", "inertial_number"}, {syy, kyy, I});
    const auto& x = t.column("strain");
    const Estimate e = measured_inertial_number(t, "strain", window_from_range(x, x.front(), x.back()));
    return std::pair{e.mean, e.err};
  });
  const double se_sigma = std::sqrt((S * S * cs * cs + K * K * ck * ck) * ar1_mean_variance(kA, kRows));
  c.check(truth / (2 * (S + K)) * se_sigma, "I");
}

// The cohesion of fit cohesion (2D): c/p = (q/p - sin phi)/cos phi, from a
// cohesive run's <q/p> (m) and the eta = 0 run's (s = sin phi, one
// reference run at the same I: no slope term), both steady means of AR(1)
// series of independent runs. Delta method: Var(c/p) = Var(m)/cos^2 +
// ((m s - 1)/cos^3)^2 Var(s). The reference run is the noisier here (its
// term is 3.4 times the other), so an error that leaves it out fails
// (<err^2>/V 0.23).
TEST(AnalysisErrorBars, CohesionFromTwoRuns) {
  const double M = 0.6, S = 0.3, sm = 0.02, ss = 0.04;
  const double cphi = std::sqrt(1 - S * S);
  const double truth = (M - S) / cphi;
  const Coverage c = realisations(13000, truth, [&](Ar1& u, Ar1& v) {
    std::vector<double> ym(kRows), ys(kRows);
    for (std::size_t i = 0; i < kRows; ++i) {
      ym[i] = M + sm * u.next();
      ys[i] = S + ss * v.next();
    }
    const SteadyStats a = whole(series_of({"q_over_p"}, {ym}), "q_over_p");
    const SteadyStats b = whole(series_of({"q_over_p"}, {ys}), "q_over_p");
    SteadyPoint run, ref;
    run.eta = 1;
    run.I = ref.I = 0.01;
    run.I_err = ref.I_err = 1e-4;
    run.mu = a.mean;
    run.mu_err = a.error();
    ref.mu = b.mean;
    ref.mu_err = b.error();
    const CohesionPoint cp = cohesion_point(run, SinPhiReference({ref}, SinPhiReference::Mode::Auto));
    return std::pair{cp.c_over_p, cp.c_over_p_err};
  });
  const double V = ar1_mean_variance(kA, kRows);
  const double ds = (M * S - 1) / (cphi * cphi * cphi);
  c.check(std::sqrt(sm * sm * V / (cphi * cphi) + ds * ds * ss * ss * V), "c/p");
}
