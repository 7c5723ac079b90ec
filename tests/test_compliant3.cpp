// Compliant contacts in 3D (WorldParams3::stiffness; coupling3.hpp's
// BodyCouplingT3): each contact's law acts on u + rho (r - r0), rho =
// 1 / (k dt^2), r0 the contact's impulse of the step before, which makes
// the contact an implicit (backward Euler) linear spring of stiffness k on
// its normal and tangential displacements, still unilateral and still
// bounded by the Coulomb cone. Checked against closed forms that do not
// come from the solver: a head-on impact (the backward Euler oscillator,
// its peak force v0 sqrt(k m), duration pi sqrt(m / k) and the numerical
// restitution exp(-pi omega dt / 2)); a tall column at rest (each contact
// carries the weight above it, with the overlap F / k of a linear spring);
// a sphere sliding down an incline (Coulomb's limit kept: acceleration
// g (sin a - mu cos a)); an adhesive bond at rest in tension (its gap F / k);
// and the same bits on 1 and 2 threads.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "world3.hpp"
#include "world3_hash.hpp"

using namespace cd;

namespace {
constexpr double kG = 9.81;
}  // namespace

// A sphere of mass m meets a fixed plane head-on at v0, no gravity, no
// friction. While in contact the scheme is, with p the step's impulse and
// v the sphere's velocity towards +z,
//     v' = v + p'/m,   p' = max(0, (rho p - v) / (rho + 1/m))
// (the law v' + rho (p' - p) >= 0 _|_ p' >= 0): backward Euler on
// m x'' = -k x, omega = sqrt(k/m). The test runs that recurrence beside
// the world (same midpoint positions, so the same steps in contact) and
// asks for the world's impulses to round-off; then the closed forms of the
// continuous spring to the accuracy backward Euler has at omega dt = 0.01:
// peak force v0 sqrt(k m) (the amplitude lost by the quarter period,
// exp(-pi omega dt / 4), is 0.8 %), contact time pi / omega (within a step
// and the phase error atan(omega dt) / (omega dt) - 1 = 3e-5), and the
// rebound speed e v0 with e = exp(-pi omega dt / 2) (the modulus
// (1 + omega^2 dt^2)^-1/2 of a step over the half period).
TEST(Compliant3, HeadOnImpactIsTheBackwardEulerSpring) {
  WorldParams3 p;
  p.dt = 1e-6;
  p.alert = 0.0;
  p.solver.tol = 1e-15;
  p.solver.max_iter = 100;
  const double r = 0.01, rho_s = 2600, v0 = 0.1;
  const double m = rho_s * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double omega = 0.01 / p.dt;  // omega dt = 0.01
  p.stiffness = m * omega * omega;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const int s = w.bodies.add_sphere(Vec3(0.003, -0.002, r), r, rho_s, Vec3(0, 0, -v0));
  ASSERT_NEAR(w.bodies.mass[s], m, 1e-15 * m);
  const double rho = 1.0 / (p.stiffness * p.dt * p.dt);

  double v = -v0, z = r, pr = 0.0, fmax = 0.0;
  int contact_steps = 0, k = 0;
  for (; k < 2000; ++k) {
    const double zm = z + 0.5 * p.dt * v;  // the midpoint configuration
    const bool row = zm - r <= 0.0;
    const double pn = row ? std::max(0.0, (rho * pr - v) / (rho + 1.0 / m)) : 0.0;
    v += pn / m;
    z = zm + 0.5 * p.dt * v;
    pr = pn;
    w.step();
    ASSERT_EQ(w.rows().size(), row ? 1u : 0u) << "step " << k;
    if (row) {
      ASSERT_NEAR(w.rows()[0].r[0], pn, 1e-12 * m * v0) << "step " << k;
    }
    ASSERT_NEAR(w.bodies.vel[s].v.z(), v, 1e-12 * v0) << "step " << k;
    if (pn > 0.0) ++contact_steps;
    fmax = std::max(fmax, pn / p.dt);
    if (!row && v > 0.0 && z > r) break;
  }
  const double vout = w.bodies.vel[s].v.z();
  const double F = v0 * std::sqrt(p.stiffness * m), T = std::numbers::pi / omega;
  const double e = std::exp(-std::numbers::pi * omega * p.dt / 2);
  std::printf("impact: peak force %.6g N (v0 sqrt(k m) %.6g), %d steps in contact (pi/omega %.1f), rebound %.6f v0 "
              "(exp(-pi omega dt/2) %.6f)\n", fmax, F, contact_steps, T / p.dt, vout / v0, e);
  EXPECT_NEAR(fmax, F, 0.01 * F);
  EXPECT_LT(fmax, F);  // backward Euler loses amplitude, never gains it
  EXPECT_NEAR(contact_steps, T / p.dt, 2.0);
  EXPECT_NEAR(vout / v0, e, 2e-3);
  EXPECT_LT(vout, v0);  // no energy from the spring
  EXPECT_EQ(w.bodies.vel[s].v.x(), 0.0);
}

