// Anisotropies recovered from synthetic contact sets drawn with prescribed
// harmonic profiles (method.md §10), by the FFT and tensor methods.
//
// Tolerances are computed, not guessed: every estimated A = a exp(2 i theta)
// is a ratio of contact sums sum N_i / sum d_i, whose sampling error follows
// from its influence function u_i = (N_i - R d_i)/mean(d) as
// se = sqrt(sum |u_i - mean u|^2)/N. An anisotropy built from two such ratios
// (a_fn = |(A_c + A_fn) - A_c|) gets the sum of their se's (a bound: the two
// are positively correlated). Checks are at 4 se (the largest of ~20 normal
// deviates stays below 4 with probability 0.999); the direction error is
// se/(2a) radians.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "analysis/src/anisotropy.hpp"
#include "analysis/src/stress.hpp"

using namespace cda;
using cplx = std::complex<double>;
constexpr double pi = std::numbers::pi;

namespace {

struct Truth {
  double ac = 0.3, tc = 0.4;
  double aln = 0.1, tln = 0.4;
  double alt = 0.05, tlt = 0.4;
  double afn = 0.35, tfn = 0.45;
  double aft = 0.15, tft = 0.35;
  double L = 1.0, F = 2.0;
};

// Draws theta in [0, pi) from (1/pi)(1 + ac cos 2(theta - tc)) by rejection,
// then each quantity with its prescribed conditional mean plus noise: fn with
// a multiplicative uniform factor (mean 1), ft, l_n and l_t with additive
// zero-mean noise. Random body ids; theta is shifted by pi at random (the
// same contact seen from the other body) to check pi-periodicity.
ContactSet draw(const Truth& t, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> G(0, 1);
  ContactSet cs;
  cs.reserve(n);
  while (cs.size() < n) {
    const double th = pi * U(rng);
    if (U(rng) * (1 + t.ac) > 1 + t.ac * std::cos(2 * (th - t.tc))) continue;
    Contact c;
    const double fn = t.F * (1 + t.afn * std::cos(2 * (th - t.tfn))) * (0.5 + U(rng));
    const double ft = -t.F * t.aft * std::sin(2 * (th - t.tft)) + 0.2 * t.F * G(rng);
    const double ln = t.L * (1 + t.aln * std::cos(2 * (th - t.tln))) + 0.05 * t.L * G(rng);
    const double lt = -t.L * t.alt * std::sin(2 * (th - t.tlt)) + 0.05 * t.L * G(rng);
    c.theta = th + (U(rng) < 0.5 ? 0.0 : -pi);
    const double nx = std::cos(c.theta), ny = std::sin(c.theta);
    c.fn = fn;
    c.ft = ft;
    c.lx = ln * nx - lt * ny;
    c.ly = ln * ny + lt * nx;
    c.status = 1;
    c.type = 0;
    c.b1 = static_cast<int>(cs.size());
    c.b2 = c.b1 + 1;
    cs.push_back(c);
  }
  return cs;
}

// se of a ratio sum N_i / sum d_i (complex numerator).
template <class Num, class Den>
double ratio_se(const ContactSet& cs, Num num, Den den) {
  cplx sn = 0;
  double sd = 0;
  for (const auto& c : cs) {
    sn += num(c);
    sd += den(c);
  }
  const double n = static_cast<double>(cs.size());
  const cplx R = sn / sd;
  const double md = sd / n;
  std::vector<cplx> u;
  cplx mu = 0;
  for (const auto& c : cs) {
    u.push_back((num(c) - R * den(c)) / md);
    mu += u.back();
  }
  mu /= n;
  double s = 0;
  for (auto& v : u) s += std::norm(v - mu);
  return std::sqrt(s) / n;
}

cplx e2(const Contact& c) { return std::polar(2.0, 2 * c.theta); }
const cplx I1(0, 1);

struct Errors {
  double c, ln, lt, fn, ft;
};

Errors sampling_errors(const ContactSet& cs) {
  const double c = ratio_se(cs, [](auto& k) { return e2(k); }, [](auto&) { return 1.0; });
  const double cln = ratio_se(cs, [](auto& k) { return k.ln() * e2(k); }, [](auto& k) { return k.ln(); });
  const double lt = ratio_se(cs, [](auto& k) { return k.lt() * I1 * e2(k); }, [](auto& k) { return k.ln(); });
  const double cfn = ratio_se(cs, [](auto& k) { return k.fn * e2(k); }, [](auto& k) { return k.fn; });
  const double ft = ratio_se(cs, [](auto& k) { return k.ft * I1 * e2(k); }, [](auto& k) { return k.fn; });
  return {c, c + cln, lt, c + cfn, ft};
}

double angle_diff(double a, double b) {  // pi-periodic
  double d = std::fmod(a - b, pi);
  if (d > pi / 2) d -= pi;
  if (d < -pi / 2) d += pi;
  return std::abs(d);
}

void expect_harmonic(const Harmonic& h, double a, double theta, double se, const char* what) {
  EXPECT_NEAR(h.a(), a, 4 * se) << what;
  EXPECT_LT(angle_diff(h.theta(), theta), 4 * se / (2 * a)) << what << " theta " << h.theta();
}

}  // namespace

