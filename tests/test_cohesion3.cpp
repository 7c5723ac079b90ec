// Cohesion in 3D (docs/3d.md "Cohesion in 3D shear"): the
// cohesion number's pull-off force f_a = eta p d^2 in a tri-periodic run,
// its refusals, the tensile strength of cohesive sphere blocks against the
// time step (the quick version of `make tensile`'s 3D study,
// cd/bench/tensile3.hpp), and a short cohesive shear at imposed pressure.
//
// The pull-off threshold itself (a sphere under a ceiling just above and
// just below f_a, closed form) is tests/test_world3_hard.cpp's
// Hard3.CohesionJustAboveHoldsJustBelowFalls and test_world3.cpp's
// World3.CohesiveSphereHangsUnderACeiling; sphere-sphere bonds in series
// (the chain and the blocks below) hold exactly f_a each.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "cd/bench/tensile3.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"
#include "world3.hpp"

using namespace cd;
namespace fs = std::filesystem;

namespace {

// The tri-periodic tests' small sample (shear3_util.hpp).
Scene prep_scene(int n) { return cdtest::shear3_prep_scene(n); }

Scene shear_scene(const std::string& start, double I, double eta) {
  Scene s = cdtest::shear3_shear_scene(start, I);
  s.cohesion_number = eta;
  return s;
}

std::string prepared(const std::string& name, int n, int steps) {
  World3 w = build_world3(prep_scene(n));
  for (int k = 0; k < steps; ++k) w.step();
  const auto dir = cdtest::scratch_dir("test_cohesion3", name);
  const std::string path = (dir / "checkpoint.bin").string();
  save_checkpoint3(path, w, 1);
  return path;
}

// The number mean of the diameters the checkpoint holds, read back into a
// world of its own (not through the scene that uses it).
double checkpoint_mean_diameter(const std::string& path) {
  WorldParams3 p;
  p.periodic = {true, true, true};  // a tri-periodic run's checkpoint
  p.cell = Vec3::Ones();            // replaced by the checkpoint's
  World3 w(p);
  load_checkpoint3(path, w);
  double sum = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) sum += 2 * w.bodies.radius[i];
  return sum / static_cast<double>(w.bodies.size());
}

