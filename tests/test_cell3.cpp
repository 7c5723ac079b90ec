// The tri-periodic 3D cell. First the observables: the contact
// stress sum f (x) l / V with branch vectors through periodic and
// Lees-Edwards images, its invariants, the kinetic stress about the mean
// shear flow, and the series columns built from them (run3.hpp:
// cell_columns3). Every expected value is analytic: a perfectly inelastic
// frictionless impact between equal spheres that touch at the step's start
// stops their approach in one step with the impulse P = (m/2) u_n, so the
// step's force on each contact is P/dt along n exactly. The branch vector
// is the one of the step's contact, at the midpoint configuration (method.md
// section 6): the centres have closed by dt/2 times their approach speed.
// Then the scene of a cell (placement, refusals, a run's columns); and a 3D
// checkpoint carrying the cell.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <numbers>
#include <string>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_util.hpp"
#include "checkpoint3.hpp"
#include "run3.hpp"
#include "setup3.hpp"
#include "world3.hpp"

using namespace cd;

namespace {

std::map<std::string, double> as_map(const Columns& c) {
  std::map<std::string, double> m;
  for (const auto& [k, v] : c) m[k] = v;
  return m;
}

WorldParams3 cell_params(const Vec3& L) {
  WorldParams3 p;
  p.dt = 1e-4;
  p.mu = 0.0;
  p.alert = 0.0;
  p.solver.tol = 1e-14;
  p.solver.max_iter = 1000;
  p.cell = L;
  p.periodic = {true, true, true};
  return p;
}

}  // namespace

// A simple-cubic lattice of 4 x 3 x 3 touching spheres (diameter d, pitch d)
// fills the cell [0, 4d) x [0, 3d) x [0, 3d). Sphere i along x moves at
// v_x = -(-1)^i v: spheres 1 and 2 approach each other, and so do sphere 3
// and the image of sphere 0 at +4d (a contact through the x image); the
// other x pairs separate and the y, z neighbours move together. Each
// approaching pair takes P = m v, f = m v / dt along x, with branch vector
// +l e_x, l = d - v dt at the midpoint (through the image: not the -3d
// between the two centres). So
//     sigma_xx = 18 pairs x f l / V = m v l / (2 dt d^3),
// every other component 0; p = sigma_xx / 3; q = sigma_xx (uniaxial).
// Every sphere has exactly one force-bearing contact: all are rattlers
// (z = 0, non_rattler = 0). The packing fraction is pi/6.
TEST(Cell3Observables, SimpleCubicImpactStressThroughXImage) {
  const double d = 0.01, r = d / 2, rho = 2600, v = 0.05;
  WorldParams3 p = cell_params(Vec3(4 * d, 3 * d, 3 * d));
  World3 w(p);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i)
        w.bodies.add_sphere(Vec3((i + 0.5) * d, (j + 0.5) * d, (k + 0.5) * d), r, rho,
                            Vec3(i % 2 == 0 ? -v : v, 0, 0));
  const double m = w.bodies.mass[0];
  w.step();
  // Every approaching pair has stopped.
  for (std::size_t i = 0; i < w.bodies.size(); ++i) EXPECT_NEAR(w.bodies.vel[i].v.norm(), 0.0, 1e-12 * v);
  const double V = 36 * d * d * d;
  EXPECT_DOUBLE_EQ(w.cell_volume(), V);
  const Eigen::Matrix3d S = w.contact_stress();
  const double sxx = m * v * (d - v * p.dt) / (2 * p.dt * d * d * d);
  EXPECT_NEAR(S(0, 0), sxx, 1e-12 * sxx);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i + j > 0) {
        EXPECT_NEAR(S(i, j), 0.0, 1e-12 * sxx) << i << j;
      }
  // 18 bearing contacts, half of them through the x image.
  int bearing = 0, through_image = 0;
  for (std::size_t k = 0; k < w.rows().size(); ++k)
    if (w.rows()[k].r[0] > 0) {
      ++bearing;
      through_image += w.infos()[k].ix != 0;
    }
  EXPECT_EQ(bearing, 18);
  EXPECT_EQ(through_image, 9);

  const auto c = as_map(cell_columns3(w, S, rho, d));
  EXPECT_NEAR(c.at("sxx"), sxx, 1e-12 * sxx);
  EXPECT_NEAR(c.at("p"), sxx / 3, 1e-12 * sxx);
  EXPECT_NEAR(c.at("q"), sxx, 1e-12 * sxx);
  EXPECT_NEAR(c.at("q_over_p"), 3.0, 1e-12);
  EXPECT_EQ(c.at("shear_stress_ratio"), 0.0);  // sigma_yy = 0
  EXPECT_EQ(c.at("shear_rate"), 0.0);
  EXPECT_EQ(c.at("strain"), 0.0);  // no shear: gamma stays 0
  EXPECT_NEAR(c.at("packing_fraction"), std::numbers::pi / 6, 1e-14);
  EXPECT_EQ(c.at("z"), 0.0);
  EXPECT_EQ(c.at("non_rattler"), 0.0);
  EXPECT_DOUBLE_EQ(c.at("cell_width"), 4 * d);
  EXPECT_DOUBLE_EQ(c.at("cell_height"), 3 * d);
  EXPECT_DOUBLE_EQ(c.at("cell_depth"), 3 * d);
  // At rest after the impacts: no kinetic stress.
  for (const char* k : {"kxx", "kxy", "kxz", "kyy", "kyz", "kzz"}) EXPECT_NEAR(c.at(k), 0.0, 1e-20) << k;
  EXPECT_EQ(c.size(), 2 + 9 + 8 + 3 + 6u);
}

