#include "report.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>

#include "cohesion.hpp"
#include "cost.hpp"
#include "plot.hpp"
#include "report_html.hpp"
#include "report_scan.hpp"
#include "report_tables.hpp"
#include "trends.hpp"

namespace fs = std::filesystem;

namespace cda {
namespace {

// A TOML basic string's content: quotes and backslashes escaped.
std::string toml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') o += "\\n";
    else o += c;
  }
  return o;
}

// Distinct finite values.
std::vector<double> distinct(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

std::string made_by(const std::string& report_cmd, const std::string& fit_cmd) {
  return fmt::format("<p><small>Made by <code>{}</code> (alone: <code>{}</code>).</small></p>\n",
                     html_escape(report_cmd), html_escape(fit_cmd));
}

// Wall time and sweeps per step against the measured I (log-log), the
// points of an inertial campaign: dir/cost_I.{png,svg}, data in cost_I.csv.
bool plot_cost_I(const std::string& dir, const ReportScan& scan) {
  // Every run with a cost: the runs left out of the fits (no steady window)
  // are often the most expensive, and leaving them out would make the cost
  // seem to fall steadily with I. Such a run is placed at its imposed I and
  // drawn apart (open symbols).
  Table t({"I", "wall_time", "sweeps_per_step", "cap_share", "steps", "steady"});
  for (const ReportRun& p : scan.runs) {
    if (!p.cost) continue;
    const bool measured = p.steady && std::isfinite(p.I.v) && p.I.v > 0;
    const double I = measured ? p.I.v : p.I_imposed;
    if (std::isfinite(I) && I > 0)
      t.add_row({I, p.cost->wall_time, p.cost->sweeps_per_step, p.cost->cap_share, p.cost->steps, measured ? 1.0 : 0.0});
  }
  t.write_csv((fs::path(dir) / "cost_I.csv").string());
  const std::string body =
      "set datafile separator ','\nset logscale x\nset logscale y\nset logscale y2\n"
      "set xlabel 'I (measured; not steady: imposed)'\nset ylabel 'wall time (s)'\nset y2label 'NLGS sweeps per step'\n"
      "set ytics nomirror\nset y2tics\nset key top right\nset grid\n"
      "plot 'cost_I.csv' every ::1 using 1:($6 > 0 ? $2 : 1/0) with linespoints pt 7 lc rgb '#1f3b73' "
      "title 'wall time', \\\n"
      "     'cost_I.csv' every ::1 using 1:($6 > 0 ? $3 : 1/0) axes x1y2 with linespoints pt 5 lc rgb '#b03a2e' "
      "title 'sweeps per step', \\\n"
      "     'cost_I.csv' every ::1 using 1:($6 > 0 ? 1/0 : $2) with points pt 6 ps 1.5 lc rgb '#1f3b73' "
      "title 'wall time, not steady', \\\n"
      "     'cost_I.csv' every ::1 using 1:($6 > 0 ? 1/0 : $3) axes x1y2 with points pt 4 ps 1.5 lc rgb '#b03a2e' "
      "title 'sweeps per step, not steady'\n";
  return plot_both(dir, "cost_I", body);
}


// Each run's series, its steady window shaded, and (2D) the polar diagrams
// of its last contact snapshot. False when gnuplot failed on one of them.
bool draw_run_plots(const ReportScan& scan, const std::string& out_dir) {
  bool ok = true;
  for (const ReportRun& r : scan.runs) {
    if (r.curve)
      ok = plot_series(out_dir, r.stem() + "_series", *r.curve, r.x_column, r.main_column,
                       r.main_stats ? &*r.main_stats : nullptr) && ok;
    if (r.fabric2) ok = plot_polar(out_dir, r.stem() + "_polar", *r.fabric2) && ok;
  }
  return ok;
}

}  // namespace

