#include "report_sections.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "cohesion.hpp"
#include "report_html.hpp"
#include "report_tables.hpp"
#include "trends.hpp"

namespace cda {
namespace {

// Distinct finite values.
std::vector<double> distinct(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

std::string mu_label(int dim) { return dim == 3 ? "μ = −σ_xy/σ_yy" : "μ* = q/p"; }

// The points of mu(I) and nu(I): the steady cohesionless runs of the first
// steady run's shape (another shape or cohesion is another law).
struct InertialPoints {
  std::vector<double> I, mu, mu_err;
  std::vector<StatePoint> nu;
};
InertialPoints inertial_points(const ReportScan& scan) {
  InertialPoints pts;
  const int shape0 = [&] {
    for (const ReportRun& p : scan.runs)
      if (p.steady) return p.nsides;
    return -1;
  }();
  for (const ReportRun& p : scan.runs) {
    if (!p.steady || !std::isfinite(p.I.v) || (std::isfinite(p.eta) && p.eta != 0) || p.nsides != shape0) continue;
    if (std::isfinite(p.mu.v)) pts.I.push_back(p.I.v), pts.mu.push_back(p.mu.v), pts.mu_err.push_back(p.mu.err);
    if (std::isfinite(p.phi.v)) {
      StatePoint s;
      s.run = p.folder;
      s.I = {p.I.v, p.I.err};
      s.nu = {p.phi.v, p.phi.err};
      s.volume = p.volume;
      pts.nu.push_back(s);
    }
  }
  return pts;
}

// mu(I) with 4 points or more; with fewer, the points alone, drawn and said
// undetermined. sel: which runs, when the campaign varies more than I.
void mu_I_fit(const InertialPoints& pts, int dim, const std::string& sel, ReportFits& out) {
  const auto& I = pts.I;
  const auto& mu = pts.mu;
  const auto& mu_err = pts.mu_err;
  if (I.size() < 4) {
    out.html += fmt::format("<p>μ(I) fit skipped: {} steady runs with {} and inertial_number{} "
                            "(4 needed)</p>\n", I.size(), mu_column(dim), sel);
    if (!I.empty()) {
      const std::string why = fmt::format("{} steady runs, 4 needed", I.size());
      out.refused.push_back({"mu_I", mu_of_I().formula, why});
      out.sum.plots_ok = plot_mu_I(out.out_dir, I, mu, mu_err, nullptr, mu_label(dim)) && out.sum.plots_ok;
      out.html += "<img src='mu_I.png' width=600>\n" + out.undetermined("mu_I", why);
    }
    return;
  }
  std::optional<FitResult> r;
  std::string why;
  try {
    r = fit_mu_I(I, mu, mu_err);
    out.fits.push_back(*r);
    out.models.push_back(mu_of_I());
    out.sum.fits.push_back("mu_I");
  } catch (const AnalysisError& e) {
    why = e.what();
    out.refused.push_back({"mu_I", mu_of_I().formula, why});
    out.sum.problems.push_back(fmt::format("mu(I) fit: {}", why));
  }
  out.sum.plots_ok = plot_mu_I(out.out_dir, I, mu, mu_err, r ? &*r : nullptr, mu_label(dim)) && out.sum.plots_ok;
  if (r)
    out.html += fmt::format("<h3>μ(I){}</h3><img src='mu_I.png' width=600><p>{}: μ1 = {:.4f} ± {:.2g}{}, "
                            "μ2 = {:.4f} ± {:.2g}{}, I0 = {:.4g} ± {:.2g}{}, χ²/dof = {:.2f}</p>\n",
                            sel, html_escape(mu_of_I().formula), (*r)["mu1"], r->err("mu1"),
                            undetermined_flag(*r, "mu1"), (*r)["mu2"], r->err("mu2"), undetermined_flag(*r, "mu2"),
                            (*r)["I0"], r->err("I0"), undetermined_flag(*r, "I0"), r->chi2_dof) +
                out.flagged(*r, "mu_I");
  else
    out.html += fmt::format("<h3>μ(I){}</h3><img src='mu_I.png' width=600><p>{}: fit refused.</p>\n", sel,
                            html_escape(mu_of_I().formula)) +
                out.undetermined("mu_I", why);
  out.html += out.made_by(fmt::format("cdanalysis fit mu-i {} --out DIR", out.campaign));
}

// nu(I) with 3 points or more; with fewer, said undetermined.
void nu_I_fit(const std::vector<StatePoint>& sp, const std::string& sel, ReportFits& out) {
  if (sp.size() < 3) {
    out.html += fmt::format("<p>ν(I) fit skipped: {} steady runs with packing_fraction{} (3 needed)</p>\n",
                            sp.size(), sel);
    if (!sp.empty())
      out.html += out.undetermined("nu_I", fmt::format("{} steady runs with packing_fraction, 3 needed", sp.size()));
    return;
  }
  std::optional<FitResult> r;
  std::string why;
  try {
    const Model m = nu_model(sp);
    r = fit_nu_I_points(sp);
    out.fits.push_back(*r);
    out.models.push_back(m);
    out.sum.plots_ok = plot_nu_I(out.out_dir, sp, *r, out.report_cmd) && out.sum.plots_ok;
    out.sum.fits.push_back("nu_I");
  } catch (const AnalysisError& e) {
    why = e.what();
    out.refused.push_back({"nu_I", nu_of_I().formula, why});
    out.sum.problems.push_back(fmt::format("nu(I) fit: {}", why));
  }
  if (r)
    out.html += fmt::format("<h3>ν(I){}</h3><img src='nu_I.png' width=600><p>{}: ν_max = {:.4f} ± {:.2g}{}, "
                            "a = {:.4g} ± {:.2g}{}, χ²/dof = {:.2f}</p>\n",
                            sel, html_escape(nu_of_I().formula), (*r)["nu_max"], r->err("nu_max"),
                            undetermined_flag(*r, "nu_max"), (*r)["a"], r->err("a"), undetermined_flag(*r, "a"),
                            r->chi2_dof) +
                out.flagged(*r, "nu_I");
  else
    out.html += fmt::format("<h3>ν(I){}</h3><p>{}: fit refused.</p>\n", sel, html_escape(nu_of_I().formula)) +
                out.undetermined("nu_I", why);
  out.html += out.made_by(fmt::format("cdanalysis fit nu-i {} --out DIR", out.campaign));
}

// The angularity table on the page: one row per run, sorted by alpha.
std::string angularity_table_html(const std::vector<AngularityPoint>& ap) {
  std::string s =
      "<p>Table: <a href='angularity.csv'>angularity.csv</a>. Series quantities: steady mean ± block-"
      "averaging error; fabric: mean ± sem over the last 5 contact snapshots. Sliding: |f_t| ≥ μ f_n (1 − "
      "tol) with the run's solver tol. Check q/p ≈ ½Σa: contact-stress q/p of the snapshots against the "
      "Fourier sum and the tensor sum with directions.</p>\n"
      "<table border=1 cellspacing=0 cellpadding=3><tr><th>n_s</th><th>α</th><th>μ*</th><th>ν*</th><th>z</th>"
      "<th>a_c</th><th>a_ln</th><th>a_lt</th><th>a_fn</th><th>a_ft</th><th>sliding</th><th>side–side</th>"
      "<th>q_sv/p</th><th>q_ss/p</th><th>q/p (snapshots)</th><th>½Σa (Fourier)</th><th>½|ΣA| (tensor)</th></tr>\n";
  for (const auto& a : ap) {
    s += fmt::format("<tr><td>{}</td><td>{:.4f}</td>", a.nsides, a.alpha);
    for (const Val* v : {&a.mu, &a.nu, &a.z, &a.a_c, &a.a_ln, &a.a_lt, &a.a_fn, &a.a_ft, &a.sliding, &a.ss_share,
                         &a.q_sv, &a.q_ss, &a.q_over_p_snap, &a.sum_half_fft, &a.sum_half_tensor})
      s += "<td>" + or_na(v->v, v->err) + "</td>";
    s += "</tr>\n";
  }
  return s + "</table>\n";
}

}  // namespace

std::vector<std::string> CampaignKind::names() const {
  std::vector<std::string> k;
  if (inertial) k.push_back("inertial (I varies)");
  if (cohesive) k.push_back("cohesive (cohesion_number varies)");
  if (angularity) k.push_back("angularity (nsides varies)");
  if (pressure) k.push_back("pressure series (pressure varies)");
  if (volume) k.push_back("volume series (volume_fraction varies; p and I measured)");
  return k;
}

CampaignKind campaign_kind(const ReportScan& scan) {
  std::vector<double> etas, Is, ps, ns, phis;
  for (const ReportRun& p : scan.runs) {
    etas.push_back(p.eta);
    Is.push_back(p.I_imposed);
    // Under volume control p is the scale of t_p only, not a variable.
    ps.push_back(p.volume ? std::nan("") : p.pressure);
    ns.push_back(p.nsides >= 0 ? p.nsides : std::nan(""));
    phis.push_back(p.volume ? p.volume_fraction : std::nan(""));
  }
  CampaignKind k;
  k.volume = distinct(phis).size() >= 2;
  k.angularity = distinct(ns).size() >= 2;
  k.cohesive = distinct(etas).size() >= 2;
  k.pressure = distinct(ps).size() >= 2;
  k.inertial = distinct(Is).size() >= 2;
  if (distinct(Is).empty()) {  // no scene says I: the measured I spanning a factor 1.5
    double lo = INFINITY, hi = 0;
    for (const ReportRun& p : scan.runs)
      if (std::isfinite(p.I.v) && p.I.v > 0) lo = std::min(lo, p.I.v), hi = std::max(hi, p.I.v);
    k.inertial = hi >= 1.5 * lo;
  }
  return k;
}

ReportFits::ReportFits(const std::string& campaign, const std::string& out_dir, ReportSummary& sum)
    : campaign(campaign),
      out_dir(out_dir),
      report_cmd(fmt::format("cdanalysis report {} --out {}", campaign, out_dir)),
      sum(sum) {}

std::string ReportFits::undetermined(const std::string& model, const std::string& why) {
  sum.undetermined.push_back(fmt::format("{}: {}", model, why));
  return fmt::format("<p><b>Undetermined</b>: {}. What would determine it: {}.</p>\n", html_escape(why),
                     html_escape(what_would_determine(model)));
}

std::string ReportFits::flagged(const FitResult& r, const std::string& model) {
  const auto u = undetermined_params(r);
  if (u.empty()) return std::string();
  return undetermined(model, fmt::format("{} not determined by the data (error not below the value)",
                                         fmt::join(u, ", ")));
}

std::string ReportFits::made_by(const std::string& fit_cmd) const {
  return fmt::format("<p><small>Made by <code>{}</code> (alone: <code>{}</code>).</small></p>\n",
                     html_escape(report_cmd), html_escape(fit_cmd));
}

std::string kind_html(const CampaignKind& kind) {
  const auto names = kind.names();
  return fmt::format("<h2>Fits</h2><p>Campaign kind, from the runs' scenes: {}.</p>\n",
                     names.empty() ? std::string("none (the runs differ in none of I, cohesion_number, "
                                                 "nsides, pressure): no fit across runs")
                                   : html_escape(fmt::format("{}", fmt::join(names, "; "))));
}

// Inertial: mu(I) and nu(I) over the cohesionless runs of one shape.
void inertial_section(const ReportScan& scan, const CampaignKind& kind, ReportFits& out) {
  const InertialPoints pts = inertial_points(scan);
  const std::string sel =
      kind.cohesive || kind.angularity ? " (runs with cohesion_number 0 and the first run's shape)" : "";
  mu_I_fit(pts, scan.dimension, sel, out);
  nu_I_fit(pts.nu, sel, out);
}

// Pressure series: e = e0 - lambda ln(p/p0), p the measured one, else the scene's.
void pressure_section(const ReportScan& scan, ReportFits& out) {
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
    out.fits.push_back(r);
    out.models.push_back(void_ratio(p0));
    out.sum.plots_ok = plot_compaction(out.out_dir, sp, r, p0, out.report_cmd) && out.sum.plots_ok;
    out.sum.fits.push_back("void_ratio");
    out.html += fmt::format("<h3>Compaction e(p)</h3><img src='compaction.png' width=600><p>{}: e0 = {:.4f} ± "
                            "{:.2g}, λ = {:.4g} ± {:.2g}, χ²/dof = {:.2f}</p>\n",
                            html_escape(void_ratio(p0).formula), r["e0"], r.err("e0"), r["lambda"],
                            r.err("lambda"), r.chi2_dof) +
                out.flagged(r, "void_ratio") +
                out.made_by(fmt::format("cdanalysis fit compaction {} --out DIR", out.campaign));
  } catch (const AnalysisError& e) {
    out.sum.problems.push_back(fmt::format("compaction fit: {}", e.what()));
    out.refused.push_back({"void_ratio", "e = e0 - lambda ln(p/p0)", e.what()});
    out.html += fmt::format("<p>Compaction fit refused: {}</p>\n", html_escape(e.what())) +
                out.undetermined("void_ratio", e.what());
  }
}

// Cohesive: c/p against the eta = 0 runs of the campaign, as fit cohesion
// makes it (each run's steady point read again by steady_point).
void cohesive_section(const ReportScan& scan, ReportFits& out) {
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
    out.fits.push_back(r);
    out.models.push_back(cohesion());
    out.sum.plots_ok = plot_cohesion(out.out_dir, cps, &r) && out.sum.plots_ok;
    out.sum.fits.push_back("cohesion");
    out.html += fmt::format("<h3>Cohesion c/p</h3><img src='cohesion.png' width=600><p>{}: k0 = {:.4g} ± {:.2g}, "
                            "β = {:.4g} ± {:.2g}, α = {:.4g} ± {:.2g}, χ²/dof = {:.2f}; {} from {} η = 0 "
                            "runs by {}</p>\n",
                            html_escape(cohesion().formula), r["k0"], r.err("k0"), r["beta"], r.err("beta"),
                            r["alpha"], r.err("alpha"), r.chi2_dof,
                            ref.dim() == 3 ? "c/p = μ − μ0(I), μ0(I)" : "sin φ(I)", ref_pts.size(),
                            ref.uses_fit() ? "the μ(I) fit" : "interpolation in ln I") +
                out.flagged(r, "cohesion") +
                out.made_by(fmt::format("cdanalysis fit cohesion {} --out DIR", out.campaign));
  } catch (const AnalysisError& e) {
    out.sum.problems.push_back(fmt::format("cohesion fit: {}", e.what()));
    out.refused.push_back({"cohesion", cohesion().formula, e.what()});
    out.html += fmt::format("<p>Cohesion fit refused: {}</p>\n", html_escape(e.what())) +
                out.undetermined("cohesion", e.what());
  }
}

