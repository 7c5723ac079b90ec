// The 3D tri-periodic protocol (docs/3d.md "Tri-periodic
// protocol"): the cell's lengths as boundary dofs at imposed pressure
// (isotropic compaction: L_x, L_y, L_z at sigma_aa = p; shear: L_y at
// sigma_yy = p), Lees-Edwards shear at imposed inertial number, shear.start
// from a 3D checkpoint, and the keys' refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "checkpoint.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "run.hpp"
#include "run3.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "world3.hpp"

#include <omp.h>

#include "le_wrap_util.hpp"
#include "shear3_util.hpp"

using namespace cd;

namespace {

// The tri-periodic tests' small sample (shear3_util.hpp).
Scene prep_scene(int n) { return cdtest::shear3_prep_scene(n); }

double tp(const Scene& s) { return s.d_mean * std::sqrt(s.density / s.pressure); }

double phi(const World3& w) {
  double v = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) v += obs::sphere_volume(w.bodies.radius[i]);
  return v / w.cell_volume();
}

}  // namespace

// ---------------------------------------------------------------- dof balance

// No contacts: spheres at rest, far from each other and from the faces
// that move, so the height's dof sees only the imposed stress: M dv/dt =
// -p A (A = L_x L_z, fixed), a mass under a constant force. The midpoint
// scheme (L_m = L + dt/2 v, v+ = v - dt p A / M, L+ = L_m + dt/2 v+) is the
// trapezoidal rule, exact for a constant acceleration: after n steps v =
// -n dt p A/M and L = L0 - p A (n dt)^2 / (2 M), to round-off. L_x, L_z
// stay. With the brake (compaction_rate c / t_p) the rate stops at the
// floor -c L_m / t_p instead; with or without it, at the approach floor
// -alert / (4 dt) (here 25 m/s, not reached, until the last part).
TEST(Shear3Cell, HeightUnderPressureWithoutContactsIsAMassUnderAConstantForce) {
  WorldParams3 p;
  p.dt = 1e-5;
  p.alert = 1e-3;
  p.cell = Vec3(0.02, 0.05, 0.03);
  p.periodic = {true, true, true};
  p.pressure = 2e3;
  p.cell_mass = 0.5;
  p.cell_dof = {false, true, false};
  World3 w(p);
  w.bodies.add_sphere(Vec3(0.005, 0.004, 0.01), 0.002, 1000);
  w.bodies.add_sphere(Vec3(0.015, 0.006, 0.02), 0.002, 1000);
  const double A = p.cell.x() * p.cell.z(), a = p.pressure * A / p.cell_mass;
  const int n = 200;
  for (int k = 0; k < n; ++k) w.step();
  const double t = n * p.dt;
  EXPECT_NEAR(w.cell().rate.y(), -a * t, 1e-12 * a * t);
  EXPECT_NEAR(w.cell().size.y(), p.cell.y() - 0.5 * a * t * t, 1e-12 * p.cell.y());
  EXPECT_EQ(w.cell().size.x(), p.cell.x());
  EXPECT_EQ(w.cell().size.z(), p.cell.z());
  EXPECT_EQ(w.bodies.pos[0], Vec3(0.005, 0.004, 0.01));  // at rest, no drift
  std::printf("L_y: %.9g m after %d steps (closed form %.9g m)\n", w.cell().size.y(), n,
              p.cell.y() - 0.5 * a * t * t);

  // The brake: -dL/dt <= min(rate L_m, alert / (4 dt)).
  WorldParams3 q = p;
  q.max_strain_rate = 0.02;  // 1/s: reached after ~40 steps
  World3 b(q);
  b.bodies.add_sphere(Vec3(0.005, 0.004, 0.01), 0.002, 1000);
  bool floored = false;
  for (int k = 0; k < n; ++k) {
    const double Ly = b.cell().size.y(), Lm = Ly + 0.5 * q.dt * b.cell().rate.y();
    const double free = b.cell().rate.y() - q.dt * a;
    const double floor = -std::min(q.max_strain_rate * Lm, 0.25 * q.alert / q.dt);
    b.step();
    EXPECT_DOUBLE_EQ(b.cell().rate.y(), std::max(free, floor)) << k;
    floored = floored || free < floor;
  }
  EXPECT_TRUE(floored);  // the test reaches the brake

  // No brake (compaction_rate = 0: no bound on the rate) still keeps the
  // approach floor: -dL/dt <= alert / (4 dt) = 2.5e-3 m/s, reached after
  // ~100 steps, after which the rate stays exactly at it.
  WorldParams3 r = p;
  r.alert = 1e-7;
  World3 c(r);
  c.bodies.add_sphere(Vec3(0.005, 0.004, 0.01), 0.002, 1000);
  int at_floor = 0;
  for (int k = 0; k < n; ++k) {
    const double free = c.cell().rate.y() - r.dt * a, floor = -0.25 * r.alert / r.dt;
    c.step();
    EXPECT_DOUBLE_EQ(c.cell().rate.y(), std::max(free, floor)) << k;
    at_floor += free < floor;
  }
  EXPECT_GT(at_floor, 50);  // the test reaches the floor
}

