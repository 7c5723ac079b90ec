// Hard cases for the 3D step, each against a closed form:
// a tetrahedral pyramid at rest (every contact force from statics) at mass
// ratio 1 (time steps 1 and 50 ms) and 10^4, a dense periodic stack, a tall column of
// alternating densities, and cohesion just above and just below the weight.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "world3.hpp"

using namespace cd;

namespace {

constexpr double kG = 9.81;

struct PyramidResult {
  double floor_n_err = 0, floor_t_err = 0, top_err = 0;
  int base_base = 0;  // relative to the expected
  double vmax = 0, overlap = 0, floor_sum_err = 0;
  int sweeps = 0;
};

// Three equal spheres (mass m) touching on a floor, a fourth (mass M) on
// them, the base spheres 2e-4 apart; rotation locked (inv_I = 0: block-like
// spheres), sphere-sphere frictionless, floor friction 0.9. Statics is then
// determinate: with
// cos(theta) = sqrt(2/3) the angle of a top contact from the vertical, each
// top contact carries M g / (3 cos theta), each floor contact a normal
// reaction (m + M/3) g and a friction (M g / 3) tan(theta) pointing inwards.
// Impulses are these times dt in every step.
PyramidResult pyramid(double ratio, double dt, int steps, int max_iter) {
  WorldParams3 p;
  p.dt = dt;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = 0.0;
  p.mu_wall = 0.9;
  p.alert = 1e-4;
  p.d_ref = 0.02;
  p.solver.tol = 1e-14;
  p.solver.max_iter = max_iter;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  // Base spheres 2e-4 apart (beyond the alert distance: no rows between
  // them; touching, their impulses would be indeterminate, any p >= 0 being
  // balanced by the floor's sticking friction).
  const double r = 0.01, R0 = (2 * r + 2e-4) / std::sqrt(3.0);  // circumradius of the base triangle
  int base[3];
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * std::numbers::pi * k / 3 + 0.3;
    base[k] = w.bodies.add_sphere(Vec3(R0 * std::cos(a), R0 * std::sin(a), r), r, 2600);
  }
  const double h = std::sqrt(4 * r * r - R0 * R0);
  const int top = w.bodies.add_sphere(Vec3(0, 0, r + h), r, 2600 * ratio);
  for (std::size_t i = 1; i < w.bodies.size(); ++i) w.bodies.vel[i].inv_I = 0.0;
  const double m = w.bodies.mass[base[0]], M = w.bodies.mass[top];
  const double cth = h / (2 * r), tth = R0 / h;
  PyramidResult out;
  for (int s = 0; s < steps; ++s) {
    w.step();
    out.sweeps = std::max(out.sweeps, w.last().solve.iterations);
    out.overlap = std::max(out.overlap, w.last().max_overlap);
  }
  const double fn = (m + M / 3) * kG * dt, ft = M / 3 * kG * tth * dt, ftop = M * kG * dt / (3 * cth);
  double sum = 0;
  int floors = 0, tops = 0;
  for (std::size_t k = 0; k < w.rows().size(); ++k) {
    const SphereRow& row = w.rows()[k];
    if (row.b1 == 0) {  // floor
      ++floors;
      sum += row.r[0];
      out.floor_n_err = std::max(out.floor_n_err, std::abs(row.r[0] - fn) / fn);
      // friction towards the axis: -ft times the horizontal unit vector from the axis
      const Vec3 x = w.bodies.pos[row.b2];
      const Vec3 in = -Vec3(x.x(), x.y(), 0).normalized();
      const Vec3 F = row.r[1] * row.t1 + row.r[2] * row.t2;
      out.floor_t_err = std::max(out.floor_t_err, (F - ft * in).norm() / ft);
    } else if (row.b1 == top || row.b2 == top) {
      ++tops;
      out.top_err = std::max(out.top_err, std::abs(row.r[0] - ftop) / ftop);
    } else {
      ++out.base_base;  // no row expected
    }
  }
  EXPECT_EQ(floors, 3);
  EXPECT_EQ(tops, 3);
  out.floor_sum_err = std::abs(sum - (3 * m + M) * kG * dt) / ((3 * m + M) * kG * dt);
  for (std::size_t i = 1; i < w.bodies.size(); ++i) out.vmax = std::max(out.vmax, w.bodies.vel[i].v.norm());
  return out;
}

}  // namespace

