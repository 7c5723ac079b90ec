#include "report_tables.hpp"

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "plot.hpp"

namespace fs = std::filesystem;

namespace cda {
namespace {

// The cost columns of a row, after its physics.
void add_cost(std::map<std::string, double>& row, const std::optional<RunCost>& c) {
  const std::vector<double> cost = cost_values(c);
  for (std::size_t k = 0; k < kCostColumns.size(); ++k) row[kCostColumns[k]] = cost[k];
}

// 2D: the last snapshot's anisotropies, Fourier and tensor, its stress
// ratio, sliding share and connectivity.
std::map<std::string, double> fabric2_row(const ReportRun& r) {
  const RunFabric& f = *r.fabric2;
  const auto& a = f.fft;
  const auto& b = f.tensor;
  return {{"run", static_cast<double>(r.index)}, {"a_c", a.c.a()}, {"theta_c", a.c.theta()},
          {"a_ln", a.ln.a()}, {"a_lt", a.lt.a()}, {"a_fn", a.fn.a()}, {"a_ft", a.ft.a()},
          {"sum_half", a.sum_half()}, {"q_over_p", f.stress.q_over_p()}, {"a_c_tensor", b.c.a()},
          {"a_ln_tensor", b.ln.a()}, {"a_lt_tensor", b.lt.a()}, {"a_fn_tensor", b.fn.a()},
          {"a_ft_tensor", b.ft.a()}, {"sliding", f.sliding},
          {"z", f.connectivity ? f.connectivity->z : std::nan("")},
          {"non_floating", f.connectivity ? f.connectivity->non_floating : std::nan("")}};
}

// 3D: each kFabric3Columns mean ± sem over the window's snapshots, the
// relative deviation of (2/5) sum a from q/p, and how many snapshots.
std::map<std::string, double> fabric3_row(const ReportRun& r) {
  const WindowFabric3& fw = *r.fabric3;
  std::map<std::string, double> row = {{"run", static_cast<double>(r.index)}};
  for (const auto& c : kFabric3Columns) {
    row[c] = fw.of(c).v;
    row[c + "_err"] = fw.of(c).err;
  }
  row["check_rel"] = fw.check_rel;
  row["check_rel_err"] = fw.check_rel_err;
  row["check_rel_branch"] = fw.check_rel_branch;
  row["check_rel_branch_err"] = fw.check_rel_branch_err;
  row["fabric_snapshots"] = static_cast<double>(fw.files.size());
  return row;
}

}  // namespace

const std::vector<std::string> kCostColumns = {"wall_time", "cpu_time", "steps", "sweeps_per_step", "cap_share"};

std::vector<double> cost_values(const std::optional<RunCost>& c) {
  if (!c) return std::vector<double>(kCostColumns.size(), std::nan(""));
  return {c->wall_time, c->cpu_time, c->steps, c->sweeps_per_step, c->cap_share};
}

std::string or_na(double v, const char* spec) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : "n/a";
}
std::string or_na(double v, double err) {
  return std::isfinite(v) ? (std::isfinite(err) ? fmt::format("{:.4g} ± {:.2g}", v, err)
                                                : fmt::format("{:.4g}", v))
                          : "n/a";
}

std::string runs_csv(const ReportScan& scan) {
  std::string s = "run,folder,status";
  for (const auto& c : kCostColumns) s += "," + c;
  s += ",threads\n";
  for (const ReportRun& r : scan.runs) {
    s += fmt::format("{},\"{}\",{}", r.index, r.folder, r.status);
    for (const double v : cost_values(r.cost)) s += "," + or_na(v, "{}");  // shortest exact text
    s += "," + (r.cost ? fmt::format("{}", r.cost->threads) : std::string("n/a")) + "\n";
  }
  return s;
}

Table steady_table(const ReportScan& scan) {
  const std::string mu = mu_column(scan.dimension);
  std::vector<std::string> names = {"run"};
  for (const std::string& q : std::vector<std::string>{mu, "inertial_number", "packing_fraction", "z", "p"})
    names.insert(names.end(), {q, q + "_err"});
  names.insert(names.end(), {"window_begin", "window_end", "tau_int", "n_eff", "rate_min", "rate_min_err"});
  names.insert(names.end(), kCostColumns.begin(), kCostColumns.end());
  Table t(names);
  for (const ReportRun& r : scan.runs) {
    if (!r.measured) continue;
    const SteadyStats& s = *r.main_stats;
    std::map<std::string, double> row = {{"run", static_cast<double>(r.index)},
                                         {mu, r.mu.v}, {mu + "_err", r.mu.err},
                                         {"inertial_number", r.I.v}, {"inertial_number_err", r.I.err},
                                         {"packing_fraction", r.phi.v}, {"packing_fraction_err", r.phi.err},
                                         {"z", r.z.v}, {"z_err", r.z.err},
                                         {"p", r.p.v}, {"p_err", r.p.err},
                                         {"window_begin", s.window.x_begin}, {"window_end", s.window.x_end},
                                         {"tau_int", s.acf.tau}, {"n_eff", s.acf.n_eff},
                                         {"rate_min", r.rate_min.v}, {"rate_min_err", r.rate_min.err}};
    add_cost(row, r.cost);
    t.add_named_row(row);
  }
  return t;
}

Table fabric_table(const ReportScan& scan) {
  std::vector<std::string> names;
  if (scan.dimension == 3) {
    // The spherical-harmonic anisotropies (fabric3.hpp), q/p with q =
    // (s1 - s3)/3 beside (2/5) sum a, and mu = -sxy/syy of the snapshots:
    // each the mean over the contact snapshots in the steady window with
    // its _err (sem over them), the relative deviation check_rel of (2/5)
    // sum a from q/p (check_rel_branch: with the branch terms a_ln, a_lt), and the count fabric_snapshots (1: the last snapshot
    // alone).
    names = {"run"};
    for (const auto& c : kFabric3Columns) names.insert(names.end(), {c, c + "_err"});
    names.insert(names.end(), {"check_rel", "check_rel_err", "check_rel_branch", "check_rel_branch_err",
                               "fabric_snapshots"});
  } else {
    names = {"run", "a_c", "theta_c", "a_ln", "a_lt", "a_fn", "a_ft", "sum_half",
             "q_over_p", "a_c_tensor", "a_ln_tensor", "a_lt_tensor", "a_fn_tensor",
             "a_ft_tensor", "sliding", "z", "non_floating"};
  }
  names.insert(names.end(), kCostColumns.begin(), kCostColumns.end());
  Table t(names);
  for (const ReportRun& r : scan.runs) {
    if (!r.fabric3 && !r.fabric2) continue;
    auto row = r.fabric3 ? fabric3_row(r) : fabric2_row(r);
    add_cost(row, r.cost);
    t.add_named_row(row);
  }
  return t;
}

void write_tables(const ReportScan& scan, const std::string& out_dir) {
  write_text((fs::path(out_dir) / "runs.csv").string(), runs_csv(scan));
  steady_table(scan).write_csv((fs::path(out_dir) / "steady.csv").string());
  fabric_table(scan).write_csv((fs::path(out_dir) / "fabric.csv").string());
}

}  // namespace cda