// ---------------------------------------------------------------- compaction

namespace {

struct Window {
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero(), S2 = Eigen::Matrix3d::Zero();  // sigma + K, and its square
  double phi = 0, phi_min = INFINITY, phi_max = 0;
  int n = 0;
  void add(const World3& w) {
    const Eigen::Matrix3d s = w.contact_stress() + w.kinetic_stress();
    S += s;
    S2 += s.cwiseProduct(s);
    const double f = ::phi(w);
    phi += f;
    phi_min = std::min(phi_min, f);
    phi_max = std::max(phi_max, f);
    ++n;
  }
  Eigen::Matrix3d mean() const { return S / n; }
};

// Compacts prep_scene(n) for `steps` steps, then averages over `avg` more.
Window compact(World3& w, int steps, int avg) {
  for (int k = 0; k < steps; ++k) w.step();
  Window win;
  for (int k = 0; k < avg; ++k) {
    w.step();
    win.add(w);
  }
  return win;
}

}  // namespace

// Isotropic compaction of 100 frictional spheres (mu = 0.4, size ratio
// 1.5) from a gas (phi = 0.19) at p, the brake at 0.1 / t_p: the sample jams
// within ~150 steps (7 t_p) and creeps (measured at tol 1e-4: phi 0.5775 at
// step 450, 0.5785 at 970). Over steps 450-750 the mean of sigma_aa + K_aa
// (contact plus kinetic, what the dofs balance) is p on each axis within
// 1 %: each length's equation holds to the solver's tol (1e-3) every step,
// and the virial stress differs from the face impulse by the lengths'
// and grains' accelerations, which average out in a sample at rest (measured:
// 1.000 +- 0.002). phi: in the range of frictional random packings
// (random loose 0.55 - random close 0.64; mu = 0.4 gives ~0.58-0.59, Silbert
// 2010, Soft Matter 6, 2918), and stays within 0.005 over the window.
TEST(Shear3Cell, IsotropicCompactionReachesThePressureOnAllThreeAxes) {
  const Scene s = prep_scene(100);
  World3 w = build_world3(s);
  const double phi0 = phi(w);
  EXPECT_LT(phi0, 0.25);
  const Window a = compact(w, 450, 300);
  const Eigen::Matrix3d S = a.mean();
  std::printf("phi %.4f -> %.4f [%.4f, %.4f]; (sigma + K)/p = %.4f %.4f %.4f (xy %.2g); L = %.4g %.4g %.4g m\n", phi0,
              a.phi / a.n, a.phi_min, a.phi_max, S(0, 0) / s.pressure, S(1, 1) / s.pressure, S(2, 2) / s.pressure,
              S(0, 1) / s.pressure, w.cell().size.x(), w.cell().size.y(), w.cell().size.z());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(S(k, k) / s.pressure, 1.0, 0.01) << k;
  EXPECT_GT(a.phi_min, 0.55);
  EXPECT_LT(a.phi_max, 0.64);
  EXPECT_LT(a.phi_max - a.phi_min, 0.005);
  // Isotropic: the lengths are independent dofs at the same stress, so the
  // cube shrinks into a near cube (measured 1.07 for 100 spheres: the shape
  // a small jammed sample settles into is its own); no axis takes the load
  // for the others.
  const Vec3 L = w.cell().size;
  EXPECT_LT(L.maxCoeff() / L.minCoeff(), 1.15);
}

// ---------------------------------------------------------------- shear

