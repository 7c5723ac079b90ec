#include "cohesion.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "plot.hpp"
#include "run.hpp"
#include "scene_info.hpp"

namespace fs = std::filesystem;

namespace cda {

const char* cohesion_mu_column(int dim) { return dim == 3 ? "shear_stress_ratio" : "q_over_p"; }
const char* cohesion_ref_name(int dim) { return dim == 3 ? "mu0" : "sin phi"; }
const char* cohesion_formula(int dim) {
  return dim == 3 ? "c/p = mu - mu0(I)" : "c/p = (q/p - sin phi)/cos phi";
}

SteadyPoint steady_point(const std::string& run_dir, const std::string& window) {
  SteadyPoint p;
  p.run = run_dir;
  const auto scene = read_scene_info(run_dir);
  p.dim = scene.dimension;
  p.eta = require(scene, scene.cohesion_number, "[contact] cohesion_number");
  if (p.eta < 0) throw AnalysisError(fmt::format("'{}': cohesion_number {} is negative", scene.file, p.eta));
  p.I_imposed = scene.inertial_number.value_or(std::numeric_limits<double>::quiet_NaN());
  const auto series = read_series(run_dir);
  const auto x = default_x_column(series);
  const auto range = window_range(window, series.column(x));
  const auto s = run_steady(run_dir, series, cohesion_mu_column(p.dim), x, range);
  const auto si = measured_inertial_number(series, x, s.stats.window);
  p.mu = s.stats.mean;
  p.mu_err = s.stats.error();
  p.I = si.mean;
  p.I_err = si.err;
  const Val rm = window_rate_min(run_dir, series, x, s.stats.window);
  p.rate_min = rm.v;
  p.rate_min_err = rm.err;
  return p;
}

SinPhiReference::SinPhiReference(std::vector<SteadyPoint> pts, Mode mode) {
  if (pts.empty())
    throw AnalysisError("fit cohesion: no eta = 0 run among the given runs; sin phi(I) of the cohesionless "
                        "material is the reference for c/p = (q/p - sin phi)/cos phi: add the eta = 0 runs "
                        "([contact] cohesion_number = 0) to the run list");
  dim_ = pts.front().dim;
  for (const auto& p : pts) {
    if (p.dim != dim_)
      throw AnalysisError(fmt::format("fit cohesion: '{}' is a {}D run and '{}' a {}D run: one fit mixes no "
                                      "dimensions", pts.front().run, dim_, p.run, p.dim));
    if (!(p.I > 0)) throw AnalysisError(fmt::format("'{}': measured inertial number {} is not positive", p.run, p.I));
  }
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.I < b.I; });
  if (mode != Mode::Interp && pts.size() >= 4) {
    std::vector<double> I, mu, e;
    for (const auto& p : pts) {
      I.push_back(p.I);
      mu.push_back(p.mu);
      e.push_back(p.mu_err);
    }
    if (mode == Mode::MuI) {
      fit_ = fit_mu_I(I, mu, e);
      use_fit_ = true;
    } else {
      // auto: a fit the data do not determine (a singular Jacobian: e.g.
      // every reference run in the linear part of mu(I), I << I0) is
      // refused by fit_mu_I; the interpolation serves instead.
      try {
        fit_ = fit_mu_I(I, mu, e);
        use_fit_ = fit_.converged;
      } catch (const AnalysisError&) {
        use_fit_ = false;
      }
    }
  } else if (mode == Mode::MuI) {
    throw AnalysisError(fmt::format("fit cohesion: --reference mu-i needs 4 eta = 0 runs, {} given", pts.size()));
  }
  // Runs at the same I (within 1e-9 relative) are merged by the weighted
  // mean, so the interpolation never divides by a zero ln I step.
  for (const auto& p : pts) {
    if (!points_.empty() && std::abs(std::log(p.I / points_.back().I)) < 1e-9) {
      auto& q = points_.back();
      const double wa = 1 / (q.mu_err * q.mu_err), wb = 1 / (p.mu_err * p.mu_err);
      q.mu = (wa * q.mu + wb * p.mu) / (wa + wb);
      q.mu_err = 1 / std::sqrt(wa + wb);
      continue;
    }
    points_.push_back(p);
  }
}

std::pair<double, double> SinPhiReference::raw(double I) const {
  if (use_fit_) {
    const Model m = mu_of_I();
    return {predict(m, fit_, &I), predict_error(m, fit_, &I)};
  }
  if (points_.size() == 1) return {points_[0].mu, points_[0].mu_err};
  // Bracketing pair, or the end pair for extrapolation.
  std::size_t k = 1;
  while (k + 1 < points_.size() && points_[k].I < I) ++k;
  const auto& a = points_[k - 1];
  const auto& b = points_[k];
  const double w = std::log(I / a.I) / std::log(b.I / a.I);
  return {(1 - w) * a.mu + w * b.mu, std::hypot((1 - w) * a.mu_err, w * b.mu_err)};
}

