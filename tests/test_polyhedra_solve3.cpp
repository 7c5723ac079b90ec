// The subspace correction of the sweep (solver.subspace, core/sweep.hpp)
// on polyhedra's block rows (block_coupling3.hpp): one step of a pile of
// 216 blocks of sides 1 : 1.5 : 2 (configs/pile-polyhedra.toml, made
// smaller), taken out of the run just before its solve.
//  - The product the conjugate gradients use, W p through the bodies'
//    inverse inertia tensors, is W p of the FCLib matrix (to_matrix, which
//    test_problem_dump3 checks against H^T M^-1 H assembled by hand).
//  - The corrected solve stops at tol on its own, in far fewer sweeps than
//    plain NLGS (which meets it only after ~2000: load moving between the
//    four points of face contacts), and is as close to a tight reference in
//    the bodies' velocities, and no worse in its law residual.
//  - On one thread or two, the same impulses to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <omp.h>

#include "block_coupling3.hpp"
#include "config.hpp"
#include "contact_problem3.hpp"
#include "problem3.hpp"
#include "setup3.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

constexpr int kStep = 110;

// The problem of step kStep, its warm start in it, as the run would solve it.
const ContactProblem3& captured() {
  static const ContactProblem3 p = [] {
    Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/pile-polyhedra.toml");
    s.n = 216;
    s.shape = {Shape3d::Cuboid};
    s.aspect = {1.0, 1.5, 2.0};
    s.subspace = 0;
    World3 w = build_world3(s);
    for (int k = 1; k < kStep; ++k) w.step();
    ContactProblem3 out;
    w.set_problem_hook([&](const ContactProblem3& q, const SolverParams&) { out = q; });
    w.step();
    return out;
  }();
  return p;
}

struct Solved {
  SolveStats st;
  ContactProblem3 p;
};

Solved solve(double tol, int max_iter, int subspace, int min_parallel = kMinParallelRows) {
  Solved s{{}, captured()};
  SolverParams prm;
  prm.tol = tol;
  prm.max_iter = max_iter;
  prm.residual_tol = 0.0;
  prm.subspace = subspace;
  prm.min_parallel = min_parallel;
  s.st = nlgs_solve3(s.p, prm);
  return s;
}

// The bodies' velocities against a reference's, in the kinetic-energy norm
// (M the masses and world inertia tensors), relative to the velocity g dt
// that one step of gravity gives every grain.
double velocity_error(const ContactProblem3& a, const ContactProblem3& ref) {
  double e = 0, m = 0;
  for (std::size_t i = 0; i < a.vel.size(); ++i) {
    if (a.vel[i].inv_m == 0.0) continue;
    const Vec3 dv = a.vel[i].v - ref.vel[i].v, dw = a.vel[i].w - ref.vel[i].w;
    e += dv.squaredNorm() / a.vel[i].inv_m + dw.dot(a.inv_inertia[i].inverse() * dw);
    m += 1.0 / a.vel[i].inv_m;
  }
  return std::sqrt(e / m) / (9.81 * 1e-3);
}

}  // namespace

TEST(PolyhedraSubspace, ProductIsTheMatrixW) {
  ContactProblem3 p = captured();
  const int n = static_cast<int>(p.rows.size());
  ASSERT_GT(n, 1000);
  std::vector<BlockRow3> rows(n);
  for (int k = 0; k < n; ++k) rows[k] = make_block_row3(p.rows[k], p.vel.data(), p.inv_inertia.data());
  sweep::BlockCoupling3 c{p.vel.data(), nullptr, rows.data(), static_cast<int>(p.vel.size())};
  std::vector<int> live(n);
  for (int k = 0; k < n; ++k) live[k] = k;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N;
  Eigen::VectorXd x(3 * n), y(3 * n);
  for (int k = 0; k < 3 * n; ++k) x[k] = N(rng);
  auto scratch = c.subspace_scratch();
  c.subspace_apply(rows.data(), live, x.data(), y.data(), scratch);
  const Problem3 P = to_matrix(p);
  const Eigen::VectorXd Wx = P.W * x;
  const double err = (y - Wx).cwiseAbs().maxCoeff(), scale = Wx.cwiseAbs().maxCoeff();
  std::printf("[ subspace ] %d block rows: |W x (bodies) - W x (matrix)| / |W x| = %.2e\n", n, err / scale);
  EXPECT_LT(err, 1e-12 * scale);
  // The bodies the product went through are a copy: the problem's own
  // velocities are untouched.
  for (std::size_t i = 0; i < p.vel.size(); ++i) ASSERT_EQ(p.vel[i].v, captured().vel[i].v) << "body " << i;
}

