// Size laws and the overlap users read: explicit diameters (a
// list or a file), a periodic cell sized from the actual size law (so a
// campaign at size ratio 4 needs no hand-made cell), and the largest overlap
// relative to the smaller grain of the pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "config.hpp"
#include "setup.hpp"
#include "world.hpp"

namespace {

cd::Scene scene(const std::string& text) { return cd::parse_scene(text, "s.toml"); }

}  // namespace

// The given diameters are the particles' (as a multiset), in an order
// shuffled by the seed, and set the mean diameter d_ref.
TEST(SizeLaws, ExplicitDiametersAreThoseOfTheParticles) {
  const cd::Scene s = scene(
      "[gravity]\ng = [0.0, 0.0]\n[particles]\ndiameters = [1e-3, 1e-3, 2e-3, 4e-3, 4e-3, 3e-3]\n"
      "region = [0.0, 0.0, 0.02, 0.02]\n");
  EXPECT_EQ(s.n, 6);  // n = 0 became the count
  const cd::World w = cd::build_world(s);
  std::vector<double> d;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) d.push_back(2 * w.bodies.radius[i]);
  std::vector<double> want = s.diameters, got = d;
  std::sort(want.begin(), want.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
  EXPECT_NE(d, s.diameters);  // shuffled (seed 1): not the sorted-ish input order
  EXPECT_DOUBLE_EQ(w.params().d_ref, 15e-3 / 6);
  // n must agree with the list.
  EXPECT_THROW(scene("[particles]\nn = 5\ndiameters = [1e-3, 2e-3]\n"), cd::ConfigError);
  EXPECT_THROW(scene("[particles]\ndiameters = [1e-3, -2e-3]\n"), cd::ConfigError);
}

// shear.width = shear.height = 0: the cell holds the particles on the
// generator's loose lattice whatever the size law. At size ratio 4 (uniform
// by area, the seeds' choice) a cell sized for ratio 2 is too small; the
// computed one fits, and is the smallest square that does (one lattice
// pitch less would not).
TEST(SizeLaws, PeriodicCellIsSizedFromTheActualSizeLaw) {
  for (const double ratio : {1.0, 2.0, 4.0, 5.0}) {
    const std::string text =
        "[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 200\nd_mean = 1e-3\nsize_dist = \"uniform_area\"\n"
        "size_ratio = " + std::to_string(ratio) + "\n[shear]\nmode = \"periodic\"\nwidth = 0.0\nheight = 0.0\n"
        "pressure = 100.0\nisotropic = true\n";
    const cd::Scene s = scene(text);
    const cd::Scene c = cd::with_auto_cell(s);
    const std::vector<double> d = cd::generated_diameters(s);
    const double pitch = 1.02 * *std::max_element(d.begin(), d.end());
    const int k = static_cast<int>(std::floor(c.cell_width / pitch));
    EXPECT_GE(k * k, 200) << ratio;
    EXPECT_LT((k - 1) * (k - 1), 200) << ratio;
    EXPECT_EQ(c.cell_width, c.cell_height);
    cd::World w = cd::build_world(s);  // places all 200 without overlap (checked there)
    EXPECT_EQ(w.cell.width, c.cell_width);
  }
}

// Two disks of diameters 1 and 4 (mm) pressed together by a wall: the
// largest overlap is reported relative to the mean diameter d_ref and to the
// smaller grain (1 mm), which is what a user compares with.
TEST(Overlap, IsReportedRelativeToTheSmallerGrain) {
  const double r1 = 0.5e-3, r2 = 2e-3, ov = 1e-5;
  const std::string text =
      "[gravity]\ng = [0.0, 0.0]\n[contact]\nalert = 0.0\n[[disk]]\npos = [0.0, 0.0]\nradius = " +
      std::to_string(r1) + "\n[[disk]]\npos = [" + std::to_string(r1 + r2 - ov) + ", 0.0]\nradius = " +
      std::to_string(r2) + "\n";
  // The initial-overlap check refuses the scene (as it should); build the
  // world from the scene without it and take one step.
  EXPECT_THROW(cd::build_world(scene(text)), std::exception);
  cd::World w(cd::world_params(scene(text)));
  w.bodies.add_disk({0.0, 0.0}, r1, 2.6);
  w.bodies.add_disk({r1 + r2 - ov, 0.0}, r2, 2.6);
  w.step();
  const double d_ref = w.params().d_ref;  // the scene's mean: (1 + 4)/2 mm
  EXPECT_NEAR(w.last().max_overlap, ov / d_ref, 1e-9 * ov / d_ref);
  EXPECT_NEAR(w.last().max_overlap_small, ov / (2 * r1), 1e-9 * ov / (2 * r1));
}