// Two spheres in contact through the Lees-Edwards image: A near the top of
// the cell, B near the bottom, the cell's y images shifted by le_offset
// along x (at rest: le_velocity 0). B's image above A sits at branch
// d n (n out of the xy plane), and A moves towards it at u along n. The
// frictionless inelastic impact gives P = (m/2) u, the midpoint branch is
// l = (d - u dt/2) n, so sigma = (P/dt) l n n^T / V: a full tensor with
// sigma_xy = sigma_yx, and mu = -sigma_xy/sigma_yy = -n_x/n_y.
TEST(Cell3Observables, TwoSphereContactThroughLeesEdwardsImage) {
  const double d = 0.01, r = d / 2, rho = 2600, u = 0.03;
  const Vec3 L(5 * d, 4 * d, 3 * d);
  WorldParams3 p = cell_params(L);
  p.le_offset = 1.7 * d;
  World3 w(p);
  const Vec3 n = Vec3(-0.5, 0.8, 0.3).normalized();  // n_x < 0: mu > 0
  const Vec3 xa(2.5 * d, L.y() - 0.7 * d, 1.5 * d);
  const Vec3 img = xa + d * n;  // B's image, above the cell
  const Vec3 xb = img - Vec3(p.le_offset, L.y(), 0);
  w.bodies.add_sphere(xa, r, rho, u * n);
  w.bodies.add_sphere(xb, r, rho);
  const double m = w.bodies.mass[0];
  w.step();
  ASSERT_EQ(w.rows().size(), 1u);
  EXPECT_NE(w.infos()[0].iy, 0);
  const double V = L.x() * L.y() * L.z();
  const double f = 0.5 * m * u / p.dt;
  const Eigen::Matrix3d S = w.contact_stress();
  const double l = d - 0.5 * u * p.dt;
  const Eigen::Matrix3d expect = f * l * n * n.transpose() / V;
  const double scale = f * l / V;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(S(i, j), expect(i, j), 1e-10 * scale) << i << j;
  const auto c = as_map(cell_columns3(w, S, rho, d));
  EXPECT_NEAR(c.at("p"), scale / 3, 1e-10 * scale);  // tr(n n^T) = 1
  EXPECT_NEAR(c.at("shear_stress_ratio"), -n.x() / n.y(), 1e-9);
  EXPECT_GT(c.at("shear_stress_ratio"), 0.0);
  EXPECT_NEAR(c.at("syz"), expect(1, 2), 1e-10 * scale);
  // One contact each: both rattlers.
  EXPECT_EQ(c.at("non_rattler"), 0.0);
  // Momentum: both spheres leave at u/2 along n.
  EXPECT_NEAR((w.bodies.vel[0].v - 0.5 * u * n).norm(), 0.0, 1e-10 * u);
  EXPECT_NEAR((w.bodies.vel[1].v - 0.5 * u * n).norm(), 0.0, 1e-10 * u);
}

