#include "report_html.hpp"

#include <fmt/core.h>

#include <cmath>

#include "report_tables.hpp"

namespace cda {
namespace {

// The shear profile's rate_min over the steady window, when measured.
std::string shear_profile_html(const Val& rate_min) {
  return fmt::format("<p>shear profile (5 layers): rate_min = {}{}</p>\n", or_na(rate_min.v, rate_min.err),
                     is_banded(rate_min.v) ? " — <b>banded</b>: a layer moves nearly as a rigid plug; this run's I is "
                                             "not the local one (cdanalysis profile)"
                                           : "");
}

// 3D: the window's anisotropies beside q/p, and which snapshots made them.
std::string fabric3_html(const ReportRun& r) {
  const WindowFabric3& fw = *r.fabric3;
  const Window w = r.main_stats ? r.main_stats->window : Window{};
  const char* xs = r.x_column == "strain" ? "γ" : "t";
  const double qp = fw.of("q_over_p").v;
  const double rel = fw.check_rel, rel_err = fw.check_rel_err;
  const std::string what =
      fw.averaged ? fmt::format("mean ± sem over {} snapshots in the steady window {} = {:.4g}–{:.4g} ({} … {}; "
                                "{:.0f} force-bearing contacts each on average)",
                                fw.files.size(), xs, w.x_begin, w.x_end, html_escape(fw.files.front()),
                                html_escape(fw.files.back()), fw.bearing)
                  : fmt::format("last snapshot {} alone ({}; no error bars from one snapshot; {:.0f} "
                                "force-bearing contacts)",
                                html_escape(fw.files.front()), html_escape(fw.alone), fw.bearing);
  return fmt::format(
      "<p>fabric: {}: a_c = {}, a_n = {}, a_t = {}; q/p = {} (q = (σ1 − σ3)/3) against "
      "(2/5)(a_c + a_n + a_t) = {}: relative deviation ((2/5)Σa − q/p)/(q/p) = {}; "
      "μ = −σ_xy/σ_yy = {}; z = {}</p>\n",
      what, or_na(fw.of("a_c").v, fw.of("a_c").err), or_na(fw.of("a_n").v, fw.of("a_n").err),
      or_na(fw.of("a_t").v, fw.of("a_t").err), or_na(qp, fw.of("q_over_p").err),
      or_na(fw.of("sum_2_5").v, fw.of("sum_2_5").err),
      std::isfinite(rel) ? (std::isfinite(rel_err) ? fmt::format("{:+.1f} % ± {:.1f} %", 100 * rel, 100 * rel_err)
                                                   : fmt::format("{:+.1f} %", 100 * rel))
                         : std::string("n/a"),
      or_na(fw.of("mu").v, fw.of("mu").err), or_na(fw.of("z").v, fw.of("z").err));
}

// 2D: the last snapshot's polar diagrams.
std::string fabric2_html(const ReportRun& r) {
  std::string s = fmt::format("<p>last snapshot {}</p>\n", html_escape(r.fabric2->file));
  for (const char* q : {"P", "fn", "ft"}) s += fmt::format("<img src='{}_polar_{}.png' width=300>\n", r.stem(), q);
  return s;
}

}  // namespace

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

std::string run_html(const ReportRun& r) {
  std::string s = fmt::format("<h3>{} ({})</h3>\n", html_escape(r.name), r.stem());
  if (!r.skipped_why.empty()) s += fmt::format("<p>{}</p>\n", html_escape(r.skipped_why));
  if (r.measured && std::isfinite(r.rate_min.v)) s += shear_profile_html(r.rate_min);
  if (!r.not_steady_why.empty()) s += fmt::format("<p>not steady: {}</p>\n", html_escape(r.not_steady_why));
  if (r.curve) s += fmt::format("<img src='{}_series.png' width=600>\n", r.stem());
  if (r.fabric3) s += fabric3_html(r);
  if (r.fabric2) s += fabric2_html(r);
  if (!r.fabric_why.empty()) s += fmt::format("<p>fabric: {}</p>\n", html_escape(r.fabric_why));
  if (!r.unreadable_why.empty()) s += fmt::format("<p>{}</p>\n", html_escape(r.unreadable_why));
  return s;
}

std::string points_html(const ReportScan& scan) {
  const int dim = scan.dimension;
  std::string s =
      fmt::format("<h2>Points</h2>\n<p>{}D runs{}.</p>\n<table border=1 cellspacing=0 cellpadding=3>\n", dim,
                  dim == 3 ? ": μ = −(σ_xy + σ_yx)/2σ_yy (shear_stress_ratio); fabric.csv holds a_c, a_n, a_t "
                             "of the spherical-harmonic expansion and q/p with q = (σ1 − σ3)/3, each the mean ± sem "
                             "over the contact snapshots in the run's steady window (fabric_snapshots of them)"
                           : "") +
      "<tr><th colspan=6>physics (steady window)</th><th colspan=5>cost (summary.toml)</th></tr>\n"
      "<tr><th>run</th><th>status</th><th>I</th><th>" + std::string(dim == 3 ? "μ = −σ_xy/σ_yy" : "μ* = q/p") +
      "</th><th>φ</th><th>z</th>"
      "<th>wall time (s)</th><th>CPU time (s)</th><th>steps</th><th>sweeps/step</th><th>at cap</th></tr>\n";
  for (const ReportRun& r : scan.runs) {
    const std::vector<double> c = cost_values(r.cost);
    s += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td></tr>\n",
        html_escape(r.name), html_escape(r.status), or_na(r.I.v, r.I.err), or_na(r.mu.v, r.mu.err),
        or_na(r.phi.v, r.phi.err), or_na(r.z.v, r.z.err), or_na(c[0], "{:.1f}"), or_na(c[1], "{:.1f}"),
        or_na(c[2], "{:.0f}"), or_na(c[3], "{:.1f}"), std::isfinite(c[4]) ? fmt::format("{:.1f} %", 100 * c[4]) : "n/a");
  }
  return s + "</table>\n";
}

