#include "dilatancy.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "plot.hpp"
#include "scene_info.hpp"
#include "steady.hpp"

namespace fs = std::filesystem;

namespace cda {

// Simple shear of a cell of fixed width whose height H follows the imposed
// pressure: velocity u_x = gamma_dot y, u_y = (H_dot/H) y, so with
// d = H_dot/H = V_dot/V (volume_strain_rate) the strain-rate tensor,
// extension positive, is D = [[0, gamma_dot/2], [gamma_dot/2, d]]. Its 2D
// Mohr circle has centre d/2 and radius sqrt(d^2 + gamma_dot^2)/2. With
// compression positive, eps_v_dot = -(D1 + D2) = -d and
// eps_q_dot = D1 - D2 = sqrt(d^2 + gamma_dot^2), hence
//   sin psi = -eps_v_dot/eps_q_dot = d / sqrt(d^2 + gamma_dot^2),
// positive when the sample dilates, in [-1, 1], and the 2D analogue of the
// Mohr-Coulomb sin phi = (s1 - s2)/(s1 + s2) = q/p.
double sin_psi(double volume_strain_rate, double shear_rate) {
  return volume_strain_rate / std::hypot(volume_strain_rate, shear_rate);
}

namespace {

double mean(const std::vector<double>& v, std::size_t b, std::size_t e) {
  double s = 0;
  for (std::size_t i = b; i < e; ++i) s += v[i];
  return s / static_cast<double>(e - b);
}

// Integrated autocorrelation time of the residuals of a line over the last
// half (row index as abscissa).
double noise_tau(const std::vector<double>& y) {
  const std::size_t n = y.size(), b = n / 2;
  std::vector<double> x(n - b), t(y.begin() + static_cast<std::ptrdiff_t>(b), y.end());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i);
  return line_fit(x, t).tau;
}

double sample_var(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = mean(v, 0, v.size());
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return s / static_cast<double>(v.size() - 1);
}

}  // namespace

