// The warm start (method.md section 5: each step starts from the previous
// step's impulses). Without it results stay within the solver's tolerance
// and only the cost grows, so the physics tests cannot see it: here the
// sweep count does. A column of grains at rest on a floor poses the same
// contact problem every step; started from the last step's impulses the
// solve is done at once (the first sweep changes nothing and stops it;
// measured 1 sweep, asserted <= 2), while from zero a Gauss-Seidel sweep only passes the
// weight one contact down the chain, so it needs at least as many sweeps as
// the column has grains.
#include <gtest/gtest.h>

#include <cstdio>

#include "world.hpp"
#include "world3.hpp"
#include "world_util.hpp"

namespace {

constexpr int kGrains = 20;

}  // namespace

TEST(WarmStart, ColumnOfDisksAtRestSolvesInTwoSweeps) {
  auto p = cdtest::params(1e-3, 9.81, 0.5);
  p.solver.tol = 1e-8;
  cd::World w(p);
  w.bodies.add_wall({-5, 0}, {5, 0});
  for (int k = 0; k < kGrains; ++k) w.bodies.add_disk({0, 0.5 + k}, 0.5, 1.0);
  for (int s = 0; s < 200; ++s) w.step();
  const int first = w.last().solve.iterations;
  w.step();
  std::printf("2D column of %d: %d sweeps a step at rest\n", kGrains, w.last().solve.iterations);
  EXPECT_LE(w.last().solve.iterations, 2);
  EXPECT_LE(first, 2);
}

TEST(WarmStart, ColumnOfSpheresAtRestSolvesInTwoSweeps) {
  cd::WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = cd::Vec3(0, 0, -9.81);
  p.mu = p.mu_wall = 0.5;
  p.alert = 1e-3;
  p.solver.tol = 1e-8;
  cd::World3 w(p);
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(0, 0, 1));
  const double r = 0.01;
  for (int k = 0; k < kGrains; ++k) w.bodies.add_sphere(cd::Vec3(0, 0, r + 2 * r * k), r, 2600);
  for (int s = 0; s < 200; ++s) w.step();
  w.step();
  std::printf("3D column of %d: %d sweeps a step at rest\n", kGrains, w.last().solve.iterations);
  EXPECT_LE(w.last().solve.iterations, 2);
}
