#include "trends.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "plot.hpp"
#include "run.hpp"
#include "scene_info.hpp"
#include "snapshot.hpp"

namespace fs = std::filesystem;

namespace cda {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Val of(const SteadyStats& s) { return {s.mean, s.error()}; }

// The steady window of a run: on its mu column (mu_column: 2D q_over_p, 3D
// shear_stress_ratio) when the series has it, else on packing_fraction (an
// isotropic compaction).
struct SteadyRun {
  Table series;
  std::string x;
  Window w;
  SteadyStats main;
};
SteadyRun steady_run(const std::string& run_dir, const std::string& window = "") {
  SteadyRun s{read_series(run_dir), "", {}, {}};
  s.x = default_x_column(s.series);
  const std::string mu = mu_column(run_dimension(run_dir));  // 3D: shear_stress_ratio
  const std::string col = s.series.has(mu) ? mu : "packing_fraction";
  const auto range = window_range(window, s.series.column(s.x));
  const auto r = run_steady(run_dir, s.series, col, s.x, range);
  s.w = r.stats.window;
  s.main = r.stats;
  return s;
}

Val series_val(const SteadyRun& s, const std::string& col) {
  if (!s.series.has(col)) return {};
  return of(stats_over(s.series, col, s.x, s.w));
}

}  // namespace

Val mean_sem(const std::vector<double>& x) {
  std::vector<double> v;
  for (double a : x)
    if (std::isfinite(a)) v.push_back(a);
  if (v.empty()) return {};
  double m = 0;
  for (double a : v) m += a;
  m /= static_cast<double>(v.size());
  if (v.size() < 2) return {m, kNaN};
  double s2 = 0;
  for (double a : v) s2 += (a - m) * (a - m);
  s2 /= static_cast<double>(v.size() - 1);
  return {m, std::sqrt(s2 / static_cast<double>(v.size()))};
}

const std::vector<std::string> kAngularityPlots = {"angularity_mu",         "angularity_nu",
                                                   "angularity_z",          "angularity_anisotropy",
                                                   "angularity_sliding",    "angularity_partial"};