// Angularity: the table of steady quantities against alpha and mu*(alpha),
// as fit angularity makes them (each run read again by angularity_point).
void angularity_section(const ReportScan& scan, int bins, ReportFits& out) {
  std::vector<AngularityPoint> ap;
  AngularityOptions opt;
  opt.bins = bins;
  for (const ReportRun& p : scan.runs) {
    if (!p.steady) continue;
    try {
      ap.push_back(angularity_point(p.folder, opt));
    } catch (const AnalysisError& e) {
      out.sum.problems.push_back(fmt::format("angularity: {}", e.what()));
    }
  }
  std::sort(ap.begin(), ap.end(), [](const auto& a, const auto& b) { return a.alpha < b.alpha; });
  std::optional<FitResult> r;
  std::string why;
  try {
    r = fit_angularity(ap);
    out.fits.push_back(*r);
    out.models.push_back(mu_of_alpha());
    out.sum.fits.push_back("mu_alpha");
  } catch (const AnalysisError& e) {
    why = fmt::format("mu*(alpha) fit: {}", e.what());
    out.sum.problems.push_back(why);
    out.refused.push_back({"mu_alpha", mu_of_alpha().formula, e.what()});
  }
  if (ap.empty()) return;
  out.sum.plots_ok = plot_angularity(out.out_dir, ap, r ? &*r : nullptr, out.report_cmd) && out.sum.plots_ok;
  out.sum.angularity = ap.size();
  out.html += "<h3>Angularity</h3>\n";
  if (r)
    out.html += fmt::format("<p>{}: μ0 = {:.4f} ± {:.2g}, μ1 = {:.4f} ± {:.2g}, α_c = {:.4g} ± {:.2g}, "
                            "χ²/dof = {:.2f} (dof {})</p>\n",
                            html_escape(mu_of_alpha().formula), (*r)["mu0"], r->err("mu0"), (*r)["mu1"],
                            r->err("mu1"), (*r)["alpha_c"], r->err("alpha_c"), r->chi2_dof, r->dof) +
                out.flagged(*r, "mu_alpha");
  else
    out.html += "<p>μ*(α) fit refused (see Problems).</p>\n" + out.undetermined("mu_alpha", why);
  out.html += angularity_table_html(ap);
  for (const auto& stem : kAngularityPlots) out.html += fmt::format("<img src='{}.png' width=450>\n", stem);
  out.html += out.made_by(fmt::format("cdanalysis fit angularity {} --out DIR", out.campaign));
}

}  // namespace cda
