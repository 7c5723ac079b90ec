// cdanalysis fit angularity: mu*(alpha) and nu*(alpha) over steady shear
// runs of several shapes, with the table of steady quantities against alpha
// (trends.hpp); or over a table of such points (--table: angularity.csv, or
// the validation tables of tests/data/validation/).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "analysis/app/command.hpp"

namespace cda::cli {

namespace {

// mu*(alpha), printed and written; nu*(alpha) beside it, or its refusal
// (a nu fit that fails does not stop the mu fit). Returns the mu fit.
FitResult fit_both(const std::vector<AngularityPoint>& pts, const std::string& toml_out) {
  const FitResult mu = cda::fit_angularity(pts);
  print_fit(mu, mu_of_alpha());
  std::vector<FitResult> fits = {mu};
  std::vector<Model> models = {mu_of_alpha()};
  std::vector<RefusedFit> refused;
  try {
    fits.push_back(fit_angularity_nu(pts));
    models.push_back(nu_of_alpha());
    print_fit(fits.back(), nu_of_alpha());
  } catch (const AnalysisError& e) {
    fmt::print(stderr, "cdanalysis: nu*(alpha) refused: {}\n", e.what());
    refused.push_back({"nu_alpha", nu_of_alpha().formula, e.what()});
  }
  write_toml(toml_out, fits, models, refused);
  return mu;
}

// The points of a table (one row per shape): alpha, mu, nu with their
// error bars when the table has them (nan where a row has none). The
// validation tables' words (protocol, window, build) are left unread.
int fit_table(const std::string& path, const std::string& toml_out) {
  const auto t = Table::read_csv(path, true, {"protocol", "window", "build"});
  const auto al = t.column("alpha"), mu = t.column("mu"), nu = t.column("nu");
  const auto mu_e = col_or_empty(t, "mu_err"), nu_e = col_or_empty(t, "nu_err");
  std::vector<AngularityPoint> pts;
  fmt::print("{:>4} {:>8} {:>17} {:>17}\n", "row", "alpha", "mu*", "nu*");
  for (std::size_t i = 0; i < t.rows(); ++i) {
    AngularityPoint a;
    a.run = fmt::format("{} line {}", path, t.line(i));
    a.alpha = al[i];
    a.mu = {mu[i], mu_e.empty() ? std::nan("") : mu_e[i]};
    a.nu = {nu[i], nu_e.empty() ? std::nan("") : nu_e[i]};
    fmt::print("{:>4} {:>8.4f} {:>8.5f}±{:<8.5f} {:>8.5f}±{:<8.5f}\n", i + 1, a.alpha, a.mu.v, a.mu.err, a.nu.v,
               a.nu.err);
    pts.push_back(a);
  }
  return with_reservations("fit angularity", {}, fit_both(pts, toml_out));
}

}  // namespace

Handler fit_angularity(CLI::App& sub) {
  struct Opt {
    std::vector<std::string> runs;
    std::string toml_out, out;
    std::string window, table;
    int snapshots = 5, bins = 36;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("runs", o->runs, "run or campaign folders (series.csv, scene.toml, contact snapshots)");
  sub.add_option("--table", o->table, "CSV with columns alpha, mu, nu and optionally mu_err, nu_err (as "
                                      "angularity.csv), instead of runs: the fits alone");
  sub.add_option("--snapshots", o->snapshots, "last contact snapshots averaged per run for the fabric")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub.add_option("--bins", o->bins, "angular bins over [0, pi)")->check(CLI::Range(4, 36000))->capture_default_str();
  add_window_option(sub, o->window);
  sub.add_option("--out", o->out, "folder for angularity.csv, the fit curve and the plots (png, svg)");
  add_toml_option(sub, o->toml_out);
  return [o] {
    if (!o->table.empty()) {
      if (!o->runs.empty()) throw AnalysisError("fit angularity: give run folders or --table, not both");
      if (!o->out.empty()) throw AnalysisError("fit angularity: --out draws the runs' fabric: it needs run folders, "
                                               "not --table");
      return fit_table(o->table, o->toml_out);
    }
    if (o->runs.empty()) throw AnalysisError("fit angularity: give run folders or --table");
    AngularityOptions opt;
    opt.snapshots = o->snapshots;
    opt.bins = o->bins;
    opt.window = o->window;
    std::vector<AngularityPoint> pts;
    std::vector<std::string> left_out;
    const auto all = expand_runs(o->runs);
    for (const auto& r : all) {
      try {
        pts.push_back(angularity_point(r, opt));
      } catch (const AnalysisError& e) {
        if (all.size() == 1) throw;
        fmt::print("{}: skipped: {}\n", r, e.what());
        left_out.push_back(r);
      }
    }
    if (pts.empty()) throw AnalysisError("fit angularity: no usable run (each was skipped, see above)");
    std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.alpha < b.alpha; });
    fmt::print("sliding: |f_t| >= mu f_n (1 - tol), tol = the run's [solver] tol; fabric: mean +- sem over "
               "the last {} contact snapshots\n", o->snapshots);
    fmt::print("{:>3} {:>3} {:>6}  {:>15} {:>15} {:>13} {:>15} {:>15} {:>15} {:>15} {:>15} {:>15} {:>15} "
               "{:>15} {:>15} {:>7} {:>7} {:>7}\n",
               "#", "n_s", "alpha", "mu*", "nu*", "z", "a_c", "a_ln", "a_lt", "a_fn", "a_ft", "sliding",
               "ss share", "q_sv/p", "q_ss/p", "q/p", "sum/2", "tensor");
    auto pm = [](const Val& v, int w) {
      return std::isfinite(v.err) ? fmt::format("{:.{}f}±{:.{}f}", v.v, w, v.err, w)
                                  : (std::isfinite(v.v) ? fmt::format("{:.{}f}", v.v, w) : "n/a");
    };
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const auto& a = pts[k];
      fmt::print("{:>3} {:>3} {:>6.4f}  {:>15} {:>15} {:>13} {:>15} {:>15} {:>15} {:>15} {:>15} {:>15} {:>15} "
                 "{:>15} {:>15} {:>7.4f} {:>7.4f} {:>7.4f}\n",
                 k, a.nsides, a.alpha, pm(a.mu, 4), pm(a.nu, 4), pm(a.z, 3), pm(a.a_c, 4), pm(a.a_ln, 4),
                 pm(a.a_lt, 4), pm(a.a_fn, 4), pm(a.a_ft, 4), pm(a.sliding, 4), pm(a.ss_share, 4),
                 pm(a.q_sv, 4), pm(a.q_ss, 4), a.q_over_p_snap.v, a.sum_half_fft.v, a.sum_half_tensor.v);
    }
    for (std::size_t k = 0; k < pts.size(); ++k)
      fmt::print("  {} = {} (alpha from the {})\n", k, pts[k].run, pts[k].alpha_source);
    fmt::print("check q/p ~ (sum a)/2: q/p of the snapshots' contact stress against the Fourier sum and the "
               "tensor sum with directions (columns q/p, sum/2, tensor)\n");
    std::optional<FitResult> r;
    try {
      r = fit_both(pts, o->toml_out);
    } catch (const AnalysisError& e) {
      if (o->out.empty()) throw;
      fmt::print(stderr, "cdanalysis: refused: {}\n", e.what());
    }
    if (!o->out.empty()) {
      if (!plot_angularity(o->out, pts, r ? &*r : nullptr, command_line()))
        fmt::print(stderr, "warning: gnuplot failed; the scripts are in {}\n", o->out);
      fmt::print("wrote {}/angularity.csv and the angularity_*.png/svg plots\n", o->out);
      if (!r) return 1;
    }
    return with_reservations("fit angularity", left_out, *r);
  };
}

}  // namespace cda::cli