// Mass ratio 1 at dt = 1 ms and at dt = 50 ms: every contact force to
// 1e-9 of its closed form (solver tolerance 1e-14 on the impulse
// increments), velocities at round-off of g dt, no overlap.
TEST(Hard3, PyramidAtRestHasTheStaticForces) {
  for (const double dt : {1e-3, 5e-2}) {
    const PyramidResult o = pyramid(1.0, dt, 50, 20000);
    std::printf("pyramid M/m 1 dt %g: floor n %.2g t %.2g sum %.2g, top %.2g, v %.2g, overlap %.2g d, <= %d sweeps\n", dt,
                o.floor_n_err, o.floor_t_err, o.floor_sum_err, o.top_err, o.vmax, o.overlap, o.sweeps);
    EXPECT_EQ(o.base_base, 0);
    EXPECT_LT(o.floor_n_err, 1e-9);
    EXPECT_LT(o.floor_t_err, 1e-9);
    EXPECT_LT(o.floor_sum_err, 1e-12);
    EXPECT_LT(o.top_err, 1e-9);
    EXPECT_LT(o.vmax, 1e-9 * kG * dt);
    EXPECT_LT(o.overlap, 1e-9);
  }
}

// Mass ratio 10^4 (the top sphere 10^4 times heavier than each base
// sphere): the same closed forms. Gauss-Seidel's contraction per sweep is
// ~1 - m/M here (the light spheres pass the heavy one's weight on a little at
// a time): measured 8210 sweeps at M/m = 100, 63660 at 10^3, and the cap of
// 2e5 in the first steps at 10^4, the warm start finishing the job. Forces to
// 1e-9 after 50 steps (measured 9e-11), and the heavy sphere does not sink.
TEST(Hard3, HeavySphereOnLightOnesStaysAtRest) {
  const PyramidResult o = pyramid(1e4, 1e-3, 50, 200000);
  std::printf("pyramid M/m 1e4: floor n %.2g t %.2g sum %.2g, top %.2g, v %.2g, overlap %.2g d, <= %d sweeps\n",
              o.floor_n_err, o.floor_t_err, o.floor_sum_err, o.top_err, o.vmax, o.overlap, o.sweeps);
  EXPECT_EQ(o.base_base, 0);
  EXPECT_LT(o.floor_n_err, 1e-9);
  EXPECT_LT(o.floor_t_err, 1e-9);
  EXPECT_LT(o.floor_sum_err, 1e-10);
  EXPECT_LT(o.top_err, 1e-9);
  EXPECT_LT(o.vmax, 1e-9 * kG * 1e-3);
  EXPECT_LT(o.overlap, 1e-9);
}

// A column of 30 spheres on a floor, densities alternating 1 : 100: at rest,
// each contact carries the weight of the spheres above it (floor: all of
// them). Returns the worst relative error of the contacts' impulses after
// 20 steps, and the run's largest sweeps and CG iterations of a step.
namespace {

struct ColumnResult {
  double worst = 0, vmax = 0, overlap = 0, tangential = 0;
  int sweeps = 0, cg = 0;
  std::size_t rows = 0;
};

ColumnResult column(int subspace) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.5;
  p.alert = 1e-4;
  p.d_ref = 0.02;
  p.solver.tol = 1e-14;
  p.solver.max_iter = 200000;
  p.solver.subspace = subspace;
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.01;
  const int n = 30;
  for (int k = 0; k < n; ++k) w.bodies.add_sphere(Vec3(0, 0, r + 2 * r * k), r, k % 2 ? 260000 : 2600);
  ColumnResult o;
  for (int s = 0; s < 20; ++s) {
    w.step();
    o.sweeps = std::max(o.sweeps, w.last().solve.iterations);
    o.cg = std::max(o.cg, w.last().solve.subspace_iterations);
    o.overlap = std::max(o.overlap, w.last().max_overlap);
  }
  o.rows = w.rows().size();
  for (const SphereRow& row : w.rows()) {
    // the lower body of the row: the floor (0) or sphere b; the weight above it
    const int lower = std::min(row.b1, row.b2);
    double above = 0;
    for (int k = lower + 1; k <= n; ++k) above += w.bodies.mass[k];
    const double expect = above * kG * p.dt;
    o.worst = std::max(o.worst, std::abs(row.r[0] - expect) / expect);
    o.tangential = std::max(o.tangential, std::hypot(row.r[1], row.r[2]) / expect);
  }
  for (int k = 1; k <= n; ++k) o.vmax = std::max(o.vmax, w.bodies.vel[k].v.norm());
  return o;
}

}  // namespace

// The column, plain NLGS: the weights to 1e-9 after 20 steps (measured
// 5e-12). The first steps hit the sweep cap (2e5: a chain propagates a load
// one colour per sweep, slowed by the mass ratio) and leave overlaps of a
// few 1e-9 d, bounded here by 1e-8 d.
TEST(Hard3, TallColumnCarriesTheWeightAbove) {
  const ColumnResult o = column(0);
  std::printf("column of 30 (1:100): contact forces within %.2g, v %.2g, overlap %.2g d, <= %d sweeps\n", o.worst,
              o.vmax, o.overlap, o.sweeps);
  ASSERT_EQ(o.rows, 30u);
  EXPECT_LT(o.worst, 1e-9);
  EXPECT_LT(o.tangential, 1e-12);
  EXPECT_LT(o.vmax, 1e-9 * kG * 1e-3);
  EXPECT_LT(o.overlap, 1e-8);
}