namespace {

// The shear scene started from a sample: I, p, dt_tp as given.
Scene shear_scene(const std::string& start, double I) { return cdtest::shear3_shear_scene(start, I); }

// A compacted sample of n spheres in a checkpoint (the dofs' path of
// shear.start: a preparation's checkpoint).
// (A given cell L_x x L_y x L_z instead of the automatic cube: L non-zero.)
std::string prepared(const std::string& name, int n, int steps, const Vec3& L = Vec3::Zero()) {
  Scene prep = prep_scene(n);
  prep.cell_width = L.x(), prep.cell_height = L.y(), prep.cell_depth = L.z();
  World3 w = build_world3(prep);
  for (int k = 0; k < steps; ++k) w.step();
  const auto dir = cdtest::scratch_dir("test_shear3", name);
  const std::string path = (dir / "checkpoint.bin").string();
  save_checkpoint3(path, w, 1);
  return path;
}

}  // namespace

// Shear at I = 0.1 of 150 spheres from a compacted sample (shear.start):
// the images slide at gamma-dot L_y with gamma-dot = I sqrt(p/rho)/d
// exactly; the spheres' own mean flow (the least-squares slope of v_x(y)
// over the spheres, averaged over steps) is that rate, its profile linear
// (the mean of v_x - gamma-dot (y - L_y/2) in 5 layers is 0), and
// sigma_yy + K_yy = p on average. Strain 1 to forget the start, then
// strain 2 in 8 blocks: the tolerances are 3 standard errors of the block
// means plus 5 % (the cell is only ~5 d high: its mean flow fluctuates,
// correlated over about a strain of 0.5, more than a block: the slope over
// successive strain windows of 0.5 ranged 0.91-1.11 gamma-dot, mean 1.01
// over strain 4; here 1.05 +- 0.03, layers within 0.03 gamma-dot L_y). The
// run is deterministic (bit-identical on any thread count), so the check
// cannot flicker; the margin is what a fluctuating window needs.
TEST(Shear3Cell, ShearAtImposedInertialNumber) {
  const std::string start = prepared("shear", 150, 300);
  const double I = 0.1;
  const Scene s = shear_scene(start, I);
  World3 w = build_world3(s);
  const double gd = I / tp(s);
  EXPECT_DOUBLE_EQ(w.shear_rate(), gd);
  EXPECT_DOUBLE_EQ(w.params().shear_rate, gd);
  EXPECT_TRUE(w.cell_dofs());
  EXPECT_EQ(w.params().cell_dof, (std::array<bool, 3>{false, true, false}));
  const Vec3 L0 = w.cell().size;
  const int steps = static_cast<int>(std::lround(1.0 / gd / w.params().dt));  // strain 1
  for (int k = 0; k < steps; ++k) w.step();
  constexpr int nb = 5, nblk = 8;
  const int avg = 2 * steps;
  double slope[nblk] = {}, syy[nblk] = {}, dev[nblk][nb] = {}, cnt[nblk][nb] = {};
  for (int k = 0; k < avg; ++k) {
    w.step();
    const int q = k * nblk / avg;
    const Eigen::Matrix3d S = w.contact_stress() + w.kinetic_stress();
    syy[q] += S(1, 1) / (avg / nblk);
    const double L = w.cell().size.y();
    // The images' velocity: gamma-dot times the step's midpoint height.
    EXPECT_NEAR(w.le_velocity(), gd * L, 1e-3 * gd * L);
    double sy = 0, sv = 0, syy2 = 0, syv = 0, m = 0;
    for (std::size_t i = 0; i < w.bodies.size(); ++i) {
      const double y = w.bodies.pos[i].y(), v = w.bodies.vel[i].v.x();
      sy += y, sv += v, syy2 += y * y, syv += y * v, m += 1;
      const int b = std::min(nb - 1, static_cast<int>(y / L * nb));
      dev[q][b] += (v - gd * (y - 0.5 * L)) / (gd * L);
      cnt[q][b] += 1;
    }
    slope[q] += (m * syv - sy * sv) / (m * syy2 - sy * sy) / (avg / nblk);
  }
  const auto stats = [&](auto f, double& mean, double& se) {
    double a = 0, a2 = 0;
    for (int q = 0; q < nblk; ++q) a += f(q) / nblk, a2 += f(q) * f(q) / nblk;
    mean = a;
    se = std::sqrt(std::max(0.0, a2 - a * a) / (nblk - 1));
  };
  double sm, sse, pm, pse;
  stats([&](int q) { return slope[q] / gd; }, sm, sse);
  stats([&](int q) { return syy[q] / s.pressure; }, pm, pse);
  std::printf("gamma-dot %.5g /s; flow slope / gamma-dot = %.4f +- %.4f; (sigma_yy + K_yy)/p = %.4f +- %.4f; "
              "L_y %.4g -> %.4g m\n", gd, sm, sse, pm, pse, L0.y(), w.cell().size.y());
  EXPECT_NEAR(sm, 1.0, 3 * sse + 0.05);
  EXPECT_NEAR(pm, 1.0, 3 * pse + 0.05);
  for (int b = 0; b < nb; ++b) {
    double dm, dse;
    stats([&](int q) { return dev[q][b] / cnt[q][b]; }, dm, dse);
    std::printf("  layer %d: <v_x - gamma-dot (y - L_y/2)> = %.4f +- %.4f gamma-dot L_y\n", b, dm, dse);
    EXPECT_NEAR(dm, 0.0, 3 * dse + 0.05) << b;
  }
  // L_x, L_z fixed; the strain counted.
  EXPECT_EQ(w.cell().size.x(), L0.x());
  EXPECT_EQ(w.cell().size.z(), L0.z());
  EXPECT_NEAR(w.cell().strain, 3.0, 1e-9);
}