// The kinetic stress removes the mean shear flow gd y e_x and the mean
// velocity: spheres (apart, no contacts) on the flow v_x = gd y, plus a
// drift c shared by all, plus +-delta e_z and +-eps e_y in pairs, give
// K_zz = N m delta^2 / V, K_yy = N m eps^2 / V, K_yz = N m delta eps / V
// (same signs in a pair), the x components 0; the inertial_number column is
// gd d sqrt(rho / (S_yy + K_yy)).
TEST(Cell3Observables, KineticStressAboutTheShearFlow) {
  const double d = 0.01, r = d / 2, rho = 2600, gd = 3.0, delta = 0.02, eps = 0.01;
  const Vec3 L(6 * d, 6 * d, 6 * d);
  WorldParams3 p = cell_params(L);
  p.le_velocity = gd * L.y();
  World3 w(p);
  EXPECT_DOUBLE_EQ(w.shear_rate(), gd);
  const Vec3 drift(0.1, -0.05, 0.07);
  int N = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) {
      const double s = (j + k) % 2 == 0 ? 1.0 : -1.0;
      const Vec3 x((0.5 + 2 * k) * d, (0.5 + 2 * j) * d, (1.0 + 2 * ((j + k) % 3)) * d);
      w.bodies.add_sphere(x, r, rho, drift + Vec3(gd * x.y(), s * eps, s * delta));
      ++N;
    }
  // The +- pairs: 5 of +1 and 4 of -1; the mean removes the odd one's share.
  const double m = w.bodies.mass[0], V = L.prod();
  double mean_s = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) mean_s += ((j + k) % 2 == 0 ? 1.0 : -1.0) / N;
  const double var = 1.0 - mean_s * mean_s;  // <s^2> - <s>^2
  const Eigen::Matrix3d K = w.kinetic_stress();
  const double kzz = N * m * delta * delta * var / V;
  EXPECT_NEAR(K(2, 2), kzz, 1e-12 * kzz);
  EXPECT_NEAR(K(1, 1), N * m * eps * eps * var / V, 1e-12 * kzz);
  EXPECT_NEAR(K(1, 2), N * m * eps * delta * var / V, 1e-12 * kzz);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(K(0, i), 0.0, 1e-12 * kzz) << i;
  const Eigen::Matrix3d S = Eigen::Vector3d(0, 50.0, 0).asDiagonal();
  const auto c = as_map(cell_columns3(w, S, rho, d));
  EXPECT_NEAR(c.at("inertial_number"), gd * d * std::sqrt(rho / (50.0 + K(1, 1))), 1e-12);
  EXPECT_DOUBLE_EQ(c.at("shear_rate"), gd);
}

// ---------------------------------------------------------------- scenes

namespace {

Scene cell_scene(int n) {
  Scene s;
  s.dimension = 3;
  s.gravity = {0, 0, 0};
  s.shear_mode = cd::ShearMode::Periodic;
  s.n = n;
  s.d_mean = 0.01;
  s.size_ratio = 1.5;
  s.density = 2600;
  s.dt = 1e-4;
  s.duration = 2e-3;
  s.mu = 0.3;
  s.alert = 0.05;
  s.series_interval = 2e-4;
  return s;
}

// Smallest gap between two spheres over all pairs, through the nearest
// periodic image (brute force).
double min_gap(const World3& w) {
  const Vec3 L = w.cell().size;
  double g = INFINITY;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    for (std::size_t j = i + 1; j < w.bodies.size(); ++j) {
      Vec3 d = w.bodies.pos[j] - w.bodies.pos[i];
      for (int a = 0; a < 3; ++a) d[a] -= L[a] * std::round(d[a] / L[a]);
      g = std::min(g, d.norm() - w.bodies.radius[i] - w.bodies.radius[j]);
    }
  return g;
}

}  // namespace