AngularityPoint angularity_point(const std::string& run_dir, const AngularityOptions& opt) {
  AngularityPoint a;
  a.run = run_dir;
  const auto scene = read_scene_info(run_dir);
  if (scene.dimension == 3)
    throw AnalysisError(fmt::format("fit angularity is 2D only: '{}' is a 3D run (dimension = 3 in its "
                                    "scene.toml; 3D runs are spheres)",
                                    run_dir));
  a.friction = scene.friction.value_or(0);
  a.sliding_tol = scene.solver_tol.value_or(1e-4);

  // alpha: the shapes of the last particles snapshot, else the scene's.
  std::optional<int> ns;
  const auto psnaps = list_snapshots(run_dir, "particles");
  if (!psnaps.empty()) {
    const auto ps = read_particles(psnaps.back());
    std::vector<int> seen;
    for (const auto& p : ps)
      if (p.nsides >= 0 && std::find(seen.begin(), seen.end(), p.nsides) == seen.end()) seen.push_back(p.nsides);
    if (seen.size() > 1)
      throw AnalysisError(fmt::format("run '{}' mixes shapes ({} different nsides in {}): no single "
                                      "angularity", run_dir, seen.size(), psnaps.back()));
    if (seen.size() == 1) {
      ns = seen[0];
      a.alpha_source = "particles snapshot";
    }
  }
  if (!ns) {
    if (scene.nsides_mixed)
      throw AnalysisError(fmt::format("'{}': [particles] nsides mixes shapes: no single angularity", scene.file));
    if (!scene.nsides)
      throw AnalysisError(fmt::format("run '{}': no nsides in its particles snapshots or in [particles] of "
                                      "scene.toml: the angularity is unknown", run_dir));
    ns = *scene.nsides;
    a.alpha_source = "scene.toml";
  }
  a.nsides = *ns;
  a.alpha = angularity_of(a.nsides);

  const auto s = steady_run(run_dir, opt.window);
  if (!s.series.has("q_over_p"))
    throw AnalysisError(fmt::format("run '{}' has no q_over_p column: not a shear run", run_dir));
  a.mu = of(s.main);
  a.nu = series_val(s, "packing_fraction");
  a.z = series_val(s, "z");
  a.p = series_val(s, "p");

  const auto snaps = list_snapshots(run_dir, "contacts");
  if (snaps.empty()) throw AnalysisError(fmt::format("run '{}' has no contact snapshot", run_dir));
  const int K = std::min<int>(opt.snapshots, static_cast<int>(snaps.size()));
  std::vector<double> ac, aln, alt, afn, aft, qp, shf, sht, sl, slf, ss, qsv, qss;
  for (int k = -K; k < 0; ++k) {
    const auto f = run_fabric(run_dir, k, opt.bins, -1, a.friction, a.sliding_tol);
    ac.push_back(f.fft.c.a());
    aln.push_back(f.fft.ln.a());
    alt.push_back(f.fft.lt.a());
    afn.push_back(f.fft.fn.a());
    aft.push_back(f.fft.ft.a());
    qp.push_back(f.stress.q_over_p());
    shf.push_back(f.fft.sum_half());
    sht.push_back(f.tensor.sum_half_vector());
    sl.push_back(f.sliding_coulomb);
    slf.push_back(f.sliding);
    ss.push_back(f.ss_share);
    const double p = f.stress.p();
    qsv.push_back(f.sv_stress && p > 0 ? f.sv_stress->q() / p : kNaN);
    qss.push_back(f.ss_stress && p > 0 ? f.ss_stress->q() / p : kNaN);
  }
  a.snapshots = static_cast<std::size_t>(K);
  a.a_c = mean_sem(ac), a.a_ln = mean_sem(aln), a.a_lt = mean_sem(alt), a.a_fn = mean_sem(afn),
  a.a_ft = mean_sem(aft);
  a.q_over_p_snap = mean_sem(qp), a.sum_half_fft = mean_sem(shf), a.sum_half_tensor = mean_sem(sht);
  a.sliding = mean_sem(sl), a.sliding_flag = mean_sem(slf), a.ss_share = mean_sem(ss);
  a.q_sv = mean_sem(qsv), a.q_ss = mean_sem(qss);
  return a;
}

Table angularity_table(const std::vector<AngularityPoint>& pts) {
  std::vector<std::string> names = {"run", "nsides", "alpha"};
  const std::vector<std::string> vals = {"mu", "nu", "z", "p", "a_c", "a_ln", "a_lt", "a_fn", "a_ft",
                                         "q_over_p_snap", "sum_half_fft", "sum_half_tensor", "sliding",
                                         "sliding_flag", "ss_share", "q_sv_over_p", "q_ss_over_p"};
  for (const auto& v : vals) {
    names.push_back(v);
    names.push_back(v + "_err");
  }
  names.push_back("snapshots");
  names.push_back("friction");
  names.push_back("sliding_tol");
  Table t(names);
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const auto& a = pts[k];
    std::vector<double> row = {static_cast<double>(k), static_cast<double>(a.nsides), a.alpha};
    for (const Val* v : {&a.mu, &a.nu, &a.z, &a.p, &a.a_c, &a.a_ln, &a.a_lt, &a.a_fn, &a.a_ft,
                         &a.q_over_p_snap, &a.sum_half_fft, &a.sum_half_tensor, &a.sliding,
                         &a.sliding_flag, &a.ss_share, &a.q_sv, &a.q_ss}) {
      row.push_back(v->v);
      row.push_back(v->err);
    }
    row.push_back(static_cast<double>(a.snapshots));
    row.push_back(a.friction);
    row.push_back(a.sliding_tol);
    t.add_row(row);
  }
  return t;
}

