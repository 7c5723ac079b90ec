// What a shear run reports, against each column's definition
// (docs/outputs.md) recomputed here from the world's state at the row's
// step, with formulas of this file's own: the packing fraction (polygon
// areas from their circumradius, the walls' glued grains counted half, the
// walls protocol's bulk band), the imposed shear rate and the strain, the
// measured inertial number, the stress invariants and ratios, the wall's
// and the bulk's ratios, and the kinetic stress. In 2D between walls and in
// the bi-periodic cell, and in 3D's tri-periodic cell. The run is stopped
// after a few hundred steps (RunOptions::max_steps), which writes a series
// row at its last step; the world is then in that step's state.
//
// And summary.toml, every line but cdlab_version, against what it says it
// is: the series' rows (one a step here, so that each row is one step's
// record), the timings' rows, the scene's length, the clock and CPU time
// and load averages read by this process around the run call, and the
// per-step records of a twin world stepped here from the same start (the
// runs are deterministic: tests/test_reproducible.cpp), for what the series
// does not hold (CG iterations, stalled accelerations, floor steps). The
// walls run mixes (solver.anderson = 5) and the 3D run takes the subspace
// correction (solver.subspace = 10), so that those lines count something;
// the periodic run's sweep cap (solver.max_iter = 40) stops some of its steps.
#include <gtest/gtest.h>
#include <omp.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/src/table.hpp"
#include "checkpoint.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "run.hpp"
#include "run3.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"

namespace fs = std::filesystem;
using namespace cd;

