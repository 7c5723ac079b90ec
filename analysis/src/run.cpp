#include "run.hpp"

#include <cmath>

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>

#include "scene_info.hpp"

namespace fs = std::filesystem;

namespace cda {

Table read_series(const std::string& run_dir) {
  std::error_code ec;
  if (!fs::is_directory(run_dir, ec))
    throw InputError(fmt::format("run folder '{}' does not exist", run_dir));
  const std::string path = (fs::path(run_dir) / "series.csv").string();
  if (!fs::exists(path, ec))
    throw InputError(fmt::format("run folder '{}' has no series.csv", run_dir));
  Table t = Table::read_csv(path);
  // cdsim writes whole rows, one per output step, forward in time: a file
  // that ends mid-row was cut (a run killed while writing, a full disk), and
  // a step written twice or a time going backwards means rows of two runs or
  // two sessions mixed; any of them would bias every window average.
  {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    char last = '\n';
    if (in && in.tellg() > 0) {
      in.seekg(-1, std::ios::end);
      in.get(last);
    }
    if (last != '\n')
      throw InputError(fmt::format("'{}' line {}: the last row is cut (no end of line after it): the file "
                                   "ends mid-row",
                                   path, t.line(t.rows() - 1)));
  }
  for (const char* c : {"step", "time"}) {
    if (!t.has(c)) continue;
    const auto& v = t.column(c);
    for (std::size_t i = 1; i < v.size(); ++i)
      if (!(v[i] > v[i - 1]))
        throw InputError(fmt::format("'{}' line {}: {} {} {} the previous row's {} (line {}): the rows must "
                                     "go forward, one per output step",
                                     path, t.line(i), c, fmt::format("{}", v[i]),
                                     v[i] == v[i - 1] ? "repeats" : "is before", fmt::format("{}", v[i - 1]),
                                     t.line(i - 1)));
  }
  return t;
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

RunFabric run_fabric(const std::string& run_dir, int k, int bins, double volume, double mu,
                     double sliding_tol, double force_rel) {
  RunFabric f;
  f.file = snapshot_path(run_dir, "contacts", k);
  const auto raw = read_contacts(f.file);
  f.contacts = raw.size();
  // Fabric over force-bearing physical contacts (cd::obs::bears_force, the
  // threshold of the whole snapshot, as for z): an open contact (alert
  // distance, or a bond that just broke) carries no force and is no part
  // of the network whose anisotropy is measured.
  const auto forces = as_forces(raw);
  const double f_eps = cd::obs::force_threshold<2>(forces, force_rel);
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

namespace {

// The anisotropies of a subset of contacts, or nothing when there is none
// or the forms do not fit them (a few dozen contacts may not).
std::optional<Anisotropy3> anisotropy3_of(const ContactSet3& cs) {
  if (cs.empty()) return std::nullopt;
  try {
    return anisotropy3(cs);
  } catch (const AnalysisError&) {
    return std::nullopt;
  }
}

ContactSet3 rows_where(const ContactSet3& cs, bool (*keep)(const Contact3&)) {
  ContactSet3 out;
  for (const auto& c : cs)
    if (keep(c)) out.push_back(c);
  return out;
}

bool is_face_face(const Contact3& c) { return c.kind == static_cast<int>(Kind3::FaceFace); }
bool is_other_polyhedra(const Contact3& c) { return c.kind > 0 && !is_face_face(c); }

}  // namespace

double RunFabric3::kind_share(Kind3 k) const {
  if (!polyhedra || physical_contacts == 0) return std::nan("");
  return static_cast<double>(by_kind[static_cast<std::size_t>(k)]) / static_cast<double>(physical_contacts);
}

double RunFabric3::q_over_p_face_face() const {
  if (!polyhedra) return std::nan("");
  const auto ps = principal(stress.s);
  double e1se1 = 0, e3se3 = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      e1se1 += ps.dir[0][i] * stress_face_face.s[i][j] * ps.dir[0][j];
      e3se3 += ps.dir[2][i] * stress_face_face.s[i][j] * ps.dir[2][j];
    }
  return (e1se1 - e3se3) / 3 / stress.p();
}

RunFabric3 run_fabric3(const std::string& run_dir, int k, double volume, double mu, double sliding_tol,
                       double force_rel) {
  RunFabric3 f;
  f.file = snapshot_path(run_dir, "contacts", k);
  const auto raw = read_contacts3(f.file);
  f.contacts = raw.size();
  const auto forces = as_forces(raw);
  const double f_eps = cd::obs::force_threshold<3>(forces, force_rel);
  // One contact per force-bearing pair (a pair bears force when one of its
  // rows does, cdsim's z): a sphere pair's row, a polyhedra pair's points
  // merged (forces summed), so that the anisotropies weigh each contact once
  // with its whole force.
  const ContactSet3 merged = merge_points3(raw);
  std::map<std::pair<int, int>, const Contact3*> poly;
  for (const auto& m : merged)
    if (m.kind > 0) poly.emplace(std::make_pair(m.c.b1, m.c.b2), &m);
  ContactSet3 bearing;
  for (const auto i : cd::obs::force_bearing_points<3>(forces, f_eps))
    bearing.push_back(raw[i].kind > 0 ? *poly.at({raw[i].c.b1, raw[i].c.b2}) : raw[i]);
  f.physical_contacts = bearing.size();
  if (bearing.empty()) throw AnalysisError(fmt::format("'{}' has no force-bearing contact", f.file));
  try {
    f.aniso = anisotropy3(bearing);
    f.branch = branch_anisotropy3(bearing);
  } catch (const AnalysisError& e) {
    f.aniso_problem = fmt::format("'{}': {}", f.file, e.what());
  }
  f.has_volume = volume > 0;
  const double V = f.has_volume ? volume : 1.0;
  f.stress = contact_stress3(raw, V);
  f.fabric = cd::obs::fabric_tensor<3>(forces, f_eps);
  std::size_t flag = 0, coulomb = 0;
  for (const auto& c : bearing) {
    flag += c.status == 2;
    coulomb += c.c.ft_norm() >= mu * c.c.fn * (1 - sliding_tol);
    ++f.by_kind[static_cast<std::size_t>(c.kind)];
    f.polyhedra = f.polyhedra || c.kind > 0;
  }
  const double nb = static_cast<double>(bearing.size());
  f.sliding = static_cast<double>(flag) / nb;
  if (mu > 0) f.sliding_coulomb = static_cast<double>(coulomb) / nb;
  if (f.polyhedra) {
    f.aniso_face_face = anisotropy3_of(rows_where(bearing, is_face_face));
    f.aniso_other = anisotropy3_of(rows_where(bearing, is_other_polyhedra));
    f.stress_face_face = contact_stress3(rows_where(raw, is_face_face), V);
    f.stress_other = contact_stress3(rows_where(raw, [](const Contact3& c) { return !is_face_face(c); }), V);
  }
  // The bodies for rattlers and z: the spheres and the polyhedra snapshots
  // with the same number (a polyhedra run writes both, its spheres empty).
  const auto spheres = companion_snapshot(f.file, "spheres"), polyhedra = companion_snapshot(f.file, "polyhedra");
  if (spheres || polyhedra) {
    ParticleSet bodies = spheres ? read_particles(*spheres) : ParticleSet{};
    if (polyhedra)
      for (const auto& p : read_polyhedra(*polyhedra)) bodies.push_back(p);
    f.connectivity = connectivity(raw, bodies, f_eps);
  }
  return f;
}

std::vector<std::optional<double>> snapshot_times(const std::string& run_dir, const std::string& prefix) {
  const fs::path pvd = fs::path(run_dir) / (prefix + ".pvd");
  std::ifstream in(pvd);
  if (!in) throw AnalysisError(fmt::format("run folder '{}' has no {}.pvd: the snapshots' times are unknown",
                                           run_dir, prefix));
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  // One <DataSet .../> per frame; its timestep and file attributes in either order.
  const std::regex dataset(R"(<DataSet\b[^>]*>)"), timestep(R"re(\btimestep="([^"]*)")re"),
      file(R"re(\bfile="([^"]*)")re");
  std::map<std::string, double> times;
  for (auto it = std::sregex_iterator(s.begin(), s.end(), dataset); it != std::sregex_iterator(); ++it) {
    const std::string tag = it->str();
    std::smatch t, f;
    if (!std::regex_search(tag, t, timestep) || !std::regex_search(tag, f, file)) continue;
    // strtod's end points into the string it read: one that outlives it.
    const std::string ts = t[1].str();
    char* end = nullptr;
    const double v = std::strtod(ts.c_str(), &end);
    if (end == ts.c_str() || *end || !std::isfinite(v))
      throw AnalysisError(fmt::format("'{}': timestep \"{}\" is not a number", pvd.string(), ts));
    times[fs::path(f[1].str()).filename().string()] = v;
  }
  if (times.empty()) throw AnalysisError(fmt::format("'{}' lists no frame", pvd.string()));
  std::vector<std::optional<double>> out;
  for (const auto& path : list_snapshots(run_dir, prefix)) {
    const auto it = times.find(fs::path(path).filename().string());
    out.push_back(it == times.end() ? std::nullopt : std::optional<double>(it->second));
  }
  return out;
}

double x_at_time(const Table& series, const std::string& x_column, double t) {
  if (x_column == "time") return t;
  const auto& time = series.column("time");
  const auto& x = series.column(x_column);
  const double nan = std::nan("");
  if (time.empty() || !std::is_sorted(time.begin(), time.end())) return nan;
  // series.csv prints 10 digits, the .pvd the shortest exact text: a
  // snapshot on the first or last row may fall just outside by rounding.
  const double tol = 1e-9 * std::max(std::abs(time.front()), std::abs(time.back()));
  if (t < time.front() - tol || t > time.back() + tol) return nan;
  t = std::clamp(t, time.front(), time.back());
  const auto it = std::lower_bound(time.begin(), time.end(), t);  // first row with time >= t
  const std::size_t r = static_cast<std::size_t>(it - time.begin());
  if (time[r] == t || r == 0) return x[r];
  const double u = (t - time[r - 1]) / (time[r] - time[r - 1]);
  return x[r - 1] + u * (x[r] - x[r - 1]);
}

WindowSnapshots snapshots_in_window(const std::string& run_dir, const Table& series,
                                    const std::string& x_column, const Window& w, const std::string& prefix) {
  WindowSnapshots ws;
  ws.total = list_snapshots(run_dir, prefix).size();
  std::vector<std::optional<double>> times;
  try {
    times = snapshot_times(run_dir, prefix);
  } catch (const AnalysisError& e) {
    ws.problem = e.what();
    return ws;
  }
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (!times[k]) continue;
    const double x = x_at_time(series, x_column, *times[k]);
    if (x >= w.x_begin && x <= w.x_end) {  // false for nan
      ws.index.push_back(static_cast<int>(k));
      ws.x.push_back(x);
      ws.time.push_back(*times[k]);
    }
  }
  return ws;
}

namespace {

// A profile's rates from their samples (per gap, and each sample's largest
// gap rate): each gap's mean +- sem, the slowest gap's, and max_rate.
void set_rates(ShearProfile& pr, const std::vector<std::vector<double>>& per, const std::vector<double>& maxima) {
  for (const auto& v : per) pr.rate.push_back(mean_sem(v));
  pr.rate_min = *std::min_element(pr.rate.begin(), pr.rate.end(), [](const Val& a, const Val& b) { return a.v < b.v; });
  pr.max_rate = mean_sem(maxima);
}

// The walls protocol's profile (shear_profile): from the displacements of
// the particles between consecutive snapshots of the window, the mean
// velocity over each interval, far less noisy than one instant's. With D
// the imposed strain of the interval (the mean of gd at its ends times its
// duration), u = dx / D is y for a homogeneous shear, 0 on the bottom wall
// and L at the top one.
ShearProfile walls_profile(const std::vector<std::string>& files, const WindowSnapshots& ws, const Table& series,
                           int layers) {
  if (!series.has("cell_width"))
    throw AnalysisError(fmt::format("'{}' has no cell_width column: not a walls shear run", series.source()));
  ShearProfile pr;
  pr.layers = layers;
  pr.walls = true;
  const auto n = static_cast<std::size_t>(layers);
  std::vector<std::vector<double>> per(n + 1);
  std::vector<double> maxima, bulk, phi, phi_centres;
  std::map<int, std::pair<double, double>> before;  // id -> (x, y) at the previous snapshot
  for (std::size_t j = 0; j < ws.index.size(); ++j) {
    const auto& file = files[static_cast<std::size_t>(ws.index[j])];
    const ParticleSet ps = read_particles(file);
    {
      const double L = x_at_time(series, "cell_height", ws.time[j]), W = x_at_time(series, "cell_width", ws.time[j]);
      if (!(L > 0) || !(W > 0))
        throw AnalysisError(fmt::format("'{}': cell_height {} and cell_width {} give no packing fraction", file, L, W));
      const double lo = 0.25 * L, hi = 0.75 * L;  // cdsim's bulk band (docs/shear.md)
      double clipped = 0, whole = 0;
      for (const Particle& p : ps) {
        clipped += area_in_band(p, lo, hi);
        if (p.y >= lo && p.y < hi) whole += cd::obs::particle_area(p.radius, std::max(p.nsides, 0));
      }
      phi.push_back(clipped / (W * (hi - lo)));
      phi_centres.push_back(whole / (W * (hi - lo)));
    }
    if (j > 0) {
      const double t0 = ws.time[j - 1], t1 = ws.time[j], tm = 0.5 * (t0 + t1);
      const double L = x_at_time(series, "cell_height", tm), W = x_at_time(series, "cell_width", tm);
      const double D = 0.5 * (x_at_time(series, "shear_rate", t0) + x_at_time(series, "shear_rate", t1)) * (t1 - t0);
      if (!(L > 0) || !(W > 0) || !(D > 0))
        throw AnalysisError(fmt::format("'{}': cell_height {}, cell_width {} and imposed strain {} since the last "
                                        "snapshot give no shear profile", file, L, W, D));
      if (D * L > 0.5 * W)
        throw AnalysisError(fmt::format("'{}': the top wall moved {:.3g} periods since the last snapshot (more than "
                                        "half): the displacements cannot be unwrapped; snapshots closer in strain "
                                        "are needed", file, D * L / W));
      std::vector<double> sum(n, 0.0);
      std::vector<std::size_t> count(n, 0);
      double sy = 0, su = 0, syy = 0, syu = 0, nb = 0;  // the central half's least squares
      for (const Particle& p : ps) {
        const auto it = before.find(p.id);
        if (it == before.end()) continue;
        double dx = p.x - it->second.first;
        dx -= W * std::round(dx / W);  // periodic along x
        const double y = 0.5 * (p.y + it->second.second), u = dx / D;
        const auto b = std::min(n - 1, static_cast<std::size_t>(std::max(0.0, y / L * static_cast<double>(n))));
        sum[b] += u;
        ++count[b];
        if (y >= 0.25 * L && y < 0.75 * L) sy += y, su += u, syy += y * y, syu += y * u, nb += 1;
      }
      std::vector<double> v(n);  // the layers' mean u
      for (std::size_t b = 0; b < n; ++b) {
        if (count[b] == 0) throw AnalysisError(fmt::format("'{}': layer {} of {} holds no particle", file, b, n));
        v[b] = sum[b] / static_cast<double>(count[b]);
      }
      const double h = L / static_cast<double>(n);  // a layer's thickness: u steps by h in a homogeneous shear
      double most = -std::numeric_limits<double>::infinity();
      const auto gap = [&](std::size_t i, double du, double width) {
        per[i].push_back(du / (width * h));
        most = std::max(most, per[i].back());
      };
      gap(0, v[0], 0.5);  // the bottom wall's grains, at rest, half a layer below layer 0's centre
      for (std::size_t i = 1; i < n; ++i) gap(i, v[i] - v[i - 1], 1.0);
      gap(n, L - v[n - 1], 0.5);  // to the top wall's grains
      maxima.push_back(most);
      const double var = syy - sy * sy / std::max(nb, 1.0);
      if (nb < 2 || !(var > 0))
        throw AnalysisError(fmt::format("'{}': {} particles in the central half of the gap, 2 at distinct heights "
                                        "needed", file, nb));
      bulk.push_back((syu - sy * su / nb) / var);
    }
    before.clear();
    for (const Particle& p : ps) before[p.id] = {p.x, p.y};
    pr.x.push_back(ws.x[j]);
  }
  pr.snapshots = ws.index.size();
  set_rates(pr, per, maxima);
  pr.bulk_rate = mean_sem(bulk);
  pr.bulk_phi = mean_sem(phi);
  pr.bulk_phi_centres = mean_sem(phi_centres);
  return pr;
}

}  // namespace

ShearProfile shear_profile(const std::string& run_dir, const Table& series, const std::string& x_column,
                           const Window& w, int layers) {
  if (layers < 2) throw AnalysisError(fmt::format("profile: {} layers, 2 or more needed", layers));
  for (const char* c : {"time", "cell_height", "shear_rate"})
    if (!series.has(c))
      throw AnalysisError(fmt::format("'{}' has no {} column: not a shear run", series.source(), c));
  const auto scene = read_scene_info(run_dir);
  const bool walls = scene.shear_mode && *scene.shear_mode == "walls";
  if (scene.shear_mode && !walls && *scene.shear_mode != "periodic")
    throw AnalysisError(fmt::format("'{}': [shear] mode is '{}': the shear profile needs a periodic (Lees-Edwards) "
                                    "cell or the walls protocol", scene.file, *scene.shear_mode));
  const std::string prefix = particles_prefix(scene.dimension);
  const auto ws = snapshots_in_window(run_dir, series, x_column, w, prefix);
  if (!ws.problem.empty()) throw AnalysisError(ws.problem);
  if (ws.index.size() < 2)
    throw AnalysisError(fmt::format("'{}': {} of its {} {} snapshots in the window {:.4g}–{:.4g}, 2 needed", run_dir,
                                    ws.index.size(), ws.total, prefix, w.x_begin, w.x_end));
  const auto files = list_snapshots(run_dir, prefix);
  if (walls) return walls_profile(files, ws, series, layers);
  ShearProfile pr;
  pr.layers = layers;
  const auto n = static_cast<std::size_t>(layers);
  std::vector<std::vector<double>> per(n);
  std::vector<double> maxima;
  for (std::size_t j = 0; j < ws.index.size(); ++j) {
    const auto k = static_cast<std::size_t>(ws.index[j]);
    const double t = ws.time[j];
    const double L = x_at_time(series, "cell_height", t), gd = x_at_time(series, "shear_rate", t);
    if (!(L > 0) || !std::isfinite(gd) || gd == 0)
      throw AnalysisError(fmt::format("'{}': cell_height {} and shear_rate {} at t = {:.6g} give no shear profile",
                                      files[k], L, gd, t));
    std::vector<double> sum(n, 0.0);
    std::vector<std::size_t> count(n, 0);
    for (const auto& p : read_particles(files[k])) {
      const double wrap = std::floor(p.y / L);
      const double y = p.y - wrap * L, vx = p.vx - wrap * gd * L;
      const auto b = std::min(n - 1, static_cast<std::size_t>(std::max(0.0, y / L * static_cast<double>(n))));
      sum[b] += vx;
      ++count[b];
    }
    std::vector<double> v(n);  // the layers' mean v_x
    for (std::size_t b = 0; b < n; ++b) {
      if (count[b] == 0) throw AnalysisError(fmt::format("'{}': layer {} of {} holds no particle", files[k], b, n));
      v[b] = sum[b] / static_cast<double>(count[b]);
    }
    double most = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const double vnext = i + 1 < n ? v[i + 1] : v[0] + gd * L;  // the last gap: across the boundary
      const double s = (vnext - v[i]) / (gd * L / static_cast<double>(n));
      per[i].push_back(s);
      most = std::max(most, s);
    }
    maxima.push_back(most);
    pr.x.push_back(ws.x[j]);
  }
  pr.snapshots = maxima.size();
  set_rates(pr, per, maxima);
  return pr;
}

std::string rate_min_note(double v, double err) {
  if (!std::isfinite(v)) return ", rate_min n/a (no particle snapshots to profile)";
  return fmt::format(", rate_min = {:.2f} +- {:.2f}{}", v, err, is_banded(v) ? " BANDED" : "");
}

Val window_rate_min(const std::string& run_dir, const Table& series, const std::string& x_column, const Window& w) {
  try {
    return shear_profile(run_dir, series, x_column, w, 5).rate_min;
  } catch (const AnalysisError&) {
    return {};
  }
}

const std::vector<std::string> kFabric3Columns = {
    "a_c", "a_n", "a_t", "sum_2_5", "sum_2_5_tensor", "q_over_p", "q_vm_over_p", "mu", "sliding", "z", "non_floating",
    // the branch anisotropies and (2/5)(a_c + a_n + a_t + a_ln + a_lt)
    "a_ln", "a_lt", "sum_2_5_branch",
    // polyhedra only (nan for spheres): RunFabric3's shares and face-face parts
    "face_face_share", "edge_face_share", "vertex_face_share", "edge_edge_share", "q_over_p_face_face",
    "a_c_face_face", "a_n_face_face", "a_t_face_face", "a_c_other", "a_n_other", "a_t_other",
    // the fabric of the branch directions (fabric3.hpp; = a_c for spheres)
    "a_c_branch"};

const Val& WindowFabric3::of(const std::string& column) const {
  const auto i = std::find(kFabric3Columns.begin(), kFabric3Columns.end(), column);
  if (i == kFabric3Columns.end()) throw AnalysisError(fmt::format("no 3D fabric column '{}'", column));
  return mean.at(static_cast<std::size_t>(i - kFabric3Columns.begin()));
}

WindowFabric3 window_fabric3(const std::string& run_dir, const Table& series, const std::string& x_column,
                             const Window* w) {
  WindowFabric3 r;
  const char* xs = x_column == "strain" ? "γ" : "t";
  std::vector<int> picks;
  if (!w) {
    r.alone = "no steady window";
  } else {
    const auto ws = snapshots_in_window(run_dir, series, x_column, *w);
    if (!ws.problem.empty()) r.alone = ws.problem;
    else if (ws.index.size() < 2)
      r.alone = fmt::format("{} of the {} contact snapshots in the steady window {} = {:.4g}–{:.4g}, 2 needed",
                            ws.index.size(), ws.total, xs, w->x_begin, w->x_end);
    else picks = ws.index;
  }
  r.averaged = !picks.empty();
  if (!r.averaged) picks = {-1};  // the last snapshot
  std::vector<std::vector<double>> per(kFabric3Columns.size());
  std::vector<double> diff, diff_branch;  // (2/5) sum a - q/p, per snapshot, without and with the branch terms
  std::string first_error;
  for (const int snap : picks) {
    RunFabric3 f;
    try {
      f = run_fabric3(run_dir, snap, -1);
    } catch (const AnalysisError& e) {
      if (!r.averaged) throw;
      r.problems.push_back(fmt::format("{}: {} (left out of the window's mean)", run_dir, e.what()));
      if (first_error.empty()) first_error = e.what();
      continue;
    }
    if (!f.aniso) r.problems.push_back(f.aniso_problem);
    const double nan = std::nan("");
    const Anisotropy3 a = f.aniso.value_or(Anisotropy3{});
    const bool ok = f.aniso.has_value();
    const std::vector<double> v = {ok ? a.a_c() : nan, ok ? a.a_n() : nan, ok ? a.a_t() : nan,
                                   ok ? a.sum_2_5() : nan, ok ? a.sum_2_5_tensor() : nan,
                                   f.stress.q_over_p(), f.stress.q_vm() / f.stress.p(),
                                   f.stress.mu(), f.sliding,
                                   f.connectivity ? f.connectivity->z : nan,
                                   f.connectivity ? f.connectivity->non_floating : nan,
                                   ok ? f.branch->a_ln() : nan, ok ? f.branch->a_lt() : nan,
                                   ok ? a.sum_2_5() + 0.4 * (f.branch->a_ln() + f.branch->a_lt()) : nan,
                                   f.kind_share(Kind3::FaceFace), f.kind_share(Kind3::EdgeFace),
                                   f.kind_share(Kind3::VertexFace), f.kind_share(Kind3::EdgeEdge),
                                   f.q_over_p_face_face(),
                                   f.aniso_face_face ? f.aniso_face_face->a_c() : nan,
                                   f.aniso_face_face ? f.aniso_face_face->a_n() : nan,
                                   f.aniso_face_face ? f.aniso_face_face->a_t() : nan,
                                   f.aniso_other ? f.aniso_other->a_c() : nan,
                                   f.aniso_other ? f.aniso_other->a_n() : nan,
                                   f.aniso_other ? f.aniso_other->a_t() : nan,
                                   ok ? f.branch->a_c_branch() : nan};
    for (std::size_t i = 0; i < v.size(); ++i) per[i].push_back(v[i]);
    diff.push_back(v[3] - v[5]);          // sum_2_5 - q_over_p
    diff_branch.push_back(v[13] - v[5]);  // sum_2_5_branch - q_over_p
    r.files.push_back(fs::path(f.file).filename().string());
    r.bearing += static_cast<double>(f.physical_contacts);
  }
  if (r.files.empty())
    throw AnalysisError(fmt::format("none of the {} contact snapshots in the steady window could be read (first: {})",
                                    picks.size(), first_error));
  r.bearing /= static_cast<double>(r.files.size());
  for (const auto& x : per) r.mean.push_back(mean_sem(x));
  const double qp = r.of("q_over_p").v;
  r.check_rel = (r.of("sum_2_5").v - qp) / qp;
  r.check_rel_err = mean_sem(diff).err / std::abs(qp);
  r.check_rel_branch = (r.of("sum_2_5_branch").v - qp) / qp;
  r.check_rel_branch_err = mean_sem(diff_branch).err / std::abs(qp);
  return r;
}

std::pair<double, double> parse_range(const std::string& s) {
  const auto colon = s.find(':');
  auto bad = [&] { return InputError(fmt::format("window '{}' is not of the form a:b with a < b", printable(s, 80))); };
  if (colon == std::string::npos) throw bad();
  const std::string a = s.substr(0, colon), b = s.substr(colon + 1);
  char *ea = nullptr, *eb = nullptr;
  const double va = std::strtod(a.c_str(), &ea), vb = std::strtod(b.c_str(), &eb);
  if (a.empty() || b.empty() || *ea || *eb || !(va < vb)) throw bad();
  return {va, vb};
}

std::pair<double, double> resolve_window(const std::string& spec, std::span<const double> x) {
  const auto colon = spec.find(':');
  const bool pa = colon != std::string::npos && colon > 0 && spec[colon - 1] == '%';
  const bool pb = !spec.empty() && spec.back() == '%';
  if (!pa && !pb) return parse_range(spec);
  auto bad = [&] {
    return InputError(fmt::format("window '{}' is not of the form a:b, or a%:b% with 0 <= a < b <= 100",
                                  printable(spec, 80)));
  };
  if (!pa || !pb) throw bad();
  std::pair<double, double> f;
  try {  // the numbers as parse_range reads them, the % signs removed
    f = parse_range(spec.substr(0, colon - 1) + spec.substr(colon, spec.size() - colon - 1));
  } catch (const InputError&) {
    throw bad();
  }
  if (!(f.first >= 0 && f.second <= 100)) throw bad();
  if (x.empty()) throw AnalysisError(fmt::format("window '{}': the series has no rows", spec));
  const double x0 = x.front(), span = x.back() - x.front();
  return {x0 + f.first / 100 * span, x0 + f.second / 100 * span};
}

std::optional<std::pair<double, double>> window_range(const std::string& spec, std::span<const double> x) {
  if (spec.empty()) return std::nullopt;
  return resolve_window(spec, x);
}

}  // namespace cda