std::string fits_to_toml(const std::vector<FitResult>& fits, const std::vector<Model>& models,
                         const std::vector<RefusedFit>& refused) {
  std::string s = "# Fit parameters written by cdanalysis. error = sqrt(error_scale * C_ii),\n"
                  "# C = (J^T W J)^-1; error_scale = max(1, chi2/dof) with error bars,\n"
                  "# chi2/dof without (see analysis/src/fit.hpp).\n";
  for (std::size_t k = 0; k < fits.size(); ++k) {
    const auto& r = fits[k];
    s += fmt::format("\n[{}]\nformula = \"{}\"\nconverged = {}\nweighted = {}\nchi2 = {}\ndof = {}\n"
                     "chi2_dof = {}\nerror_scale = {}\n",
                     r.model, k < models.size() ? models[k].formula : "", r.converged, r.weighted,
                     toml_num(r.chi2), r.dof, toml_num(r.chi2_dof), toml_num(r.scale));
    s += "names = [";
    for (std::size_t i = 0; i < r.names.size(); ++i) s += fmt::format("{}\"{}\"", i ? ", " : "", r.names[i]);
    s += "]\ncovariance = [";
    const std::size_t p = r.names.size();
    for (std::size_t i = 0; i < p; ++i) {
      s += i ? ", [" : "[";
      for (std::size_t j = 0; j < p; ++j) s += (j ? ", " : "") + toml_num(r.cov[i * p + j]);
      s += "]";
    }
    s += "]\n";
    if (const auto u = undetermined_params(r); !u.empty()) {
      s += "undetermined = [";
      for (std::size_t i = 0; i < u.size(); ++i) s += fmt::format("{}\"{}\"", i ? ", " : "", u[i]);
      s += "]\n";
    }
    for (std::size_t i = 0; i < p; ++i)
      s += fmt::format("\n[{}.params.{}]\nvalue = {}\nerror = {}\n", r.model, r.names[i],
                       toml_num(r.value[i]), toml_num(r.error[i]));
  }
  for (const auto& f : refused)
    s += fmt::format("\n[{}]\nformula = \"{}\"\ndetermined = false\nreason = \"{}\"\n", f.model, f.formula,
                     toml_escape(f.reason));
  return s;
}

bool plot_mu_I(const std::string& dir, std::span<const double> I, std::span<const double> mu,
               std::span<const double> mu_err, const FitResult* r, const std::string& ylabel) {
  const Model model = mu_of_I();
  std::filesystem::create_directories(dir);
  Table pts({"I", "mu", "mu_err"});
  for (std::size_t i = 0; i < I.size(); ++i) pts.add_row({I[i], mu[i], mu_err[i]});
  pts.write_csv((fs::path(dir) / "mu_I_data.csv").string());
  const std::string head = fmt::format("set datafile separator ','\nset logscale x\nset xlabel 'I'\nset ylabel '{}'\n"
                                       "set key top left\nset grid\n", ylabel);
  if (!r)  // the fit was refused: the points alone, said so
    return plot_both(dir, "mu_I", head + "plot 'mu_I_data.csv' every ::1 using 1:2:3 with yerrorbars pt 7 lc rgb "
                                         "'black' title 'runs (μ(I) fit undetermined)'\n");
  Table curve({"I", "mu", "lo", "hi"});
  const double lo = *std::min_element(I.begin(), I.end()) / 2, hi = *std::max_element(I.begin(), I.end()) * 2;
  for (int k = 0; k <= 200; ++k) {
    const double x = lo * std::pow(hi / lo, k / 200.0);
    const double m = predict(model, *r, &x), e = predict_error(model, *r, &x);
    curve.add_row({x, m, m - e, m + e});
  }
  curve.write_csv((fs::path(dir) / "mu_I_fit.csv").string());
  const std::string body = head + fmt::format(
      "plot 'mu_I_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
      "     'mu_I_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' "
      "title 'μ_1 = {:.3f}{}, μ_2 = {:.3f}{}, I_0 = {:.3g}{}', \\\n"
      "     'mu_I_data.csv' every ::1 using 1:2:3 with yerrorbars pt 7 lc rgb 'black' title 'runs'\n",
      (*r)["mu1"], undetermined_flag(*r, "mu1"), (*r)["mu2"], undetermined_flag(*r, "mu2"), (*r)["I0"],
      undetermined_flag(*r, "I0"));
  return plot_both(dir, "mu_I", body);
}