RunDilatancy run_dilatancy(const std::string& run_dir, const Table& series, const DilatancyOptions& opt) {
  refuse_3d(run_dir, "fit dilatancy (sin psi from the 2D Mohr circle of the strain rate)");
  RunDilatancy r;
  r.run = run_dir;
  const auto& qp = series.column("q_over_p");
  const auto& vsr = series.column("volume_strain_rate");
  const auto& rate = series.column("shear_rate");
  const std::vector<double>* strain = series.has("strain") ? &series.column("strain") : nullptr;
  if (opt.strain && !strain) series.column("strain");  // throws, naming the file
  std::vector<double> row_strain;
  for (std::size_t i = 0; i < qp.size(); ++i) {
    const bool in = !opt.strain || ((*strain)[i] >= opt.strain->first && (*strain)[i] <= opt.strain->second);
    // No shear rate (start-up rows, or a pause): the dilatancy angle is
    // undefined there, not zero.
    if (!in || !std::isfinite(qp[i]) || !std::isfinite(vsr[i]) || !std::isfinite(rate[i]) || rate[i] == 0) {
      ++r.skipped;
      continue;
    }
    r.row_sin_phi.push_back(qp[i]);
    r.row_sin_psi.push_back(sin_psi(vsr[i], rate[i]));
    row_strain.push_back(strain ? (*strain)[i] : static_cast<double>(i));
  }
  r.rows = r.row_sin_phi.size();
  if (r.rows < 32)
    throw AnalysisError(fmt::format("'{}': {} rows with a shear rate{}, at least 32 needed for the dilatancy "
                                    "fit", series.source(), r.rows, opt.strain ? " in the strain range" : ""));
  r.tau = std::max(noise_tau(r.row_sin_phi), noise_tau(r.row_sin_psi));
  r.block_rows = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(4 * r.tau)));
  const std::size_t nb = r.rows / r.block_rows;
  std::vector<double> bx(nb), by(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    bx[k] = mean(r.row_sin_psi, k * r.block_rows, (k + 1) * r.block_rows);
    by[k] = mean(r.row_sin_phi, k * r.block_rows, (k + 1) * r.block_rows);
  }
  const std::size_t m = std::max<std::size_t>(2, opt.blocks_per_bin);
  if (nb < 2 * m)
    throw AnalysisError(fmt::format("'{}': {} blocks of {} rows (tau = {:.3g} rows), at least {} needed for two "
                                    "bins of {} blocks", series.source(), nb, r.block_rows, r.tau, 2 * m, m));
  // Consecutive blocks in bins of m; a remainder joins the last bin.
  const std::size_t nbins = nb / m;
  std::vector<double> bin_x;
  for (std::size_t j = 0; j < nbins; ++j) {
    const std::size_t b0 = j * m, b1 = j + 1 == nbins ? nb : b0 + m;
    const double n = static_cast<double>(b1 - b0);
    DilatancyBin b;
    b.blocks = b1 - b0;
    b.sin_psi = mean(bx, b0, b1);
    b.sin_phi = mean(by, b0, b1);
    double vxx = 0, vyy = 0;
    for (std::size_t k = b0; k < b1; ++k) {
      vxx += (bx[k] - b.sin_psi) * (bx[k] - b.sin_psi);
      vyy += (by[k] - b.sin_phi) * (by[k] - b.sin_phi);
    }
    b.sin_psi_err = std::sqrt(vxx / (n * (n - 1)));
    b.sin_phi_err = std::sqrt(vyy / (n * (n - 1)));
    b.strain_begin = row_strain[b0 * r.block_rows];
    b.strain_end = row_strain[b1 * r.block_rows - 1];
    bin_x.push_back(b.sin_psi);
    r.bins.push_back(b);
  }
  // Noise covariance from the bins of the last half (at least 2).
  const std::size_t j0 = std::min(nbins / 2, nbins - 2);
  const double nl = static_cast<double>(nbins - j0);
  double mx = 0, my = 0;
  for (std::size_t j = j0; j < nbins; ++j) {
    mx += r.bins[j].sin_psi / nl;
    my += r.bins[j].sin_phi / nl;
  }
  for (std::size_t j = j0; j < nbins; ++j) {
    const double dx = r.bins[j].sin_psi - mx, dy = r.bins[j].sin_phi - my;
    r.sxx += dx * dx / (nl - 1);
    r.sxy += dx * dy / (nl - 1);
    r.syy += dy * dy / (nl - 1);
  }
  const double var_x = sample_var(bin_x);
  r.reliability = var_x > 0 ? std::clamp(1 - r.sxx / var_x, 0.0, 1.0) : 0.0;
  return r;
}

double RunDilatancy::sigma(double b) const {
  std::vector<double> d;
  for (const auto& bin : bins) d.push_back(bin.sin_phi - b * bin.sin_psi);
  // Bins that agree exactly (noise-free data) would get a zero error bar:
  // floored far below any real noise.
  return std::sqrt(std::max(sample_var(d), 1e-24));
}

DilatancyFit fit_dilatancy_runs(std::vector<RunDilatancy> runs) {
  DilatancyFit f;
  std::vector<double> x, y;
  auto sigmas = [&](double b) {
    std::vector<double> s;
    for (const auto& r : runs)
      for (std::size_t j = 0; j < r.bins.size(); ++j) s.push_back(r.sigma(b));
    return s;
  };
  for (const auto& r : runs)
    for (const auto& b : r.bins) {
      x.push_back(b.sin_psi);
      y.push_back(b.sin_phi);
    }
  if (x.size() < 3)
    throw AnalysisError(fmt::format("fit dilatancy: {} binned points over {} runs, at least 3 needed", x.size(),
                                    runs.size()));
  f.fixed = fit_dilatancy(x, y, sigmas(1.0));
  // Deming/York objective (header, step 5): inputs (x, y, Sxx, Sxy, Syy),
  // target 0, unit error bars, so fit()'s error scale is max(1, chi2/dof).
  Model deming = dilatancy_free();
  deming.inputs = {"sin_psi", "sin_phi", "Sxx", "Sxy", "Syy"};
  deming.f = [](const double* v, const double* p) {
    const double var = v[4] - 2 * p[1] * v[3] + p[1] * p[1] * v[2];
    return (p[0] + p[1] * v[0] - v[1]) / std::sqrt(std::max(var, 1e-24));
  };
  FitData dd;
  dd.dim = 5;
  for (const auto& r : runs)
    for (const auto& b : r.bins) dd.add({b.sin_psi, b.sin_phi, r.sxx, r.sxy, r.syy}, 0.0, 1.0);
  f.free = fit(deming, dd, {f.fixed["sin_phi_c"], 1.0});
  f.runs = std::move(runs);
  return f;
}

