#include "report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "plot.hpp"
#include "report_html.hpp"
#include "report_scan.hpp"
#include "report_sections.hpp"
#include "report_tables.hpp"

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

// Cost against I, for a campaign over I: the measured I (not steady: the
// imposed one) of the costed runs spanning a factor 1.5 or more. The page's
// section, or empty.
std::string cost_section(const ReportScan& scan, const std::string& out_dir, ReportSummary& sum) {
  double lo = INFINITY, hi = 0;
  std::size_t n = 0;
  for (const ReportRun& p : scan.runs) {
    const double I = p.steady && std::isfinite(p.I.v) && p.I.v > 0 ? p.I.v : p.I_imposed;
    if (p.cost && std::isfinite(I) && I > 0) ++n, lo = std::min(lo, I), hi = std::max(hi, I);
  }
  if (n < 2 || hi < 1.5 * lo) return "";
  sum.cost_plot = true;
  sum.plots_ok = plot_cost_I(out_dir, scan) && sum.plots_ok;
  return "<h2>Cost against I</h2><img src='cost_I.png' width=600>"
         "<p>Every run with a summary.toml; the runs without a steady window (open symbols) at their "
         "imposed I. Data: <a href='cost_I.csv'>cost_I.csv</a>.</p>\n";
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

ReportSummary write_report(const std::string& campaign, const std::string& out_dir, int bins,
                           const std::string& window) {
  const ReportScan scan = scan_campaign(campaign, bins, window);
  fs::create_directories(out_dir);
  ReportSummary sum = summarize(scan);
  sum.plots_ok = draw_run_plots(scan, out_dir);
  write_tables(scan, out_dir);

  // The fits by the campaign's kind, each kind its section of the page.
  const CampaignKind kind = campaign_kind(scan);
  sum.kinds = kind.names();
  ReportFits fits(campaign, out_dir, sum);
  fits.html = kind_html(kind);
  if (kind.inertial) inertial_section(scan, kind, fits);
  if (kind.pressure) pressure_section(scan, fits);
  if (kind.cohesive) cohesive_section(scan, fits);
  if (kind.angularity) angularity_section(scan, bins, fits);
  write_text((fs::path(out_dir) / "fits.toml").string(), fits_to_toml(fits.fits, fits.models, fits.refused));

  const std::string cost_html = cost_section(scan, out_dir, sum);
  write_text((fs::path(out_dir) / "index.html").string(), report_page(scan, sum, fits.html, cost_html));
  return sum;
}

}  // namespace cda