// A column of n spheres resting on a plane under gravity: at rest each
// contact j (from the bottom) carries the weight of the n - j spheres above
// it, whatever the stiffness (statics), and its overlap is that force over
// k (a linear spring loaded from zero: the spring's displacement is the sum
// of the steps' v' dt, the midpoint positions move by (v + v') dt / 2, and
// the two sums differ by the end velocities' dt / 2, zero at rest); with
// equal spheres and with a top sphere 1000 times heavier.
TEST(Compliant3, TallColumnCarriesTheWeightsWithTheSpringsOverlaps) {
  const double r = 0.005, rho_s = 2600;
  // 30 equal spheres, then 10 with the top one 1000 times denser (a mass
  // ratio of 1000 on a column of light ones: a hard case of Gauss-Seidel).
  for (const double heavy : {1.0, 1000.0}) {
    SCOPED_TRACE(heavy);
    const int n = heavy > 1.0 ? 10 : 30;
    WorldParams3 p;
    p.dt = 1e-4;
    p.gravity = Vec3(0, 0, -kG);
    p.mu = p.mu_wall = 0.5;
    p.alert = 0.1 * 2 * r;
    p.solver.tol = 1e-10;
    p.solver.max_iter = 20000;
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
    for (int j = 0; j < n; ++j)
      w.bodies.add_sphere(Vec3(0.01, 0.02, r + 2 * r * j), r, j == n - 1 ? heavy * rho_s : rho_s);
    double weight = 0;  // the whole column's
    for (int j = 1; j <= n; ++j) weight += w.bodies.mass[j] * kG;
    // The whole column's weight compresses the bottom contact by 1e-5 r.
    p.stiffness = weight / (1e-5 * r);
    w.set_params(p);
    // omega dt = dt sqrt(k / m) = 1.7 (equal spheres): backward Euler
    // damps the column's modes by (1 + omega_i^2 dt^2)^-1/2 a step; the
    // slowest, omega_1 ~ omega pi / (2n), by 1e-3 in 3000 steps (with the
    // heavy top, its mode on the n springs in series: omega dt = 0.44,
    // by e^-87 in 1000).
    const int steps = heavy > 1.0 ? 1000 : 3000;
    double sweeps = 0;
    for (int k = 0; k < steps; ++k) {
      w.step();
      sweeps += w.last().solve.iterations;
    }
    ASSERT_EQ(w.rows().size(), static_cast<std::size_t>(n));
    double worst_f = 0, worst_gap = 0;
    for (const SphereRow& row : w.rows()) {
      const int below = std::min(row.b1, row.b2), above = std::max(row.b1, row.b2);
      ASSERT_EQ(above - below, 1) << "the column's rows join neighbours";
      double want = 0;  // the weight of the spheres above the contact (body 0 is the plane)
      for (int j = above; j <= n; ++j) want += w.bodies.mass[j] * kG;
      const double f = row.r[0] / p.dt;
      worst_f = std::max(worst_f, std::abs(f - want) / weight);
      const double gap =
          above == 1 ? w.bodies.pos[1].z() - r : (w.bodies.pos[above] - w.bodies.pos[below]).norm() - 2 * r;
      worst_gap = std::max(worst_gap, std::abs(-gap - want / p.stiffness) / (weight / p.stiffness));
      EXPECT_LT(std::abs(row.r[1]) + std::abs(row.r[2]), 1e-9 * row.r[0]);
    }
    std::printf("column of %d, top %gx denser: forces within %.2e of the weights above, overlaps within %.2e of "
                "F/k (of the bottom's), %d sweeps in the last step, %.0f a step\n",
                n, heavy, worst_f, worst_gap, w.last().solve.iterations, sweeps / steps);
    EXPECT_LT(worst_f, 1e-6);
    // The heavy top's fall opens contacts below it for a while, and a spring
    // closes again from where its contact closes (its gap term's step):
    // the overlaps are F/k plus what those closures left, 1 % of the
    // bottom's here. Equal spheres keep every contact closed.
    if (heavy == 1.0) {
      EXPECT_LT(worst_gap, 1e-3);
    }
    for (int j = 1; j <= n; ++j) EXPECT_LT(w.bodies.vel[j].v.norm(), 1e-6 * std::sqrt(kG * r)) << j;
  }
}

