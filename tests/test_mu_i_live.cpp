// A live check of the rheology: the current simulator
// compacts a small sample and shears it at one inertial number, and its
// steady friction and packing fraction must match the reference campaigns
// of `make regress` (tests/data/regress*: the same scene settings, 100 disks
// and 200 spheres, fitted by cdanalysis fit mu-i over strain 1-3), in 2D
// and 3D. AnalysisRegress.SimulatorCampaign* refits the committed series;
// this runs the simulator.
//
// Scenes: the regress campaigns' settings (size ratio 2, uniform_area, mu
// 0.4, alert 0.1 d, tol 1e-4, dt = 0.05 t_p, cell mass 0.1, strain 3, the
// steady window strain 1-3), at one I inside each reference range (2D 0.05,
// 3D 0.1), from a sample compacted in the test (the campaigns' preparation
// is slower; the shear forgets it by strain 1). 2D: 100 disks, mu = q/p
// (the 2D reference fits q_over_p); 3D: 150 spheres, mu = -sigma_xy/sigma_yy
// (3D fits shear_stress_ratio), 150 rather than 200 to keep it well under
// a minute (size enters both within the tolerance below).
//
// Tolerances: 3 combined standard errors (the run's block error over 8
// blocks of strain 0.25, rows of 10 steps as series rows, the fit's at that I from its covariance; for phi
// the reference run's block error) plus a stated margin for what differs
// from the reference run: another sample (seed, size, preparation) of the
// same material: 2 % of mu and 1 % of phi. Measured (2026-11-26): 2D at
// I = 0.05, mu 0.364 +- 0.010 against 0.359 +- 0.007 (tolerance 0.044),
// phi 0.7925 against 0.7968 (0.020); 3D at I = 0.1, mu 0.462 +- 0.013
// against 0.433 +- 0.005 (0.051), phi 0.5816 against 0.5744 (0.013).
//
// What it resolves (measured by hand, particle friction halved to 0.2):
// 2D, mu 0.319 +- 0.008 (fails by 0.001: a hair, not a margin to rely on;
// the halved 2D friction dies in test_shear's closed-form friction through
// a Lees-Edwards image), phi 0.806; 3D, mu 0.403 +- 0.013 (passes: at I =
// 0.1 a small cell's friction hardly depends on mu_p), phi 0.596 against
// 0.574 (fails by 0.009).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "checkpoint.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "regress_ref.hpp"
#include "observables.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "world.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

using cdtest::blocks;
using cdtest::Est;
using cdtest::RefFit;

// The common settings (regress campaigns).
Scene base(int dim, int n) {
  Scene s;
  s.dimension = dim;
  s.gravity = dim == 3 ? std::vector<double>{0, 0, 0} : std::vector<double>{0, 0};
  s.shear_mode = ShearMode::Periodic;
  s.n = n;
  s.d_mean = 1e-3;
  s.size_ratio = 2.0;
  s.size_dist = SizeDist::UniformArea;
  s.density = dim == 3 ? 2600 : 2.6;
  s.pressure = dim == 3 ? 1e5 : 100.0;
  s.mu = 0.4;
  s.alert = 0.1;
  s.tol = 1e-4;
  s.max_iter = 2000;
  s.dt_tp = 0.05;
  s.cell_mass = 0.1;
  return s;
}

// Compaction: isotropic at p, the lengths shrinking at most at 0.1 / t_p,
// for 200 steps (10 t_p: the sample is near jamming; the shear's first
// unit of strain, left out, finishes the job).
Scene prep(int dim, int n) {
  Scene s = base(dim, n);
  s.isotropic = true;
  s.compaction_rate = 0.1;
  s.duration = 200 * 0.05 * s.d_mean * std::sqrt(s.density / s.pressure);
  return s;
}

Scene shear(int dim, const std::string& start, double I) {
  Scene s = base(dim, 0);
  s.inertial_number = I;
  s.strain = 3.0;
  s.start = start;
  return s;
}

struct Steady {
  Est mu, phi, I;
};

void compare(const char* what, double I, const Steady& m, const RefFit& f, const Est& phi_ref) {
  const double mu_ref = f.mu(m.I.mean), se_fit = f.se(m.I.mean);
  const double tol_mu = 3 * std::hypot(m.mu.se, se_fit) + 0.02 * mu_ref;
  const double tol_phi = 3 * std::hypot(m.phi.se, phi_ref.se) + 0.01 * phi_ref.mean;
  std::printf("%s at I = %.4f +- %.4f: mu %.4f +- %.4f (reference fit %.4f +- %.4f, tolerance %.4f); phi %.4f "
              "+- %.4f (reference run %.4f +- %.4f, tolerance %.4f)\n",
              what, m.I.mean, m.I.se, m.mu.mean, m.mu.se, mu_ref, se_fit, tol_mu, m.phi.mean, m.phi.se,
              phi_ref.mean, phi_ref.se, tol_phi);
  EXPECT_NEAR(m.I.mean, I, 0.05 * I) << what;
  EXPECT_NEAR(m.mu.mean, mu_ref, tol_mu) << what;
  EXPECT_NEAR(m.phi.mean, phi_ref.mean, tol_phi) << what;
}

