#include "report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "cost.hpp"

namespace fs = std::filesystem;

namespace cda {
namespace {

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("cannot write '{}'", path));
  out << text;
}

std::string toml_num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string s = fmt::format("{:.17g}", v);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}

// The cost columns of every table, and their values (nan without a summary).
const std::vector<std::string> kCostColumns = {"wall_time", "cpu_time", "steps", "sweeps_per_step",
                                               "cap_share"};
std::vector<double> cost_values(const std::optional<RunCost>& c) {
  if (!c) return std::vector<double>(kCostColumns.size(), std::nan(""));
  return {c->wall_time, c->cpu_time, c->steps, c->sweeps_per_step, c->cap_share};
}

// A value for a text table: "n/a" when not measured.
std::string or_na(double v, const char* spec = "{:.4g}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : "n/a";
}
std::string or_na(double v, double err) {
  return std::isfinite(v) ? (std::isfinite(err) ? fmt::format("{:.4g} ± {:.2g}", v, err)
                                                : fmt::format("{:.4g}", v))
                          : "n/a";
}

// One row of the report's table of points: physics and cost side by side.
struct Point {
  std::string name, status;
  double I = std::nan(""), I_err = std::nan(""), mu = std::nan(""), mu_err = std::nan("");
  double phi = std::nan(""), phi_err = std::nan(""), z = std::nan(""), z_err = std::nan("");
  std::optional<RunCost> cost;
};

// Wall time and sweeps per step against the measured I (log-log), the
// points of an inertial campaign: dir/cost_I.{png,svg}, data in cost_I.csv.
bool plot_cost_I(const std::string& dir, const std::vector<Point>& points) {
  Table t({"I", "wall_time", "sweeps_per_step", "cap_share", "steps"});
  for (const Point& p : points)
    if (p.cost && std::isfinite(p.I) && p.I > 0)
      t.add_row({p.I, p.cost->wall_time, p.cost->sweeps_per_step, p.cost->cap_share, p.cost->steps});
  t.write_csv((fs::path(dir) / "cost_I.csv").string());
  const std::string body =
      "set datafile separator ','\nset logscale x\nset logscale y\nset logscale y2\n"
      "set xlabel 'I (measured)'\nset ylabel 'wall time (s)'\nset y2label 'NLGS sweeps per step'\n"
      "set ytics nomirror\nset y2tics\nset key top right\nset grid\n"
      "plot 'cost_I.csv' every ::1 using 1:2 with linespoints pt 7 lc rgb '#1f3b73' title 'wall time', \\\n"
      "     'cost_I.csv' every ::1 using 1:3 axes x1y2 with linespoints pt 5 lc rgb '#b03a2e' "
      "title 'sweeps per step'\n";
  return plot_both(dir, "cost_I", body);
}

}  // namespace

std::string fits_to_toml(const std::vector<FitResult>& fits, const std::vector<Model>& models) {
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
    for (std::size_t i = 0; i < p; ++i)
      s += fmt::format("\n[{}.params.{}]\nvalue = {}\nerror = {}\n", r.model, r.names[i],
                       toml_num(r.value[i]), toml_num(r.error[i]));
  }
  return s;
}

bool run_gnuplot(const std::string& script) {
  const std::string cmd = fmt::format("gnuplot '{}' > '{}.log' 2>&1", script, script);
  return std::system(cmd.c_str()) == 0;
}

bool plot_both(const std::string& dir, const std::string& stem, const std::string& body, int width,
               int height) {
  const std::string gp = (fs::path(dir) / (stem + ".gp")).string();
  const std::string s = fmt::format(
      "# cdanalysis plot; rerun with: gnuplot {0}.gp\ncd '{1}'\n"
      "set terminal pngcairo size {2},{3} enhanced\nset output '{0}.png'\n{4}\n"
      "set terminal svg size {2},{3} dynamic enhanced\nset output '{0}.svg'\nreplot\nunset output\n",
      stem, fs::absolute(dir).string(), width, height, body);
  write_text(gp, s);
  return run_gnuplot(gp);
}

bool plot_series(const std::string& dir, const std::string& stem, const Table& series,
                 const std::string& x_column, const std::string& column, const Window* w) {
  Table t({x_column, column});
  const auto& x = series.column(x_column);
  const auto& y = series.column(column);
  for (std::size_t i = 0; i < x.size(); ++i) t.add_row({x[i], y[i]});
  t.write_csv((fs::path(dir) / (stem + ".csv")).string());
  std::string body = fmt::format("set datafile separator ','\nset key top right\nset xlabel '{}'\n"
                                 "set ylabel '{}' noenhanced\nset grid\n", x_column, column);
  if (w)
    body += fmt::format("set object 1 rect from {},graph 0 to {},graph 1 fc rgb '#cce5ff' fs solid 0.5 behind\n",
                        w->x_begin, w->x_end);
  body += fmt::format("plot '{}.csv' using 1:2 every ::1 with lines lc rgb '#1f3b73' title '{}{}' noenhanced\n",
                      stem, column, w ? " (steady window shaded)" : "");
  return plot_both(dir, stem, body);
}

