// The walls protocol (shear.mode = "walls"): grains between two rough walls
// of glued grains, no gravity, the top wall at imposed normal stress p and
// moving at V = gamma-dot x gap. Checked against momentum balance, which
// holds whatever the grains do:
// - the top wall is a body whose vertical motion the imposed load p W and
//   the contacts drive; over a window in which it does not accelerate on
//   average, the mean force the sample exerts on it is p W (wall_sigma = p);
// - in steady simple shear the stress is uniform across the gap (d sigma_xy
//   / dy = rho a_x averages to 0), so the bulk's (the central half of the
//   gap, away from the walls' layering) sigma_yy and sigma_xy are the wall's
//   traction, within their error bars.
// And the cell given as 0 x 0 is sized so that the compacted sample is about
// as wide as tall.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "cli_util.hpp"
#include "config.hpp"
#include "analysis/src/run.hpp"
#include "setup.hpp"

namespace {

// 200 disks of size ratio 4 (uniform by area, the angularity study's law)
// at p = 100 N/m and I = 0.05, in a cell sized for them: the top wall falls
// onto the loose lattice by strain ~6.5 (a quarter of the alert distance a
// step), then the sample shears; the steady window is strain 7 to 10.
const std::string kSets =
    " --set particles.n=200 --set particles.nsides=[0] --set particles.size_ratio=4"
    " --set 'particles.size_dist=\"uniform_area\"' --set shear.width=0 --set shear.height=0"
    " --set shear.inertial_number=0.05 --set shear.strain=10 --set time.duration=0"
    " --set output.series_strain=0.02 --set output.snapshot_interval=0";

cda::SteadyStats steady(const std::string& run, const cda::Table& series, const std::string& column) {
  return cda::run_steady(run, series, column, "strain", std::make_pair(7.0, 10.0)).stats;
}

}  // namespace

TEST(WallsProtocol, WallTractionIsTheImposedStressAndTheBulkStress) {
  const auto dir = cdtest::scratch_dir("walls_protocol", "balance");
  const cdtest::CmdResult r =
      cdtest::run_command(std::string(CDLAB_BINARY_DIR) + "/cd/cdsim " + CDLAB_SOURCE_DIR +
                          "/configs/shear-walls.toml -q --fresh --out " + dir.string() + kSets);
  ASSERT_EQ(r.code, 0) << r.out;
  const cda::Table series = cda::read_series(dir.string());
  const cda::SteadyStats sigma = steady(dir, series, "wall_sigma"), tau = steady(dir, series, "wall_tau");
  const cda::SteadyStats byy = steady(dir, series, "bulk_syy"), bxy = steady(dir, series, "bulk_sxy");
  const cda::SteadyStats mu = steady(dir, series, "wall_mu"), bmu = steady(dir, series, "bulk_mu");
  const cda::SteadyStats h = steady(dir, series, "cell_height");
  std::printf("wall: sigma %.2f +- %.2f, tau %.2f +- %.2f, mu %.4f +- %.4f; bulk: syy %.2f +- %.2f, "
              "-sxy %.2f +- %.2f, mu %.4f +- %.4f; gap %.4g m, width %.4g m\n",
              sigma.mean, sigma.error(), tau.mean, tau.error(), mu.mean, mu.error(), byy.mean, byy.error(),
              -bxy.mean, bxy.error(), bmu.mean, bmu.error(), h.mean, series.column("cell_width").back());
  // The wall's equation of motion: mean force = p W + M dv/T, the second
  // term at most M gamma-dot gap / (W T) ~ 1e-4 p here; 2 % is the rows'
  // sampling (a row's mean is over its own steps, the window's rows equal).
  EXPECT_NEAR(sigma.mean, 100.0, 2.0);
  // Uniform stress across the gap: the bulk's is the wall's, 4 combined
  // standard errors.
  EXPECT_NEAR(byy.mean, sigma.mean, 4 * std::hypot(byy.error(), sigma.error()));
  EXPECT_NEAR(-bxy.mean, tau.mean, 4 * std::hypot(bxy.error(), tau.error()));
  EXPECT_NEAR(bmu.mean, mu.mean, 4 * std::hypot(bmu.error(), mu.error()));
  // A frictional dense flow (mu_p = 0.4 disks near I = 0.05: mu ~ 0.3).
  EXPECT_GT(mu.mean, 0.2);
  EXPECT_LT(mu.mean, 0.45);
  // Dense: the bulk's packing fraction within the sheared disks' range.
  const cda::SteadyStats phi = steady(dir, series, "bulk_packing_fraction");
  EXPECT_GT(phi.mean, 0.75);
  EXPECT_LT(phi.mean, 0.85);
  // About as wide as tall once compacted (the cell sized at phi = 0.8; the
  // walls' first layers are looser): within 20 %.
  EXPECT_NEAR(h.mean / series.column("cell_width").back(), 1.0, 0.2);
}

// The cell sized for the grains: its width that of a square of their area
// at phi = 0.8, its height the loose lattice's rows between the walls'
// grains (placed without overlap: the build checks it).
TEST(WallsProtocol, AutomaticCellHoldsTheGrainsAndIsSquareOnceDense) {
  const cd::Scene s = cd::load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/shear-walls.toml",
                                     {"particles.n=500", "particles.size_ratio=4", "particles.size_dist=uniform_area",
                                      "shear.width=0", "shear.height=0"});
  const cd::World w = cd::build_world(s);
  double area = 0.0;
  int grains = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) {
      ++grains;
      // a regular hexagon of circumradius r: (3 sqrt 3 / 2) r^2
      area += 1.5 * std::sqrt(3.0) * w.bodies.radius[i] * w.bodies.radius[i];
    }
  EXPECT_EQ(grains, 500);
  EXPECT_NEAR(w.cell.width, std::sqrt(area / 0.8), 1e-9 * w.cell.width);
  // Loose: the lattice is far taller than the dense sample.
  EXPECT_GT(w.cell.height, 2 * w.cell.width);
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) {
      EXPECT_GT(w.bodies.pos[i].y(), 0.0);
      EXPECT_LT(w.bodies.pos[i].y(), w.cell.height);
    }
}
