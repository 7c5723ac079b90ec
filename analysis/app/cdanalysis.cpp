// cdanalysis: steady-state statistics, fabric, fits and reports of cdsim
// runs. Every failure prints one line naming the file or quantity at fault.
// Exit codes (error.hpp): 0 done; 1 analysis refused (a degenerate fit, no
// steady window, a compare-fits FAIL); 2 bad input (usage, unreadable or
// malformed file, non-finite value, option out of range).
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "analysis/src/cohesion.hpp"
#include "analysis/src/compare.hpp"
#include "analysis/src/dilatancy.hpp"
#include "analysis/src/fabric_bounds.hpp"
#include "analysis/src/fit.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/scene_info.hpp"
#include "analysis/src/trends.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

void print_stats(const RunSteady& r) {
  const auto& s = r.stats;
  fmt::print("run        {}\ncolumn     {}\nwindow     {} {} .. {} ({} rows, {})\n", r.run, r.column,
             r.x_column, s.window.x_begin, s.window.x_end, s.window.end - s.window.begin,
             r.detected ? "detected" : "given");
  fmt::print("mean       {:.8g} +- {:.3g}\n", s.mean, s.error());
  fmt::print("blocking   sem {:.3g} +- {:.2g} at block size {}{}\n", s.blocks.sem, s.blocks.sem_err,
             s.blocks.block_size, s.blocks.converged ? "" : " (no plateau: lower bound)");
  fmt::print("autocorr   tau_int {:.3g} +- {:.2g} rows, N_eff {:.1f}, sem {:.3g}{}\n", s.acf.tau,
             s.acf.tau_err, s.acf.n_eff, s.acf.sem, s.acf.converged ? "" : " (window not converged)");
  fmt::print("trend      slope {:.3g} +- {:.3g} per unit {}\n", s.trend.slope, s.trend.slope_se,
             r.x_column);
}

// z and rattlers of a fabric (2D and 3D), or why they are missing.
void print_connectivity(const std::optional<cda::Connectivity>& conn, const char* bodies) {
  if (!conn) {
    fmt::print("connect.   no {} snapshot next to the contacts: z not computed\n", bodies);
    return;
  }
  const auto& c = *conn;
  fmt::print("connect.   z {:.4f}  rattlers {} of {}  non-floating {:.4f}  P_c", c.z, c.rattlers, c.particles,
             c.non_floating);
  for (std::size_t i = 0; i < c.P.size(); ++i) fmt::print(" {}:{:.3f}", i, c.P[i]);
  fmt::print("\n");
}

void print_harmonics(const char* label, const Anisotropy& a) {
  fmt::print("{:<8} a_c {:.4f} ({:.1f} deg)  a_ln {:.4f}  a_lt {:.4f}  a_fn {:.4f} ({:.1f} deg)  "
             "a_ft {:.4f} ({:.1f} deg)  sum/2 {:.4f}\n",
             label, a.c.a(), a.c.theta() * 180 / M_PI, a.ln.a(), a.lt.a(), a.fn.a(),
             a.fn.theta() * 180 / M_PI, a.ft.a(), a.ft.theta() * 180 / M_PI, a.sum_half());
}

void print_fit(const FitResult& r, const Model& m) {
  fmt::print("{}  ({})\n", r.model, m.formula);
  for (std::size_t i = 0; i < r.names.size(); ++i)
    fmt::print("  {:<10} {:.6g} +- {:.3g}\n", r.names[i], r.value[i], r.error[i]);
  fmt::print("  chi2/dof {:.3f} (dof {}), error scale {:.3g}, {}{}\n", r.chi2_dof, r.dof, r.scale,
             r.converged ? "converged" : "NOT converged: ", r.message);
}

void write_toml(const std::string& path, const std::vector<FitResult>& f, const std::vector<Model>& m) {
  if (path.empty()) return;
  std::ofstream out(path);
  if (!out) throw AnalysisError(fmt::format("cannot write '{}'", path));
  out << fits_to_toml(f, m);
  fmt::print("wrote {}\n", path);
}

// Run folders from the arguments: a folder holding series.csv is a run, any
// other folder a campaign whose subfolders are runs (report.hpp).
std::vector<std::string> expand_runs(const std::vector<std::string>& args) {
  std::vector<std::string> runs;
  for (const auto& a : args) {
    const auto r = campaign_runs(a);
    runs.insert(runs.end(), r.begin(), r.end());
  }
  return runs;
}