// ---------------------------------------------------------------- restart, threads

// A shear run at imposed p and I (height a dof, images sliding, warm
// starts) stopped after 40 steps and resumed from its checkpoint in a world
// rebuilt from the scene, on 2 threads with every loop parallel
// (min_parallel = 1), ends bit-identical to 100 steps never stopped on 1
// thread: positions, velocities, the cell's lengths, rates, offset, strain.
// With compliant contacts too (contact.stiffness_number): their springs'
// forces are the warm-start memory, which the checkpoint must carry; and
// compliant with cohesion (eta = 10), where that memory also decides which
// bonds are springs in tension (no gap term: method.md section 15).
TEST(Shear3Cell, CheckpointResumesBitIdenticallyOnOneOrTwoThreads) {
  const std::string start = prepared("restart", 100, 200);
  struct Case {
    double kappa, eta;
    const char* name;
  };
  for (const Case cs : {Case{0.0, 0.0, "ckpt"}, Case{1e4, 0.0, "ckpt_compliant"},
                        Case{1e4, 10.0, "ckpt_compliant_cohesive"}}) {
    const double kappa = cs.kappa;
    SCOPED_TRACE(cs.name);
    Scene s = shear_scene(start, 0.1);
    s.stiffness_number = kappa;
    s.cohesion_number = cs.eta;
    const auto make = [&] { return cdtest::parallel_world3(s); };
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    World3 a = make();
    for (int k = 0; k < 100; ++k) a.step();
    World3 b = make();
    for (int k = 0; k < 40; ++k) b.step();
    const auto dir = cdtest::scratch_dir("test_shear3", cs.name);
    const std::string path = (dir / "checkpoint.bin").string();
    save_checkpoint3(path, b, 5);
    World3 c = make();
    load_checkpoint3(path, c);
    omp_set_num_threads(2);
    for (int k = 0; k < 60; ++k) c.step();
    omp_set_num_threads(saved);
    ASSERT_GT(a.rows().size(), 200u);  // dense: contacts across the moving faces
    int across = 0;
    for (const ContactInfo3& f : a.infos()) across += f.iy != 0;
    EXPECT_GT(across, 0);
    EXPECT_NE(a.cell().rate.y(), 0.0);
    for (std::size_t i = 0; i < a.bodies.size(); ++i) {
      ASSERT_EQ(c.bodies.pos[i], a.bodies.pos[i]) << i;
      ASSERT_EQ(c.bodies.vel[i].v, a.bodies.vel[i].v) << i;
      ASSERT_EQ(c.bodies.vel[i].w, a.bodies.vel[i].w) << i;
    }
    EXPECT_EQ(c.cell().size, a.cell().size);
    EXPECT_EQ(c.cell().rate, a.cell().rate);
    EXPECT_EQ(c.cell().le_offset, a.cell().le_offset);
    EXPECT_EQ(c.cell().strain, a.cell().strain);
    EXPECT_EQ(a.params().stiffness > 0, kappa > 0);
    if (cs.eta > 0) {
      int pulling = 0;  // bonds in tension at the end: the case is exercised
      for (const SphereRow& r : a.rows()) pulling += r.r[0] < 0.0;
      EXPECT_GT(pulling, 0);
    }
  }
}

// ---------------------------------------------------------------- bad input