SinPhiReference::Value SinPhiReference::at(double I, double I_err) const {
  if (!(I > 0)) throw AnalysisError(fmt::format("sin phi reference: inertial number {} is not positive", I));
  Value v;
  const auto [s, e] = raw(I);
  // The error of I through the slope of sin phi(I) (central difference in ln I).
  const double h = 1e-3;
  const double slope = (raw(I * std::exp(h)).first - raw(I * std::exp(-h)).first) / (2 * h * I);
  v.sin_phi = s;
  v.err = std::hypot(e, slope * I_err);
  v.extrapolated = I < points_.front().I * (1 - 1e-9) || I > points_.back().I * (1 + 1e-9);
  return v;
}

bool SteadyPoint::banded() const { return is_banded(rate_min); }

CohesionPoint cohesion_point(const SteadyPoint& p, const SinPhiReference& ref) {
  CohesionPoint c;
  c.run = p;
  if (p.dim != ref.dim())
    throw AnalysisError(fmt::format("fit cohesion: '{}' is a {}D run and the eta = 0 runs are {}D: one fit mixes no "
                                    "dimensions", p.run, p.dim, ref.dim()));
  c.ref = ref.at(p.I, p.I_err);
  const double s = c.ref.sin_phi, m = p.mu;
  if (p.dim == 3) {
    // The Coulomb law on the shear plane: mu = mu0(I) + c/p.
    c.c_over_p = m - s;
    c.c_over_p_err = std::hypot(p.mu_err, c.ref.err);
    return c;
  }
  if (!(std::abs(s) < 1))
    throw AnalysisError(fmt::format("'{}': reference sin phi = {} at I = {} is outside (-1, 1)", p.run, s, p.I));
  const double cphi = std::sqrt(1 - s * s);
  c.c_over_p = (m - s) / cphi;
  const double dm = 1 / cphi, ds = (m * s - 1) / (cphi * cphi * cphi);
  c.c_over_p_err = std::hypot(dm * p.mu_err, ds * c.ref.err);
  return c;
}