// The same column with the subspace correction (solver.subspace = 100): once
// the first pair of sweeps has loaded the chain, the sticking rows' linear
// problem is the whole problem, and conjugate gradients solve it in about
// as many iterations as it has unknowns (90) where Gauss-Seidel needs the
// cap. The same weights to 1e-9, no overlap, and every step far below the
// cap: at most 50 sweeps and 200 CG iterations (measured 2026-11-26: 33 and
// 142, the plain column 200 000, its cap; a deterministic count, not a time).
TEST(Hard3, TallColumnWithSubspaceCorrection) {
  const ColumnResult o = column(100);
  std::printf("column of 30 (1:100), subspace(100): contact forces within %.2g, v %.2g, overlap %.2g d, <= %d sweeps, "
              "<= %d CG\n",
              o.worst, o.vmax, o.overlap, o.sweeps, o.cg);
  ASSERT_EQ(o.rows, 30u);
  EXPECT_LT(o.worst, 1e-9);
  EXPECT_LT(o.tangential, 1e-12);
  EXPECT_LT(o.vmax, 1e-9 * kG * 1e-3);
  EXPECT_LT(o.overlap, 1e-8);
  EXPECT_LE(o.sweeps, 50);
  EXPECT_LE(o.cg, 200);
}

// Cohesion at the threshold: a sphere under a ceiling with pull-off force
// f_a = 1.01 m g hangs (r_n = -m g dt, no motion); with f_a = 0.99 m g it
// leaves at a = g - f_a/m while within the debonding distance (the full
// adhesive impulse -f_a dt acts), for sqrt(2 debond / a) (45 steps here),
// then falls freely at g. Both laws
// (frictionless, Coulomb).
TEST(Hard3, CohesionJustAboveHoldsJustBelowFalls) {
  for (const bool friction : {false, true})
    for (const double ratio : {1.01, 0.99}) {
      WorldParams3 p;
      p.dt = 1e-3;
      p.gravity = Vec3(0, 0, -kG);
      p.mu = p.mu_wall = friction ? 0.4 : 0.0;
      p.alert = 1e-4;
      p.debond = 1e-4;
      p.solver.tol = 1e-14;
      const double r = 0.01;
      World3 w(p);
      w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, -1));
      const int s = w.bodies.add_sphere(Vec3(0, 0, -r), r, 2600);
      const double m = w.bodies.mass[s];
      p.adhesion = ratio * m * kG;
      w.set_params(p);
      if (ratio > 1) {
        for (int k = 0; k < 100; ++k) {
          w.step();
          ASSERT_EQ(w.rows().size(), 1u);
          EXPECT_NEAR(w.rows()[0].r[0], -m * kG * p.dt, 1e-12 * m * kG * p.dt);
        }
        EXPECT_LT(w.bodies.vel[s].v.norm(), 1e-15);
        EXPECT_NEAR(w.bodies.pos[s].z(), -r, 1e-15);
        continue;
      }
      const double a = kG - p.adhesion / m;
      int bonded = 0;
      double v = 0;
      for (int k = 0; k < 200; ++k) {
        w.step();
        const bool b = !w.rows().empty() && w.rows()[0].adh > 0;
        if (b) {
          ++bonded;
          EXPECT_NEAR(w.rows()[0].r[0], -p.adhesion * p.dt, 1e-12 * m * kG * p.dt);
          v += a * p.dt;
        } else {
          v += kG * p.dt;
        }
        EXPECT_NEAR(-w.bodies.vel[s].v.z(), v, 1e-12 * kG * p.dt * (k + 1)) << k;
      }
      std::printf("cohesion 0.99 m g (%s): bonded %d steps at a = %.4g, then free fall\n",
                  friction ? "Coulomb" : "frictionless", bonded, a);
      // Bonded while the gap a t^2 / 2 is within debond: t = sqrt(2 debond / a),
      // to a step (the gap is taken at the midpoint).
      EXPECT_NEAR(bonded, std::sqrt(2 * p.debond / a) / p.dt, 1.0);
    }
}

