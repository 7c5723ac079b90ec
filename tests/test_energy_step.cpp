// Energy step by step in dissipative 3D scenes: e = 0,
// friction, cohesion. The 2D scenes are checked by tests/world_util.hpp's
// run_watched (test_pile, test_polygon, test_cohesion), which derives the
// balance and the solver's bound; this is its 3D sibling on World3's rows:
//   E(k+1) - E(k) = 1/2 sum_c p.(u+ + u-)   exactly (midpoint scheme),
//   = S (1/2 sum p.u-) + A (-1/2 sum a u_n+) + D (1/2 sum (p_n + a) u_n+ + p_t.u_t+),
// with D <= 0 for a converged law and D <= eps = 1/2 w_max z_max ||dp||_2
// ||p||_2 for the solve's last sweep (world_util.hpp). Each step must
// satisfy the balance to round-off and D <= eps: a step whose contacts
// inject more energy than an unconverged solve can fails, however much was
// dissipated before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pile3d.hpp"
#include "world3.hpp"
#include "world_util.hpp"

using namespace cd;

namespace {

cdtest::StepEnergy step_energy3(World3& w) {
  return cdtest::step_energy_with(w, [](const SphereRow& r, const std::vector<BodyVel3>& v0,
                                        const std::vector<BodyVel3>& v1) {
    const Vec3 um = r.to_frame(relative_velocity(r, v0[r.b1], v0[r.b2]));
    const Vec3 up = r.to_frame(relative_velocity(r, v1[r.b1], v1[r.b2]));
    return cdtest::RowEnergy{0.5 * r.r.dot(um), -0.5 * r.adh * up[0],
                             0.5 * ((r.r[0] + r.adh) * up[0] + r.r[1] * up[1] + r.r[2] * up[2]),
                             std::abs(r.r.dot(um + up)), r.r.squaredNorm(), std::max(r.wnn, r.wtt)};
  });
}

// 100 spheres of pile3d (r 2.5-5 mm, mu = 0.4, e = 0) dropped into their
// box, 250 steps of 1 ms (the fall, the impacts, settling), tol 1e-4 as the
// scene's default, alert 0.02 r_mean (pile3d's 0.5 closes every gap before
// it overlaps, so that nothing would act on overlaps: here impacts overlap
// by up to ~1e-3 r); with cohesion: f_a = 20 m g of a mean sphere, debond
// 0.1 r_mean.
void run_pile3(double adhesion_mg, const char* name) {
  Pile3dParams q;
  q.n_spheres = 100;
  q.alert_rel = 0.02;
  q.mu = 0.4;
  q.solver.tol = 1e-4;
  q.solver.max_iter = 2000;
  World3 w = make_pile3d(q);
  const double m = 2600.0 * 4.0 / 3.0 * 3.141592653589793 * std::pow(q.r_mean, 3);
  if (adhesion_mg > 0) {
    WorldParams3 p = w.params();
    p.adhesion = adhesion_mg * m * 9.81;
    p.debond = 0.1 * q.r_mean;
    w.set_params(p);
  }
  double mgd = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) mgd += w.bodies.mass[i] * 9.81 * 2 * q.r_mean;
  double max_gain = 0, max_law = 0, max_ratio = 0, max_scheme = 0, max_adh = 0, e_peak = 0;
  int steps_gaining = 0;
  double max_overlap = 0;
  for (int k = 0; k < 250; ++k) {
    const cdtest::StepEnergy e = step_energy3(w);
    cdtest::expect_step_energy(e, k, name);
    max_gain = std::max(max_gain, e.gain);
    steps_gaining += e.gain > 0;
    max_law = std::max(max_law, e.law);
    if (e.law > 1e-12 * e.scale) max_ratio = std::max(max_ratio, e.law / e.eps);
    max_scheme = std::max(max_scheme, e.scheme);
    max_adh = std::max(max_adh, e.adhesion);
    e_peak = std::max(e_peak, w.kinetic_energy());
    max_overlap = std::max(max_overlap, w.last().max_overlap);
  }
  EXPECT_GT(e_peak, 1e-2 * mgd);  // it did fall
  std::printf("%s: largest one-step gain of E %.2e m g d (%d steps gained), law term %.2e m g d (%.2g of "
              "the solver bound), scheme term %.2e, adhesion term %.2e m g d; largest overlap %.1e d\n",
              name, max_gain / mgd, steps_gaining, max_law / mgd, max_ratio, max_scheme / mgd, max_adh / mgd,
              max_overlap);
}

}  // namespace

TEST(EnergyStep3, FrictionalPileLosesEnergyEveryStep) { run_pile3(0.0, "3D pile, mu 0.4"); }

TEST(EnergyStep3, CohesivePileLosesEnergyEveryStep) { run_pile3(20.0, "3D cohesive pile, f_a = 20 m g"); }

// Pure contact dynamics (overlap_correction = 0) leaves an overlap as it
// is: two spheres overlapping by 1 % of a diameter, at rest, without
// gravity, stay at rest to the bit (the law asks u_n >= 0 of a contact that
// is not approaching, so no impulse). An overlap correction left on would
// push them apart, putting in kinetic energy that no balance bound sees
// when overlaps are small; here any speed at all is caught.
TEST(EnergyStep3, PureContactDynamicsPutsNoEnergyIntoAnOverlap) {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3::Zero();
  p.mu = p.mu_wall = 0.4;
  p.alert = 1e-3;
  p.solver.tol = 1e-12;
  ASSERT_EQ(p.overlap_correction, 0.0);
  World3 w(p);
  const double r = 0.01;
  w.bodies.add_sphere(Vec3(0, 0, 0), r, 2600);
  w.bodies.add_sphere(Vec3(2 * r - 0.02 * r, 0, 0), r, 2600);  // overlap 0.01 d
  for (int k = 0; k < 20; ++k) w.step();
  EXPECT_GT(w.last().max_overlap, 0.0) << "the contact was not seen";
  EXPECT_EQ(w.kinetic_energy(), 0.0);
  for (std::size_t i = 0; i < w.bodies.size(); ++i) EXPECT_EQ(w.bodies.vel[i].v, Vec3::Zero()) << i;
}