namespace {

constexpr double kPi = std::numbers::pi;

// The last row of a series.csv, by column name (cdanalysis' reader).
std::map<std::string, double> last_row(const fs::path& series) {
  const cda::Table t = cda::Table::read_csv(series.string());
  std::map<std::string, double> row;
  for (const std::string& name : t.names()) row[name] = t.column(name).back();
  return row;
}

// A regular n-gon of circumradius R: n triangles of apex angle 2 pi/n.
double area(double R, int nsides) {
  return nsides == 0 ? kPi * R * R : 0.5 * nsides * R * R * std::sin(2 * kPi / nsides);
}

// Columns are written to 10 significant digits.
void expect_written(double column, double value, const char* what) {
  EXPECT_NEAR(column, value, 2e-9 * std::abs(value) + 1e-300) << what;
}

// The 2D stress columns: p and q of the symmetric part, q/p, and tau/sigma_n.
void expect_invariants_2d(const std::map<std::string, double>& r) {
  const double sxx = r.at("sxx"), syy = r.at("syy"), sxy = 0.5 * (r.at("sxy") + r.at("syx"));
  const double p = 0.5 * (sxx + syy), q = std::hypot(0.5 * (sxx - syy), sxy);
  expect_written(r.at("p"), p, "p");
  expect_written(r.at("q"), q, "q");
  expect_written(r.at("q_over_p"), q / p, "q_over_p");
  expect_written(r.at("shear_stress_ratio"), -sxy / syy, "shear_stress_ratio");
}

// I = gamma-dot d sqrt(rho / (sigma_yy + K_yy)), and the imposed rate.
void expect_inertial(const std::map<std::string, double>& r, const Scene& s, const char* syy, const char* kyy) {
  const double gd = s.inertial_number * std::sqrt(s.pressure / s.density) / s.d_mean;
  expect_written(r.at("shear_rate"), gd, "shear_rate");
  expect_written(r.at("inertial_number"), gd * s.d_mean * std::sqrt(s.density / (r.at(syy) + r.at(kyy))),
                 "inertial_number");
}

RunOptions stop_after(const fs::path& dir, std::int64_t steps) {
  RunOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  opt.fresh = true;
  opt.max_steps = steps;
  return opt;
}

// A series row every step (and none by strain): each row is one step's.
const std::vector<std::string> kRowEveryStep = {"output.series_strain=0", "output.series_interval=1e-12"};
std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

double process_cpu() {  // user + system seconds of this process, every thread
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

std::vector<double> loadavg() {  // the 1, 5 and 15 min load averages
  std::ifstream in("/proc/loadavg");
  std::vector<double> l(3, -1.0);
  in >> l[0] >> l[1] >> l[2];
  return l;
}

// What this process saw around a run call.
struct Around {
  double wall = 0, cpu = 0;  // elapsed and CPU seconds of the call
  std::vector<double> load_before, load_after;
};
Around around(const std::function<void()>& call) {
  Around a;
  a.load_before = loadavg();
  const double cpu0 = process_cpu();
  const auto t0 = std::chrono::steady_clock::now();
  call();
  a.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  a.cpu = process_cpu() - cpu0;
  a.load_after = loadavg();
  return a;
}

// The per-step records of a world stepped here, summed as summary.toml
// says it sums them.
struct Tally {
  std::int64_t steps = 0;
  double sweeps = 0, sweeps_max = 0, cap = 0, cg = 0, anderson_off = 0, subspace_off = 0, floor = 0;
  double residual_max = 0, residual_last = 0, overlap_max = 0;
};
template <class W>
Tally step_twin(W& w, std::int64_t steps) {
  Tally t;
  for (; t.steps < steps; ++t.steps) {
    w.step();
    const StepStats& st = w.last();
    t.sweeps += st.solve.iterations;
    t.sweeps_max = std::max(t.sweeps_max, double(st.solve.iterations));
    t.cap += st.solve.cap_hit;
    t.cg += st.solve.subspace_iterations;
    t.anderson_off += st.solve.anderson_off > 0;
    t.subspace_off += st.solve.subspace_off > 0;
    t.floor += st.floor_held;
    t.residual_max = std::max(t.residual_max, st.solve.residual_max);
    t.residual_last = st.solve.residual_max;
    t.overlap_max = std::max(t.overlap_max, st.max_overlap);
  }
  return t;
}

double number(const std::map<std::string, std::string>& f, const char* key) {
  EXPECT_TRUE(f.count(key)) << key;
  return f.count(key) ? std::stod(f.at(key)) : std::nan("");
}

std::vector<double> triple(const std::map<std::string, std::string>& f, const char* key) {
  std::string v = f.count(key) ? f.at(key) : "";
  EXPECT_TRUE(v.size() > 2 && v.front() == '[' && v.back() == ']') << key << " = " << v;
  for (char& c : v)
    if (c == '[' || c == ']' || c == ',') c = ' ';
  std::istringstream in(v);
  std::vector<double> l;
  for (double x; in >> x;) l.push_back(x);
  return l;
}

// summary.toml of a run stopped by max_steps after `steps` steps of a scene
// of total_steps (or ended at them), against the series and timings (a row
// a step), the twin's tally, and what this process saw around the call.
void expect_summary(const fs::path& dir, std::int64_t steps, std::int64_t total_steps, const Tally& twin,
                    const Around& a, int threads) {
  const auto f = cdtest::summary_fields(dir / "summary.toml");
  const cda::Table series = cda::Table::read_csv((dir / "series.csv").string());
  const cda::Table timings = cda::Table::read_csv((dir / "timings.csv").string());
  ASSERT_EQ(series.rows(), static_cast<std::size_t>(steps)) << "a row a step";
  ASSERT_EQ(twin.steps, steps);
  // Stopped by max_steps before the scene's end, or at it (the 3D run's
  // 200 steps are its whole strain).
  EXPECT_EQ(f.at("status"), steps < total_steps ? "\"max-steps\"" : "\"done\"");
  EXPECT_EQ(number(f, "steps"), static_cast<double>(steps));
  EXPECT_EQ(series.column("step").back(), static_cast<double>(steps));
  EXPECT_EQ(number(f, "total_steps"), static_cast<double>(total_steps));
  EXPECT_EQ(number(f, "sessions"), 1.0);
  EXPECT_EQ(number(f, "threads"), static_cast<double>(threads));

  // From the series: each row is one step's, written to 10 digits.
  const auto& it = series.column("iterations");
  double sweeps = 0, sweeps_max = 0, cap = 0, res = 0, ov = 0;
  for (std::size_t r = 0; r < series.rows(); ++r) {
    EXPECT_EQ(series.column("step")[r], static_cast<double>(r + 1));
    sweeps += it[r];
    sweeps_max = std::max(sweeps_max, series.column("iterations_max")[r]);
    cap += series.column("cap_hit")[r];
    res = std::max(res, series.column("residual")[r]);
    ov = std::max(ov, series.column("max_overlap")[r]);
  }
  const double n = static_cast<double>(steps);
  expect_written(number(f, "sweeps_mean"), sweeps / n, "sweeps_mean");
  EXPECT_EQ(number(f, "sweeps_max"), sweeps_max);
  EXPECT_EQ(number(f, "cap_steps"), cap);
  EXPECT_DOUBLE_EQ(number(f, "cap_share"), cap / n);
  expect_written(number(f, "residual_max"), res, "residual_max");
  expect_written(number(f, "residual_final"), series.column("residual").back(), "residual_final");
  expect_written(number(f, "overlap_max"), ov, "overlap_max");

  // From the twin's own records (exact: the same steps).
  EXPECT_EQ(number(f, "sweeps_mean"), twin.sweeps / n);
  EXPECT_EQ(number(f, "sweeps_max"), twin.sweeps_max);
  EXPECT_EQ(number(f, "cap_steps"), twin.cap);
  EXPECT_EQ(number(f, "residual_max"), twin.residual_max);
  EXPECT_EQ(number(f, "residual_final"), twin.residual_last);
  EXPECT_EQ(number(f, "overlap_max"), twin.overlap_max);
  EXPECT_EQ(number(f, "cg_iterations"), twin.cg);
  EXPECT_EQ(number(f, "cg_iterations_mean"), twin.cg / n);
  EXPECT_EQ(number(f, "anderson_off_steps"), twin.anderson_off);
  EXPECT_EQ(number(f, "subspace_off_steps"), twin.subspace_off);
  EXPECT_EQ(number(f, "floor_steps"), twin.floor);

  // Wall time: the run loop's, so at least the sum of its stages' times in
  // timings.csv (measured inside it, on the same steady clock; 10 digits)
  // and at most the call's elapsed time. CPU time: the process's over the
  // loop, so at most its CPU time over the call (getrusage is monotone).
  double stages = 0;
  for (const std::string& c : timings.names())
    if (c.starts_with("t_"))
      for (double x : timings.column(c)) stages += x;
  const double wall = number(f, "wall_time"), cpu = number(f, "cpu_time");
  EXPECT_GT(stages, 0.0);
  EXPECT_GE(wall, stages * (1 - 1e-9));
  EXPECT_LE(wall, a.wall);
  EXPECT_GT(cpu, 0.0);
  EXPECT_LE(cpu, a.cpu + 1e-6);
  // The loads are /proc/loadavg's, read by the run as it starts and ends;
  // the kernel updates them every 5 s, so a call shorter than that sees at
  // most one update: each is what this process read before or after.
  const auto ls = triple(f, "load_start"), le = triple(f, "load_end");
  ASSERT_EQ(ls.size(), 3u);
  ASSERT_EQ(le.size(), 3u);
  if (a.wall < 4.5) {
    for (const auto& l : {ls, le}) EXPECT_TRUE(l == a.load_before || l == a.load_after) << l[0] << " " << l[1];
  }
}

}  // namespace

// 120 hexagons between rough walls (configs/shear-walls.toml, its cell
// sized for them), 300 steps at I = 0.05: the top wall falling onto them
// and shearing. The glued grains (static bodies, centres on the walls'
// lines) count half in the cell's packing fraction; the bulk's is that of
// the grains whose centre lies in [H/4, 3H/4).
TEST(ReportedQuantities, WallsRowMatchesItsDefinitions) {
  const Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/shear-walls.toml",
                             with({"particles.n=120", "shear.width=0", "shear.height=0", "shear.inertial_number=0.05",
                                   "output.snapshot_interval=0", "time.duration=1", "solver.anderson=5"},
                                  kRowEveryStep));
  World w = build_world(s);
  const fs::path dir = cdtest::scratch_dir("test_reported_quantities", "walls");
  RunSummary sum;
  const Around a = around([&] { sum = run(w, s, stop_after(dir, 300)); });
  World twin = build_world(s);
  const Tally t = step_twin(twin, 300);
  EXPECT_EQ(s.strain, 0.0);  // the run's length is time.duration
  expect_summary(dir, 300, std::llround(s.duration / w.params().dt), t, a, omp_get_max_threads());
  const auto r = last_row(dir / "series.csv");
  ASSERT_EQ(r.at("step"), 300);
  const double W = w.cell.width, H = w.cell.height;
  expect_written(r.at("cell_width"), W, "cell_width");
  expect_written(r.at("cell_height"), H, "cell_height");
  double solid = 0, band = 0;
  int glued = 0, inside = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    if (w.bodies.shape[i] == Shape::Segment) continue;
    const double a = area(w.bodies.radius[i], w.bodies.nsides[i]);
    if (!w.bodies.is_dynamic(i)) {
      solid += 0.5 * a;
      ++glued;
      continue;
    }
    solid += a;
    const double y = w.bodies.pos[i].y();
    if (y >= 0.25 * H && y < 0.75 * H) band += a, ++inside;
  }
  EXPECT_GT(glued, 10);
  EXPECT_GT(inside, 20);
  expect_written(r.at("packing_fraction"), solid / (W * H), "packing_fraction");
  expect_written(r.at("bulk_packing_fraction"), band / (0.5 * W * H), "bulk_packing_fraction");
  expect_written(r.at("strain"), w.cell.strain, "strain");
  expect_invariants_2d(r);
  expect_inertial(r, s, "syy", "kyy");
  const Eigen::Matrix2d K = w.kinetic_stress();
  expect_written(r.at("kxx"), K(0, 0), "kxx");
  expect_written(r.at("kyy"), K(1, 1), "kyy");
  // The wall's and the bulk's ratios.
  expect_written(r.at("wall_mu"), r.at("wall_tau") / r.at("wall_sigma"), "wall_mu");
  const double bxx = r.at("bulk_sxx"), byy = r.at("bulk_syy"), bxy = r.at("bulk_sxy");
  expect_written(r.at("bulk_q_over_p"), std::hypot(0.5 * (bxx - byy), bxy) / (0.5 * (bxx + byy)), "bulk_q_over_p");
  expect_written(r.at("bulk_mu"), -bxy / byy, "bulk_mu");
  EXPECT_EQ(sum.steps, 300);
}