// A dense packing under a load: FCC layers of nx x ny spheres in a cell
// periodic in x and y on a floor, the top layer `top` times denser. Spheres
// at the cell's sides rest on the images of others. At rest, the vertical
// impulses across every horizontal cut (between layers k - 1 and k, and the
// floor) sum to the weight above it times dt (the momentum balance of the
// layers above). Returns the worst cut's relative error after 20 steps.
namespace {

struct PackingResult {
  double worst = 0, vmax = 0, overlap = 0;
  int sweeps = 0, cg = 0, within = 0;
  std::size_t rows = 0;
};

PackingResult packing(int nx, int ny, int layers, double top, int max_iter, int subspace, double tol = 1e-11) {
  const double r = 0.005, s3 = std::sqrt(3.0), dz = 2 * r * std::sqrt(2.0 / 3.0);
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -kG);
  p.mu = p.mu_wall = 0.3;
  p.alert = 1e-3 * r;
  p.d_ref = 2 * r;
  p.solver.tol = tol;
  p.solver.max_iter = max_iter;
  p.solver.subspace = subspace;
  p.solver.min_parallel = 1 << 30;  // one thread: the test is about statics
  p.cell = Vec3(2 * r * nx, s3 * r * ny, 1.0);
  p.periodic = {true, true, false};
  World3 w(p);
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  std::vector<int> layer_of(1, -1);
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Vec3 x(2 * r * i + r * (j % 2) + r * (k % 3), s3 * r * j + r / s3 * (k % 3), r + k * dz);
        w.bodies.add_sphere(x, r, k == layers - 1 ? 2600 * top : 2600);
        layer_of.push_back(k);
      }
  PackingResult o;
  for (int st = 0; st < 20; ++st) {
    w.step();
    o.sweeps = std::max(o.sweeps, w.last().solve.iterations);
    o.cg = std::max(o.cg, w.last().solve.subspace_iterations);
    o.overlap = std::max(o.overlap, w.last().max_overlap);
  }
  std::vector<double> cut(layers, 0.0), above(layers, 0.0);  // cut k: below layer k
  for (std::size_t i = 1; i < w.bodies.size(); ++i)
    for (int k = 0; k <= layer_of[i]; ++k) above[k] += w.bodies.mass[i] * kG * p.dt;
  for (const SphereRow& row : w.rows()) {
    const int upper = std::max(layer_of[row.b1], layer_of[row.b2]);
    const int lower = std::min(layer_of[row.b1], layer_of[row.b2]);
    if (upper == lower) {
      ++o.within;
      continue;
    }
    EXPECT_EQ(upper, lower + 1);
    // impulse on body 2, world frame; upward on the upper body
    const Vec3 P = row.to_world(row.r);
    const bool b2_upper = layer_of[row.b2] == upper;
    cut[upper] += b2_upper ? P.z() : -P.z();
  }
  for (int k = 0; k < layers; ++k) o.worst = std::max(o.worst, std::abs(cut[k] - above[k]) / above[k]);
  for (std::size_t i = 1; i < w.bodies.size(); ++i) o.vmax = std::max(o.vmax, w.bodies.vel[i].v.norm());
  o.rows = w.rows().size();
  return o;
}

// At rest after 20 steps: the cuts carry the weight above them to 1e-9,
// velocities below 1e-9 g dt, overlaps below 1e-8 d.
void expect_static(const PackingResult& o) {
  EXPECT_LT(o.worst, 1e-9);
  EXPECT_LT(o.vmax, 1e-9 * kG * 1e-3);
  EXPECT_LT(o.overlap, 1e-8);
}

}  // namespace

// 6 layers of 16 under a 10 times denser top, plain NLGS: the cuts to 1e-9
// after 20 steps (measured 9e-11 at tol 1e-11; this hyperstatic stack needs
// the 5000-sweep cap in every step, and at 10 layers of 36 under a 100 times
// denser top 3000 sweeps left 3e-5: slow Gauss-Seidel, not a wrong statics).
TEST(Hard3, DensePeriodicPackingCarriesTheWeightAboveEachLayer) {
  const PackingResult o = packing(4, 4, 6, 10, 5000, 0);
  std::printf("dense periodic packing: %zu rows (%d within layers), cuts within %.2g, v %.2g, overlap %.2g d, <= %d "
              "sweeps\n",
              o.rows, o.within, o.worst, o.vmax, o.overlap, o.sweeps);
  expect_static(o);
}

// The case plain NLGS could not do above: 10 layers of 36 under a 100 times
// denser top (2088 rows), with the subspace correction (solver.subspace =
// 50) at tol 1e-12 and the same 5000-sweep cap: the cuts to 1e-9 (measured
// 2026-11-26: 1.4e-12, at most 2945 CG iterations a step; plain NLGS at tol
// 1e-13 and the same cap leaves 3.4e-6, velocities 8e-7 m/s).
TEST(Hard3, DenseHeavyTopPackingWithSubspaceCorrection) {
  const PackingResult o = packing(6, 6, 10, 100, 5000, 50, 1e-12);
  std::printf("dense packing, 10 x 36, top 100x, subspace(50): %zu rows, cuts within %.2g, v %.2g, overlap %.2g d, "
              "<= %d sweeps, <= %d CG\n",
              o.rows, o.worst, o.vmax, o.overlap, o.sweeps, o.cg);
  expect_static(o);
}
