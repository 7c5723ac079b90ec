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
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>

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

}  // namespace

// 120 hexagons between rough walls (configs/shear-walls.toml, its cell
// sized for them), 300 steps at I = 0.05: the top wall falling onto them
// and shearing. The glued grains (static bodies, centres on the walls'
// lines) count half in the cell's packing fraction; the bulk's is that of
// the grains whose centre lies in [H/4, 3H/4).
TEST(ReportedQuantities, WallsRowMatchesItsDefinitions) {
  const Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/shear-walls.toml",
                             {"particles.n=120", "shear.width=0", "shear.height=0", "shear.inertial_number=0.05",
                              "output.snapshot_interval=0", "time.duration=1"});
  World w = build_world(s);
  const fs::path dir = cdtest::scratch_dir("test_reported_quantities", "walls");
  const RunSummary sum = run(w, s, stop_after(dir, 300));
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
                             {"shear.start=\"" + ckpt + "\"", "shear.inertial_number=0.05", "particles.nsides=[5]",
                              "output.snapshot_interval=0"});
  World w = build_world(s);
  run(w, s, stop_after(dir / "shear", 200));
  const auto r = last_row(dir / "shear" / "series.csv");
  ASSERT_EQ(r.at("step"), 200);
  double solid = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    ASSERT_EQ(w.bodies.nsides[i], 5);
    solid += area(w.bodies.radius[i], 5);
  }
  expect_written(r.at("packing_fraction"), solid / (w.cell.width * w.cell.height), "packing_fraction");
  const double gd = s.inertial_number * std::sqrt(s.pressure / s.density) / s.d_mean;
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
  const Scene s = cdtest::shear3_shear_scene(ckpt, 0.1);
  World3 w = build_world3(s);
  run3(w, s, stop_after(dir / "shear", 200));
  const auto r = last_row(dir / "shear" / "series.csv");
  ASSERT_EQ(r.at("step"), 200);
  double solid = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) solid += 4.0 / 3.0 * kPi * std::pow(w.bodies.radius[i], 3);
  const Vec3 L = w.cell().size;
  expect_written(r.at("packing_fraction"), solid / (L.x() * L.y() * L.z()), "packing_fraction");
  const double gd = s.inertial_number * std::sqrt(s.pressure / s.density) / s.d_mean;
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
