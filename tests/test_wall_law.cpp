// Wall friction and body order: contact.mu_wall applies to every contact
// with a driven body (a segment wall or a grain glued to a rough wall),
// whichever body the pair lists first. A driven body is body 1 of its
// contacts; were a glued grain body 2, mu_wall would be ignored in walls
// mode.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "config.hpp"
#include "setup.hpp"
#include "world_util.hpp"

namespace {

// A free disk resting on a driven (glued) disk that moves sideways at V:
// while it slides, the friction on the free disk is mu_wall m g, so after k
// steps of dt its velocity is vx = k mu_wall g dt. The free disk rides over
// the moving one, so the normal force is m (g - V^2/(R1 + R2)) (2.5e-4 of mg
// for V = 0.05 m/s), and the frame turns by k dt V/(R1 + R2) = 2.5e-5 rad:
// tolerance 1e-3. (The slip, V - vx - omega R, falls by 3 mu_wall g dt a
// step, 3e-4 m/s: the contact slides throughout.)
struct SlideResult {
  double vx, omega;
};

SlideResult slide_on_driven(bool driven_first, double mu, double mu_wall, int steps) {
  cd::WorldParams p = cdtest::params(1e-4, 9.81, mu);
  p.mu_wall = mu_wall;
  p.alert = 0.01;
  cd::World w(p);
  const double R = 0.5, V = 0.05;
  auto add_driven = [&] {
    const int b = w.bodies.add_disk({0.0, 0.0}, R, 1.0);
    w.bodies.driven[b] = 1;
    w.bodies.vel[b] = {V, 0.0, 0.0, 0.0, 0.0};
  };
  if (driven_first) add_driven();
  w.bodies.add_disk({0.0, 2 * R}, R, 1.0);
  if (!driven_first) add_driven();
  const int free_body = driven_first ? 1 : 0;
  for (int k = 0; k < steps; ++k) w.step();
  EXPECT_EQ(w.rows().size(), 1u);
  return {w.bodies.vel[free_body].vx, w.bodies.vel[free_body].w};
}

TEST(WallLaw, MuWallActsOnContactsWithADrivenBodyWhicheverComesFirst) {
  const int k = 5;
  const double dt = 1e-4, g = 9.81, mu = 0.4, mu_wall = 0.1;
  const SlideResult a = slide_on_driven(true, mu, mu_wall, k);
  const SlideResult b = slide_on_driven(false, mu, mu_wall, k);
  const double expect = k * mu_wall * g * dt;
  std::printf("[ wall law ] vx after %d steps: %.6e (driven first), %.6e (driven second), "
              "mu_wall g t = %.6e, mu g t = %.6e\n", k, a.vx, b.vx, expect, k * mu * g * dt);
  EXPECT_NEAR(a.vx, expect, 1e-3 * expect);
  EXPECT_NEAR(b.vx, expect, 1e-3 * expect);
  // The order of the pair is a label: the same physics, to round-off.
  EXPECT_NEAR(a.vx, b.vx, 1e-12 * expect);
  EXPECT_NEAR(a.omega, b.omega, 1e-12 * std::abs(a.omega) + 1e-300);
}

// Wall-driven shear of hexagons between rough walls (configs/shear-walls.toml,
// smaller) with mu_wall = 0.1 < mu = 0.4: every contact with a glued grain
// obeys |p_t| <= mu_wall p_n, some slide at that bound (the walls drag the
// sample), and grain-grain contacts use mu (some exceed mu_wall). The top
// wall starts just above the grains (height 0.0135): it falls by at most a
// quarter of the alert distance a step, and loads the sample in 300 steps.
TEST(WallLaw, RoughWallShearUsesTheScenesWallFriction) {
  const cd::Scene s =
      cd::load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/shear-walls.toml",
                     {"particles.n=80", "shear.width=0.012", "shear.height=0.0135", "contact.mu_wall=0.1",
                      "solver.tol=1e-6", "solver.max_iter=20000"});
  cd::World w = cd::build_world(s);
  for (int k = 0; k < 300; ++k) w.step();
  int wall_rows = 0, wall_sliding = 0, grain_above = 0;
  double wall_ratio_max = 0, grain_ratio_max = 0;
  for (const cd::ContactRow& r : w.rows()) {
    if (r.pn <= 1e-12 * w.last().solve.p_mean) continue;
    const double ratio = std::abs(r.pt) / r.pn;
    const bool wall = !w.bodies.is_dynamic(r.b1) || !w.bodies.is_dynamic(r.b2);
    if (wall) {
      ++wall_rows;
      wall_ratio_max = std::max(wall_ratio_max, ratio);
      wall_sliding += ratio > 0.1 * (1 - 1e-6);
    } else {
      grain_ratio_max = std::max(grain_ratio_max, ratio);
      grain_above += ratio > 0.1 * (1 + 1e-6);
    }
  }
  std::printf("[ wall law ] %d loaded wall contacts (%d at |p_t| = mu_wall p_n), max |p_t|/p_n: "
              "walls %.6f, grains %.4f (%d grain contacts above mu_wall)\n",
              wall_rows, wall_sliding, wall_ratio_max, grain_ratio_max, grain_above);
  ASSERT_GE(wall_rows, 5);
  EXPECT_LE(wall_ratio_max, 0.1 * (1 + 1e-9));
  EXPECT_GT(wall_sliding, 0);
  EXPECT_GT(grain_ratio_max, 0.1 * (1 + 1e-3));
  EXPECT_GT(grain_above, 0);
}

}  // namespace