// shear.mode = "periodic" in a dimension = 3 scene: a tri-periodic cell,
// 0 x 0 x 0 the cube of side k pitch (k = ceil(N^(1/3)) = 6 for 150, pitch
// 1.02 d_max), no walls, the spheres inside it, none touching another or an
// image (the jitter stays within the slack), at rest. With no gravity and
// nothing in contact, 20 steps leave every sphere where it was, and the
// series columns show zero stress and the packing fraction sum(pi d^3/6)/V.
TEST(Cell3Scene, PeriodicSceneIsATriPeriodicCellOfLooseSpheres) {
  const Scene s = cell_scene(150);
  World3 w = build_world3(s);
  const auto [d_min, d_max] = diameter_bounds(s);
  const double side = 6 * 1.02 * d_max * (1 + 1e-9);  // the 1e-9: floor(side / pitch) = 6
  const WorldParams3& p = w.params();
  EXPECT_TRUE(p.periodic[0] && p.periodic[1] && p.periodic[2]);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(p.cell[a], side, 1e-12 * side) << a;
  EXPECT_EQ(p.gravity, Vec3::Zero());
  ASSERT_EQ(w.bodies.size(), 150u);
  double vol = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    EXPECT_EQ(w.bodies.shape[i], Shape3::Sphere);
    EXPECT_GE(2 * w.bodies.radius[i], d_min * (1 - 1e-12));
    EXPECT_LE(2 * w.bodies.radius[i], d_max * (1 + 1e-12));
    for (int a = 0; a < 3; ++a) {
      EXPECT_GT(w.bodies.pos[i][a], w.bodies.radius[i]) << i;
      EXPECT_LT(w.bodies.pos[i][a], side - w.bodies.radius[i]) << i;
    }
    vol += std::numbers::pi / 6 * std::pow(2 * w.bodies.radius[i], 3);
  }
  const double g0 = min_gap(w);
  EXPECT_GT(g0, 0.0);
  std::printf("150 spheres: cell %.4g m, packing fraction %.4f, smallest gap %.3g d_mean\n", side,
              vol / (side * side * side), g0 / s.d_mean);
  const std::vector<Vec3> x0 = w.bodies.pos;
  for (int k = 0; k < 20; ++k) w.step();
  for (std::size_t i = 0; i < w.bodies.size(); ++i) EXPECT_EQ(w.bodies.pos[i], x0[i]) << i;
  const auto c = as_map(cell_columns3(w, w.contact_stress(), s.density, s.d_mean));
  EXPECT_NEAR(c.at("packing_fraction"), vol / (side * side * side), 1e-12);
  EXPECT_EQ(c.at("p"), 0.0);
  EXPECT_EQ(c.at("z"), 0.0);

  // Lengths given: the cell is those.
  Scene g = s;
  g.cell_width = 0.08;
  g.cell_height = 0.07;
  g.cell_depth = 0.09;
  const World3 wg = build_world3(g);
  EXPECT_EQ(wg.cell().size, Vec3(0.08, 0.07, 0.09));
  EXPECT_GT(min_gap(wg), 0.0);
}