// A sphere on a plane tilted by a (gravity turned by a about y), mu small
// enough that it slides as it rolls (tan a > 7 mu / 2): Coulomb's force mu
// N acts against the slip, so the centre accelerates at g (sin a - mu cos
// a) along the slope and the spin at mu N l / I, exactly as with rigid
// contacts once the normal spring has settled (the cone bounds the
// compliant impulse as it bounds the rigid one). The lever arm l is the
// centre's distance to the contact point, which sits mid-overlap: l = r -
// delta / 2 with the spring's overlap delta = N / k (4.4e-7 r here, 400
// times the tolerance).
TEST(Compliant3, SlidingSphereKeepsCoulombsLimit) {
  const double a = 0.5, mu = 0.1, r = 0.01, rho_s = 2600;
  const double m = rho_s * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  WorldParams3 p;
  p.dt = 1e-4;
  p.gravity = kG * Vec3(std::sin(a), 0, -std::cos(a));
  p.mu = p.mu_wall = mu;
  p.alert = 0.01 * r;
  p.solver.tol = 1e-13;
  p.solver.max_iter = 1000;
  p.stiffness = m * kG / (1e-6 * r);
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const int s = w.bodies.add_sphere(Vec3(0, 0, r), r, rho_s);
  for (int k = 0; k < 500; ++k) w.step();  // the normal spring settles (omega dt = 3.1)
  const double v1 = w.bodies.vel[s].v.x(), w1 = w.bodies.vel[s].w.y();
  const int steps = 1000;
  for (int k = 0; k < steps; ++k) w.step();
  const double T = steps * p.dt;
  const double acc = (w.bodies.vel[s].v.x() - v1) / T, spin = (w.bodies.vel[s].w.y() - w1) / T;
  const double N = m * kG * std::cos(a), l = r - 0.5 * N / p.stiffness, I = 0.4 * m * r * r;
  const double acc0 = kG * (std::sin(a) - mu * std::cos(a)), spin0 = mu * N * l / I;
  std::printf("sliding: acceleration %.12g (g (sin a - mu cos a) %.12g), spin rate %.12g (%.12g)\n", acc, acc0, spin,
              spin0);
  ASSERT_GT(w.bodies.vel[s].v.x() - r * w.bodies.vel[s].w.y(), 0.0) << "still sliding";
  EXPECT_NEAR(acc, acc0, 1e-9 * acc0);
  EXPECT_NEAR(spin, spin0, 1e-9 * spin0);
}

