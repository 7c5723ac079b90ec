// The 3D overlap projection (WorldParams3::overlap_projection,
// cd/src/3d/projection3.cpp): a split-impulse position correction that moves
// positions, never velocities.
//  - Two overlapping spheres at rest, masses 1 : 8: the projection opens
//    their overlap g by beta |g| along the normal, each sphere displaced in
//    inverse proportion to its mass (the frictionless two-body pseudo-solve
//    has the closed form u_n = -beta g / dt, shared as inv_m_i / (inv_m_1 +
//    inv_m_2)); velocities stay exactly zero.
//  - A dense tri-periodic lattice packing with overlaps up to ~6 % of a
//    diameter, at rest: pure CD never moves it (rows with u_n = 0 >= 0 carry
//    nothing); the projection removes the overlaps within a few steps to
//    below its trigger (1e-3 of the smaller diameter) without putting in
//    any kinetic energy (exactly 0), and does so bit-identically on 1 and 2
//    threads (thousands of rows: both threads work).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <omp.h>

#include "projection_trigger.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

WorldParams3 params(double beta) {
  WorldParams3 p;
  p.dt = 1e-4;
  p.mu = 0.4;
  p.solver.tol = 1e-12;
  p.solver.max_iter = 1000;
  p.overlap_projection = beta;
  return p;
}

// Largest overlap over the step's rows relative to the pair's smaller diameter.
double max_overlap_small(const World3& w) {
  double m = 0;
  const auto& rows = w.rows();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double g = w.infos()[k].gap;
    const double d = 2 * std::min(w.bodies.radius[rows[k].b1], w.bodies.radius[rows[k].b2]);
    m = std::max(m, -g / d);
  }
  return m;
}

}  // namespace

TEST(Projection3, TwoSpheresOpenByBetaInInverseMassRatio) {
  const double r1 = 0.5e-3, r2 = 1e-3, ov = 0.02 * 2 * r1, beta = 0.5;
  WorldParams3 p = params(beta);
  World3 w(p);
  const Vec3 n = Vec3(1, 2, 2) / 3.0;  // a unit normal off the axes
  const Vec3 x1(0.01, 0.02, 0.03);
  const Vec3 x2 = x1 + (r1 + r2 - ov) * n;
  w.bodies.add_sphere(x1, r1, 2600);
  w.bodies.add_sphere(x2, r2, 2600);
  w.step();
  const double inv1 = 1 / w.bodies.mass[0], inv2 = 1 / w.bodies.mass[1];
  const double open = beta * ov;  // the gap the projection adds
  const Vec3 d1 = w.bodies.pos[0] - x1, d2 = w.bodies.pos[1] - x2;
  EXPECT_NEAR(d1.dot(n), -open * inv1 / (inv1 + inv2), 1e-12 * open);
  EXPECT_NEAR(d2.dot(n), open * inv2 / (inv1 + inv2), 1e-12 * open);
  EXPECT_LT((d1 - d1.dot(n) * n).norm(), 1e-12 * open);
  EXPECT_LT((d2 - d2.dot(n) * n).norm(), 1e-12 * open);
  EXPECT_NEAR((w.bodies.pos[1] - w.bodies.pos[0]).norm(), r1 + r2 - (1 - beta) * ov, 1e-12 * ov);
  EXPECT_EQ(w.bodies.vel[0].v, Vec3::Zero());
  EXPECT_EQ(w.bodies.vel[1].v, Vec3::Zero());
  EXPECT_EQ(w.kinetic_energy(), 0.0);
  EXPECT_EQ(w.last().projection_work, 0.0);  // no contact force: no work
}

namespace {

// 512 spheres on a simple cubic lattice of pitch a = 1 mm (8 x 8 x 8 in a
// tri-periodic cell of 8 a), diameters a (1 + 0.06 U), U uniform in [0, 1),
// positions jittered by 0.01 a: each sphere overlaps its six neighbours by
// up to ~6 % of a diameter. Deterministic (seed 11).
World3 dense_cell(double beta) {
  const int m = 8;
  const double a = 1e-3;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  WorldParams3 p = params(beta);
  p.mu = 0.0;
  p.cell = Vec3(m * a, m * a, m * a);
  p.periodic = {true, true, true};
  p.alert = 0.05 * a;
  World3 w(p);
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const Vec3 jit(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
        w.bodies.add_sphere(a * (Vec3(i + 0.5, j + 0.5, k + 0.5) + 0.02 * jit), 0.5 * a * (1 + 0.06 * U(rng)), 2600);
      }
  return w;
}

}  // namespace

TEST(Projection3, DenseCellLosesItsOverlapsWithoutEnergy) {
  World3 still = dense_cell(0.0);
  still.step();
  const double ov0 = max_overlap_small(still);
  ASSERT_GT(ov0, 0.02);                  // the packing does overlap
  ASSERT_GT(still.rows().size(), 1000u);  // and is dense
  const auto x0 = still.bodies.pos;
  for (int k = 0; k < 5; ++k) still.step();
  EXPECT_EQ(still.bodies.pos, x0);  // pure CD leaves it where it is
  EXPECT_DOUBLE_EQ(max_overlap_small(still), ov0);

  auto run = [](int threads) {
    omp_set_num_threads(threads);
    World3 w = dense_cell(0.5);
    for (int k = 0; k < 30; ++k) {
      w.step();
      EXPECT_EQ(w.kinetic_energy(), 0.0) << "step " << k;
    }
    return w;
  };
  const World3 a = run(1), b = run(2);
  omp_set_num_threads(1);
  // Below the trigger: 1e-3 of the smaller diameter (projection3.cpp).
  EXPECT_LT(max_overlap_small(a), 1e-3);
  EXPECT_EQ(a.bodies.pos, b.bodies.pos);
}

// The projection's pseudo-velocity solve is plain NLGS whatever the scene's
// accelerations (projection_trigger.hpp): neither Anderson's mixing nor the
// subspace correction (which would act on its frictionless law), at most
// kSweeps sweeps, no law-residual stop; the tolerance is the scene's.
TEST(Projection3, ItsSolveIsPlainNlgs) {
  cd::SolverParams sp;
  sp.tol = 3e-4;
  sp.max_iter = 2000;
  sp.residual_tol = 3e-3;
  sp.anderson = 5;
  sp.subspace = 10;
  const cd::SolverParams q = cd::projection::solver_params(sp);
  EXPECT_EQ(q.anderson, 0);
  EXPECT_EQ(q.subspace, 0);
  EXPECT_EQ(q.residual_tol, 0.0);
  EXPECT_EQ(q.max_iter, cd::projection::kSweeps);
  EXPECT_EQ(q.tol, 3e-4);
}
