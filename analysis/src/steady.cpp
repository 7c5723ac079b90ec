#include "steady.hpp"

#include <fftw3.h>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cda {
namespace {

double mean_of(std::span<const double> x) {
  return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
}

double var_of(std::span<const double> x, double m) {  // 1/n
  double s = 0;
  for (double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size());
}

// |mean(first 10%) - mean(last 50%)| over its standard error.
double geweke_z(std::span<const double> y, double tau) {
  const std::size_t n = y.size();
  const std::size_t na = std::max<std::size_t>(8, n / 10), nb = n / 2;
  const auto a = y.first(na), b = y.last(nb);
  const double ma = mean_of(a), mb = mean_of(b);
  const double se2 = 2 * tau * (var_of(a, ma) / static_cast<double>(na) + var_of(b, mb) / static_cast<double>(nb));
  return se2 > 0 ? std::abs(ma - mb) / std::sqrt(se2) : 0.0;
}

}  // namespace

BlockAverage block_average(std::span<const double> x) {
  if (x.size() < 2) throw AnalysisError("block average: fewer than 2 samples");
  BlockAverage r;
  r.mean = mean_of(x);
  const double n0 = static_cast<double>(x.size());
  std::vector<double> b(x.begin(), x.end());
  std::size_t size = 1;
  while (b.size() >= 2) {
    const double n = static_cast<double>(b.size());
    const double sem = std::sqrt(var_of(b, mean_of(b)) / (n - 1));
    r.levels.push_back({size, b.size(), sem, sem / std::sqrt(2 * (n - 1))});
    std::vector<double> next(b.size() / 2);
    for (std::size_t i = 0; i < next.size(); ++i) next[i] = 0.5 * (b[2 * i] + b[2 * i + 1]);
    b = std::move(next);
    size *= 2;
  }
  const double sem1 = r.levels.front().sem;
  const BlockLevel* pick = nullptr;
  for (const auto& l : r.levels) {
    if (l.blocks < 4) break;
    const double ratio = sem1 > 0 ? l.sem / sem1 : 1.0;
    const double B = static_cast<double>(l.block_size);
    if (B * B * B > 2 * n0 * std::pow(ratio, 4)) {
      pick = &l;
      r.converged = true;
      break;
    }
  }
  if (!pick) {
    for (const auto& l : r.levels)
      if (l.blocks >= 4) pick = &l;
    if (!pick) pick = &r.levels.front();
  }
  r.sem = pick->sem;
  r.sem_err = pick->sem_err;
  r.block_size = pick->block_size;
  return r;
}

std::vector<double> autocorrelation(std::span<const double> x) {
  const std::size_t n = x.size();
  if (n < 2) throw AnalysisError("autocorrelation: fewer than 2 samples");
  const double m = mean_of(x);
  const std::size_t len = 2 * n;
  std::vector<double> buf(len, 0.0);
  for (std::size_t i = 0; i < n; ++i) buf[i] = x[i] - m;
  std::vector<fftw_complex> spec(len / 2 + 1);
  fftw_plan fwd = fftw_plan_dft_r2c_1d(static_cast<int>(len), buf.data(), spec.data(), FFTW_ESTIMATE);
  fftw_execute(fwd);
  fftw_destroy_plan(fwd);
  for (auto& s : spec) {
    s[0] = s[0] * s[0] + s[1] * s[1];
    s[1] = 0;
  }
  fftw_plan bwd = fftw_plan_dft_c2r_1d(static_cast<int>(len), spec.data(), buf.data(), FFTW_ESTIMATE);
  fftw_execute(bwd);
  fftw_destroy_plan(bwd);
  std::vector<double> rho(n);
  const double c0 = buf[0];
  for (std::size_t t = 0; t < n; ++t) rho[t] = c0 > 0 ? buf[t] / c0 : (t == 0 ? 1.0 : 0.0);
  return rho;
}

AutoCorrTime autocorrelation_time(std::span<const double> x, double c) {
  const auto rho = autocorrelation(x);
  const std::size_t n = x.size();
  AutoCorrTime r;
  double tau = 0.5;
  std::size_t w = 0;
  for (std::size_t t = 1; t < n / 2; ++t) {
    tau += rho[t];
    w = t;
    if (static_cast<double>(t) >= c * tau) {
      r.converged = true;
      break;
    }
  }
  r.tau = std::max(tau, 0.5);  // anticorrelated noise: no credit below white noise
  r.window = w;
  const double nn = static_cast<double>(n);
  r.tau_err = r.tau * std::sqrt(2.0 * (2.0 * static_cast<double>(w) + 1) / nn);
  r.n_eff = nn / (2 * r.tau);
  r.sem = std::sqrt(var_of(x, mean_of(x)) * 2 * r.tau / nn);
  return r;
}