// With k = 0 the option is off: not one bit of the default path moves
// (the hashes of test_world3_physics' OffLeavesTheDefaultPathBitIdentical
// and test_world3_hashes cover it). A compliant pile of 300 spheres, its
// colours swept on two threads (min_parallel 1), gives the same bits on 1
// and 2 threads.
TEST(Compliant3, SameBitsOnOneAndTwoThreads) {
  auto run = [](int threads) {
    omp_set_num_threads(threads);
    WorldParams3 p;
    p.dt = 2e-4;
    p.gravity = Vec3(0, 0, -kG);
    p.mu = p.mu_wall = 0.5;
    p.alert = 2e-4;
    p.solver.tol = 1e-6;
    p.solver.max_iter = 500;
    p.solver.min_parallel = 1;
    p.stiffness = 1e4;
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
    for (const Vec3& n : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)})
      w.bodies.add_plane(-0.02 * n, n);
    // 300 spheres of radii 2-2.6 mm on a jittered lattice of pitch 5.3 mm:
    // gaps of 0.1-1.3 mm, the closest within the alert distance at once.
    int k = 0;
    for (int iz = 0; k < 300; ++iz)
      for (int iy = 0; iy < 6 && k < 300; ++iy)
        for (int ix = 0; ix < 6 && k < 300; ++ix, ++k) {
          const double jit = 1e-4 * std::sin(1.7 * k);
          w.bodies.add_sphere(Vec3(-0.0133 + 0.0053 * ix + jit, -0.0133 + 0.0053 * iy - jit, 0.0027 + 0.0053 * iz),
                              0.002 + 0.0006 * (0.5 + 0.5 * std::sin(3.1 * k)), 2600);
        }
    std::size_t rows = 0;
    for (int s = 0; s < 600; ++s) {
      w.step();
      rows = std::max(rows, w.rows().size());
    }
    return std::pair{cdtest::world3_hash(w), rows};
  };
  const auto [h1, rows1] = run(1);
  const auto [h2, rows2] = run(2);
  omp_set_num_threads(1);
  std::printf("compliant pile: up to %zu rows, hash %016llx\n", rows1, static_cast<unsigned long long>(h1));
  EXPECT_GT(rows1, 400u);
  EXPECT_EQ(h1, h2);
}
// The tangential spring (WorldParams3::stiffness_ratio = k_t / k): a sphere
// resting on a plane, rotation locked (inv_I = 0, so W = I / m and the
// tangential and normal components do not couple), its normal spring
// settled at m g (omega dt = 1: the step damps it by 2^-1/2), is set
// sliding at v0 along x. While the contact sticks (the peak force v0
// sqrt(k_t m) is 2 % of mu m g here) the tangential scheme is the backward
// Euler oscillator of stiffness k_t, p' = (rho_t p - v) / (rho_t + 1/m),
// rho_t = 1 / (k_t dt^2), v' = v + p'/m, run beside the world: its
// impulses to round-off, then the continuous spring's peak force v0
// sqrt(k_t m) within 1 % and its half period pi sqrt(m / k_t) within 2
// steps, both set by k_t = 1e-4 k (omega_t dt = 0.01), not by k.
TEST(Compliant3, TangentialSpringHasItsOwnStiffness) {
  WorldParams3 p;
  p.dt = 1e-4;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.5;
  p.alert = 1e-4;
  p.solver.tol = 1e-15;
  p.solver.max_iter = 100;
  const double r = 0.01, rho_s = 2600, v0 = 1e-3;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const int s = w.bodies.add_sphere(Vec3(0.002, 0.003, r), r, rho_s);
  w.bodies.vel[s].inv_I = 0.0;
  const double m = w.bodies.mass[s];
  p.stiffness = m / (p.dt * p.dt);  // omega dt = 1
  p.stiffness_ratio = 1e-4;         // omega_t dt = 0.01
  w.set_params(p);
  for (int k = 0; k < 200; ++k) w.step();
  ASSERT_EQ(w.rows().size(), 1u);
  ASSERT_NEAR(w.rows()[0].r[0], m * kG * p.dt, 1e-12 * m * kG * p.dt);
  const double kt = p.stiffness * p.stiffness_ratio, rho_t = 1.0 / (kt * p.dt * p.dt);
  w.bodies.vel[s].v.x() = v0;
  double v = v0, pt = 0.0, fmax = 0.0;
  int first_zero = -1;
  for (int k = 0; k < 1000; ++k) {
    const double pn = (rho_t * pt - v) / (rho_t + 1.0 / m);
    v += pn / m;
    pt = pn;
    w.step();
    ASSERT_EQ(w.rows().size(), 1u) << k;
    const double world_pt = w.rows()[0].to_world(w.rows()[0].r).x();
    ASSERT_NEAR(world_pt, pt, 1e-9 * m * v0) << "step " << k;
    ASSERT_NEAR(w.bodies.vel[s].v.x(), v, 1e-12 * v0) << "step " << k;
    fmax = std::max(fmax, -pt / p.dt);
    if (first_zero < 0 && k > 0 && pt > 0.0) first_zero = k;  // the force changes sign: half a period
  }
  const double F = v0 * std::sqrt(kt * m), T = std::numbers::pi * std::sqrt(m / kt);
  std::printf("tangential spring (k_t = 1e-4 k): peak force %.6g N (v0 sqrt(k_t m) %.6g), sign change at step %d "
              "(pi sqrt(m/k_t) = %.1f steps)\n", fmax, F, first_zero, T / p.dt);
  EXPECT_NEAR(fmax, F, 0.01 * F);
  EXPECT_NEAR(first_zero, T / p.dt, 2.0);
}