// What a 3D cell does not have, or a key without what it needs, is refused
// by key (SceneError: cdsim exits 2, as Scene3.BadInputIsRefusedNamingTheKey
// checks through cdsim).
TEST(Cell3Scene, UnsupportedKeysAreRefusedByName) {
  const auto refused = [](Scene s, const std::string& key) {
    try {
      check_scene3(s);
      ADD_FAILURE() << key << " accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  Scene s = cell_scene(100);
  EXPECT_NO_THROW(check_scene3(s));
  // The protocol's keys without the pressure they need (tests/test_shear3.cpp: with it).
  { Scene t = s; t.pressure = 100; EXPECT_NO_THROW(check_scene3(t)); }
  { Scene t = s; t.inertial_number = 0.1; refused(t, "shear.inertial_number needs shear.pressure"); }
  { Scene t = s; t.isotropic = true; refused(t, "shear.isotropic needs shear.pressure"); }
  { Scene t = s; t.compaction_rate = 0.01; refused(t, "shear.compaction_rate needs shear.pressure"); }
  { Scene t = s; t.strain = 1; refused(t, "shear.strain"); }
  { Scene t = s; t.dt_tp = 0.01; refused(t, "shear.dt_tp"); }
  { Scene t = s; t.start = "x/checkpoint.bin"; refused(t, "shear.start"); }
  { Scene t = s; t.cohesion_number = 1; refused(t, "contact.cohesion_number"); }
  { Scene t = s; t.checkpoint_strain = 1; refused(t, "output.checkpoint_strain"); }
  { Scene t = s; t.gravity = {0, 0, -9.81}; refused(t, "gravity.g"); }
  { Scene t = s; t.box_width = t.box_depth = 0.1; refused(t, "box.width"); }
  { Scene t = s; t.cell_width = 0.1; refused(t, "shear.depth"); }
  { Scene t = s; t.cell_width = t.cell_height = 0.1; t.cell_depth = 0.025; refused(t, "shear.depth = 0.025"); }
  { Scene t = s; t.cell_width = t.cell_height = t.cell_depth = 0.04; refused(t, "particles.n = 100"); }
  { Scene t = s; t.shear_mode = cd::ShearMode::Walls; refused(t, "shear.mode"); }
  { Scene t = s; t.shear_mode = cd::ShearMode::None; t.cell_depth = 0.1; refused(t, "depth"); }
}

// A cdsim-style run of a cell (run3 through the shared run loop) writes the
// cell's columns into series.csv. The spheres get a random velocity each
// (a granular gas, no contacts at first): in a closed periodic cell the
// total momentum is conserved to round-off and the kinetic stress of the
// last row equals the one computed from the final state; the trace of the
// contact stress is >= 0 (frictional inelastic contacts only push).
TEST(Cell3Scene, RunWritesTheCellColumns) {
  const Scene s = cell_scene(64);
  World3 w = build_world3(s);
  std::mt19937_64 g(7);
  std::normal_distribution<double> N(0.0, 0.2);
  Vec3 P0 = Vec3::Zero();
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    w.bodies.vel[i].v = Vec3(N(g), N(g), N(g));
    P0 += w.bodies.mass[i] * w.bodies.vel[i].v;
  }
  const auto dir = cdtest::scratch_dir("test_cell3", "run");
  RunOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  opt.fresh = true;
  run3(w, s, opt);
  Vec3 P = Vec3::Zero();
  double pm = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    P += w.bodies.mass[i] * w.bodies.vel[i].v;
    pm += w.bodies.mass[i] * 0.2;
  }
  EXPECT_LT((P - P0).norm(), 1e-12 * pm);
  std::ifstream f(dir / "series.csv");
  std::string head, line, last;
  std::getline(f, head);
  int rows = 0;
  while (std::getline(f, line)) last = line, ++rows;
  EXPECT_EQ(rows, 10);
  std::vector<std::string> names, vals;
  for (std::istringstream h(head); std::getline(h, line, ',');) names.push_back(line);
  for (std::istringstream h(last); std::getline(h, line, ',');) vals.push_back(line);
  ASSERT_EQ(names.size(), vals.size());
  std::map<std::string, double> row;
  for (std::size_t i = 0; i < names.size(); ++i) row[names[i]] = std::stod(vals[i]);
  for (const char* k : {"strain", "shear_rate", "sxx", "sxy", "sxz", "syx", "syy", "syz", "szx", "szy", "szz", "p", "q", "q_over_p",
                        "shear_stress_ratio", "inertial_number", "packing_fraction", "z", "non_rattler",
                        "cell_width", "cell_height", "cell_depth", "kxx", "kxy", "kxz", "kyy", "kyz", "kzz"})
    EXPECT_TRUE(row.count(k)) << k;
  const Eigen::Matrix3d K = w.kinetic_stress();
  EXPECT_NEAR(row["kxx"], K(0, 0), 1e-6 * K.trace());
  EXPECT_NEAR(row["kyz"], K(1, 2), 1e-6 * K.trace());
  EXPECT_GT(K.trace(), 0.0);
  EXPECT_GE(row["p"], 0.0);
  EXPECT_NEAR(row["p"], (row["sxx"] + row["syy"] + row["szz"]) / 3, 1e-6 * std::abs(row["p"]) + 1e-300);
  std::printf("gas: %d rows, last p = %.4g Pa, K_tr/3 = %.4g Pa\n", rows, row["p"], K.trace() / 3);
}