// shear.start: a 2D checkpoint (its dimension), a 3D pile's (its cell),
// spheres of another density or mean diameter are refused, naming why.
TEST(Shear3Cell, StartRefusesOtherSamples) {
  const auto refused = [](const Scene& s, const std::string& what) {
    try {
      build_world3(s);
      ADD_FAILURE() << what << ": accepted";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("shear.start"), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
    }
  };
  const auto dir = cdtest::scratch_dir("test_shear3", "bad");
  // A 3D sample of loose spheres (0 steps: the checkpoint format is the same).
  const std::string good = prepared("bad-good", 30, 0);
  Scene s = shear_scene(good, 0.1);
  s.n = 0;
  EXPECT_NO_THROW(build_world3(s));
  { Scene t = s; t.density = 1000; refused(t, "density"); }
  { Scene t = s; t.d_mean = 2e-3; refused(t, "mean diameter"); }
  { Scene t = s; t.n = 10; refused(t, "particles.n = 0"); }
  { Scene t = s; t.cell_width = t.cell_height = t.cell_depth = 0.01; refused(t, "gives the cell"); }
  { Scene t = s; t.start = (dir / "missing.bin").string(); refused(t, "missing.bin"); }
  // A 2D checkpoint.
  {
    Scene s2;
    s2.dimension = 2;
    s2.gravity = {0, 0};
    s2.shear_mode = cd::ShearMode::Periodic;
    s2.n = 20;
    s2.d_mean = 1e-3;
    s2.density = 2.6;
    World w2 = build_world(s2);
    const std::string p2 = (dir / "2d.bin").string();
    save_checkpoint(p2, w2, 1);
    Scene t = s;
    t.start = p2;
    refused(t, "dimension");
  }
  // A 3D pile's checkpoint: no cell.
  {
    Scene pile = prep_scene(20);
    pile.shear_mode = cd::ShearMode::None;
    pile.pressure = 0;
    pile.isotropic = false;
    pile.compaction_rate = 0;
    pile.dt_tp = 0;
    pile.dt = 1e-5;
    pile.gravity = {0, 0, -9.81};
    World3 wp = build_world3(pile);
    const std::string pp = (dir / "pile.bin").string();
    save_checkpoint3(pp, wp, 1);
    Scene t = s;
    t.start = pp;
    refused(t, "periodic");
  }
}