// Compacts a sample of the scene prep(dim, n) and shears it at I to strain
// 3; from strain 1 on, every 10 steps (strain 0.005 at I = 0.1, a series
// row) gives row(mean contact stress, mean K_yy, world) a sample.
template <class W, class Build, class Save, class Strain, class Row>
void run_shear(int dim, int n, double I, const char* name, Build build, Save save, Strain strain, Row row) {
  const auto dir = cdtest::scratch_dir("test_mu_i_live", name);
  const std::string ckpt = (dir / "prep.bin").string();
  {
    const Scene s = prep(dim, n);
    W w = build(s);
    const long steps = std::llround(s.duration / w.params().dt);
    for (long k = 0; k < steps; ++k) w.step();
    save(ckpt, w);
  }
  W w = build(shear(dim, ckpt, I));
  using M = std::decay_t<decltype(w.contact_stress())>;
  M acc = M::Zero();
  double kyy = 0;
  int in_row = 0;
  while (strain(w) < 3.0 - 1e-9) {
    w.step();
    if (strain(w) < 1.0) continue;
    acc += w.contact_stress();
    kyy += w.kinetic_stress()(1, 1);
    if (++in_row < 10) continue;
    row(M(acc / in_row), kyy / in_row, w);
    acc.setZero();
    kyy = 0;
    in_row = 0;
  }
}

// I from the imposed shear rate and the row's sigma_yy + K_yy (the series'
// inertial_number).
double inertial(double gd, const Scene& s, double syy_kyy) {
  return gd * s.d_mean * std::sqrt(s.density / syy_kyy);
}

}  // namespace

TEST(MuILive, DisksMatchTheReferenceCampaign) {
  const double I = 0.05;
  const Scene s = base(2, 0);
  std::vector<double> qp, phi, inum;
  run_shear<World>(
      2, 100, I, "2d", [](const Scene& sc) { return build_world(sc); },
      [](const std::string& path, const World& w) { save_checkpoint(path, w, 1); },
      [](const World& w) { return w.cell.strain; },
      [&](const Eigen::Matrix2d& S, double kyy, const World& w) {
        const obs::Tensor<2> St = {{{S(0, 0), S(0, 1)}, {S(1, 0), S(1, 1)}}};
        qp.push_back(obs::deviator_2d(St) / obs::mean_2d(St));
        inum.push_back(inertial(w.shear_rate(), s, S(1, 1) + kyy));
        double area = 0;
        for (std::size_t i = 0; i < w.bodies.size(); ++i)
          area += std::numbers::pi * w.bodies.radius[i] * w.bodies.radius[i];
        phi.push_back(area / (w.cell.width * w.cell.height));
      });
  compare("2D, 100 disks", I, {blocks(qp), blocks(phi), blocks(inum)},
          cdtest::read_fit(std::string(CDLAB_TEST_DATA) + "/regress/mu_i.toml"),
          cdtest::reference_phi(std::string(CDLAB_TEST_DATA) + "/regress/inertial/I_0.05/series.csv"));
}

TEST(MuILive, SpheresMatchTheReferenceCampaign) {
  const double I = 0.1;
  const Scene s = base(3, 0);
  std::vector<double> mu, phi, inum;
  run_shear<World3>(
      3, 150, I, "3d", [](const Scene& sc) { return build_world3(sc); },
      [](const std::string& path, const World3& w) { save_checkpoint3(path, w, 1); },
      [](const World3& w) { return w.cell().strain; },
      [&](const Eigen::Matrix3d& S, double kyy, const World3& w) {
        mu.push_back(-0.5 * (S(0, 1) + S(1, 0)) / S(1, 1));
        inum.push_back(inertial(w.shear_rate(), s, S(1, 1) + kyy));
        double vol = 0;
        for (std::size_t i = 0; i < w.bodies.size(); ++i)
          vol += 4.0 / 3.0 * std::numbers::pi * std::pow(w.bodies.radius[i], 3);
        phi.push_back(vol / w.cell_volume());
      });
  compare("3D, 150 spheres", I, {blocks(mu), blocks(phi), blocks(inum)},
          cdtest::read_fit(std::string(CDLAB_TEST_DATA) + "/regress3d/mu_i.toml"),
          cdtest::reference_phi(std::string(CDLAB_TEST_DATA) + "/regress3d/inertial/I_0.1/series.csv"));
}