namespace {

// One steady quantity (mu or nu) of the points against alpha, weighted when
// every point has an error bar.
FitResult fit_against_alpha(const Model& m, const std::vector<AngularityPoint>& pts, Val AngularityPoint::*y) {
  std::vector<double> al, v, err;
  bool all_err = true;
  for (const auto& a : pts) {
    al.push_back(a.alpha);
    v.push_back((a.*y).v);
    err.push_back((a.*y).err);
    all_err = all_err && std::isfinite((a.*y).err) && (a.*y).err > 0;
  }
  if (!all_err) err.clear();
  return fit_of_alpha(m, al, v, err);
}

}  // namespace

FitResult fit_angularity(const std::vector<AngularityPoint>& pts) {
  return fit_against_alpha(mu_of_alpha(), pts, &AngularityPoint::mu);
}
FitResult fit_angularity_nu(const std::vector<AngularityPoint>& pts) {
  return fit_against_alpha(nu_of_alpha(), pts, &AngularityPoint::nu);
}

namespace {

std::string header(const std::string& command) {
  return fmt::format("# made by: {}\nset datafile separator ','\nset datafile missing 'nan'\nset grid\n"
                     "set xlabel 'angularity α = 2π/n_s (disks 0)'\n",
                     command);
}

// Columns of angularity.csv by name (1-based for gnuplot).
int col(const Table& t, const std::string& name) {
  const auto& n = t.names();
  return static_cast<int>(std::find(n.begin(), n.end(), name) - n.begin()) + 1;
}

std::string errorbars(const Table& t, const std::string& v, const std::string& title, const char* colour,
                      int pt) {
  // nan error bars (a single snapshot) draw as points: gnuplot skips the
  // whole row of an errorbar plot with a missing value, so 0 is used instead.
  return fmt::format("'angularity.csv' every ::1 using 3:{0}:(${1} == ${1} ? ${1} : 0) with yerrorbars pt {2} "
                     "lc rgb '{3}' title '{4}'",
                     col(t, v), col(t, v + "_err"), pt, colour, title);
}

}  // namespace

bool plot_angularity(const std::string& dir, const std::vector<AngularityPoint>& pts, const FitResult* fit,
                     const std::string& command) {
  fs::create_directories(dir);
  const Table t = angularity_table(pts);
  t.write_csv((fs::path(dir) / "angularity.csv").string());
  bool ok = true;
  // mu* with the fit and its band.
  std::string body = header(command) + "set ylabel 'μ* = q/p'\nset key bottom right\n";
  std::string plot = "plot ";
  if (fit) {
    const Model m = mu_of_alpha();
    Table c({"alpha", "mu", "lo", "hi"});
    double amax = 0;
    for (const auto& a : pts) amax = std::max(amax, a.alpha);
    for (int k = 0; k <= 200; ++k) {
      const double x = 1.1 * amax * k / 200.0;
      const double y = predict(m, *fit, &x), e = predict_error(m, *fit, &x);
      c.add_row({x, y, y - e, y + e});
    }
    c.write_csv((fs::path(dir) / "angularity_mu_fit.csv").string());
    plot += fmt::format(
        "'angularity_mu_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
        "     'angularity_mu_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' "
        "title 'μ_0 = {:.3f}, μ_1 = {:.3f}, α_c = {:.3g}', \\\n     ",
        (*fit)["mu0"], (*fit)["mu1"], (*fit)["alpha_c"]);
  }
  plot += errorbars(t, "mu", "runs", "black", 7) + "\n";
  ok = plot_both(dir, "angularity_mu", body + plot) && ok;
  ok = plot_both(dir, "angularity_nu",
                 header(command) + "set ylabel 'ν* (packing fraction)'\nset key top right\nplot " +
                     errorbars(t, "nu", "ν*", "black", 7) + "\n") &&
       ok;
  ok = plot_both(dir, "angularity_z",
                 header(command) + "set ylabel 'z (rattlers removed)'\nset key top right\nplot " +
                     errorbars(t, "z", "z", "black", 7) + "\n") &&
       ok;
  ok = plot_both(dir, "angularity_anisotropy",
                 header(command) + "set ylabel 'anisotropy'\nset key outside right\nplot " +
                     errorbars(t, "a_c", "a_c", "#1f3b73", 7) + ", \\\n     " +
                     errorbars(t, "a_ln", "a_{ln}", "#2e8b57", 5) + ", \\\n     " +
                     errorbars(t, "a_lt", "a_{lt}", "#8fbc8f", 4) + ", \\\n     " +
                     errorbars(t, "a_fn", "a_{fn}", "#b03a2e", 9) + ", \\\n     " +
                     errorbars(t, "a_ft", "a_{ft}", "#e59866", 11) + "\n",
                 900, 500) &&
       ok;
  ok = plot_both(dir, "angularity_sliding",
                 header(command) + "set ylabel 'share of force-bearing contacts'\nset key top left\nplot " +
                     errorbars(t, "sliding", "sliding (|f_t| ≥ μ f_n (1 − tol))", "#b03a2e", 7) +
                     ", \\\n     " + errorbars(t, "ss_share", "side–side", "#1f3b73", 5) + "\n") &&
       ok;
  ok = plot_both(dir, "angularity_partial",
                 header(command) + "set ylabel 'strength'\nset key top left\nplot " +
                     errorbars(t, "mu", "μ* = q/p (series)", "black", 7) + ", \\\n     " +
                     errorbars(t, "q_sv_over_p", "q_{sv}/p", "#2e8b57", 5) + ", \\\n     " +
                     errorbars(t, "q_ss_over_p", "q_{ss}/p", "#1f3b73", 9) + "\n") &&
       ok;
  return ok;
}