// The dimension shared by the runs of one fit (run_dimension); runs of
// different dimensions are refused: one fit mixes no dimensions.
int common_dimension(const std::vector<std::string>& runs, const std::string& what) {
  if (runs.empty()) return 2;
  const int dim = run_dimension(runs.front());
  for (const auto& r : runs)
    if (const int d = run_dimension(r); d != dim)
      throw AnalysisError(fmt::format("{}: '{}' is a {}D run and '{}' a {}D run: one fit mixes no dimensions",
                                      what, runs.front(), dim, r, d));
  return dim;
}

// The command as typed, for the plots' "made by" line.
std::string command_line(int argc, char** argv) {
  std::string c = "cdanalysis";
  for (int i = 1; i < argc; ++i) c += std::string(" ") + argv[i];
  return c;
}

std::vector<double> col_or_empty(const Table& t, const std::string& name) {
  return t.has(name) ? t.column(name) : std::vector<double>{};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdanalysis: analysis of cdsim runs (steady state, fabric, rheology fits, reports)"};
  app.require_subcommand(1);

  // steady
  auto* steady = app.add_subcommand("steady", "steady-state mean and error bar of one series column");
  std::string run, column, xcol, window, out;
  steady->add_option("run", run, "run folder (holding series.csv)")->required();
  steady->add_option("--column", column, "column of series.csv (default: q_over_p; 3D runs: shear_stress_ratio)");
  steady->add_option("--x", xcol, "abscissa column (default: strain if present, else time)");
  steady->add_option("--window", window, "steady window a:b in the abscissa, or a%:b% of the run's span of it "
                                         "(default: detected)");
  steady->add_option("--out", out, "folder for the time-series plot (png, svg) and its data");

  // fabric
  auto* fabric = app.add_subcommand("fabric", "anisotropies, stress and connectivity of a contact snapshot");
  int snapshot = -1, bins = 36;
  double volume = -1;
  fabric->add_option("run", run, "run folder (holding contacts_NNNNN.vtp)")->required();
  fabric->add_option("--snapshot", snapshot, "snapshot index (negative: from the end)")->capture_default_str();
  fabric->add_option("--bins", bins, "angular bins over [0, pi) (2D; 3D runs use the tensors)")
      ->check(CLI::Range(4, 36000))
      ->capture_default_str();
  fabric->add_option("--volume", volume, "volume (area) V for the stress, > 0; default: stress times V")
      ->check(CLI::PositiveNumber);
  fabric->add_option("--out", out, "folder for the angular profiles and polar plots");

  // profile
  auto* profile = app.add_subcommand("profile", "is the shear homogeneous? local shear rate across the layers of a "
                                                "periodic shear run, over its steady window (run.hpp shear_profile)");
  int layers = 5;
  profile->add_option("run", run, "run folder (series.csv, particle snapshots and their .pvd)")->required();
  profile->add_option("--layers", layers, "layers across the gradient direction y")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  profile->add_option("--window", window, "as steady's --window (default: the detected steady window of mu)");

  // fit
  auto* fit = app.add_subcommand("fit", "rheology fits (method.md section 11)");
  fit->require_subcommand(1);
  std::vector<std::string> runs;
  std::string table, toml_out;
  auto* mu_i = fit->add_subcommand("mu-i", "mu(I) = mu1 + (mu2 - mu1)/(1 + I0/I) over steady runs");
  mu_i->add_option("runs", runs, "run or campaign folders (each run: steady mean of q_over_p and "
                                 "inertial_number)");
  mu_i->add_option("--table", table, "CSV with columns I, mu and optionally mu_err, instead of runs");
  mu_i->add_option("--toml", toml_out, "write the fit parameters to this TOML file");
  mu_i->add_option("--out", out, "folder for the plot mu_I.png/svg (points, fit, 1-sigma band)");
  mu_i->add_option("--window", window, "steady window a:b of each run's abscissa (strain), or a%:b% of each "
                                       "run's span of it, e.g. 50%:100% the second half (default: detected per run)");
  auto* coh = fit->add_subcommand(
      "cohesion",
      "c/p = k0 eta/(1 - beta ln(1 - I/(1 + alpha eta)^(1/2))) over steady runs: eta from scene.toml "
      "([contact] cohesion_number), I the measured inertial_number, c/p = (q/p - sin phi)/cos phi with "
      "sin phi(I) from the eta = 0 runs among those given; 3D runs: c/p = mu - mu0(I), mu the "
      "shear_stress_ratio, mu0(I) that of the eta = 0 runs");
  std::string reference = "auto";
  coh->add_option("runs", runs, "run or campaign folders, eta = 0 reference runs included");
  coh->add_option("--table", table, "CSV with columns eta, I, c_over_p and optionally c_over_p_err, instead of runs");
  coh->add_option("--reference", reference,
                  "sin phi(I) of the eta = 0 runs: mu-i (fit, 4+ runs), interp (linear in ln I), auto "
                  "(mu-i with 4+ runs, else interp)")
      ->check(CLI::IsMember({"auto", "mu-i", "interp"}))
      ->capture_default_str();
  coh->add_option("--out", out, "folder for c/p data, model curves and the plot (png, svg)");
  coh->add_option("--toml", toml_out, "write the fit parameters to this TOML file");
  coh->add_option("--window", window, "steady window a:b of each run's abscissa (strain), or a%:b% of each "
                                      "run's span of it (default: detected per run)");
  bool exclude_banded = false;
  coh->add_flag("--exclude-banded", exclude_banded,
                "leave the cohesive runs whose shear is banded (profile's rate_min below 0.5: not a homogeneous "
                "flow at the run's I) out of the model fit; they stay in the data and the plot (open circles)");
  auto* dil = fit->add_subcommand(
      "dilatancy",
      "sin phi = sin phi_c + sin psi over the rows of shear runs (transient and steady), sin phi = q/p, "
      "sin psi = volume_strain_rate/sqrt(volume_strain_rate^2 + shear_rate^2); also the free slope b");
  std::size_t blocks_per_bin = 4;
  std::string strain_range;
  dil->add_option("runs", runs, "run or campaign folders (series.csv with q_over_p, volume_strain_rate, "
                                "shear_rate)")->required();
  dil->add_option("--blocks-per-bin", blocks_per_bin,
                  "blocks of ceil(4 tau) rows averaged into one point (consecutive in strain)")
      ->check(CLI::Range(2, 1000000))
      ->capture_default_str();
  dil->add_option("--strain", strain_range, "use the rows with a <= strain <= b only (a:b; default all)");
  dil->add_option("--out", out, "folder for the binned points, the fit curve and the plot (png, svg)");
  dil->add_option("--toml", toml_out, "write the fit parameters (fixed and free slope) to this TOML file");
  auto* ang = fit->add_subcommand(
      "angularity",
      "mu*(alpha) = mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)) over steady shear runs, alpha = 2 pi/n_s "
      "(disks 0) from each run's shapes; also the table of nu*, z, anisotropies, sliding and side-side "
      "shares, partial strengths q_sv/p, q_ss/p and the check q/p ~ (sum a)/2 per run");
  int ang_snapshots = 5;
  ang->add_option("runs", runs, "run or campaign folders (series.csv, scene.toml, contact snapshots)")->required();
  ang->add_option("--snapshots", ang_snapshots, "last contact snapshots averaged per run for the fabric")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  ang->add_option("--bins", bins, "angular bins over [0, pi)")->check(CLI::Range(4, 36000))->capture_default_str();
  ang->add_option("--out", out, "folder for angularity.csv, the fit curve and the plots (png, svg)");
  ang->add_option("--toml", toml_out, "write the fit parameters to this TOML file");
  auto* nui = fit->add_subcommand("nu-i", "nu(I) = nu_max - a I over steady runs (packing_fraction against "
                                          "the measured inertial number)");
  nui->add_option("runs", runs, "run or campaign folders");
  nui->add_option("--table", table, "CSV with columns I, nu and optionally nu_err, instead of runs");
  nui->add_option("--out", out, "folder for the plot nu_I.png/svg and its data");
  nui->add_option("--toml", toml_out, "write the fit parameters to this TOML file");
  nui->add_option("--window", window, "steady window a:b of each run's abscissa (strain), or a%:b% of each "
                                      "run's span of it (default: detected per run)");
  auto* comp = fit->add_subcommand(
      "compaction", "e = e0 - lambda ln(p/p0) over steady (or compacted) runs at several p: e = 1/nu - 1 "
                    "from the steady packing_fraction, p the steady mean of the series' p (else the scene's "
                    "[shear] pressure)");
  double p0 = 0;
  comp->add_option("runs", runs, "run or campaign folders");
  comp->add_option("--table", table, "CSV with columns p, e and optionally e_err, instead of runs");
  comp->add_option("--p0", p0, "reference pressure (default: the geometric mean of the p's)")
      ->check(CLI::PositiveNumber);
  comp->add_option("--out", out, "folder for the plot compaction.png/svg and its data");
  comp->add_option("--toml", toml_out, "write the fit parameters to this TOML file");
  auto* bounds = fit->add_subcommand("fabric-bounds", "envelope z_min, z_max of (z, a_c) points");
  double k_bound = 1.0;
  bounds->add_option("--table", table, "CSV with columns z, a_c (optionally z_err, a_c_err)")->required();
  bounds->add_option("--k", k_bound, "bound prefactor (1 from method.md's definition)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();

  // compare-fits
  auto* cmp = app.add_subcommand(
      "compare-fits",
      "compare the parameters of two fit TOML files (as written by --toml or report). A parameter FAILs "
      "when |new - ref| > TOL_SIGMA sqrt(err_ref^2 + err_new^2) AND |new - ref| > TOL_REL |ref|; a model "
      "or parameter of REFERENCE missing from NEW, a non-finite value, or a fit no longer converged FAILs "
      "too. Exit status: 0 all OK, 1 some FAIL, 2 a file unreadable.");
  std::string ref_toml, new_toml;
  double tol_sigma = 3, tol_rel = 0;
  cmp->add_option("reference", ref_toml, "reference fit TOML")->required();
  cmp->add_option("new", new_toml, "new fit TOML")->required();
  cmp->add_option("--tol-sigma", tol_sigma, "combined standard uncertainties allowed")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  cmp->add_option("--tol-rel", tol_rel, "relative change allowed (0: the sigma test alone)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();

  // report
  auto* report = app.add_subcommand("report", "tables, fits, plots and index.html for a campaign");
  std::string campaign;
  report->add_option("campaign", campaign, "campaign folder (its subfolders are runs)")->required();
  report->add_option("--out", out, "report folder (default: CAMPAIGN/report)");
  report->add_option("--bins", bins, "angular bins over [0, pi)")
      ->check(CLI::Range(4, 36000))
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // --help: 0; every usage error: bad input
  }

  try {
    if (steady->parsed()) {
      const auto series = read_series(run);
      if (column.empty()) column = mu_column(run_dimension(run));
      const std::string x = xcol.empty() ? default_x_column(series) : xcol;
      const auto range = window_range(window, series.column(x));
      const auto r = run_steady(run, series, column, x, range);
      print_stats(r);
      if (!out.empty()) {
        fs::create_directories(out);
        if (!plot_series(out, "series_" + column, series, x, column, &r.stats.window))
          fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", out);
      }
    } else if (profile->parsed()) {
      const auto series = read_series(run);
      const std::string x = default_x_column(series);
      const auto r = run_steady(run, series, mu_column(run_dimension(run)), x, window_range(window, series.column(x)));
      const auto& w = r.stats.window;
      const auto pr = shear_profile(run, series, x, w, layers);
      fmt::print("window     {} {:.4g} to {:.4g}: {} particle snapshots\n", x, w.x_begin, w.x_end, pr.snapshots);
      fmt::print("local shear rate / mean rate between layer centres (1: homogeneous), mean +- sem over them:\n");
      for (int i = 0; i < layers; ++i)
        fmt::print("  gap {:>3}-{:<3} {:.3f} +- {:.3f}{}\n", i, (i + 1) % layers, pr.rate[i].v, pr.rate[i].err,
                   i + 1 == layers ? "  (across the periodic boundary)" : "");
      fmt::print("rate_min   {:.3f} +- {:.3f}{}\n", pr.rate_min.v, pr.rate_min.err,
                 is_banded(pr.rate_min.v) ? fmt::format("  banded: below {} (a layer moves nearly as a rigid "
                                                              "plug; the run's I is not the local one)",
                                                              kBandedRateMin)
                                                : std::string());
      fmt::print("max_rate   {:.3f} +- {:.3f} (per snapshot, then averaged)\n", pr.max_rate.v, pr.max_rate.err);
    } else if (fabric->parsed() && run_dimension(run) == 3) {
      if (!out.empty())
        throw AnalysisError(fmt::format("fabric --out (polar plots of the angular profiles) is 2D only: '{}' is "
                                        "a 3D run (dimension = 3 in its scene.toml)", run));
      const auto f = run_fabric3(run, snapshot, volume);
      const auto pr = principal(f.stress.s);
      fmt::print("snapshot   {}\ncontacts   {} ({} force-bearing)\n", f.file, f.contacts, f.physical_contacts);
      fmt::print("stress     p {:.6g}  q {:.6g}  q/p {:.4f}  (q = (s1 - s3)/3)  q_vm/p {:.4f}  mu {:.4f}  "
                 "skew {:.3g}{}\n",
                 f.stress.p(), f.stress.q(), f.stress.q_over_p(), f.stress.q_vm() / f.stress.p(), f.stress.mu(),
                 f.stress.skew(), f.has_volume ? "" : "  (times V: no --volume)");
      fmt::print("principal  s1 {:.6g} ({:.3f} {:.3f} {:.3f})  s2 {:.6g}  s3 {:.6g} ({:.3f} {:.3f} {:.3f})\n",
                 pr.value[0], pr.dir[0][0], pr.dir[0][1], pr.dir[0][2], pr.value[1], pr.value[2], pr.dir[2][0],
                 pr.dir[2][1], pr.dir[2][2]);
      fmt::print("fabric     <nn> xx {:.4f}  yy {:.4f}  zz {:.4f}  xy {:.4f}  xz {:.4f}  yz {:.4f}\n", f.fabric[0][0],
                 f.fabric[1][1], f.fabric[2][2], f.fabric[0][1], f.fabric[0][2], f.fabric[1][2]);
      if (f.aniso) {
        const auto& a = *f.aniso;
        fmt::print("harmonics  a_c {:.4f}  a_n {:.4f}  a_t {:.4f}  <f> {:.6g}  ({} iterations)\n", a.a_c(), a.a_n(),
                   a.a_t(), a.mean_f, a.iterations);
        fmt::print("check      q/p {:.4f} vs (2/5)(a_c + a_n + a_t) {:.4f}, with directions {:.4f}, on the stress "
                   "axes {:.4f}\n",
                   f.stress.q_over_p(), a.sum_2_5(), a.sum_2_5_tensor(), a.sum_2_5_on(f.stress));
      } else {
        fmt::print("harmonics  none: {}\n", f.aniso_problem);
      }
      fmt::print("sliding    {:.4f} of force-bearing contacts (status flag)\n", f.sliding);
      print_connectivity(f.connectivity, "spheres");
    } else if (fabric->parsed()) {
      const auto f = run_fabric(run, snapshot, bins, volume);
      fmt::print("snapshot   {}\ncontacts   {} ({} force-bearing physical)\n", f.file, f.contacts,
                 f.physical_contacts);
      print_harmonics("fft", f.fft);
      print_harmonics("tensor", f.tensor);
      fmt::print("stress     p {:.6g}  q {:.6g}  q/p {:.4f}  theta_s {:.1f} deg  skew {:.3g}{}\n",
                 f.stress.p(), f.stress.q(), f.stress.q_over_p(), f.stress.theta() * 180 / M_PI,
                 f.stress.skew(), f.has_volume ? "" : "  (times V: no --volume)");
      fmt::print("check      q/p {:.4f} vs (sum a)/2 {:.4f} (fft), {:.4f} (tensor, with directions)\n",
                 f.stress.q_over_p(), f.fft.sum_half(), f.tensor.sum_half_vector());
      fmt::print("sliding    {:.4f} of force-bearing contacts\n", f.sliding);
      fmt::print("fabric     <nn> xx {:.4f}  xy {:.4f}  yy {:.4f}\n", f.fabric[0][0], f.fabric[0][1],
                 f.fabric[1][1]);
      if (f.sv) print_harmonics("sv", *f.sv);
      if (f.ss) print_harmonics("ss", *f.ss);
      if (f.sv_stress) fmt::print("sv stress  p {:.6g} q {:.6g}\n", f.sv_stress->p(), f.sv_stress->q());
      if (f.ss_stress) fmt::print("ss stress  p {:.6g} q {:.6g}\n", f.ss_stress->p(), f.ss_stress->q());
      print_connectivity(f.connectivity, "particles");
      if (!out.empty()) {
        fs::create_directories(out);
        if (!plot_polar(out, "polar", f)) fmt::print(stderr, "warning: gnuplot failed; scripts in {}\n", out);
      }
    } else if (mu_i->parsed()) {
      std::vector<double> I, mu, err;
      std::string mu_label = "μ* = q/p";
      if (!table.empty()) {
        const auto t = Table::read_csv(table);
        I = t.column("I");
        mu = t.column("mu");
        err = col_or_empty(t, "mu_err");
      } else {
        if (runs.empty()) throw AnalysisError("fit mu-i: give run folders or --table");
        const auto all = expand_runs(runs);
        const int dim = common_dimension(all, "fit mu-i");
        if (dim == 3) {
          fmt::print("3D runs: mu = shear_stress_ratio = -(sxy + syx)/2 / syy\n");
          mu_label = "μ = −σ_xy/σ_yy";
        }
        for (const auto& r : all) {
          const auto series = read_series(r);
          const auto x = default_x_column(series);
          const auto range = window_range(window, series.column(x));
          const auto s = run_steady(r, series, mu_column(dim), x, range);
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
      const auto r = fit_mu_I(I, mu, err);
      print_fit(r, mu_of_I());
      write_toml(toml_out, {r}, {mu_of_I()});
      if (!out.empty()) {
        if (err.empty()) err.assign(I.size(), 0.0);
        if (!plot_mu_I(out, I, mu, err, r, mu_label))
          fmt::print("cdanalysis: gnuplot did not run: {}/mu_I.gp written, no PNG\n", out);
        else
          fmt::print("wrote {}/mu_I.png and mu_I.svg\n", out);
      }
    } else if (coh->parsed()) {
      if (!table.empty()) {
        if (!runs.empty()) throw AnalysisError("fit cohesion: give run folders or --table, not both");
        // cohesion_data.csv of an earlier fit may be given: its rate_min is
        // nan for runs without particle snapshots, so nan is read, and
        // refused in the columns the fit uses.
        const auto t = Table::read_csv(table, true);
        for (const char* c : {"eta", "I", "c_over_p", "c_over_p_err"}) {
          if (!t.has(c)) continue;
          const auto& v = t.column(c);
          for (std::size_t i = 0; i < v.size(); ++i)
            if (!std::isfinite(v[i]))
              throw InputError(fmt::format("'{}' line {}, column '{}': not a finite number", table, i + 2, c));
        }
        const auto r = fit_cohesion(t.column("eta"), t.column("I"), t.column("c_over_p"),
                                    col_or_empty(t, "c_over_p_err"));
        print_fit(r, cohesion());
        write_toml(toml_out, {r}, {cohesion()});
      } else {
        if (runs.empty()) throw AnalysisError("fit cohesion: give run folders or --table");
        std::vector<SteadyPoint> ref_pts, coh_pts;
        const auto all = expand_runs(runs);
        const int dim = common_dimension(all, "fit cohesion");
        for (const auto& r : all) {
          const auto p = steady_point(r, window);
          (p.eta == 0 ? ref_pts : coh_pts).push_back(p);
        }
        if (coh_pts.empty()) throw AnalysisError("fit cohesion: no run with eta > 0 among the given runs");
        const auto mode = reference == "mu-i"     ? SinPhiReference::Mode::MuI
                          : reference == "interp" ? SinPhiReference::Mode::Interp
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
                     exclude_banded && p.banded() ? " (left out of the fit: --exclude-banded)" : "");
          pts.push_back(cp);
          if (exclude_banded && p.banded()) continue;
          eta.push_back(p.eta);
          I.push_back(p.I);
          c.push_back(cp.c_over_p);
          ce.push_back(cp.c_over_p_err);
        }
        FitResult r;
        try {
          r = fit_cohesion(eta, I, c, ce);
        } catch (const AnalysisError&) {
          // The c/p points are a result on their own: written and plotted
          // before the refusal (exit 1) when the model is not determined.
          if (!out.empty() && !plot_cohesion(out, pts, nullptr))
            fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", out);
          if (!out.empty()) fmt::print("wrote the c/p points (no model) in {}\n", out);
          throw;
        }
        print_fit(r, cohesion());
        std::vector<FitResult> fits = {r};
        std::vector<Model> models = {cohesion()};
        if (ref.uses_fit()) {
          fits.push_back(ref.fit());
          models.push_back(mu_of_I());
        }
        write_toml(toml_out, fits, models);
        if (!out.empty() && !plot_cohesion(out, pts, &r))
          fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", out);
      }
    } else if (dil->parsed()) {
      DilatancyOptions opt;
      opt.blocks_per_bin = blocks_per_bin;
      if (!strain_range.empty()) opt.strain = parse_range(strain_range);
      std::vector<RunDilatancy> rd;
      const auto all = expand_runs(runs);
      for (const auto& r : all) {
        // A run too short for its bins is skipped with the reason (the
        // transient data of the other runs still make a fit); none usable: error.
        refuse_3d(r, "fit dilatancy (sin psi from the 2D Mohr circle of the strain rate)");
        try {
          rd.push_back(run_dilatancy(r, read_series(r), opt));
        } catch (const AnalysisError& e) {
          if (all.size() == 1) throw;
          fmt::print("{}: skipped: {}\n", r, e.what());
          continue;
        }
        const auto& d = rd.back();
        fmt::print("{}: {} rows ({} skipped), tau {:.3g} rows, blocks of {} rows, {} bins, reliability of "
                   "sin psi {:.3f}\n",
                   r, d.rows, d.skipped, d.tau, d.block_rows, d.bins.size(), d.reliability);
      }
      if (rd.empty()) throw AnalysisError("fit dilatancy: no usable run (each was skipped, see above)");
      const auto f = fit_dilatancy_runs(std::move(rd));
      print_fit(f.fixed, dilatancy());
      print_fit(f.free, dilatancy_free());
      const double b = f.free["b"], be = f.free.err("b");
      fmt::print("slope check: b = {:.4f} +- {:.4f}, (b - 1)/err = {:.2f}{}\n", b, be, (b - 1) / be,
                 std::abs(b - 1) > 3 * be ? "  (b differs from the model's 1 by more than 3 sigma; a free "
                                            "slope is biased towards 0 by the reliability of sin psi)"
                                          : "");
      write_toml(toml_out, {f.fixed, f.free}, {dilatancy(), dilatancy_free()});
      if (!out.empty() && !plot_dilatancy(out, f))
        fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", out);
    } else if (ang->parsed()) {
      AngularityOptions opt;
      opt.snapshots = ang_snapshots;
      opt.bins = bins;
      std::vector<AngularityPoint> pts;
      const auto all = expand_runs(runs);
      for (const auto& r : all) {
        try {
          pts.push_back(angularity_point(r, opt));
        } catch (const AnalysisError& e) {
          if (all.size() == 1) throw;
          fmt::print("{}: skipped: {}\n", r, e.what());
        }
      }
      if (pts.empty()) throw AnalysisError("fit angularity: no usable run (each was skipped, see above)");
      std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.alpha < b.alpha; });
      fmt::print("sliding: |f_t| >= mu f_n (1 - tol), tol = the run's [solver] tol; fabric: mean +- sem over "
                 "the last {} contact snapshots\n", ang_snapshots);
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
        r = fit_angularity(pts);
        print_fit(*r, mu_of_alpha());
        write_toml(toml_out, {*r}, {mu_of_alpha()});
      } catch (const AnalysisError& e) {
        if (out.empty()) throw;
        fmt::print(stderr, "cdanalysis: refused: {}\n", e.what());
      }
      if (!out.empty()) {
        if (!plot_angularity(out, pts, r ? &*r : nullptr, command_line(argc, argv)))
          fmt::print(stderr, "warning: gnuplot failed; the scripts are in {}\n", out);
        fmt::print("wrote {}/angularity.csv and the angularity_*.png/svg plots\n", out);
        if (!r) return 1;
      }
    } else if (nui->parsed() || comp->parsed()) {
      const bool is_nu = nui->parsed();
      std::vector<StatePoint> pts;
      if (!table.empty()) {
        if (!runs.empty()) throw AnalysisError("fit: give run folders or --table, not both");
        const auto t = Table::read_csv(table);
        const auto xs = t.column(is_nu ? "I" : "p");
        const auto ys = t.column(is_nu ? "nu" : "e");
        const auto es = col_or_empty(t, is_nu ? "nu_err" : "e_err");
        for (std::size_t i = 0; i < xs.size(); ++i) {
          StatePoint s;
          s.run = fmt::format("row {}", i + 1);
          const double err = es.empty() ? std::nan("") : es[i];
          if (is_nu) {
            s.I = {xs[i], std::nan("")};
            s.nu = {ys[i], err};
          } else {  // e given: store nu = 1/(1 + e) so that e() is e again
            s.p = {xs[i], std::nan("")};
            s.nu = {1 / (1 + ys[i]), err / ((1 + ys[i]) * (1 + ys[i]))};
          }
          pts.push_back(s);
        }
      } else {
        if (runs.empty()) throw AnalysisError("fit: give run folders or --table");
        const auto all = expand_runs(runs);
        common_dimension(all, is_nu ? "fit nu-i" : "fit compaction");
        for (const auto& r : all) {
          const auto s = state_point(r, is_nu ? window : std::string());
          if (is_nu)
            fmt::print("{}: I = {:.4g} +- {:.2g}, nu = {:.5f} +- {:.5f}\n", r, s.I.v, s.I.err, s.nu.v, s.nu.err);
          else
            fmt::print("{}: p = {:.5g}{}, nu = {:.5f} +- {:.5f}, e = {:.5f} +- {:.5f}\n", r, s.p.v,
                       s.p_from_scene ? " (scene)" : fmt::format(" +- {:.2g}", s.p.err), s.nu.v, s.nu.err, s.e(),
                       s.e_err());
          pts.push_back(s);
        }
      }
      // Without error bars on every point the fit is unweighted.
      bool all_err = true;
      for (auto& s : pts) all_err = all_err && std::isfinite(s.nu.err) && s.nu.err > 0;
      FitResult r;
      Model m = nu_of_I();
      double pref = p0;
      if (is_nu) {
        if (all_err) {
          r = fit_nu_I_points(pts);
        } else {
          std::vector<double> I, nu;
          for (const auto& s : pts) I.push_back(s.I.v), nu.push_back(s.nu.v);
          r = fit_nu_I(I, nu, {});
        }
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
      print_fit(r, m);
      write_toml(toml_out, {r}, {m});
      if (!out.empty()) {
        if (!all_err)
          for (auto& s : pts) s.nu.err = 0;
        const bool ok = is_nu ? plot_nu_I(out, pts, r, command_line(argc, argv))
                              : plot_compaction(out, pts, r, pref, command_line(argc, argv));
        if (!ok) fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", out);
        else fmt::print("wrote {}/{}.png and .svg\n", out, is_nu ? "nu_I" : "compaction");
      }
    } else if (cmp->parsed()) {
      const auto a = read_fit_toml(ref_toml);
      const auto b = read_fit_toml(new_toml);
      const auto c = compare_fits(a, b, tol_sigma, tol_rel);
      fmt::print("reference {}\nnew       {}\n{}", ref_toml, new_toml, format_comparison(c, tol_sigma, tol_rel));
      if (!c.ok()) return 1;
    } else if (bounds->parsed()) {
      {  // a 3D fabric table (the report's, with a_n) is refused before its values are read
        std::ifstream head(table);
        std::string line;
        std::getline(head, line);
        if (("," + line + ",").find(",a_n,") != std::string::npos)
          throw AnalysisError(fmt::format("fit fabric-bounds is 2D only: '{}' is a 3D fabric table (column a_n); "
                                          "the bounds of method.md §11 bound the 2D density (z/2pi)(1 + a_c cos "
                                          "2theta)",
                                          table));
      }
      const auto t = Table::read_csv(table);
      const auto b = fabric_bounds(t.column("z"), t.column("a_c"), col_or_empty(t, "z_err"),
                                   col_or_empty(t, "a_c_err"), k_bound);
      fmt::print("fabric bounds (k = {}): z_min {:.4f} +- {:.2g} (row {}), z_max {:.4f} +- {:.2g} (row {})\n"
                 "peak a_c* {:.4f} at z* {:.4f}\n",
                 b.k, b.z_min, b.z_min_err, b.i_min + 1, b.z_max, b.z_max_err, b.i_max + 1, b.a_star(),
                 b.z_star());
    } else if (report->parsed()) {
      const std::string dir = out.empty() ? (fs::path(campaign) / "report").string() : out;
      const auto s = write_report(campaign, dir, bins);
      fmt::print("report in {}: {} runs, {} steady, {} with fabric{}\n", dir, s.runs, s.steady, s.fabric,
                 s.plots_ok ? "" : " (some plots failed: see the .gp.log files)");
      if (s.costed)
        fmt::print("cost: {:.1f} s wall time ({:.2f} h), {:.1f} s CPU time over {} runs{}\n", s.wall_time,
                   s.wall_time / 3600, s.cpu_time, s.costed,
                   s.costed < s.runs ? fmt::format(" ({} without summary.toml: n/a)", s.runs - s.costed) : "");
      else
        fmt::print("cost: n/a (no run has a summary.toml)\n");
      fmt::print("campaign kind: {}; fits: {}\n", s.kinds.empty() ? "none" : fmt::format("{}", fmt::join(s.kinds, "; ")),
                 s.fits.empty() ? "none" : fmt::format("{}", fmt::join(s.fits, ", ")));
      for (const auto& p : s.problems) fmt::print(stderr, "problem: {}\n", p);
      fmt::print("open {}/index.html\n", dir);
    }
  } catch (const InputError& e) {
    fmt::print(stderr, "cdanalysis: bad input: {}\n", e.what());
    return 2;
  } catch (const AnalysisError& e) {
    fmt::print(stderr, "cdanalysis: refused: {}\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "cdanalysis: error: {}\n", e.what());
    return 2;
  }
  return 0;
}