Window window_from_range(std::span<const double> x, double a, double b) {
  Window w;
  std::size_t first = x.size(), last = 0, count = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i] >= a && x[i] <= b) {
      first = std::min(first, i);
      last = std::max(last, i);
      ++count;
    }
  }
  if (count < 2)
    throw AnalysisError(fmt::format("window {}:{} holds {} rows; at least 2 needed", a, b, count));
  w.begin = first;
  w.end = last + 1;
  w.x_begin = x[first];
  w.x_end = x[last];
  return w;
}

LineFit line_fit(std::span<const double> x, std::span<const double> y, double noise_tau) {
  const std::size_t n = x.size();
  if (n < 3 || y.size() != n) throw AnalysisError("line fit: fewer than 3 points");
  const double mx = mean_of(x), my = mean_of(y);
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  LineFit f;
  if (sxx <= 0) throw AnalysisError("line fit: all x values are equal");
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  std::vector<double> res(n);
  double rss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    res[i] = y[i] - f.intercept - f.slope * x[i];
    rss += res[i] * res[i];
  }
  f.tau = noise_tau > 0 ? noise_tau : autocorrelation_time(res).tau;
  f.slope_se = std::sqrt(rss / static_cast<double>(n - 2) / sxx * 2 * f.tau);
  return f;
}

Window detect_steady_window(std::span<const double> x, std::span<const double> y,
                            const SteadyOptions& opt, const std::string& what) {
  const std::size_t n = x.size();
  if (y.size() != n) throw AnalysisError(fmt::format("{}: x and y differ in length", what));
  const auto min_len = static_cast<std::size_t>(std::ceil(opt.min_fraction * static_cast<double>(n)));
  if (n < 16 || min_len < 8)
    throw AnalysisError(fmt::format(
        "{}: {} rows are too few to find a steady window (the shortest candidate would hold {} "
        "rows; at least 8 needed)",
        what, n, min_len));
  const std::size_t last_start = n - min_len;
  const int k_max = std::max(opt.candidates, 1);
  const double tau_ref = line_fit(x.subspan(n / 2), y.subspan(n / 2)).tau;
  std::size_t accepted = n;  // none yet
  for (int k = k_max; k >= 0; --k) {
    const std::size_t start = last_start * static_cast<std::size_t>(k) / static_cast<std::size_t>(k_max);
    const auto fit = line_fit(x.subspan(start), y.subspan(start), tau_ref);
    const bool drifts = std::abs(fit.slope) > opt.t_crit * fit.slope_se ||
                        geweke_z(y.subspan(start), tau_ref) > opt.t_crit;
    if (drifts) break;
    accepted = start;
  }
  if (accepted == n)
    throw AnalysisError(fmt::format(
        "{}: no steady window: the last {:.0f}% of the run (x from {} to {}) still drifts",
        what, 100 * opt.min_fraction, x[last_start], x[n - 1]));
  const auto acf = autocorrelation_time(y.subspan(accepted));
  if (acf.n_eff < opt.min_independent)
    throw AnalysisError(fmt::format(
        "{}: steady window x from {} to {} is too short: {:.1f} independent samples (tau = {:.1f} "
        "rows), at least {} needed",
        what, x[accepted], x[n - 1], acf.n_eff, acf.tau, opt.min_independent));
  return {accepted, n, x[accepted], x[n - 1]};
}

double SteadyStats::error() const {
  return blocks.converged ? blocks.sem : std::max(blocks.sem, acf.sem);
}

SteadyStats steady_stats(std::span<const double> x, std::span<const double> y, const Window& w,
                         const std::string& what) {
  if (w.end > y.size() || w.end > x.size() || w.begin >= w.end)
    throw AnalysisError(fmt::format("{}: window rows {}..{} outside the series", what, w.begin, w.end));
  if (w.end - w.begin < 16)
    throw AnalysisError(fmt::format(
        "{}: steady window x from {} to {} holds {} rows; at least 16 are needed for an error bar",
        what, w.x_begin, w.x_end, w.end - w.begin));
  SteadyStats s;
  s.window = w;
  const auto ys = y.subspan(w.begin, w.end - w.begin);
  const auto xs = x.subspan(w.begin, w.end - w.begin);
  s.mean = mean_of(ys);
  s.blocks = block_average(ys);
  s.acf = autocorrelation_time(ys);
  s.trend = line_fit(xs, ys);
  return s;
}

}  // namespace cda