bool plot_polar(const std::string& dir, const std::string& stem, const RunFabric& f) {
  const auto& p = f.profile;
  const auto& a = f.fft;
  // Data over [0, 2 pi): the pi-periodic profile twice. The Fourier fit
  // curves are the harmonic forms with the FFT estimates.
  Table data({"theta", "P", "fn", "ft"});
  Table fitc({"theta", "P", "fn", "ft"});
  constexpr double pi = std::numbers::pi;
  for (int rep = 0; rep < 2; ++rep)
    for (std::size_t k = 0; k < p.theta.size(); ++k)
      if (p.count[k])  // interpolated empty bins are not data
        data.add_row({p.theta[k] + rep * pi, p.P[k], p.fn[k], p.ft[k]});
  for (int k = 0; k <= 360; ++k) {
    const double th = 2 * pi * k / 360;
    fitc.add_row({th, (1 + a.c.a() * std::cos(2 * (th - a.c.theta()))) / (2 * pi),
                  a.mean_fn * (1 + a.fn.a() * std::cos(2 * (th - a.fn.theta()))),
                  -a.mean_fn * a.ft.a() * std::sin(2 * (th - a.ft.theta()))});
  }
  data.write_csv((fs::path(dir) / (stem + "_profile.csv")).string());
  fitc.write_csv((fs::path(dir) / (stem + "_fourier.csv")).string());
  bool ok = true;
  struct Q {
    const char* name;
    int col;
    std::string label, offset, unit;
  };
  // <ft> changes sign: it is drawn as <fn> + <ft>(theta) so the radius stays
  // positive (the circle r = <fn> is the zero line).
  const std::string off = toml_num(a.mean_fn);
  // The radius is the quantity itself: its unit on the radial axis (forces
  // in N: cdsim's 2D forces, as the stress is in N/m).
  for (const Q& q : {Q{"P", 2, fmt::format("P(θ), a_c = {:.3f}", a.c.a()), "0", "P(θ) (1/rad)"},
                     Q{"fn", 3, fmt::format("<f_n>(θ), a_{{fn}} = {:.3f}", a.fn.a()), "0", "<f_n> (N)"},
                     Q{"ft", 4, fmt::format("<f_n> + <f_t>(θ), a_{{ft}} = {:.3f}", a.ft.a()), off,
                       "<f_n> + <f_t> (N)"}}) {
    const std::string body = fmt::format(
        "set datafile separator ','\nset polar\nset angles radians\nset size square\n"
        "unset xtics\nunset ytics\nset border polar\nset grid polar pi/6\nset key bottom right\n"
        "set rtics format '%g'\nset rlabel '{}'\n"
        "set title '{}'\n"
        "plot '{}_profile.csv' every ::1 using 1:(${}+{}) with points pt 7 ps 0.6 title 'binned', \\\n"
        "     '{}_fourier.csv' every ::1 using 1:(${}+{}) with lines lw 2 title 'Fourier fit'\n",
        q.unit, q.label, stem, q.col, q.offset, stem, q.col, q.offset);
    ok = plot_both(dir, stem + "_" + q.name, body, 600, 600) && ok;
  }
  return ok;
}

std::vector<std::string> campaign_runs(const std::string& campaign) {
  std::error_code ec;
  if (!fs::is_directory(campaign, ec))
    throw InputError(fmt::format("campaign folder '{}' does not exist", campaign));
  std::vector<std::string> runs;
  if (fs::exists(fs::path(campaign) / "series.csv")) runs.push_back(campaign);
  for (const auto& e : fs::directory_iterator(campaign))
    if (e.is_directory() && fs::exists(e.path() / "series.csv")) runs.push_back(e.path().string());
  std::sort(runs.begin(), runs.end());
  if (runs.empty())
    throw InputError(fmt::format(
        "campaign folder '{}' holds no run (no series.csv in it or in its subfolders)", campaign));
  return runs;
}