bool plot_mu_I(const std::string& dir, std::span<const double> I, std::span<const double> mu,
               std::span<const double> mu_err, const FitResult& r) {
  const Model model = mu_of_I();
  std::filesystem::create_directories(dir);
  Table pts({"I", "mu", "mu_err"});
  for (std::size_t i = 0; i < I.size(); ++i) pts.add_row({I[i], mu[i], mu_err[i]});
  pts.write_csv((fs::path(dir) / "mu_I_data.csv").string());
  Table curve({"I", "mu", "lo", "hi"});
  const double lo = *std::min_element(I.begin(), I.end()) / 2, hi = *std::max_element(I.begin(), I.end()) * 2;
  for (int k = 0; k <= 200; ++k) {
    const double x = lo * std::pow(hi / lo, k / 200.0);
    const double m = predict(model, r, &x), e = predict_error(model, r, &x);
    curve.add_row({x, m, m - e, m + e});
  }
  curve.write_csv((fs::path(dir) / "mu_I_fit.csv").string());
  const std::string body = fmt::format(
      "set datafile separator ','\nset logscale x\nset xlabel 'I'\nset ylabel 'μ* = q/p'\n"
      "set key top left\nset grid\n"
      "plot 'mu_I_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
      "     'mu_I_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' "
      "title 'μ_1 = {:.3f}, μ_2 = {:.3f}, I_0 = {:.3g}', \\\n"
      "     'mu_I_data.csv' every ::1 using 1:2:3 with yerrorbars pt 7 lc rgb 'black' title 'runs'\n",
      r["mu1"], r["mu2"], r["I0"]);
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
    std::string label, offset;
  };
  // <ft> changes sign: it is drawn as <fn> + <ft>(theta) so the radius stays
  // positive (the circle r = <fn> is the zero line).
  const std::string off = toml_num(a.mean_fn);
  for (const Q& q : {Q{"P", 2, fmt::format("P(θ), a_c = {:.3f}", a.c.a()), "0"},
                     Q{"fn", 3, fmt::format("<f_n>(θ), a_{{fn}} = {:.3f}", a.fn.a()), "0"},
                     Q{"ft", 4, fmt::format("<f_n> + <f_t>(θ), a_{{ft}} = {:.3f}", a.ft.a()), off}}) {
    const std::string body = fmt::format(
        "set datafile separator ','\nset polar\nset angles radians\nset size square\n"
        "unset xtics\nunset ytics\nset border 0\nset grid polar pi/6\nset key bottom right\n"
        "set title '{}'\n"
        "plot '{}_profile.csv' every ::1 using 1:(${}+{}) with points pt 7 ps 0.6 title 'binned', \\\n"
        "     '{}_fourier.csv' every ::1 using 1:(${}+{}) with lines lw 2 title 'Fourier fit'\n",
        q.label, stem, q.col, q.offset, stem, q.col, q.offset);
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
  const auto runs = campaign_runs(campaign);
  fs::create_directories(out_dir);
  ReportSummary sum;
  sum.runs = runs.size();
  const std::vector<std::string> quantities = {"q_over_p", "inertial_number", "packing_fraction", "z", "p"};
  std::vector<std::string> names = {"run"};
  for (const auto& q : quantities) {
    names.push_back(q);
    names.push_back(q + "_err");
  }
  names.insert(names.end(), {"window_begin", "window_end", "tau_int", "n_eff"});
  names.insert(names.end(), kCostColumns.begin(), kCostColumns.end());
  Table steady(names);
  std::vector<std::string> fabric_names = {
      "run", "a_c", "theta_c", "a_ln", "a_lt", "a_fn", "a_ft", "sum_half", "q_over_p",
      "a_c_tensor", "a_ln_tensor", "a_lt_tensor", "a_fn_tensor", "a_ft_tensor",
      "sliding", "z", "non_floating"};
  fabric_names.insert(fabric_names.end(), kCostColumns.begin(), kCostColumns.end());
  Table fabric(fabric_names);
  std::string runs_csv = "run,folder,status";
  for (const auto& c : kCostColumns) runs_csv += "," + c;
  runs_csv += ",threads\n";
  std::vector<Point> points;
  std::string html_runs;
  std::vector<double> I, mu, mu_err;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::string& run = runs[k];
    const std::string name = fs::path(run).filename().string();
    std::string status = "ok";
    std::string stem = fmt::format("run{:03d}", k);
    html_runs += fmt::format("<h3>{} ({})</h3>\n", html_escape(name), stem);
    Point pt;
    pt.name = name;
    try {
      pt.cost = read_run_cost(run);
    } catch (const AnalysisError& e) {
      sum.problems.push_back(e.what());  // the cost columns say n/a
    }
    if (pt.cost) {
      ++sum.costed;
      sum.wall_time += pt.cost->wall_time;
      sum.cpu_time += pt.cost->cpu_time;
    }
    const std::vector<double> cost = cost_values(pt.cost);
    try {
      const auto series = read_series(run);
      const std::string xc = default_x_column(series);
      const std::string main = series.has("q_over_p") ? "q_over_p" : "kinetic_energy";
      Window w{};
      bool have_window = false;
      try {
        const auto rs = run_steady(run, series, main, xc, std::nullopt);
        w = rs.stats.window;
        have_window = true;
        std::vector<double> row = {static_cast<double>(k)};
        double tau = rs.stats.acf.tau, neff = rs.stats.acf.n_eff;
        for (const auto& q : quantities) {
          if (q == "inertial_number" && series.has(q)) {
            const auto st = measured_inertial_number(series, xc, w);  // from <sigma_yy>
            row.push_back(st.mean);
            row.push_back(st.err);
          } else if (series.has(q)) {
            const auto st = stats_over(series, q, xc, w);
            row.push_back(st.mean);
            row.push_back(st.error());
          } else {
            row.push_back(std::nan(""));
            row.push_back(std::nan(""));
          }
        }
        row.insert(row.end(), {w.x_begin, w.x_end, tau, neff});
        row.insert(row.end(), cost.begin(), cost.end());
        steady.add_row(row);
        pt.mu = row[1], pt.mu_err = row[2], pt.I = row[3], pt.I_err = row[4];
        pt.phi = row[5], pt.phi_err = row[6], pt.z = row[7], pt.z_err = row[8];
        ++sum.steady;
        if (series.has("q_over_p") && series.has("inertial_number")) {
          I.push_back(row[3]);
          mu.push_back(row[1]);
          mu_err.push_back(row[2]);
        }
      } catch (const AnalysisError& e) {
        status = "not steady";
        sum.problems.push_back(fmt::format("{}: {}", run, e.what()));
        html_runs += fmt::format("<p>not steady: {}</p>\n", html_escape(e.what()));
      }
      sum.plots_ok = plot_series(out_dir, stem + "_series", series, xc, main, have_window ? &w : nullptr) && sum.plots_ok;
      html_runs += fmt::format("<img src='{}_series.png' width=600>\n", stem);
      if (!list_snapshots(run, "contacts").empty()) {
        try {
          const auto f = run_fabric(run, -1, bins, -1);
          const auto& a = f.fft;
          const auto& b = f.tensor;
          std::vector<double> frow = {
              static_cast<double>(k), a.c.a(), a.c.theta(), a.ln.a(), a.lt.a(), a.fn.a(),
              a.ft.a(), a.sum_half(), f.stress.q_over_p(), b.c.a(), b.ln.a(), b.lt.a(),
              b.fn.a(), b.ft.a(), f.sliding,
              f.connectivity ? f.connectivity->z : std::nan(""),
              f.connectivity ? f.connectivity->non_floating : std::nan("")};
          frow.insert(frow.end(), cost.begin(), cost.end());
          fabric.add_row(frow);
          ++sum.fabric;
          sum.plots_ok = plot_polar(out_dir, stem + "_polar", f) && sum.plots_ok;
          html_runs += fmt::format("<p>last snapshot {}</p>\n", html_escape(f.file));
          for (const char* q : {"P", "fn", "ft"})
            html_runs += fmt::format("<img src='{}_polar_{}.png' width=300>\n", stem, q);
        } catch (const AnalysisError& e) {
          sum.problems.push_back(fmt::format("{}: {}", run, e.what()));
          html_runs += fmt::format("<p>fabric: {}</p>\n", html_escape(e.what()));
        }
      }
    } catch (const AnalysisError& e) {
      status = "unreadable";
      sum.problems.push_back(e.what());
      html_runs += fmt::format("<p>{}</p>\n", html_escape(e.what()));
    }
    runs_csv += fmt::format("{},\"{}\",{}", k, run, status);
    for (const double v : cost) runs_csv += "," + or_na(v, "{}");  // shortest exact text
    runs_csv += "," + (pt.cost ? fmt::format("{}", pt.cost->threads) : std::string("n/a")) + "\n";
    pt.status = status;
    points.push_back(pt);
  }
  write_text((fs::path(out_dir) / "runs.csv").string(), runs_csv);
  steady.write_csv((fs::path(out_dir) / "steady.csv").string());
  fabric.write_csv((fs::path(out_dir) / "fabric.csv").string());

  std::vector<FitResult> fits;
  std::vector<Model> models;
  std::string html_fit;
  if (I.size() >= 4) {
    try {
      const auto r = fit_mu_I(I, mu, mu_err);
      fits.push_back(r);
      models.push_back(mu_of_I());
      sum.plots_ok = plot_mu_I(out_dir, I, mu, mu_err, r) && sum.plots_ok;
      html_fit = fmt::format("<h2>μ(I)</h2><img src='mu_I.png' width=600><p>{}: chi2/dof = {:.2f}</p>\n",
                             html_escape(mu_of_I().formula), r.chi2_dof);
    } catch (const AnalysisError& e) {
      sum.problems.push_back(fmt::format("mu(I) fit: {}", e.what()));
    }
  } else {
    html_fit = fmt::format("<p>μ(I) fit skipped: {} steady runs with q_over_p and inertial_number "
                           "(4 needed)</p>\n", I.size());
  }
  write_text((fs::path(out_dir) / "fits.toml").string(), fits_to_toml(fits, models));

  // Cost against I, for a campaign over I (measured I spanning a factor 1.5 or more).
  std::string html_cost;
  {
    double lo = INFINITY, hi = 0;
    std::size_t n = 0;
    for (const Point& p : points)
      if (p.cost && std::isfinite(p.I) && p.I > 0) ++n, lo = std::min(lo, p.I), hi = std::max(hi, p.I);
    if (n >= 2 && hi >= 1.5 * lo) {
      sum.cost_plot = true;
      sum.plots_ok = plot_cost_I(out_dir, points) && sum.plots_ok;
      html_cost = "<h2>Cost against I</h2><img src='cost_I.png' width=600>"
                  "<p>Data: <a href='cost_I.csv'>cost_I.csv</a>.</p>\n";
    }
  }

  // The table of points: physics, then what each cost (summary.toml; n/a without one).
  std::string html_points =
      "<h2>Points</h2>\n<table border=1 cellspacing=0 cellpadding=3>\n"
      "<tr><th colspan=6>physics (steady window)</th><th colspan=5>cost (summary.toml)</th></tr>\n"
      "<tr><th>run</th><th>status</th><th>I</th><th>μ* = q/p</th><th>φ</th><th>z</th>"
      "<th>wall time (s)</th><th>CPU time (s)</th><th>steps</th><th>sweeps/step</th><th>at cap</th></tr>\n";
  for (const Point& p : points) {
    const std::vector<double> c = cost_values(p.cost);
    html_points += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td></tr>\n",
        html_escape(p.name), html_escape(p.status), or_na(p.I, p.I_err), or_na(p.mu, p.mu_err),
        or_na(p.phi, p.phi_err), or_na(p.z, p.z_err), or_na(c[0], "{:.1f}"), or_na(c[1], "{:.1f}"),
        or_na(c[2], "{:.0f}"), or_na(c[3], "{:.1f}"),
        std::isfinite(c[4]) ? fmt::format("{:.1f} %", 100 * c[4]) : "n/a");
  }
  html_points += "</table>\n";
  const std::string html_total =
      sum.costed
          ? fmt::format("<p>Cost of the campaign: {:.1f} s of wall time ({:.2f} h) and {:.1f} s of CPU "
                        "time over the {} runs with a summary.toml{}.</p>\n",
                        sum.wall_time, sum.wall_time / 3600, sum.cpu_time, sum.costed,
                        sum.costed < sum.runs
                            ? fmt::format("; {} without one are not counted", sum.runs - sum.costed)
                            : "")
          : "<p>Cost of the campaign: n/a (no run has a summary.toml).</p>\n";

  std::string html = fmt::format(
      "<!doctype html>\n<html><head><meta charset='utf-8'><title>cdanalysis report</title></head><body>\n"
      "<h1>cdanalysis report: {}</h1>\n<p>{} runs, {} steady, {} with fabric. Tables: "
      "<a href='runs.csv'>runs.csv</a>, <a href='steady.csv'>steady.csv</a>, "
      "<a href='fabric.csv'>fabric.csv</a>; fits: <a href='fits.toml'>fits.toml</a>.</p>\n",
      html_escape(campaign), sum.runs, sum.steady, sum.fabric);
  html += html_total + html_points + html_fit + html_cost;
  if (!sum.problems.empty()) {
    html += "<h2>Problems</h2><ul>\n";
    for (const auto& p : sum.problems) html += "<li>" + html_escape(p) + "</li>\n";
    html += "</ul>\n";
  }
  html += "<h2>Runs</h2>\n" + html_runs + "</body></html>\n";
  write_text((fs::path(out_dir) / "index.html").string(), html);
  return sum;
}

}  // namespace cda
