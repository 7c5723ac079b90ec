#include "run.hpp"

#include <cmath>

#include <fmt/core.h>

#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace cda {

Table read_series(const std::string& run_dir) {
  std::error_code ec;
  if (!fs::is_directory(run_dir, ec))
    throw InputError(fmt::format("run folder '{}' does not exist", run_dir));
  const std::string path = (fs::path(run_dir) / "series.csv").string();
  if (!fs::exists(path, ec))
    throw InputError(fmt::format("run folder '{}' has no series.csv", run_dir));
  return Table::read_csv(path);
}

std::string default_x_column(const Table& series) {
  return series.has("strain") ? "strain" : "time";
}

RunSteady run_steady(const std::string& run_dir, const Table& series, const std::string& column,
                     const std::string& x_column,
                     const std::optional<std::pair<double, double>>& range,
                     const SteadyOptions& opt) {
  RunSteady r;
  r.run = run_dir;
  r.column = column;
  r.x_column = x_column;
  const auto& x = series.column(x_column);
  const auto& y = series.column(column);
  const std::string what = fmt::format("'{}' column '{}'", series.source(), column);
  Window w;
  if (range) {
    w = window_from_range(x, range->first, range->second);
  } else {
    w = detect_steady_window(x, y, opt, what);
    r.detected = true;
  }
  r.stats = steady_stats(x, y, w, what);
  return r;
}

SteadyStats stats_over(const Table& series, const std::string& column, const std::string& x_column,
                       const Window& w) {
  return steady_stats(series.column(x_column), series.column(column), w,
                      fmt::format("'{}' column '{}'", series.source(), column));
}

Estimate measured_inertial_number(const Table& series, const std::string& x_column, const Window& w) {
  if (!series.has("syy")) {
    const SteadyStats si = stats_over(series, "inertial_number", x_column, w);
    return {si.mean, si.error()};
  }
  // The normal stress the simulator's I uses: contact syy plus the kinetic
  // kyy when the series has it (cdsim writes both).
  Table t = series;
  const auto& syy = series.column("syy");
  std::vector<double> total(syy.begin(), syy.end());
  if (series.has("kyy")) {
    const auto& kyy = series.column("kyy");
    for (std::size_t r = 0; r < total.size(); ++r) total[r] += kyy[r];
  }
  t.add_column("sigma_yy_total", total);
  const SteadyStats ss = stats_over(t, "sigma_yy_total", x_column, w);
  // I sqrt(sigma_yy) = gamma-dot d sqrt(rho): the same on every row.
  const auto& I = series.column("inertial_number");
  double k = 0;
  for (std::size_t r = w.begin; r < w.end; ++r)
    if (total[r] > 0) {
      k = I[r] * std::sqrt(total[r]);
      break;
    }
  if (k <= 0 || ss.mean <= 0)
    throw AnalysisError(fmt::format("'{}': no positive syy in the steady window", series.source()));
  const double i = k / std::sqrt(ss.mean);
  return {i, 0.5 * i * ss.error() / ss.mean};
}

// The bodies snapshot with the same number as a contacts snapshot
// (stem "particles" in 2D, "spheres" in 3D), if it exists.
static std::optional<std::string> companion_snapshot(const std::string& contacts_file, const std::string& stem) {
  const fs::path f(contacts_file);
  const std::string p =
      (f.parent_path() / (stem + f.filename().string().substr(std::string("contacts").size()))).string();
  std::error_code ec;
  if (!fs::exists(p, ec)) return std::nullopt;
  return p;
}