StatePoint state_point(const std::string& run_dir, const std::string& window) {
  StatePoint s;
  s.run = run_dir;
  const auto r = steady_run(run_dir, window);
  if (!r.series.has("packing_fraction"))
    throw AnalysisError(fmt::format("run '{}' has no packing_fraction column", run_dir));
  s.nu = series_val(r, "packing_fraction");
  if (r.series.has("inertial_number")) {
    const auto e = measured_inertial_number(r.series, r.x, r.w);
    s.I = {e.mean, e.err};
  }
  std::optional<SceneInfo> scene;
  try {
    scene = read_scene_info(run_dir);
  } catch (const AnalysisError&) {
  }
  if (scene && scene->inertial_number) s.I_imposed = *scene->inertial_number;
  s.volume = scene && scene->volume_control;
  if (r.series.has("p")) {
    s.p = series_val(r, "p");
  } else if (scene && scene->pressure) {
    s.p = {*scene->pressure, kNaN};
    s.p_from_scene = true;
  }
  return s;
}

bool volume_points(const std::vector<StatePoint>& pts) {
  const StatePoint* vol = nullptr;
  const StatePoint* prs = nullptr;
  for (const auto& p : pts) (p.volume ? vol : prs) = &p;
  if (vol && prs)
    throw AnalysisError(fmt::format("fit nu(I): run '{}' is at imposed volume (nu exact, I measured) and '{}' at "
                                    "imposed pressure (I imposed, nu measured): fit them apart (compare-fits "
                                    "compares the two nu_I)",
                                    vol->run, prs->run));
  return vol != nullptr;
}

Model nu_model(const std::vector<StatePoint>& pts) { return volume_points(pts) ? nu_of_I_volume() : nu_of_I(); }

FitResult fit_nu_I_points(const std::vector<StatePoint>& pts, bool weighted) {
  const bool volume = volume_points(pts);
  std::vector<double> I, nu, err;
  for (const auto& p : pts) {
    if (!std::isfinite(p.I.v))
      throw AnalysisError(fmt::format("fit nu(I): run '{}' has no inertial_number", p.run));
    I.push_back(p.I.v);
    nu.push_back(p.nu.v);
    if (weighted) err.push_back(volume ? p.I.err : p.nu.err);
  }
  return volume ? fit_nu_I_volume(nu, I, err) : fit_nu_I(I, nu, err);
}

double default_p0(const std::vector<StatePoint>& pts) {
  double lg = 0;
  std::size_t n = 0;
  for (const auto& p : pts)
    if (p.p.v > 0) lg += std::log(p.p.v), ++n;
  return n ? std::exp(lg / static_cast<double>(n)) : 1.0;
}