bool plot_cohesion(const std::string& dir, const std::vector<CohesionPoint>& pts, const FitResult* r) {
  fs::create_directories(dir);
  const bool d3 = !pts.empty() && pts.front().run.dim == 3;
  Table data({"eta", "I", "I_err", d3 ? "mu" : "q_over_p", d3 ? "mu_err" : "q_over_p_err", d3 ? "mu0" : "sin_phi",
              d3 ? "mu0_err" : "sin_phi_err", "c_over_p", "c_over_p_err", "extrapolated", "rate_min",
              "rate_min_err", "banded"});
  std::set<double> etas;
  double lo = 1, hi = 0;
  for (const auto& c : pts) {
    data.add_row({c.run.eta, c.run.I, c.run.I_err, c.run.mu, c.run.mu_err, c.ref.sin_phi, c.ref.err, c.c_over_p,
                  c.c_over_p_err, c.ref.extrapolated ? 1.0 : 0.0, c.run.rate_min, c.run.rate_min_err,
                  c.run.banded() ? 1.0 : 0.0});
    etas.insert(c.run.eta);
    lo = std::min(lo, c.run.I);
    hi = std::max(hi, c.run.I);
  }
  data.write_csv((fs::path(dir) / "cohesion_data.csv").string());
  lo /= 2;
  hi = std::min(hi * 2, 0.99);
  // One curve per eta, each in its own block (blank line between) for `index`.
  std::string curves = "# I,c_over_p per eta block\n";
  const Model m = cohesion();
  std::string plot = "plot ";
  int k = 0;
  bool banded_titled = false;
  for (double eta : etas) {
    if (k) curves += "\n\n";
    for (int i = 0; r && i <= 100; ++i) {
      const double x[2] = {eta, lo * std::pow(hi / lo, i / 100.0)};
      curves += fmt::format("{},{}\n", x[1], predict(m, *r, x));
    }
    // banded runs (column 13, shear_profile): open circles
    if (r)
      plot += fmt::format("{}'cohesion_fit.csv' index {} using 1:2 with lines lc {} title 'model, η = {:g}', \\\n"
                          "     'cohesion_data.csv' every ::1 using ($1=={:.17g} && $13==0?$2:1/0):8:3:9 with "
                          "xyerrorbars pt 7 lc {} notitle",
                          k ? ", \\\n     " : "", k, k + 1, eta, eta, k + 1);
    else  // no model: the points, joined per eta
      plot += fmt::format("{}'cohesion_data.csv' every ::1 using ($1=={:.17g}?$2:1/0):8:3:9 with xyerrorlines "
                          "pt 7 lc {} title 'η = {:g}'",
                          k ? ", \\\n     " : "", eta, k + 1, eta);
    if (std::any_of(pts.begin(), pts.end(), [&](const CohesionPoint& c) { return c.run.eta == eta && c.run.banded(); })) {
      plot += fmt::format(", \\\n     'cohesion_data.csv' every ::1 using ($1=={:.17g} && $13==1?$2:1/0):8:3:9 "
                          "with xyerrorbars pt 6 ps 2 lc {} {}",
                          eta, k + 1, banded_titled ? "notitle" : "title 'banded (open)'");
      banded_titled = true;
    }
    ++k;
  }
  {
    std::ofstream out(fs::path(dir) / "cohesion_fit.csv");
    out << curves;
  }
  const std::string body = fmt::format(
      "set datafile separator ','\nset logscale x\nset xlabel 'I (measured)'\nset ylabel 'c/p'\n"
      "set key outside right\nset grid\nset title '{}'\n{}\n",
      r ? fmt::format("k_0 = {:.4g}, β = {:.3g}, α = {:.3g}", (*r)["k0"], (*r)["beta"], (*r)["alpha"])
        : std::string("the model is not determined by these runs (fit refused)"),
      plot);
  if (!plot_both(dir, "cohesion", body, 900, 500)) return false;
  if (!r) return true;
  // The collapse: c/p/eta against I_c = I/(1 + alpha eta)^(1/2) with the
  // fitted alpha, and the model's one curve k0/(1 - beta ln(1 - I_c)) (its
  // c/p at eta = 1 and I = I_c (1 + alpha)^(1/2), over eta).
  const double alpha = (*r)["alpha"];
  Table col({"eta", "I_c", "c_over_p_per_eta", "c_over_p_per_eta_err", "banded"});
  double clo = 1, chi = 0;
  for (const auto& c : pts) {
    const double scale = 1 + alpha * c.run.eta;
    const double ic = scale > 0 ? c.run.I / std::sqrt(scale) : std::nan("");
    col.add_row({c.run.eta, ic, c.c_over_p / c.run.eta, c.c_over_p_err / c.run.eta, c.run.banded() ? 1.0 : 0.0});
    if (std::isfinite(ic)) clo = std::min(clo, ic), chi = std::max(chi, ic);
  }
  col.write_csv((fs::path(dir) / "cohesion_collapse.csv").string());
  std::string master = "# I_c,c_over_p_per_eta\n";
  if (1 + alpha > 0 && clo < chi) {
    clo /= 2;
    chi = std::min(chi * 2, 0.99);
    for (int i = 0; i <= 100; ++i) {
      const double ic = clo * std::pow(chi / clo, i / 100.0);
      const double x[2] = {1.0, ic * std::sqrt(1 + alpha)};
      if (x[1] < 1) master += fmt::format("{},{}\n", ic, predict(m, *r, x));
    }
  }
  {
    std::ofstream out(fs::path(dir) / "cohesion_collapse_fit.csv");
    out << master;
  }
  std::string cplot = "plot 'cohesion_collapse_fit.csv' using 1:2 with lines lc 0 title 'k_0/(1 − β ln(1 − I_c))'";
  k = 0;
  for (double eta : etas) {
    cplot += fmt::format(", \\\n     'cohesion_collapse.csv' every ::1 using ($1=={:.17g} && $5==0?$2:1/0):3:4 with "
                         "yerrorbars pt 7 lc {} title 'η = {:g}'",
                         eta, k + 1, eta);
    cplot += fmt::format(", \\\n     'cohesion_collapse.csv' every ::1 using ($1=={:.17g} && $5==1?$2:1/0):3:4 with "
                         "yerrorbars pt 6 ps 2 lc {} notitle",
                         eta, k + 1);
    ++k;
  }
  const std::string cbody = fmt::format(
      "set datafile separator ','\nset logscale x\nset xlabel 'I_c = I/(1 + αη)^{{1/2}}'\nset ylabel 'c/(p η)'\n"
      "set key bottom left\nset grid\nset title 'collapse: α = {:.3g} (open: banded runs)'\n{}\n",
      alpha, cplot);
  return plot_both(dir, "cohesion_collapse", cbody, 900, 500);
}

}  // namespace cda