RunFabric run_fabric(const std::string& run_dir, int k, int bins, double volume, double mu,
                     double sliding_tol) {
  RunFabric f;
  f.file = snapshot_path(run_dir, "contacts", k);
  const auto raw = read_contacts(f.file);
  f.contacts = raw.size();
  // Fabric over force-bearing physical contacts (cd::obs::bears_force, the
  // threshold of the whole snapshot, as for z): an open contact (alert
  // distance, or a bond that just broke) carries no force and is no part
  // of the network whose anisotropy is measured.
  const auto forces = as_forces(raw);
  const double f_eps = cd::obs::force_threshold<2>(forces);
  // Points are tested before the side-side points are merged: a pair bears
  // force when one of its points does, even if their forces cancel.
  ContactSet bearing;
  for (std::size_t k = 0; k < raw.size(); ++k)
    if (cd::obs::bears_force(forces[k], f_eps)) bearing.push_back(raw[k]);
  const ContactSet cs = merge_side_side(bearing);
  f.physical_contacts = cs.size();
  if (cs.empty()) throw AnalysisError(fmt::format("'{}' has no force-bearing contact", f.file));
  f.fft = anisotropy_fft(cs, bins);
  f.tensor = anisotropy_tensor(cs);
  f.profile = angular_profile(cs, bins);
  f.has_volume = volume > 0;
  const double V = f.has_volume ? volume : 1.0;
  f.stress = contact_stress(raw, V);
  f.sliding = sliding_share(cs, 0, 1e-6, f_eps);
  if (mu > 0) f.sliding_coulomb = sliding_share(cs, mu, sliding_tol, f_eps);
  f.ss_share = static_cast<double>(of_type(cs, 2).size()) / static_cast<double>(cs.size());
  f.fabric = cd::obs::fabric_tensor<2>(forces, f_eps);
  for (int type : {1, 2}) {
    const auto sub = of_type(cs, type);
    if (sub.empty()) continue;
    (type == 1 ? f.sv : f.ss) = anisotropy_tensor(sub);
    (type == 1 ? f.sv_stress : f.ss_stress) = contact_stress(of_type(raw, type), V);
  }
  // The particles snapshot with the same number, for rattlers and z.
  if (const auto pfile = companion_snapshot(f.file, "particles")) f.connectivity = connectivity(raw, read_particles(*pfile), f_eps);
  return f;
}

RunFabric3 run_fabric3(const std::string& run_dir, int k, double volume, double mu, double sliding_tol) {
  RunFabric3 f;
  f.file = snapshot_path(run_dir, "contacts", k);
  const auto raw = read_contacts3(f.file);
  f.contacts = raw.size();
  const auto forces = as_forces(raw);
  const double f_eps = cd::obs::force_threshold<3>(forces);
  ContactSet3 bearing;
  for (const auto i : cd::obs::force_bearing_points<3>(forces, f_eps)) bearing.push_back(raw[i]);
  f.physical_contacts = bearing.size();
  if (bearing.empty()) throw AnalysisError(fmt::format("'{}' has no force-bearing contact", f.file));
  try {
    f.aniso = anisotropy3(bearing);
  } catch (const AnalysisError& e) {
    f.aniso_problem = fmt::format("'{}': {}", f.file, e.what());
  }
  f.has_volume = volume > 0;
  f.stress = contact_stress3(raw, f.has_volume ? volume : 1.0);
  f.fabric = cd::obs::fabric_tensor<3>(forces, f_eps);
  std::size_t flag = 0, coulomb = 0;
  for (const auto& c : bearing) {
    flag += c.status == 2;
    coulomb += c.c.ft_norm() >= mu * c.c.fn * (1 - sliding_tol);
  }
  const double nb = static_cast<double>(bearing.size());
  f.sliding = static_cast<double>(flag) / nb;
  if (mu > 0) f.sliding_coulomb = static_cast<double>(coulomb) / nb;
  if (const auto pfile = companion_snapshot(f.file, "spheres")) f.connectivity = connectivity(raw, read_particles(*pfile), f_eps);
  return f;
}

std::pair<double, double> parse_range(const std::string& s) {
  const auto colon = s.find(':');
  auto bad = [&] { return AnalysisError(fmt::format("window '{}' is not of the form a:b with a < b", s)); };
  if (colon == std::string::npos) throw bad();
  const std::string a = s.substr(0, colon), b = s.substr(colon + 1);
  char *ea = nullptr, *eb = nullptr;
  const double va = std::strtod(a.c_str(), &ea), vb = std::strtod(b.c_str(), &eb);
  if (a.empty() || b.empty() || *ea || *eb || !(va < vb)) throw bad();
  return {va, vb};
}

}  // namespace cda