// A sphere of weight mg hanging under a ceiling by adhesion (pull-off f_a,
// debonding distance 0.01 d): a compliant bond is a linear spring in
// tension too. From the touching start the sphere sinks and settles (the
// step damps omega dt = 1.4 by (1 + omega^2 dt^2)^-1/2) at the stretch of
// a spring loaded by its weight: the bond pulls with mg (statics), its gap
// is mg / k (the spring, not the rigid gap term that would pull the gap
// back to zero), and the bond never pulls harder than f_a. With f_a = 2 mg
// it holds; with f_a = mg / 2 it cannot: the pull stops at f_a, the sphere
// sinks past the debonding distance and falls freely.
TEST(Compliant3, AdhesiveBondIsASpringInTension) {
  const double r = 0.005, rho_s = 2600;
  for (const double fa_mg : {2.0, 0.5}) {
    SCOPED_TRACE(fa_mg);
    WorldParams3 p;
    p.dt = 1e-4;
    p.gravity = Vec3(0, 0, -kG);
    p.mu = p.mu_wall = 0.5;
    p.alert = 0.1 * 2 * r;
    p.debond = 0.01 * 2 * r;
    p.solver.tol = 1e-12;
    p.solver.max_iter = 1000;
    World3 w(p);
    w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, -1));  // a ceiling at z = 0
    const int s = w.bodies.add_sphere(Vec3(0.01, 0.02, -r), r, rho_s);
    const double mg = w.bodies.mass[s] * kG;
    p.adhesion = fa_mg * mg;
    p.stiffness = mg / (1e-5 * r);  // the weight stretches the bond by 1e-5 r
    w.set_params(p);
    double pull_max = 0;  // the bond's largest pull, in units of f_a
    int steps = 0;
    for (; steps < 400; ++steps) {
      w.step();
      if (!w.rows().empty()) pull_max = std::max(pull_max, -w.rows()[0].r[0] / (p.dt * p.adhesion));
    }
    const double gap = -r - w.bodies.pos[s].z();
    std::printf("f_a = %g mg: %zu rows, gap %.6e m (mg/k %.6e), largest pull %.12f f_a, v_z %.3e m/s\n", fa_mg,
                w.rows().size(), gap, mg / p.stiffness, pull_max, w.bodies.vel[s].v.z());
    EXPECT_LE(pull_max, 1 + 1e-12);
    if (fa_mg > 1) {
      ASSERT_EQ(w.rows().size(), 1u);
      EXPECT_NEAR(-w.rows()[0].r[0] / p.dt, mg, 1e-9 * mg);
      EXPECT_NEAR(gap, mg / p.stiffness, 1e-6 * mg / p.stiffness);
      EXPECT_LT(std::abs(w.bodies.vel[s].v.z()), 1e-9 * std::sqrt(kG * r));
    } else {
      EXPECT_NEAR(pull_max, 1.0, 1e-9);  // the bond pulled at its limit before it broke
      EXPECT_GT(gap, p.debond);
      // Falling freely: v_z = -g t since the bond broke; at least 0.03 s of the 0.04 s.
      EXPECT_LT(w.bodies.vel[s].v.z(), -kG * 0.03);
    }
  }
}