std::string cost_total_html(const ReportSummary& sum) {
  if (!sum.costed) return "<p>Cost of the campaign: n/a (no run has a summary.toml).</p>\n";
  return fmt::format("<p>Cost of the campaign: {:.1f} s of wall time ({:.2f} h) and {:.1f} s of CPU "
                     "time over the {} runs with a summary.toml{}.</p>\n",
                     sum.wall_time, sum.wall_time / 3600, sum.cpu_time, sum.costed,
                     sum.costed < sum.runs ? fmt::format("; {} without one are not counted", sum.runs - sum.costed)
                                           : "");
}

std::string report_page(const ReportScan& scan, const ReportSummary& sum, const std::string& fits_html,
                        const std::string& cost_html) {
  std::string html = fmt::format(
      "<!doctype html>\n<html><head><meta charset='utf-8'><title>cdanalysis report</title></head><body>\n"
      "<h1>cdanalysis report: {}</h1>\n<p>{} runs, {} steady, {} with fabric. Tables: "
      "<a href='runs.csv'>runs.csv</a>, <a href='steady.csv'>steady.csv</a>, "
      "<a href='fabric.csv'>fabric.csv</a>; fits: <a href='fits.toml'>fits.toml</a>.</p>\n",
      html_escape(scan.campaign), sum.runs, sum.steady, sum.fabric);
  html += cost_total_html(sum) + points_html(scan) + fits_html + cost_html;
  if (!sum.problems.empty()) {
    html += "<h2>Problems</h2><ul>\n";
    for (const auto& p : sum.problems) html += "<li>" + html_escape(p) + "</li>\n";
    html += "</ul>\n";
  }
  html += "<h2>Runs</h2>\n";
  for (const ReportRun& r : scan.runs) html += run_html(r);
  return html + "</body></html>\n";
}

}  // namespace cda