ReportSummary write_report(const std::string& campaign, const std::string& out_dir, int bins) {
  const ReportScan scan = scan_campaign(campaign, bins);
  fs::create_directories(out_dir);
  ReportSummary sum = summarize(scan);
  sum.plots_ok = draw_run_plots(scan, out_dir);
  const int dim = scan.dimension;
  const std::string mu_col = mu_column(dim);
  write_tables(scan, out_dir);

  std::vector<FitResult> fits;
  std::vector<Model> models;
  std::vector<RefusedFit> refused;
  std::string html_fit;
  const std::string report_cmd = fmt::format("cdanalysis report {} --out {}", campaign, out_dir);

  // The campaign's kind, from the runs: what their scenes (and shapes) vary.
  std::vector<double> etas, Is, ps, ns;
  for (const ReportRun& p : scan.runs) {
    etas.push_back(p.eta);
    Is.push_back(p.I_imposed);
    ps.push_back(p.pressure);
    ns.push_back(p.nsides >= 0 ? p.nsides : std::nan(""));
  }
  const bool by_shape = distinct(ns).size() >= 2, by_eta = distinct(etas).size() >= 2,
             by_p = distinct(ps).size() >= 2;
  bool by_I = distinct(Is).size() >= 2;
  if (distinct(Is).empty()) {  // no scene says I: the measured I spanning a factor 1.5
    double lo = INFINITY, hi = 0;
    for (const ReportRun& p : scan.runs)
      if (std::isfinite(p.I.v) && p.I.v > 0) lo = std::min(lo, p.I.v), hi = std::max(hi, p.I.v);
    by_I = hi >= 1.5 * lo;
  }
  std::vector<std::string> kinds;
  if (by_I) kinds.push_back("inertial (I varies)");
  if (by_eta) kinds.push_back("cohesive (cohesion_number varies)");
  if (by_shape) kinds.push_back("angularity (nsides varies)");
  if (by_p) kinds.push_back("pressure series (pressure varies)");
  sum.kinds = kinds;
  html_fit += fmt::format("<h2>Fits</h2><p>Campaign kind, from the runs' scenes: {}.</p>\n",
                          kinds.empty() ? std::string("none (the runs differ in none of I, cohesion_number, "
                                                      "nsides, pressure): no fit across runs")
                                        : html_escape(fmt::format("{}", fmt::join(kinds, "; "))));

  // Never a dead end: a fit the data do not determine is written (fits.toml:
  // determined = false and the reason, or the undetermined parameters) and
  // drawn (the points alone, or the curve with the parameters flagged), with
  // what would determine it.
  const auto undetermined_html = [&](const std::string& model, const std::string& why) {
    sum.undetermined.push_back(fmt::format("{}: {}", model, why));
    return fmt::format("<p><b>Undetermined</b>: {}. What would determine it: {}.</p>\n", html_escape(why),
                       html_escape(what_would_determine(model)));
  };
  const auto flagged = [&](const FitResult& r, const std::string& model) {
    const auto u = undetermined_params(r);
    if (u.empty()) return std::string();
    return undetermined_html(model, fmt::format("{} not determined by the data (error not below the value)",
                                                fmt::join(u, ", ")));
  };
  // Inertial: mu(I) and nu(I) over the cohesionless runs of one shape.
  if (by_I) {
    std::vector<double> I, mu, mu_err;
    std::vector<StatePoint> sp;
    const int shape0 = [&] {
      for (const ReportRun& p : scan.runs)
        if (p.steady) return p.nsides;
      return -1;
    }();
    for (const ReportRun& p : scan.runs) {
      if (!p.steady || !std::isfinite(p.I.v) || (std::isfinite(p.eta) && p.eta != 0) || p.nsides != shape0)
        continue;
      if (std::isfinite(p.mu.v)) I.push_back(p.I.v), mu.push_back(p.mu.v), mu_err.push_back(p.mu.err);
      if (std::isfinite(p.phi.v)) {
        StatePoint s;
        s.run = p.folder;
        s.I = {p.I.v, p.I.err};
        s.nu = {p.phi.v, p.phi.err};
        sp.push_back(s);
      }
    }
    const std::string sel = by_eta || by_shape ? " (runs with cohesion_number 0 and the first run's shape)" : "";
    if (I.size() >= 4) {
      std::optional<FitResult> r;
      std::string why;
      try {
        r = fit_mu_I(I, mu, mu_err);
        fits.push_back(*r);
        models.push_back(mu_of_I());
        sum.fits.push_back("mu_I");
      } catch (const AnalysisError& e) {
        why = e.what();
        refused.push_back({"mu_I", mu_of_I().formula, why});
        sum.problems.push_back(fmt::format("mu(I) fit: {}", why));
      }
      sum.plots_ok = plot_mu_I(out_dir, I, mu, mu_err, r ? &*r : nullptr, dim == 3 ? "μ = −σ_xy/σ_yy" : "μ* = q/p") &&
                     sum.plots_ok;
      if (r)
        html_fit += fmt::format("<h3>μ(I){}</h3><img src='mu_I.png' width=600><p>{}: μ1 = {:.4f} ± {:.2g}{}, "
                                "μ2 = {:.4f} ± {:.2g}{}, I0 = {:.4g} ± {:.2g}{}, χ²/dof = {:.2f}</p>\n",
                                sel, html_escape(mu_of_I().formula), (*r)["mu1"], r->err("mu1"),
                                undetermined_flag(*r, "mu1"), (*r)["mu2"], r->err("mu2"), undetermined_flag(*r, "mu2"),
                                (*r)["I0"], r->err("I0"), undetermined_flag(*r, "I0"), r->chi2_dof) +
                    flagged(*r, "mu_I");
      else
        html_fit += fmt::format("<h3>μ(I){}</h3><img src='mu_I.png' width=600><p>{}: fit refused.</p>\n", sel,
                                html_escape(mu_of_I().formula)) +
                    undetermined_html("mu_I", why);
      html_fit += made_by(report_cmd, fmt::format("cdanalysis fit mu-i {} --out DIR", campaign));
    } else {
      html_fit += fmt::format("<p>μ(I) fit skipped: {} steady runs with {} and inertial_number{} "
                              "(4 needed)</p>\n", I.size(), mu_col, sel);
      if (!I.empty()) {
        const std::string why = fmt::format("{} steady runs, 4 needed", I.size());
        refused.push_back({"mu_I", mu_of_I().formula, why});
        sum.plots_ok = plot_mu_I(out_dir, I, mu, mu_err, nullptr, dim == 3 ? "μ = −σ_xy/σ_yy" : "μ* = q/p") &&
                       sum.plots_ok;
        html_fit += "<img src='mu_I.png' width=600>\n" + undetermined_html("mu_I", why);
      }
    }
    if (sp.size() >= 3) {
      std::optional<FitResult> r;
      std::string why;
      try {
        r = fit_nu_I_points(sp);
        fits.push_back(*r);
        models.push_back(nu_of_I());
        sum.plots_ok = plot_nu_I(out_dir, sp, *r, report_cmd) && sum.plots_ok;
        sum.fits.push_back("nu_I");
      } catch (const AnalysisError& e) {
        why = e.what();
        refused.push_back({"nu_I", nu_of_I().formula, why});
        sum.problems.push_back(fmt::format("nu(I) fit: {}", why));
      }
      if (r)
        html_fit += fmt::format("<h3>ν(I){}</h3><img src='nu_I.png' width=600><p>{}: ν_max = {:.4f} ± {:.2g}{}, "
                                "a = {:.4g} ± {:.2g}{}, χ²/dof = {:.2f}</p>\n",
                                sel, html_escape(nu_of_I().formula), (*r)["nu_max"], r->err("nu_max"),
                                undetermined_flag(*r, "nu_max"), (*r)["a"], r->err("a"), undetermined_flag(*r, "a"),
                                r->chi2_dof) +
                    flagged(*r, "nu_I");
      else
        html_fit += fmt::format("<h3>ν(I){}</h3><p>{}: fit refused.</p>\n", sel, html_escape(nu_of_I().formula)) +
                    undetermined_html("nu_I", why);
      html_fit += made_by(report_cmd, fmt::format("cdanalysis fit nu-i {} --out DIR", campaign));
    } else {
      html_fit += fmt::format("<p>ν(I) fit skipped: {} steady runs with packing_fraction{} (3 needed)</p>\n",
                              sp.size(), sel);
      if (!sp.empty())
        html_fit += undetermined_html("nu_I", fmt::format("{} steady runs with packing_fraction, 3 needed", sp.size()));
    }
  }

  // Pressure series: e = e0 - lambda ln(p/p0).
  if (by_p) {
    std::vector<StatePoint> sp;
    for (const ReportRun& p : scan.runs) {
      if (!p.steady || !std::isfinite(p.phi.v)) continue;
      StatePoint s;
      s.run = p.folder;
      s.nu = {p.phi.v, p.phi.err};
      s.p = std::isfinite(p.p.v) ? Val{p.p.v, p.p.err} : Val{p.pressure, std::nan("")};
      sp.push_back(s);
    }
    try {
      const double p0 = default_p0(sp);
      const auto r = fit_compaction_points(sp, p0);
      fits.push_back(r);
      models.push_back(void_ratio(p0));
      sum.plots_ok = plot_compaction(out_dir, sp, r, p0, report_cmd) && sum.plots_ok;
      sum.fits.push_back("void_ratio");
      html_fit += fmt::format("<h3>Compaction e(p)</h3><img src='compaction.png' width=600><p>{}: e0 = {:.4f} ± "
                              "{:.2g}, λ = {:.4g} ± {:.2g}, χ²/dof = {:.2f}</p>\n",
                              html_escape(void_ratio(p0).formula), r["e0"], r.err("e0"), r["lambda"],
                              r.err("lambda"), r.chi2_dof) +
                  flagged(r, "void_ratio") +
                  made_by(report_cmd, fmt::format("cdanalysis fit compaction {} --out DIR", campaign));
    } catch (const AnalysisError& e) {
      sum.problems.push_back(fmt::format("compaction fit: {}", e.what()));
      refused.push_back({"void_ratio", "e = e0 - lambda ln(p/p0)", e.what()});
      html_fit += fmt::format("<p>Compaction fit refused: {}</p>\n", html_escape(e.what())) +
                  undetermined_html("void_ratio", e.what());
    }
  }

  // Cohesive: c/p against the eta = 0 runs of the campaign.
  if (by_eta) {
    try {
      std::vector<SteadyPoint> ref_pts, coh_pts;
      for (const ReportRun& p : scan.runs) {
        if (!p.steady || !std::isfinite(p.eta)) continue;
        const auto q = steady_point(p.folder);
        (q.eta == 0 ? ref_pts : coh_pts).push_back(q);
      }
      if (coh_pts.empty() || ref_pts.empty())
        throw AnalysisError(fmt::format("{} eta = 0 and {} eta > 0 steady runs: both are needed", ref_pts.size(),
                                        coh_pts.size()));
      const SinPhiReference ref(ref_pts, SinPhiReference::Mode::Auto);
      std::vector<CohesionPoint> cps;
      std::vector<double> eta, I, c, ce;
      for (const auto& q : coh_pts) {
        cps.push_back(cohesion_point(q, ref));
        eta.push_back(q.eta), I.push_back(q.I), c.push_back(cps.back().c_over_p), ce.push_back(cps.back().c_over_p_err);
      }
      const auto r = fit_cohesion(eta, I, c, ce);
      fits.push_back(r);
      models.push_back(cohesion());
      sum.plots_ok = plot_cohesion(out_dir, cps, &r) && sum.plots_ok;
      sum.fits.push_back("cohesion");
      html_fit += fmt::format("<h3>Cohesion c/p</h3><img src='cohesion.png' width=600><p>{}: k0 = {:.4g} ± {:.2g}, "
                              "β = {:.4g} ± {:.2g}, α = {:.4g} ± {:.2g}, χ²/dof = {:.2f}; {} from {} η = 0 "
                              "runs by {}</p>\n",
                              html_escape(cohesion().formula), r["k0"], r.err("k0"), r["beta"], r.err("beta"),
                              r["alpha"], r.err("alpha"), r.chi2_dof,
                              ref.dim() == 3 ? "c/p = μ − μ0(I), μ0(I)" : "sin φ(I)", ref_pts.size(),
                              ref.uses_fit() ? "the μ(I) fit" : "interpolation in ln I") +
                  flagged(r, "cohesion") +
                  made_by(report_cmd, fmt::format("cdanalysis fit cohesion {} --out DIR", campaign));
    } catch (const AnalysisError& e) {
      sum.problems.push_back(fmt::format("cohesion fit: {}", e.what()));
      refused.push_back({"cohesion", cohesion().formula, e.what()});
      html_fit += fmt::format("<p>Cohesion fit refused: {}</p>\n", html_escape(e.what())) +
                  undetermined_html("cohesion", e.what());
    }
  }

  // Angularity: the table of steady quantities against alpha and mu*(alpha).
  if (by_shape) {
    std::vector<AngularityPoint> ap;
    AngularityOptions opt;
    opt.bins = bins;
    for (const ReportRun& p : scan.runs) {
      if (!p.steady) continue;
      try {
        ap.push_back(angularity_point(p.folder, opt));
      } catch (const AnalysisError& e) {
        sum.problems.push_back(fmt::format("angularity: {}", e.what()));
      }
    }
    std::sort(ap.begin(), ap.end(), [](const auto& a, const auto& b) { return a.alpha < b.alpha; });
    std::optional<FitResult> r;
    try {
      r = fit_angularity(ap);
      fits.push_back(*r);
      models.push_back(mu_of_alpha());
      sum.fits.push_back("mu_alpha");
    } catch (const AnalysisError& e) {
      sum.problems.push_back(fmt::format("mu*(alpha) fit: {}", e.what()));
      refused.push_back({"mu_alpha", mu_of_alpha().formula, e.what()});
    }
    if (!ap.empty()) {
      const std::string fit_cmd = fmt::format("cdanalysis fit angularity {} --out DIR", campaign);
      sum.plots_ok = plot_angularity(out_dir, ap, r ? &*r : nullptr, report_cmd) && sum.plots_ok;
      sum.angularity = ap.size();
      html_fit += "<h3>Angularity</h3>\n";
      if (r)
        html_fit += fmt::format("<p>{}: μ0 = {:.4f} ± {:.2g}, μ1 = {:.4f} ± {:.2g}, α_c = {:.4g} ± {:.2g}, "
                                "χ²/dof = {:.2f} (dof {})</p>\n",
                                html_escape(mu_of_alpha().formula), (*r)["mu0"], r->err("mu0"), (*r)["mu1"],
                                r->err("mu1"), (*r)["alpha_c"], r->err("alpha_c"), r->chi2_dof, r->dof) +
                    flagged(*r, "mu_alpha");
      else
        html_fit += "<p>μ*(α) fit refused (see Problems).</p>\n" +
                    undetermined_html("mu_alpha", sum.problems.empty() ? "" : sum.problems.back());
      html_fit +=
          "<p>Table: <a href='angularity.csv'>angularity.csv</a>. Series quantities: steady mean ± block-"
          "averaging error; fabric: mean ± sem over the last 5 contact snapshots. Sliding: |f_t| ≥ μ f_n (1 − "
          "tol) with the run's solver tol. Check q/p ≈ ½Σa: contact-stress q/p of the snapshots against the "
          "Fourier sum and the tensor sum with directions.</p>\n"
          "<table border=1 cellspacing=0 cellpadding=3><tr><th>n_s</th><th>α</th><th>μ*</th><th>ν*</th><th>z</th>"
          "<th>a_c</th><th>a_ln</th><th>a_lt</th><th>a_fn</th><th>a_ft</th><th>sliding</th><th>side–side</th>"
          "<th>q_sv/p</th><th>q_ss/p</th><th>q/p (snapshots)</th><th>½Σa (Fourier)</th><th>½|ΣA| (tensor)</th></tr>\n";
      for (const auto& a : ap) {
        html_fit += fmt::format("<tr><td>{}</td><td>{:.4f}</td>", a.nsides, a.alpha);
        for (const Val* v : {&a.mu, &a.nu, &a.z, &a.a_c, &a.a_ln, &a.a_lt, &a.a_fn, &a.a_ft, &a.sliding,
                             &a.ss_share, &a.q_sv, &a.q_ss, &a.q_over_p_snap, &a.sum_half_fft, &a.sum_half_tensor})
          html_fit += "<td>" + or_na(v->v, v->err) + "</td>";
        html_fit += "</tr>\n";
      }
      html_fit += "</table>\n";
      for (const auto& stem : kAngularityPlots)
        html_fit += fmt::format("<img src='{}.png' width=450>\n", stem);
      html_fit += made_by(report_cmd, fit_cmd);
    }
  }
  write_text((fs::path(out_dir) / "fits.toml").string(), fits_to_toml(fits, models, refused));

  // Cost against I, for a campaign over I (measured I spanning a factor 1.5 or more).
  std::string html_cost;
  {
    double lo = INFINITY, hi = 0;
    std::size_t n = 0;
    for (const ReportRun& p : scan.runs) {
      const double I = p.steady && std::isfinite(p.I.v) && p.I.v > 0 ? p.I.v : p.I_imposed;
      if (p.cost && std::isfinite(I) && I > 0) ++n, lo = std::min(lo, I), hi = std::max(hi, I);
    }
    if (n >= 2 && hi >= 1.5 * lo) {
      sum.cost_plot = true;
      sum.plots_ok = plot_cost_I(out_dir, scan) && sum.plots_ok;
      html_cost = "<h2>Cost against I</h2><img src='cost_I.png' width=600>"
                  "<p>Every run with a summary.toml; the runs without a steady window (open symbols) at their "
                  "imposed I. Data: <a href='cost_I.csv'>cost_I.csv</a>.</p>\n";
    }
  }

  write_text((fs::path(out_dir) / "index.html").string(), report_page(scan, sum, html_fit, html_cost));
  return sum;
}

}  // namespace cda