TEST(AnalysisAnisotropy, RecoversPrescribedHarmonicsBothWays) {
  const Truth t;
  const auto cs = draw(t, 200000, 12345);
  const auto se = sampling_errors(cs);
  for (const auto& a : {anisotropy_tensor(cs), anisotropy_fft(cs, 36)}) {
    expect_harmonic(a.c, t.ac, t.tc, se.c, "a_c");
    expect_harmonic(a.ln, t.aln, t.tln, se.ln, "a_ln");
    expect_harmonic(a.lt, t.alt, t.tlt, se.lt, "a_lt");
    expect_harmonic(a.fn, t.afn, t.tfn, se.fn, "a_fn");
    expect_harmonic(a.ft, t.aft, t.tft, se.ft, "a_ft");
    // <f_n> of the harmonic form (orientation average), 0.5% from its value:
    // the multiplicative noise has relative sd 0.29, over 2e5 contacts the
    // se of the mean is 0.07%.
    EXPECT_NEAR(a.mean_fn, t.F, 0.005 * t.F);
    EXPECT_NEAR(a.mean_ln, t.L, 0.005 * t.L);
  }
}

TEST(AnalysisAnisotropy, FftAndTensorAgree) {
  // Both estimate the same A from the same contacts; each is within se of
  // the truth, so their difference is within 2 se, tested at 4 se.
  Truth t;
  t.ac = 0.5;
  t.tc = 2.0;
  t.afn = 0.2;
  t.tfn = 2.1;
  t.aft = 0.3;
  t.tft = 1.9;
  const auto cs = draw(t, 50000, 777);
  const auto se = sampling_errors(cs);
  const auto a = anisotropy_fft(cs, 36), b = anisotropy_tensor(cs);
  EXPECT_LT(std::abs(a.c.A - b.c.A), 4 * se.c);
  EXPECT_LT(std::abs(a.ln.A - b.ln.A), 4 * se.ln);
  EXPECT_LT(std::abs(a.lt.A - b.lt.A), 4 * se.lt);
  EXPECT_LT(std::abs(a.fn.A - b.fn.A), 4 * se.fn);
  EXPECT_LT(std::abs(a.ft.A - b.ft.A), 4 * se.ft);
}

TEST(AnalysisAnisotropy, NoiselessQuantilesAreExact) {
  // Deterministic set: angles at the quantiles of P (inverse CDF by
  // bisection), exact harmonic values. No sampling error; the remaining
  // error is the discreteness of N = 36000 angles and, for the FFT, the
  // variation of P inside a 5 degree bin: both O(1e-4), tested at 1e-3.
  const Truth t;
  const std::size_t n = 36000;
  ContactSet cs;
  for (std::size_t j = 0; j < n; ++j) {
    const double u = (static_cast<double>(j) + 0.5) / static_cast<double>(n);
    double lo = 0, hi = pi;
    for (int it = 0; it < 60; ++it) {  // F(th) = (th + ac/2 (sin 2(th-tc) + sin 2tc))/pi
      const double m = 0.5 * (lo + hi);
      const double F = (m + 0.5 * t.ac * (std::sin(2 * (m - t.tc)) + std::sin(2 * t.tc))) / pi;
      (F < u ? lo : hi) = m;
    }
    const double th = 0.5 * (lo + hi);
    Contact c;
    c.theta = th;
    c.fn = t.F * (1 + t.afn * std::cos(2 * (th - t.tfn)));
    c.ft = -t.F * t.aft * std::sin(2 * (th - t.tft));
    const double ln = t.L * (1 + t.aln * std::cos(2 * (th - t.tln)));
    const double lt = -t.L * t.alt * std::sin(2 * (th - t.tlt));
    c.lx = ln * std::cos(th) - lt * std::sin(th);
    c.ly = ln * std::sin(th) + lt * std::cos(th);
    cs.push_back(c);
  }
  for (const auto& a : {anisotropy_tensor(cs), anisotropy_fft(cs, 36)}) {
    EXPECT_NEAR(a.c.a(), t.ac, 1e-3);
    EXPECT_NEAR(a.c.theta(), t.tc, 1e-3);
    EXPECT_NEAR(a.ln.a(), t.aln, 1e-3);
    EXPECT_NEAR(a.lt.a(), t.alt, 1e-3);
    EXPECT_NEAR(a.fn.a(), t.afn, 1e-3);
    EXPECT_NEAR(a.fn.theta(), t.tfn, 1e-2);
    EXPECT_NEAR(a.ft.a(), t.aft, 1e-3);
    EXPECT_NEAR(a.ft.theta(), t.tft, 1e-2);
    EXPECT_NEAR(a.mean_fn, t.F, 1e-3 * t.F);
  }
}