// 100 pentagons compacted in the bi-periodic cell, then 200 steps of shear
// at I = 0.05 from that sample (shear.start): packing fraction over the
// cell's area, the strain gamma-dot t, I and the invariants.
TEST(ReportedQuantities, PeriodicRowMatchesItsDefinitions) {
  const fs::path dir = cdtest::scratch_dir("test_reported_quantities", "periodic");
  const std::string cfg = std::string(CDLAB_SOURCE_DIR) + "/configs/";
  const std::string ckpt = (dir / "prep.bin").string();
  {
    const Scene p = load_scene(cfg + "shear-prep.toml", {"particles.n=100", "particles.nsides=[5]",
                                                         "shear.width=0.016", "shear.height=0.016"});
    World w = build_world(p);
    for (int k = 0; k < 300; ++k) w.step();
    save_checkpoint(ckpt, w, 1);
  }
  const Scene s = load_scene(cfg + "shear-inertial.toml",
                             with({"shear.start=\"" + ckpt + "\"", "shear.inertial_number=0.05",
                                   "particles.nsides=[5]", "output.snapshot_interval=0", "solver.max_iter=40"},
                                  kRowEveryStep));
  World w = build_world(s);
  const Around a = around([&] { run(w, s, stop_after(dir / "shear", 200)); });
  World twin = build_world(s);
  const Tally t = step_twin(twin, 200);
  EXPECT_GT(t.cap, 0.0);  // some steps need more than 40 sweeps
  const double gd = s.inertial_number * std::sqrt(s.pressure / s.density) / s.d_mean;
  // The run's length is shear.strain at the imposed rate.
  expect_summary(dir / "shear", 200, std::llround(s.strain / gd / w.params().dt), t, a, omp_get_max_threads());
  const auto r = last_row(dir / "shear" / "series.csv");
  ASSERT_EQ(r.at("step"), 200);
  double solid = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    ASSERT_EQ(w.bodies.nsides[i], 5);
    solid += area(w.bodies.radius[i], 5);
  }
  expect_written(r.at("packing_fraction"), solid / (w.cell.width * w.cell.height), "packing_fraction");
  expect_written(r.at("strain"), 200 * w.params().dt * gd, "strain");
  expect_invariants_2d(r);
  expect_inertial(r, s, "syy", "kyy");
}