// The keys of the protocol without what they need, refused by name (with a
// pressure they are accepted: the tests above).
TEST(Shear3Cell, KeysWithoutWhatTheyNeedAreRefusedByName) {
  const auto refused = [](const Scene& s, const std::string& key) {
    try {
      check_scene3(s);
      ADD_FAILURE() << key << " accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  const Scene s = prep_scene(100);
  EXPECT_NO_THROW(check_scene3(s));
  { Scene t = s; t.inertial_number = 0.1; refused(t, "shear.isotropic"); }
  { Scene t = s; t.isotropic = false; t.strain = 1; refused(t, "shear.strain > 0 needs shear.inertial_number"); }
  { Scene t = s; t.checkpoint_strain = 0.5; refused(t, "output.checkpoint_strain"); }
  // The cohesion number works at imposed pressure (tests/test_cohesion3.cpp); not with a given f_a.
  { Scene t = s; t.cohesion_number = 0.5; EXPECT_NO_THROW(check_scene3(t)); }
  { Scene t = s; t.cohesion_number = 0.5; t.adhesion = 1e-3; refused(t, "contact.cohesion_number"); }
  { Scene t = s; t.pressure = 0; t.dt_tp = 0; t.dt = 1e-5; refused(t, "shear.isotropic needs shear.pressure"); }
  { Scene t = s; t.pressure = 0; t.isotropic = false; t.dt_tp = 0; t.dt = 1e-5; refused(t, "shear.compaction_rate needs shear.pressure"); }
  { Scene t = s; t.pressure = std::nan(""); refused(t, "t_p"); }
  // The lengths shrink by at most a quarter of the alert distance a step:
  // with none they could not shrink.
  { Scene t = s; t.alert = 0; refused(t, "shear.pressure > 0 needs contact.alert > 0"); }
  { Scene t = s; t.alert = 0; t.compaction_rate = 0; refused(t, "shear.pressure > 0 needs contact.alert > 0"); }
  // The overlap projection serves 3D too (tests/test_projection3.cpp).
  { Scene t = s; t.overlap_projection = 0.5; EXPECT_NO_THROW(check_scene3(t)); }
}

// output.checkpoint_strain in 3D: the plan (core/run_plan.hpp's, shared) puts a
// checkpoint every 0.25 of strain on series rows, and a cdsim-style run
// (run3) to strain 0.5 leaves a checkpoint whose cell is the run's last
// (lengths, rate, offset, strain 0.5) and whose spheres are the world's.
TEST(Shear3Cell, CheckpointByStrain) {
  const std::string start = prepared("ckstrain", 60, 100);
  Scene s = shear_scene(start, 0.1);
  s.strain = 0.5;
  s.checkpoint_strain = 0.25;
  const double dt = time_step(s), gd = shear_rate(s);
  s.series_interval = 5 * dt;
  const RunPlan plan = plan_of(s, dt);
  EXPECT_EQ(plan.nsteps, 100);  // 0.5 / (gd dt) = 0.5 / (0.1 x 0.05)
  EXPECT_EQ(plan.every_ckpt_strain, 50);
  EXPECT_NEAR(plan.every_ckpt_strain * dt * gd, 0.25, 1e-9);
  World3 w = build_world3(s);
  const auto dir = cdtest::scratch_dir("test_shear3", "ckstrain-run");
  RunOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  opt.fresh = true;
  run3(w, s, opt);
  EXPECT_NEAR(w.cell().strain, 0.5, 1e-9);
  // series.csv's strain column (as in 2D) is gamma-dot t at every row: the
  // rate is imposed, so row k (every 5 steps) is at 5 k dt gd; the last 0.5.
  {
    std::ifstream f(dir / "series.csv");
    std::string line;
    std::getline(f, line);
    int col = -1, k = 0;
    std::istringstream h(line);
    for (std::string name; std::getline(h, name, ','); ++k)
      if (name == "strain") col = k;
    ASSERT_GE(col, 0) << "series.csv has no strain column";
    int rows = 0;
    double strain = -1;
    while (std::getline(f, line)) {
      std::istringstream r(line);
      std::string v;
      for (int j = 0; j <= col; ++j) std::getline(r, v, ',');
      strain = std::stod(v);
      ++rows;
      EXPECT_NEAR(strain, 5 * rows * dt * gd, 1e-9) << "row " << rows;
    }
    EXPECT_EQ(rows, 20);
    EXPECT_NEAR(strain, 0.5, 1e-9);
  }
  World3 c = build_world3(s);
  load_checkpoint3((dir / "checkpoint.bin").string(), c);
  EXPECT_EQ(c.cell().strain, w.cell().strain);
  EXPECT_EQ(c.cell().size, w.cell().size);
  EXPECT_EQ(c.cell().rate, w.cell().rate);
  EXPECT_EQ(c.cell().le_offset, w.cell().le_offset);
  for (std::size_t i = 0; i < w.bodies.size(); ++i) ASSERT_EQ(c.bodies.pos[i], w.bodies.pos[i]) << i;
}

// ---------------------------------------------------------------- wraps

// 150 spheres compacted in a cell about twice as tall (y) as long (x),
// then sheared at I = 0.1 to strain 2: the offset gamma L_y passes L_x
// every strain L_x/L_y ~ 0.5, about four wraps. A wrap must look like any
// other step (le_wrap_util.hpp, as in 2D: test_shear.cpp).
TEST(LeesEdwardsWrap, WrapsOfTheOffsetAreContinuous3D) {
  const std::string start = prepared("wrap", 150, 450, Vec3(0.0052, 0.0104, 0.0064));
  Scene s = shear_scene(start, 0.1);
  s.strain = 2.0;
  World3 w = build_world3(s);
  const Vec3 L = w.cell().size;
  EXPECT_GT(L.y() / L.x(), 1.5);
  const int n = static_cast<int>(std::lround(s.strain / w.shear_rate() / w.params().dt));
  std::vector<cdtest::WrapStep> steps;
  std::size_t settle = 0;
  for (int k = 0; k < n; ++k) {
    w.step();
    const Eigen::Matrix3d S = w.contact_stress();
    steps.push_back({w.cell().le_offset, double(w.last().active), w.last().max_overlap, S(0, 1), S(1, 1),
                     w.kinetic_energy()});
    if (w.cell().strain < 0.3) settle = steps.size();  // the start-up transient left out
  }
  // max_overlap is of the mean diameter d_ref: 1 % of the smallest grain's.
  double r_min = w.bodies.radius[0];
  for (double r : w.bodies.radius) r_min = std::min(r_min, r);
  cdtest::expect_wraps_continuous(steps, settle, 3, 0.01 * 2 * r_min / w.params().d_ref, "3D, L_y/L_x = " + std::to_string(L.y() / L.x()));
}