bool plot_dilatancy(const std::string& dir, const DilatancyFit& f) {
  fs::create_directories(dir);
  // At most ~4000 raw rows in the plot: a backdrop, not data.
  std::size_t total = 0;
  for (const auto& r : f.runs) total += r.rows;
  const std::size_t stride = std::max<std::size_t>(1, total / 4000);
  Table rows({"sin_psi", "sin_phi"}),
      bins({"run", "sin_psi", "sin_psi_err", "sin_phi", "sin_phi_err", "sigma", "blocks", "strain_begin", "strain_end"});
  double lo = 1, hi = -1;
  for (std::size_t k = 0; k < f.runs.size(); ++k) {
    const auto& r = f.runs[k];
    for (std::size_t i = 0; i < r.rows; i += stride) rows.add_row({r.row_sin_psi[i], r.row_sin_phi[i]});
    const double sig = r.sigma(1.0);
    for (const auto& b : r.bins) {
      bins.add_row({static_cast<double>(k), b.sin_psi, b.sin_psi_err, b.sin_phi, b.sin_phi_err, sig,
                    static_cast<double>(b.blocks), b.strain_begin, b.strain_end});
      lo = std::min(lo, b.sin_psi);
      hi = std::max(hi, b.sin_psi);
    }
  }
  const double pad = 0.1 * std::max(hi - lo, 0.02);
  lo -= pad;
  hi += pad;
  Table curve({"sin_psi", "fixed", "fixed_lo", "fixed_hi", "free"});
  const Model m1 = dilatancy(), m2 = dilatancy_free();
  for (int k = 0; k <= 100; ++k) {
    const double x = lo + (hi - lo) * k / 100.0;
    const double v = predict(m1, f.fixed, &x), e = predict_error(m1, f.fixed, &x);
    curve.add_row({x, v, v - e, v + e, predict(m2, f.free, &x)});
  }
  rows.write_csv((fs::path(dir) / "dilatancy_rows.csv").string());
  bins.write_csv((fs::path(dir) / "dilatancy_bins.csv").string());
  curve.write_csv((fs::path(dir) / "dilatancy_fit.csv").string());
  const std::string body = fmt::format(
      "set datafile separator ','\nset xlabel 'sin ψ = V̇/V / (V̇²/V² + γ̇²)^{{1/2}}'\nset ylabel 'sin φ = q/p'\n"
      "set key top left\nset grid\nset xrange [{}:{}]\n"
      "plot 'dilatancy_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
      "     'dilatancy_rows.csv' every ::1 using 1:2 with dots lc rgb '#b0b0b0' title 'rows', \\\n"
      "     'dilatancy_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' "
      "title 'sin φ_c + sin ψ, sin φ_c = {:.4f} ± {:.2g}', \\\n"
      "     'dilatancy_fit.csv' every ::1 using 1:5 with lines lw 1 dt 2 lc rgb '#c0392b' "
      "title 'free slope b = {:.3f} ± {:.2g}', \\\n"
      "     'dilatancy_bins.csv' every ::1 using 2:4:3:5:($1+1) with xyerrorbars pt 7 ps 0.7 lc variable "
      "title 'strain bins (colour: run)'\n",
      lo, hi, f.fixed["sin_phi_c"], f.fixed.err("sin_phi_c"), f.free["b"], f.free.err("b"));
  return plot_both(dir, "dilatancy", body);
}

}  // namespace cda