void refused(const Scene& s, const std::vector<std::string>& words) {
  try {
    build_world3(s);
    ADD_FAILURE() << words.front() << ": accepted";
  } catch (const SceneError& e) {
    for (const auto& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

}  // namespace

// ---------------------------------------------------------------- the key

// f_a = eta p d^2 with d the mean diameter the scene's t_p and I use
// (particles.d_mean): from a checkpoint (shear.start) whose diameters'
// mean is computed here from the file, and for generated spheres (the size
// law's mean). Exact up to round-off (one product). The same d sets the
// shear rate: a d_mean 5 % off the sample's moves both, and 20 % off is
// refused. 2D keeps f_a = eta p d.
TEST(Cohesion3Scene, AdhesionIsEtaPDSquaredWithTheRunsMeanDiameter) {
  const std::string start = prepared("key", 40, 0);
  const double d = checkpoint_mean_diameter(start);
  const double eta = 10, p = 1e5, I = 0.1;
  Scene s = shear_scene(start, I, eta);
  s.d_mean = d;
  {
    const World3 w = build_world3(s);
    EXPECT_NEAR(w.params().adhesion, eta * p * d * d, 1e-12 * eta * p * d * d);
    EXPECT_NEAR(w.shear_rate(), I * std::sqrt(p / s.density) / d, 1e-12 * w.shear_rate());
    std::printf("checkpoint mean diameter %.6g m: f_a = %.6g N (eta p d^2 = %.6g N)\n", d, w.params().adhesion,
                eta * p * d * d);
  }
  {
    Scene t = s;
    t.d_mean = 1.05 * d;
    const World3 w = build_world3(t);
    EXPECT_NEAR(w.params().adhesion, eta * p * t.d_mean * t.d_mean, 1e-12 * w.params().adhesion);
    EXPECT_NEAR(w.shear_rate(), I * std::sqrt(p / s.density) / t.d_mean, 1e-12 * w.shear_rate());
  }
  { Scene t = s; t.d_mean = 1.2 * d; refused(t, {"shear.start", "mean diameter", "particles.d_mean"}); }
  // A preparation with cohesion: generated spheres, d = particles.d_mean.
  {
    Scene t = prep_scene(40);
    t.cohesion_number = eta;
    EXPECT_NEAR(world_params3(t).adhesion, eta * p * t.d_mean * t.d_mean, 1e-12 * eta * p * t.d_mean * t.d_mean);
  }
  // eta = 0: contact.adhesion as given.
  {
    Scene t = s;
    t.cohesion_number = 0;
    t.adhesion = 0.25;
    EXPECT_EQ(build_world3(t).params().adhesion, 0.25);
  }
  // 2D: p is a force per length, f_a = eta p d.
  {
    Scene t;
    t.gravity = {0, 0};
    t.shear_mode = cd::ShearMode::Periodic;
    t.n = 20;
    t.d_mean = 1e-3;
    t.density = 2.6;
    t.pressure = 100;
    t.cohesion_number = eta;
    EXPECT_NEAR(world_params(t).adhesion, eta * 100 * 1e-3, 1e-15);
  }
}

// The key where it does not apply, refused by name (SceneError, which cdsim
// turns into exit 2 before writing anything): without shear.pressure,
// together with contact.adhesion, in a pile (no periodic cell), an f_a that
// is not finite; and through cdsim.
TEST(Cohesion3Scene, BadCombinationsAreRefusedNamingTheKey) {
  const std::string start = prepared("bad", 30, 0);
  Scene s = shear_scene(start, 0.1, 10);
  EXPECT_NO_THROW(build_world3(s));
  {
    Scene t = prep_scene(30);
    t.pressure = 0;
    t.isotropic = false;
    t.compaction_rate = 0;
    t.dt_tp = 0;
    t.dt = 1e-5;
    t.cohesion_number = 10;
    refused(t, {"contact.cohesion_number", "shear.pressure", "contact.adhesion"});
  }
  { Scene t = s; t.adhesion = 1e-3; refused(t, {"contact.adhesion", "contact.cohesion_number", "not both"}); }
  { Scene t = s; t.cohesion_number = 1e300; t.pressure = 1e300; refused(t, {"f_a", "contact.cohesion_number"}); }
  {
    Scene t = prep_scene(30);
    t.shear_mode = cd::ShearMode::None;
    t.pressure = 0;
    t.isotropic = false;
    t.compaction_rate = 0;
    t.dt_tp = 0;
    t.dt = 1e-5;
    t.gravity = {0, 0, -9.81};
    t.cohesion_number = 10;
    refused(t, {"contact.cohesion_number", "shear.mode = \"periodic\""});
  }
  // cdsim: exit 2, the key named, no output folder.
  const fs::path exe = fs::path(CDLAB_BINARY_DIR) / "cd" / "cdsim";
  ASSERT_TRUE(fs::exists(exe)) << exe;
  const auto dir = cdtest::scratch_dir("test_cohesion3", "cli");
  const std::string src = CDLAB_SOURCE_DIR;
  for (const auto& [args, word] : std::vector<std::pair<std::string, std::string>>{
           {src + "/configs/shear3-prep.toml --set contact.cohesion_number=10 --set contact.adhesion=1", "not both"},
           {src + "/configs/pile3d.toml --set contact.cohesion_number=10", "contact.cohesion_number"}}) {
    const auto r = cdtest::run_command(exe.string() + " " + args + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find("contact.cohesion_number"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(word), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << args;
  }
}

// ---------------------------------------------------------------- dt study

// The tensile strength of cohesive sphere blocks pulled apart at V = 0.01
// d/t_a (cd/bench/tensile3.hpp: closed forms of a chain, f_a; a
// simple-cubic block of 3 x 3 columns, 9 f_a; an FCC block of 8 spheres a
// layer bonded at 45 degrees, 8 x 4 f_a/sqrt(2)) at dt = 1, 0.3, 0.1, 0.03
// t_a (V dt = delta_a ... 0.03 delta_a). Each is the closed form within
// 2 eps_f f_a dt/(m V) (twice the solver's velocity error relative to the
// pull speed: 2 % at dt = t_a, docs/accuracy.md) + 1e-3, and the distance to
// it does not grow as dt falls (up to 1e-3 of round-off and solver noise):
// the strength converges to the closed form as dt -> 0.
TEST(Cohesion3Tensile, StrengthConvergesToTheClosedFormAsDtFalls) {
  const cdbench::Pull3Options o;
  for (const cdbench::Block3& blk : {cdbench::chain3(6), cdbench::cubic3(3, 4), cdbench::fcc3(2, 4)}) {
    double prev = INFINITY;
    for (const double dt : {1.0, 0.3, 0.1, 0.03}) {
      const cdbench::Pull3 r = cdbench::pull3(blk, dt, o);
      const double err = std::abs(r.sigma_t / blk.exact - 1);
      std::printf("%-7s dt %5.2f t_a: sigma_t %.6f f_a (exact %.6f), rel. error %.2e, %d steps, %.0f sweeps/step, "
                  "bonds %d, caps %d\n",
                  blk.kind.c_str(), dt, r.sigma_t, blk.exact, err, r.steps, r.sweeps, r.bonds0, r.cap_hits);
      EXPECT_LE(err, 2 * cdbench::pull3_solver_error(o.tol, dt, o.speed) + 1e-3) << blk.kind << " dt " << dt;
      EXPECT_LE(err, prev + 1e-3) << blk.kind << " dt " << dt;
      prev = err;
    }
  }
}

// ---------------------------------------------------------------- shear

// A cohesive shear at eta = 10, I = 0.1 of 150 spheres from a compacted
// sample (tests/test_shear3.cpp's), through shear.start: f_a = eta p d^2.
// After 0.3 of strain, over 0.4 more in 8 blocks: the stresses are finite,
// sigma_yy + K_yy = p within 3 block standard errors + 5 % (the
// non-cohesive test's tolerance, Shear3Cell.ShearAtImposedInertialNumber),
// contacts carry tension (r_n < 0: bonds) and none pulls more than f_a
// (r_n >= -f_a dt: the law's bound, which the local solver enforces by
// projection, to round-off: 1e-9 f_a). The first 40 steps on 2 threads
// (every loop parallel) are bit-identical to those on 1.
TEST(Cohesion3Shear, CohesiveShearAtImposedPressure) {
  const std::string start = prepared("shear", 150, 300);
  const double eta = 10, I = 0.1;
  const Scene s = shear_scene(start, I, eta);
  const auto make = [&] { return cdtest::parallel_world3(s); };
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  World3 w = make();
  const double fa = w.params().adhesion, d = s.d_mean, p = s.pressure, dt = w.params().dt;
  EXPECT_NEAR(fa, eta * p * d * d, 1e-12 * fa);
  const int per_strain = static_cast<int>(std::lround(1.0 / w.shear_rate() / dt));  // 200
  const int skip = 3 * per_strain / 10, avg = 4 * per_strain / 10;
  constexpr int nblk = 8, kThreadSteps = 40;
  World3 w2 = make();
  omp_set_num_threads(2);
  for (int k = 0; k < kThreadSteps; ++k) w2.step();
  omp_set_num_threads(1);
  double syy[nblk] = {}, rn_min = 0;
  long tensile = 0, rows = 0, sweeps = 0, caps = 0;
  bool finite = true;
  for (int k = 0; k < skip + avg; ++k) {
    w.step();
    sweeps += w.last().solve.iterations;
    caps += w.last().solve.cap_hit;
    if (k + 1 == kThreadSteps) {
      for (std::size_t i = 0; i < w.bodies.size(); ++i) {
        ASSERT_EQ(w2.bodies.pos[i], w.bodies.pos[i]) << i;
        ASSERT_EQ(w2.bodies.vel[i].v, w.bodies.vel[i].v) << i;
        ASSERT_EQ(w2.bodies.vel[i].w, w.bodies.vel[i].w) << i;
      }
      EXPECT_EQ(w2.cell().size, w.cell().size);
      EXPECT_EQ(w2.cell().rate, w.cell().rate);
    }
    const Eigen::Matrix3d S = w.contact_stress() + w.kinetic_stress();
    finite = finite && S.allFinite();
    for (const SphereRow& r : w.rows()) {
      rn_min = std::min(rn_min, r.r[0] / dt);
      tensile += r.r[0] < 0;
    }
    rows += static_cast<long>(w.rows().size());
    if (k >= skip) syy[(k - skip) * nblk / avg] += S(1, 1) / p / (avg / nblk);
  }
  omp_set_num_threads(saved);
  double m = 0, m2 = 0;
  for (const double x : syy) m += x / nblk, m2 += x * x / nblk;
  const double se = std::sqrt(std::max(0.0, m2 - m * m) / (nblk - 1));
  std::printf("eta %g: f_a = %.4g N; (sigma_yy + K_yy)/p = %.4f +- %.4f; tensile rows %.1f %%, min r_n/dt = -f_a "
              "(1 + %.2g); %.0f sweeps/step, %ld of %d steps at the cap\n",
              eta, fa, m, se, 100.0 * tensile / rows, -rn_min / fa - 1, double(sweeps) / (skip + avg), caps,
              skip + avg);
  EXPECT_TRUE(finite);
  EXPECT_NEAR(m, 1.0, 3 * se + 0.05);
  EXPECT_GT(tensile, 0);
  EXPECT_GE(rn_min, -fa * (1 + 1e-9));
}