TEST(AnalysisAnisotropy, StressRatioMatchesHalfSumToSecondOrder) {
  // q/p = |sum A|/2 holds to first order in the anisotropies; the neglected
  // products of two anisotropies are bounded by (sum a)^2/4 (each pair's
  // cross term is at most a_x a_y / 2 in the deviator and the trace).
  Truth t;
  t.ac = 0.15;
  t.aln = 0.05;
  t.alt = 0.03;
  t.afn = 0.2;
  t.aft = 0.1;
  t.tc = t.tln = t.tlt = t.tfn = t.tft = 0.7;
  const auto cs = draw(t, 100000, 99);
  const auto s = contact_stress(cs, 1.0);
  const auto a = anisotropy_tensor(cs);
  const double sum = a.c.a() + a.ln.a() + a.lt.a() + a.fn.a() + a.ft.a();
  EXPECT_NEAR(s.q_over_p(), a.sum_half_vector(), sum * sum / 4);
  EXPECT_NEAR(s.q_over_p(), a.sum_half(), sum * sum / 4);
  EXPECT_NEAR(s.theta(), 0.7, 0.05);
}

TEST(AnalysisAnisotropy, IsotropicSetHasSmallAnisotropy) {
  Truth t;
  t.ac = t.aln = t.alt = t.afn = t.aft = 0;
  const auto cs = draw(t, 20000, 5);
  const auto se = sampling_errors(cs);
  const auto a = anisotropy_fft(cs);
  EXPECT_LT(a.c.a(), 4 * se.c);
  EXPECT_LT(a.fn.a(), 4 * se.fn);
}

TEST(AnalysisAnisotropy, ProfileFillsEmptyBinsAndSlidingShare) {
  ContactSet cs;
  for (int k = 0; k < 4; ++k) {
    Contact c;
    c.theta = k * pi / 4 + 0.01;  // 4 of 36 bins occupied
    c.fn = 1 + k;
    c.ft = k == 2 ? 0.5 : 0.1;
    c.status = k == 2 ? 2 : 1;
    c.lx = std::cos(c.theta);
    c.ly = std::sin(c.theta);
    cs.push_back(c);
  }
  Contact open;
  open.status = 0;  // no force: not counted
  cs.push_back(open);
  const auto p = angular_profile(cs, 36);
  // Occupied bins 0 (two contacts: k = 0 and the open one), 9, 18, 27.
  EXPECT_EQ(p.empty_bins, 32u);
  EXPECT_EQ(p.count[0], 2u);
  EXPECT_DOUBLE_EQ(p.fn[0], 0.5);           // (1 + 0)/2
  EXPECT_DOUBLE_EQ(p.fn[9], 2.0);
  EXPECT_NEAR(p.fn[4], 0.5 + 1.5 * 4 / 9, 1e-12);  // linear between bins 0 and 9
  EXPECT_NEAR(p.fn[31], 4.0 + (0.5 - 4.0) * 4 / 9, 1e-12);  // periodic: 27 -> 36 = 0
  // Sliding share over the 4 force-bearing contacts: by status, one slides;
  // by |ft| >= mu fn with mu = 0.15, k = 2 (0.5 >= 0.45) and no other.
  EXPECT_DOUBLE_EQ(sliding_share(cs), 0.25);
  EXPECT_DOUBLE_EQ(sliding_share(cs, 0.15), 0.25);
}
