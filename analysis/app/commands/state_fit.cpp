// What fit nu-i and fit compaction share: both fit a steady state (packing
// fraction) against one variable (I or p) over runs or a table, weighted
// when every point has an error bar. Runs at imposed volume (and a table with
// I_err and no nu_err) have nu exact and I measured: nu(I) is fitted in I,
// weighted by I's error bars.
#include <fmt/core.h>

#include <cmath>

#include "analysis/app/command.hpp"

namespace cda::cli {

int run_state_fit(const StateFitOptions& o, bool is_nu) {
  std::vector<StatePoint> pts;
  std::vector<std::string> left_out;
  if (!o.table.empty()) {
    if (!o.runs.empty()) throw AnalysisError("fit: give run folders or --table, not both");
    const auto t = Table::read_csv(o.table);
    const auto xs = t.column(is_nu ? "I" : "p");
    const auto ys = t.column(is_nu ? "nu" : "e");
    const auto es = col_or_empty(t, is_nu ? "nu_err" : "e_err");
    const auto Ies = is_nu && es.empty() ? col_or_empty(t, "I_err") : std::vector<double>{};
    for (std::size_t i = 0; i < xs.size(); ++i) {
      StatePoint s;
      s.run = fmt::format("row {}", i + 1);
      const double err = es.empty() ? std::nan("") : es[i];
      if (is_nu) {
        s.I = {xs[i], Ies.empty() ? std::nan("") : Ies[i]};
        s.nu = {ys[i], err};
        s.volume = !Ies.empty();
      } else {  // e given: store nu = 1/(1 + e) so that e() is e again
        s.p = {xs[i], std::nan("")};
        s.nu = {1 / (1 + ys[i]), err / ((1 + ys[i]) * (1 + ys[i]))};
      }
      pts.push_back(s);
    }
  } else {
    if (o.runs.empty()) throw AnalysisError("fit: give run folders or --table");
    const auto all = expand_runs(o.runs);
    common_dimension(all, is_nu ? "fit nu-i" : "fit compaction");
    for (const auto& r : all) {
      // A run without a steady window is left out with the reason; a single run is refused.
      StatePoint s;
      try {
        s = state_point(r, o.window);
      } catch (const AnalysisError& e) {
        if (all.size() == 1) throw;
        fmt::print("{}: left out: {}\n", r, e.what());
        left_out.push_back(r);
        continue;
      }
      if (is_nu)
        fmt::print("{}: I = {:.4g} +- {:.2g}, nu = {:.5f} +- {:.5f}\n", r, s.I.v, s.I.err, s.nu.v, s.nu.err);
      else
        fmt::print("{}: p = {:.5g}{}, nu = {:.5f} +- {:.5f}, e = {:.5f} +- {:.5f}\n", r, s.p.v,
                   s.p_from_scene ? " (scene)" : fmt::format(" +- {:.2g}", s.p.err), s.nu.v, s.nu.err, s.e(),
                   s.e_err());
      pts.push_back(s);
    }
  }
  // Without error bars on every point the fit is unweighted: those of nu,
  // or at imposed volume (nu exact) those of I.
  FitResult r;
  Model m = nu_of_I();
  double pref = o.p0;
  bool all_err = true, volume = false;
  try {
  volume = is_nu && volume_points(pts);
  for (auto& s : pts) {
    const Val& v = volume ? s.I : s.nu;
    all_err = all_err && std::isfinite(v.err) && v.err > 0;
  }
  if (is_nu) {
    if (volume) {
      m = nu_of_I_volume();
      fmt::print("imposed volume: nu exact, I measured: fitted as {}\n", m.formula);
    }
    r = fit_nu_I_points(pts, all_err);
  } else {
    if (!(pref > 0)) pref = default_p0(pts);
    m = void_ratio(pref);
    if (all_err) {
      r = fit_compaction_points(pts, pref);
    } else {
      std::vector<double> p, e;
      for (const auto& s : pts) p.push_back(s.p.v), e.push_back(s.e());
      r = fit_void_ratio(p, e, {}, pref);
    }
  }
  } catch (const AnalysisError& e) {
    // Refused: the TOML says why (the points are printed above), exit 1.
    if (dynamic_cast<const InputError*>(&e)) throw;
    write_toml(o.toml_out, {}, {}, {{m.name, m.formula, e.what()}});
    throw AnalysisError(fmt::format("{}; what would determine it: {}", e.what(), what_would_determine(m.name)));
  }
  print_fit(r, m);
  write_toml(o.toml_out, {r}, {m});
  if (!o.out.empty()) {
    if (!all_err)
      for (auto& s : pts) (volume ? s.I.err : s.nu.err) = 0;
    const bool ok = is_nu ? plot_nu_I(o.out, pts, r, command_line())
                          : plot_compaction(o.out, pts, r, pref, command_line());
    if (!ok) fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", o.out);
    else fmt::print("wrote {}/{}.png and .svg\n", o.out, is_nu ? "nu_I" : "compaction");
  }
  return with_reservations(is_nu ? "fit nu-i" : "fit compaction", left_out, r);
}

}  // namespace cda::cli