TEST(PolyhedraSubspace, MeetsTolInFewerSweepsWithTheSameAnswer) {
  const Solved ref = solve(1e-10, 20000, 0);
  const Solved plain = solve(1e-4, 5000, 0);
  const Solved sub = solve(1e-4, 5000, 10);
  const double ep = velocity_error(plain.p, ref.p), es = velocity_error(sub.p, ref.p);
  std::printf("[ subspace ] step %d, %zu rows, tol 1e-4: plain %d sweeps (cap %d), residual %.2e, |dv| %.2e g dt; "
              "subspace(10) %d sweeps + %d CG (cap %d), residual %.2e, |dv| %.2e g dt; reference %d sweeps\n",
              kStep, ref.p.rows.size(), plain.st.iterations, plain.st.cap_hit, plain.st.residual_max, ep,
              sub.st.iterations, sub.st.subspace_iterations, sub.st.cap_hit, sub.st.residual_max, es,
              ref.st.iterations);
  EXPECT_FALSE(sub.st.cap_hit);
  EXPECT_GT(sub.st.subspace_iterations, 0);
  // A CG iteration costs about half a sweep (one product through the
  // bodies): the corrected solve's whole work is below a quarter of plain
  // NLGS's sweeps (measured: 140 + CG against 2264).
  EXPECT_LT(sub.st.iterations + sub.st.subspace_iterations / 2, plain.st.iterations / 4);
  EXPECT_LE(es, 2.0 * ep);
  EXPECT_LE(sub.st.residual_max, 1.5 * plain.st.residual_max);
}

// The corrections run on one thread between sweeps: the same impulses, bit
// for bit, when the sweeps run on one thread or two (min_parallel 64 forces
// the parallel sweep).
TEST(PolyhedraSubspace, ResultsDoNotDependOnThreads) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  const Solved one = solve(1e-4, 400, 10, 64);
  omp_set_num_threads(2);
  const Solved two = solve(1e-4, 400, 10, 64);
  omp_set_num_threads(before);
  EXPECT_EQ(one.st.iterations, two.st.iterations);
  EXPECT_GT(one.st.subspace_iterations, 0);
  for (std::size_t k = 0; k < one.p.rows.size(); ++k) ASSERT_EQ(one.p.rows[k].r, two.p.rows[k].r) << "row " << k;
}

// One cube of configs/pile-polyhedra.toml alone (particles.n = 1, the
// scene's subspace correction on): it falls into the box just its size and
// lands flat beside a wall, its 4 face points resting, 2 points of the wall
// within alert. At step 46 the sweep's iterate gave the wall's open points
// an impulse, so the linear problem of the correction (those rows held at
// u = 0 while closing, beside the resting ones) had no solution, and the
// conjugate gradients stepped along W's null space: impulses of 1e3 N s on
// a 0.09 g cube, which the law's relative stop then accepted, and a kinetic
// energy of 2e14 J. A direction W barely sees now ends the correction.
// Asserted: the energy never rises (a rigid, inelastic, frictional law
// only dissipates), and the cube ends resting flat at its half side.
TEST(PolyhedraSubspace, ACorrectionWithNoSolutionIsNotTaken) {
  Scene s = load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/pile-polyhedra.toml");
  s.n = 1;
  ASSERT_GT(s.subspace, 0);
  World3 w = build_world3(s);
  int c = -1;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.shape[i] == Shape3::Polyhedron) c = static_cast<int>(i);
  ASSERT_GE(c, 0);
  const double m = w.bodies.mass[c], g = 9.81;
  const double e0 = w.kinetic_energy() + m * g * w.bodies.pos[c].z();
  double rise = 0;
  for (int k = 0; k < 400; ++k) {
    w.step();
    rise = std::max(rise, w.kinetic_energy() + m * g * w.bodies.pos[c].z() - e0);
  }
  // Round-off and the solver's tolerance: 1e-6 of the energy it fell with.
  EXPECT_LT(rise, 1e-6 * e0);
  const double half = w.bodies.radius[c] / std::sqrt(3.0);  // the cube's half side (its inradius)
  EXPECT_NEAR(w.bodies.pos[c].z(), half, 1e-3 * half);
  EXPECT_LT(w.kinetic_energy(), 1e-9 * e0);
}