// ---------------------------------------------------------------- checkpoint

// A 3D checkpoint carries the cell's state: a sheared gas (Lees-Edwards
// images moving at gd L_y, le_offset advancing every step) stopped after 40
// steps and continued from its checkpoint in a world rebuilt from the scene
// (le_offset 0 there) ends bit-identical to 80 steps never stopped,
// le_offset included. Without the cell in the checkpoint the resumed run
// starts from offset 0 and the images, hence the contacts, differ. A
// checkpoint of a cell is refused by a world without one.
TEST(Cell3Checkpoint, ResumesTheLeesEdwardsOffset) {
  const Scene s = cell_scene(64);
  const auto make = [&] {
    World3 w = build_world3(s);
    WorldParams3 p = w.params();
    p.le_velocity = 40.0 * p.cell.y();  // gd = 40 /s
    w.set_params(p);
    std::mt19937_64 g(3);
    std::normal_distribution<double> N(0.0, 0.3);
    for (std::size_t i = 0; i < w.bodies.size(); ++i) w.bodies.vel[i].v = Vec3(N(g), N(g), N(g));
    return w;
  };
  World3 a = make();
  for (int k = 0; k < 80; ++k) a.step();
  World3 b = make();
  for (int k = 0; k < 40; ++k) b.step();
  const auto dir = cdtest::scratch_dir("test_cell3", "ckpt");
  const std::string path = (dir / "checkpoint.bin").string();
  save_checkpoint3(path, b, 42);
  World3 c = make();
  EXPECT_EQ(c.cell().le_offset, 0.0);
  EXPECT_EQ(load_checkpoint3(path, c), 42u);
  EXPECT_EQ(c.cell().le_offset, b.cell().le_offset);
  EXPECT_NE(c.cell().le_offset, 0.0);
  for (int k = 0; k < 40; ++k) c.step();
  EXPECT_EQ(c.cell().le_offset, a.cell().le_offset);
  bool contacts = false;
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(c.bodies.pos[i], a.bodies.pos[i]) << i;
    EXPECT_EQ(c.bodies.vel[i].v, a.bodies.vel[i].v) << i;
  }
  for (const SphereRow& r : a.rows()) contacts = contacts || r.r[0] > 0;
  EXPECT_TRUE(contacts);  // the gas collides: the comparison sees the images
  std::printf("le_offset after 80 steps: %.6g m (cell %.4g m)\n", a.cell().le_offset, a.cell().size.x());

  Scene box = s;
  box.shear_mode = cd::ShearMode::None;
  box.gravity = {0, 0, -9.81};
  World3 d = build_world3(box);
  try {
    load_checkpoint3(path, d);
    ADD_FAILURE() << "a cell's checkpoint loaded into a box";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("periodic along"), std::string::npos) << e.what();
  }
}
