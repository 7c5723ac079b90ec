// cdanalysis fit cohesion: c/p = k0 eta/(1 - beta ln(1 - I_c)) over steady
// runs, against the eta = 0 runs given alongside (cohesion.hpp).
#include <fmt/core.h>

#include <cmath>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/cohesion.hpp"

namespace cda::cli {
namespace {

struct Opt {
  std::vector<std::string> runs;
  std::string table, toml_out, out, window, reference = "auto";
  bool exclude_banded = false;
};

void from_table(const Opt& o) {
  if (!o.runs.empty()) throw AnalysisError("fit cohesion: give run folders or --table, not both");
  // cohesion_data.csv of an earlier fit may be given: its rate_min is
  // nan for runs without particle snapshots, so nan is read, and
  // refused in the columns the fit uses.
  const auto t = Table::read_csv(o.table, true);
  for (const char* c : {"eta", "I", "c_over_p", "c_over_p_err"}) {
    if (!t.has(c)) continue;
    const auto& v = t.column(c);
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i]))
        throw InputError(fmt::format("'{}' line {}, column '{}': not a finite number", o.table, i + 2, c));
  }
  const auto r = cda::fit_cohesion(t.column("eta"), t.column("I"), t.column("c_over_p"),
                              col_or_empty(t, "c_over_p_err"));
  print_fit(r, cohesion());
  write_toml(o.toml_out, {r}, {cohesion()});
}

int from_runs(const Opt& o) {
  if (o.runs.empty()) throw AnalysisError("fit cohesion: give run folders or --table");
  std::vector<SteadyPoint> ref_pts, coh_pts;
  const auto all = expand_runs(o.runs);
  const int dim = common_dimension(all, "fit cohesion");
  std::vector<std::string> left_out;
  for (const auto& r : all) {
    // A run without a steady window is left out with the reason; a single run is refused.
    try {
      const auto p = steady_point(r, o.window);
      (p.eta == 0 ? ref_pts : coh_pts).push_back(p);
    } catch (const AnalysisError& e) {
      if (all.size() == 1) throw;
      fmt::print("{}: left out: {}\n", r, e.what());
      left_out.push_back(r);
    }
  }
  if (coh_pts.empty()) throw AnalysisError("fit cohesion: no run with eta > 0 among the given runs");
  const auto mode = o.reference == "mu-i"     ? SinPhiReference::Mode::MuI
                    : o.reference == "interp" ? SinPhiReference::Mode::Interp
                                              : SinPhiReference::Mode::Auto;
  const SinPhiReference ref(ref_pts, mode);
  const char* ref_name = cohesion_ref_name(dim);
  if (dim == 3)
    fmt::print("3D runs: mu = {} (-(sigma_xy + sigma_yx)/(2 sigma_yy)), {}, eta = f_a/(p d^2)\n",
               cohesion_mu_column(dim), cohesion_formula(dim));
  fmt::print("reference: {} eta = 0 runs, {}(I) by {}\n", ref_pts.size(), ref_name,
             ref.uses_fit() ? "the mu(I) fit" : "interpolation in ln I");
  // rate_min of shear_profile: is the run's shear homogeneous?
  const auto homogeneity = [](const SteadyPoint& p) { return rate_min_note(p.rate_min, p.rate_min_err); };
  for (const auto& p : ref.points())
    fmt::print("  {}: I = {:.4g} +- {:.2g}, {} = {:.4f} +- {:.4f}{}\n", p.run, p.I, p.I_err, ref_name, p.mu,
               p.mu_err, homogeneity(p));
  if (ref.uses_fit()) print_fit(ref.fit(), mu_of_I());
  std::vector<CohesionPoint> pts;
  std::vector<double> eta, I, c, ce;
  for (const auto& p : coh_pts) {
    const auto cp = cohesion_point(p, ref);
    fmt::print("{}: eta = {:g}, I = {:.4g} +- {:.2g} (imposed {:.4g}), {} = {:.4f} +- {:.4f}, "
               "{} = {:.4f} +- {:.4f}{}, c/p = {:.4f} +- {:.4f}{}{}\n",
               p.run, p.eta, p.I, p.I_err, p.I_imposed, dim == 3 ? "mu" : "q/p", p.mu, p.mu_err, ref_name,
               cp.ref.sin_phi, cp.ref.err, cp.ref.extrapolated ? " (extrapolated)" : "", cp.c_over_p,
               cp.c_over_p_err, homogeneity(p),
               o.exclude_banded && p.banded() ? " (left out of the fit: --exclude-banded)" : "");
    pts.push_back(cp);
    if (o.exclude_banded && p.banded()) continue;
    eta.push_back(p.eta);
    I.push_back(p.I);
    c.push_back(cp.c_over_p);
    ce.push_back(cp.c_over_p_err);
  }
  FitResult r;
  try {
    r = cda::fit_cohesion(eta, I, c, ce);
  } catch (const AnalysisError&) {
    // The c/p points are a result on their own: written and plotted
    // before the refusal (exit 1) when the model is not determined.
    if (!o.out.empty() && !plot_cohesion(o.out, pts, nullptr))
      fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", o.out);
    if (!o.out.empty()) fmt::print("wrote the c/p points (no model) in {}\n", o.out);
    throw;
  }
  print_fit(r, cohesion());
  std::vector<FitResult> fits = {r};
  std::vector<Model> models = {cohesion()};
  if (ref.uses_fit()) {
    fits.push_back(ref.fit());
    models.push_back(mu_of_I());
  }
  write_toml(o.toml_out, fits, models);
  if (!o.out.empty() && !plot_cohesion(o.out, pts, &r))
    fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", o.out);
  return with_reservations("fit cohesion", left_out, r);
}

}  // namespace

Handler fit_cohesion(CLI::App& sub) {
  auto o = std::make_shared<Opt>();
  sub.add_option("runs", o->runs, "run or campaign folders, eta = 0 reference runs included");
  sub.add_option("--table", o->table,
                 "CSV with columns eta, I, c_over_p and optionally c_over_p_err, instead of runs");
  sub.add_option("--reference", o->reference,
                 "sin phi(I) of the eta = 0 runs: mu-i (fit, 4+ runs), interp (linear in ln I), auto "
                 "(mu-i with 4+ runs, else interp)")
      ->check(CLI::IsMember({"auto", "mu-i", "interp"}))
      ->capture_default_str();
  sub.add_option("--out", o->out, "folder for c/p data, model curves and the plot (png, svg)");
  add_toml_option(sub, o->toml_out);
  add_window_option(sub, o->window);
  sub.add_flag("--exclude-banded", o->exclude_banded,
               "leave the cohesive runs whose shear is banded (profile's rate_min below 0.5: not a homogeneous "
               "flow at the run's I) out of the model fit; they stay in the data and the plot (open circles)");
  return [o] {
    if (!o->table.empty()) {
      from_table(*o);
      return 0;
    }
    return from_runs(*o);
  };
}

}  // namespace cda::cli
