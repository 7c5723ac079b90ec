// cdanalysis fit mu-i: mu(I) = mu1 + (mu2 - mu1)/(1 + I0/I) over steady runs.
#include <fmt/core.h>

#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/report.hpp"

namespace cda::cli {

Handler fit_mu_i(CLI::App& sub) {
  struct Opt {
    std::vector<std::string> runs;
    std::string table, toml_out, out, window;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("runs", o->runs, "run or campaign folders (each run: steady mean of q_over_p and "
                                  "inertial_number)");
  sub.add_option("--table", o->table, "CSV with columns I, mu and optionally mu_err, instead of runs");
  add_toml_option(sub, o->toml_out);
  sub.add_option("--out", o->out, "folder for the plot mu_I.png/svg (points, fit, 1-sigma band)");
  add_window_option(sub, o->window);
  return [o] {
    std::vector<double> I, mu, err;
    std::vector<std::string> left_out;
    std::string mu_label = "μ* = q/p";
    if (!o->table.empty()) {
      const auto t = Table::read_csv(o->table);
      I = t.column("I");
      mu = t.column("mu");
      err = col_or_empty(t, "mu_err");
    } else {
      if (o->runs.empty()) throw AnalysisError("fit mu-i: give run folders or --table");
      const auto all = expand_runs(o->runs);
      const int dim = common_dimension(all, "fit mu-i");
      if (dim == 3) {
        fmt::print("3D runs: mu = shear_stress_ratio = -(sxy + syx)/2 / syy\n");
        mu_label = "μ = −σ_xy/σ_yy";
      }
      for (const auto& r : all) {
        // A run without a steady window, or whose series is damaged, is left
        // out with the reason (the others still make a fit); a single run is refused.
        Table series;
        std::string x;
        RunSteady s;
        try {
          series = read_series(r);
          x = default_x_column(series);
          s = run_steady(r, series, mu_column(dim), x, window_range(o->window, series.column(x)));
        } catch (const AnalysisError& e) {
          if (all.size() == 1) throw;
          fmt::print("{}: left out: {}\n", r, e.what());
          left_out.push_back(r);
          continue;
        }
        const auto si = measured_inertial_number(series, x, s.stats.window);
        I.push_back(si.mean);
        mu.push_back(s.stats.mean);
        err.push_back(s.stats.error());
        const Val rm = window_rate_min(r, series, x, s.stats.window);
        fmt::print("{}: I = {:.4g} +- {:.2g}, mu = {:.4f} +- {:.4f}{}\n", r, si.mean, si.err, s.stats.mean,
                   s.stats.error(), rate_min_note(rm.v, rm.err));
        if (is_banded(rm.v))
          fmt::print(stderr, "warning: {}: banded shear (rate_min {:.2f}): its I is not the local one "
                             "(cdanalysis profile)\n", r, rm.v);
      }
    }
    // Refused (too few runs, a singular Jacobian): the points are still
    // written and drawn, and the TOML says why, before exit 1.
    std::optional<FitResult> r;
    try {
      r = cda::fit_mu_I(I, mu, err);
    } catch (const AnalysisError& e) {
      if (dynamic_cast<const InputError*>(&e)) throw;
      write_toml(o->toml_out, {}, {}, {{"mu_I", mu_of_I().formula, e.what()}});
      if (!o->out.empty() && !I.empty()) {
        if (err.empty()) err.assign(I.size(), 0.0);
        plot_mu_I(o->out, I, mu, err, nullptr, mu_label);
        fmt::print("wrote the points (no fit) in {}/mu_I.png\n", o->out);
      }
      throw AnalysisError(fmt::format("{}; what would determine it: {}", e.what(), what_would_determine("mu_I")));
    }
    print_fit(*r, mu_of_I());
    write_toml(o->toml_out, {*r}, {mu_of_I()});
    if (!o->out.empty()) {
      if (err.empty()) err.assign(I.size(), 0.0);
      if (!plot_mu_I(o->out, I, mu, err, &*r, mu_label))
        fmt::print("cdanalysis: gnuplot did not run: {}/mu_I.gp written, no PNG\n", o->out);
      else
        fmt::print("wrote {}/mu_I.png and mu_I.svg\n", o->out);
    }
    return with_reservations("fit mu-i", left_out, *r);
  };
}

}  // namespace cda::cli