// 3D: 100 spheres compacted in the tri-periodic cell, then 200 steps at
// I = 0.1: packing fraction sum (4/3) pi r^3 / (L_x L_y L_z), p = tr/3,
// von Mises q = sqrt(3/2 s:s) of the symmetric part, I with sigma_yy +
// K_yy, the strain gamma-dot t.
TEST(ReportedQuantities, TriPeriodicRowMatchesItsDefinitions) {
  const fs::path dir = cdtest::scratch_dir("test_reported_quantities", "tri");
  const std::string ckpt = (dir / "prep.bin").string();
  {
    World3 w = build_world3(cdtest::shear3_prep_scene(100));
    for (int k = 0; k < 300; ++k) w.step();
    save_checkpoint3(ckpt, w, 1);
  }
  Scene s = cdtest::shear3_shear_scene(ckpt, 0.1);
  s.subspace = 10;
  s.series_strain = 0;
  s.series_interval = 1e-12;  // a row a step
  World3 w = build_world3(s);
  const Around a = around([&] { run3(w, s, stop_after(dir / "shear", 200)); });
  World3 twin = build_world3(s);
  const Tally t = step_twin(twin, 200);
  EXPECT_GT(t.cg, 0.0);
  const double gd = s.inertial_number * std::sqrt(s.pressure / s.density) / s.d_mean;
  expect_summary(dir / "shear", 200, std::llround(s.strain / gd / w.params().dt), t, a, omp_get_max_threads());
  const auto r = last_row(dir / "shear" / "series.csv");
  ASSERT_EQ(r.at("step"), 200);
  double solid = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) solid += 4.0 / 3.0 * kPi * std::pow(w.bodies.radius[i], 3);
  const Vec3 L = w.cell().size;
  expect_written(r.at("packing_fraction"), solid / (L.x() * L.y() * L.z()), "packing_fraction");
  expect_written(r.at("strain"), 200 * w.params().dt * gd, "strain");
  Eigen::Matrix3d S;
  const char* names[3][3] = {{"sxx", "sxy", "sxz"}, {"syx", "syy", "syz"}, {"szx", "szy", "szz"}};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) S(a, b) = r.at(names[a][b]);
  const Eigen::Matrix3d sym = 0.5 * (S + S.transpose());
  const double p = sym.trace() / 3;
  const Eigen::Matrix3d dev = sym - p * Eigen::Matrix3d::Identity();
  const double q = std::sqrt(1.5 * (dev.array() * dev.array()).sum());
  // The columns are each rounded to 10 digits: q from them carries that.
  EXPECT_NEAR(r.at("p"), p, 1e-8 * p);
  EXPECT_NEAR(r.at("q"), q, 1e-8 * p);
  EXPECT_NEAR(r.at("q_over_p"), q / p, 1e-8);
  expect_inertial(r, s, "syy", "kyy");
  const Eigen::Matrix3d K = w.kinetic_stress();
  expect_written(r.at("kyy"), K(1, 1), "kyy");
}