FitResult fit_compaction_points(const std::vector<StatePoint>& pts, double p0) {
  std::vector<double> p, e, err;
  for (const auto& s : pts) {
    if (!std::isfinite(s.p.v))
      throw AnalysisError(fmt::format("fit compaction: run '{}' has neither a p column nor [shear] pressure",
                                      s.run));
    if (!(s.nu.v > 0 && s.nu.v < 1))
      throw AnalysisError(fmt::format("fit compaction: run '{}' has packing fraction {} outside (0, 1)", s.run,
                                      s.nu.v));
    p.push_back(s.p.v);
    e.push_back(s.e());
    err.push_back(s.e_err());
  }
  return fit_void_ratio(p, e, err, p0);
}

namespace {
void write_curve(const std::string& path, double lo, double hi, bool log, const Model& m, const FitResult& r) {
  Table c({"x", "y", "lo", "hi"});
  for (int k = 0; k <= 200; ++k) {
    const double x = log ? lo * std::pow(hi / lo, k / 200.0) : lo + (hi - lo) * k / 200.0;
    const double y = predict(m, r, &x), e = predict_error(m, r, &x);
    c.add_row({x, y, y - e, y + e});
  }
  c.write_csv(path);
}
}  // namespace

bool plot_nu_I(const std::string& dir, const std::vector<StatePoint>& pts, const FitResult& r,
               const std::string& command) {
  fs::create_directories(dir);
  Table d({"I", "I_err", "nu", "nu_err"});
  double lo = INFINITY, hi = 0;
  for (const auto& p : pts) {
    d.add_row({p.I.v, p.I.err, p.nu.v, p.nu.err});
    lo = std::min(lo, p.I.v), hi = std::max(hi, p.I.v);
  }
  d.write_csv((fs::path(dir) / "nu_I_data.csv").string());
  write_curve((fs::path(dir) / "nu_I_fit.csv").string(), 0, 1.1 * hi, false, nu_of_I(), r);
  const std::string body = fmt::format(
      "# made by: {}\nset datafile separator ','\nset grid\nset xlabel 'I (measured)'\nset ylabel 'ν'\n"
      "set key top right\n"
      "plot 'nu_I_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
      "     'nu_I_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' title 'ν_{{max}} = {:.4f}{}, "
      "a = {:.3g}{}', \\\n"
      "     'nu_I_data.csv' every ::1 using 1:3:2:4 with xyerrorbars pt 7 lc rgb 'black' title 'runs'\n",
      command, r["nu_max"], undetermined_flag(r, "nu_max"), r["a"], undetermined_flag(r, "a"));
  return plot_both(dir, "nu_I", body);
}

bool plot_compaction(const std::string& dir, const std::vector<StatePoint>& pts, const FitResult& r, double p0,
                     const std::string& command) {
  fs::create_directories(dir);
  Table d({"p", "p_err", "e", "e_err"});
  double lo = INFINITY, hi = 0;
  for (const auto& s : pts) {
    d.add_row({s.p.v, std::isfinite(s.p.err) ? s.p.err : 0.0, s.e(), s.e_err()});
    lo = std::min(lo, s.p.v), hi = std::max(hi, s.p.v);
  }
  d.write_csv((fs::path(dir) / "compaction_data.csv").string());
  write_curve((fs::path(dir) / "compaction_fit.csv").string(), lo / 1.5, hi * 1.5, true, void_ratio(p0), r);
  const std::string body = fmt::format(
      "# made by: {}\nset datafile separator ','\nset grid\nset logscale x\nset xlabel 'p'\n"
      "set ylabel 'void ratio e = 1/ν − 1'\nset key top right\n"
      "plot 'compaction_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \\\n"
      "     'compaction_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' title 'e_0 = {:.4f}, "
      "λ = {:.3g} (p_0 = {:.4g})', \\\n"
      "     'compaction_data.csv' every ::1 using 1:3:2:4 with xyerrorbars pt 7 lc rgb 'black' title 'runs'\n",
      command, r["e0"], r["lambda"], p0);
  return plot_both(dir, "compaction", body);
}

}  // namespace cda
