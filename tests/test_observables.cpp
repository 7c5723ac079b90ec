// cd/src/core/observables.hpp on hand-made networks with known answers (stress,
// force-bearing, rattlers, packing fraction, fabric), and end to end: the z
// that cdsim writes in series.csv on a cohesive run is the z cdanalysis
// computes from the same step's snapshot.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>

#include "analysis/src/coordination.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/snapshot.hpp"
#include "analysis/src/stress.hpp"
#include "cli_util.hpp"
#include "observables.hpp"

namespace fs = std::filesystem;
using namespace cd::obs;
constexpr double pi = std::numbers::pi;

namespace {

using C2 = Contact<2>;

// An L x L periodic square lattice of unit spacing (disks of radius 1/2,
// ids row by row): each disk touches its right and upper neighbours (via
// the images at the cell's edge), horizontal contacts with fn = fx and
// ft = tx, vertical ones with fn = fy.
std::vector<C2> square_lattice(int L, double fx, double tx, double fy) {
  std::vector<C2> cs;
  for (int j = 0; j < L; ++j)
    for (int i = 0; i < L; ++i) {
      const int id = j * L + i;
      cs.push_back(contact_2d(id, j * L + (i + 1) % L, 1, 0, fx, tx, 1, 0));
      cs.push_back(contact_2d(id, ((j + 1) % L) * L + i, 0, 1, fy, 0, 0, 1));
    }
  return cs;
}

std::vector<std::int32_t> iota_ids(int n) {
  std::vector<std::int32_t> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = i;
  return v;
}

}  // namespace

TEST(Observables, SquareLatticeStressFabricCoordinationPacking) {
  // 3 x 3 cell (V = 9), 18 contacts: sigma_xx = 9 fx / 9, sigma_yy = fy,
  // sigma_yx = tx (f = fn n + ft t, t = +y for n = +x, l = +x), sigma_xy = 0.
  const auto cs = square_lattice(3, 2.0, 0.25, 1.0);
  const auto s = contact_stress<2>(cs, 9.0);
  EXPECT_EQ(s[0][0], 2.0);
  EXPECT_EQ(s[1][1], 1.0);
  EXPECT_EQ(s[1][0], 0.25);
  EXPECT_EQ(s[0][1], 0.0);
  EXPECT_EQ(mean_2d(s), 1.5);
  EXPECT_DOUBLE_EQ(deviator_2d(s), std::hypot(0.5, 0.125));
  EXPECT_THROW(contact_stress<2>(cs, 0.0), std::invalid_argument);

  const auto F = fabric_tensor<2>(cs);
  EXPECT_EQ(F[0][0], 0.5);
  EXPECT_EQ(F[1][1], 0.5);
  EXPECT_EQ(F[0][1], 0.0);

  const auto ids = iota_ids(9);
  const auto c = coordination<2>(cs, ids);
  EXPECT_EQ(c.force_bearing, 18u);
  EXPECT_EQ(c.rattlers, 0u);
  EXPECT_EQ(c.z, 4.0);
  EXPECT_EQ(c.non_rattler, 1.0);
  ASSERT_EQ(c.P.size(), 5u);
  EXPECT_EQ(c.P[4], 1.0);

  // Packing: 9 disks of radius 1/2 in the 3 x 3 cell: pi/4.
  const std::vector<double> areas(9, particle_area(0.5));
  EXPECT_DOUBLE_EQ(packing_fraction(areas, {}, 9.0), pi / 4);
}

TEST(Observables, TriangleOfDisksStressIsTheSumOfOuterProducts) {
  // Three unit disks touching pairwise (centres on an equilateral triangle
  // of side 2), in a box of area V = 10; each contact with its own fn, ft.
  const double h = std::sqrt(3.0);
  const double x[3][2] = {{0, 0}, {2, 0}, {1, h}};
  const int pairs[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  const double fn[3] = {3.0, 1.5, -0.5}, ft[3] = {0.2, -0.4, 0.1};
  std::vector<C2> cs;
  double expect[2][2] = {};
  for (int k = 0; k < 3; ++k) {
    const int a = pairs[k][0], b = pairs[k][1];
    const double lx = x[b][0] - x[a][0], ly = x[b][1] - x[a][1];
    const double nx = lx / 2, ny = ly / 2;
    cs.push_back(contact_2d(a, b, nx, ny, fn[k], ft[k], lx, ly));
    const double f[2] = {fn[k] * nx - ft[k] * ny, fn[k] * ny + ft[k] * nx};
    const double l[2] = {lx, ly};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) expect[i][j] += f[i] * l[j] / 10.0;
  }
  const auto s = contact_stress<2>(cs, 10.0);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(s[i][j], expect[i][j], 1e-15) << i << j;
  // Frictionless and all fn = 1: isotropic, p = (1/V) sum fn |l| / 2 = 3/10.
  for (auto& c : cs) {
    c.fn = 1;
    c.ft = {0, 0};
  }
  const auto t = contact_stress<2>(cs, 10.0);
  EXPECT_NEAR(mean_2d(t), 0.3, 1e-15);
  EXPECT_NEAR(deviator_2d(t), 0.0, 1e-15);
  EXPECT_NEAR(t[0][1], t[1][0], 1e-15);
  // Swapping the roles of the bodies (n, l and f reversed) changes nothing.
  auto swapped = cs;
  for (auto& c : swapped) {
    std::swap(c.b1, c.b2);
    for (int i = 0; i < 2; ++i) {
      c.n[i] = -c.n[i];
      c.l[i] = -c.l[i];
      c.ft[i] = -c.ft[i];
    }
  }
  const auto u = contact_stress<2>(swapped, 10.0);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_EQ(u[i][j], t[i][j]);
}

TEST(Observables, ForceBearingCountsTensionAndPairsOnce) {
  // Mean |fn| = (1 + 1 + 0.5 + 0.5 + 0 + 1e-20 + 0)/7; f_eps = 1e-9 x that.
  const std::vector<C2> cs = {
      contact_2d(0, 1, 1, 0, 1.0, 0, 1, 0),      // compression
      contact_2d(1, 2, 1, 0, -1.0, 0, 1, 0),     // cohesive pull at -f_a: bears force
      contact_2d(2, 3, 1, 0, 0.5, 0, 1, 0),      // side-side: +0.5 ...
      contact_2d(3, 2, -1, 0, 0.5, 0, -1, 0),    // ... and -0.5 (on 3, seen from 3): one pair
      contact_2d(3, 4, 1, 0, 0.0, 0, 1, 0),      // closed, no force: does not bear
      contact_2d(4, 5, 1, 0, 1e-20, 0, 1, 0),    // round-off: does not bear
      contact_2d(5, 6, 1, 0, 0.0, 0.3, 1, 0),    // fn = 0 with a cohesive ft: bears
  };
  const double f_eps = force_threshold<2>(cs);
  EXPECT_DOUBLE_EQ(f_eps, 1e-9 * (3.0 + 1e-20) / 7);
  const auto links = force_bearing_links<2>(cs);
  const std::vector<Link> expect = {{0, 1}, {1, 2}, {2, 3}, {5, 6}};
  EXPECT_EQ(links, expect);
  // One point per pair, the first in the order given.
  const std::vector<std::size_t> points = {0, 1, 2, 6};
  EXPECT_EQ(force_bearing_points<2>(cs), points);
  // An explicit threshold overrides the default.
  EXPECT_EQ(force_bearing_links<2>(cs, 0.75).size(), 2u);  // |fn| + |ft| = 1: 0-1, 1-2
}

TEST(Observables, RattlersAreRemovedRecursivelyInAnyOrder) {
  // Particles 0..7; 100 and 101 are walls (not particles).
  //   triangle 0-1-2; chain 2-3-4: 4 has 1 contact -> rattler, then 3 -> rattler
  //   5 touches wall 100 at two points (one contact) -> rattler
  //   6 touches walls 100 and 101 -> 2 contacts, stays; 7 touches nothing
  const std::vector<Link> links = {{0, 1}, {1, 2}, {0, 2}, {2, 3}, {3, 4}, {5, 100}, {6, 100}, {6, 101}};
  const std::vector<std::int32_t> particles = {0, 1, 2, 3, 4, 5, 6, 7};
  const auto c = coordination(links, particles);
  const std::vector<bool> rattler = {false, false, false, true, true, true, false, true};
  EXPECT_EQ(c.is_rattler, rattler);
  EXPECT_EQ(c.rattlers, 4u);
  // Remaining: 0, 1, 2 with 2 contacts each, 6 with its 2 walls.
  EXPECT_EQ(c.z, 2.0);
  EXPECT_EQ(c.non_rattler, 0.5);
  // P_c before removal: 0:1 (7)  1:2 (4, 5)  2:4 (0, 1, 6, 3)  3:1 (2).
  const std::vector<double> P = {1.0 / 8, 2.0 / 8, 4.0 / 8, 1.0 / 8};
  EXPECT_EQ(c.P, P);
  // The 2-core does not depend on the order of the links or of the ids.
  std::mt19937 rng(7);
  for (int k = 0; k < 20; ++k) {
    auto l = links;
    std::shuffle(l.begin(), l.end(), rng);
    const auto d = coordination(l, particles);
    EXPECT_EQ(d.z, c.z);
    EXPECT_EQ(d.is_rattler, c.is_rattler);
  }
  // A longer chain hanging from the triangle is peeled link by link.
  std::vector<Link> chain = {{0, 1}, {1, 2}, {0, 2}};
  std::vector<std::int32_t> ids = {0, 1, 2};
  for (int i = 3; i < 50; ++i) {
    chain.push_back({i - 1, i});
    ids.push_back(i);
  }
  const auto e = coordination(chain, ids);
  EXPECT_EQ(e.rattlers, 47u);
  EXPECT_EQ(e.z, 2.0);
  // No particle left: z = 0; no particle at all: everything 0.
  EXPECT_EQ(coordination(std::vector<Link>{{0, 1}}, std::vector<std::int32_t>{0, 1}).z, 0.0);
  EXPECT_EQ(coordination(std::vector<Link>{}, std::vector<std::int32_t>{}).non_rattler, 0.0);
  EXPECT_THROW(coordination(std::vector<Link>{{2, 1}}, ids), std::invalid_argument);
}

TEST(Observables, PackingFractionOfKnownShapes) {
  EXPECT_DOUBLE_EQ(particle_area(1.0), pi);
  EXPECT_DOUBLE_EQ(particle_area(1.0, 4), 2.0);                      // square of circumradius 1
  EXPECT_DOUBLE_EQ(particle_area(2.0, 6), 1.5 * std::sqrt(3.0) * 4);  // hexagon: (3 sqrt 3 / 2) R^2
  EXPECT_DOUBLE_EQ(sphere_volume(1.5), 4.5 * pi);
  // Two disks of radius 1 and a wall grain (counted half) in a 4 x 4 cell.
  const std::vector<double> a = {pi, pi, pi}, w = {1, 1, 0.5};
  EXPECT_DOUBLE_EQ(packing_fraction(a, w, 16.0), 2.5 * pi / 16);
  EXPECT_THROW(packing_fraction(a, w, 0.0), std::invalid_argument);
  EXPECT_THROW(packing_fraction(a, std::vector<double>{1.0}, 1.0), std::invalid_argument);
  // Hexagonal packing of disks (one disk of radius 1/2 per rhombus of area
  // sqrt(3)/2): pi / (2 sqrt 3).
  EXPECT_DOUBLE_EQ(packing_fraction(std::vector<double>{particle_area(0.5)}, {}, std::sqrt(3.0) / 2),
                   pi / (2 * std::sqrt(3.0)));
}

TEST(Observables, ThreeDimensionalSimpleCubicLattice) {
  // 2 x 2 x 2 periodic simple cubic lattice: 8 spheres, 24 contacts, unit
  // spacing, fn = 1, 2, 3 along x, y, z: sigma = diag(1, 2, 3) x 8 / 8.
  std::vector<Contact<3>> cs;
  for (int id = 0; id < 8; ++id)
    for (int a = 0; a < 3; ++a) {
      Contact<3> c;
      c.b1 = id;
      c.b2 = id ^ (1 << a);
      c.n[static_cast<std::size_t>(a)] = 1;
      c.l[static_cast<std::size_t>(a)] = 1;
      c.fn = a + 1.0;
      cs.push_back(c);
    }
  const auto s = contact_stress<3>(cs, 8.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(s[i][j], i == j ? i + 1.0 : 0.0);
  // Each pair is touched twice (the neighbour and its image): 12 physical
  // contacts, z = 3 (a pair counts once), F = I/3.
  const auto F = fabric_tensor<3>(cs);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(F[i][i], 1.0 / 3);
  std::vector<std::int32_t> ids = {0, 1, 2, 3, 4, 5, 6, 7};
  const auto c = coordination<3>(cs, ids);
  EXPECT_EQ(c.force_bearing, 12u);
  EXPECT_EQ(c.z, 3.0);
}

// ---- end to end ----

namespace {

// series.csv as name -> column of strings (exactly as written).
std::map<std::string, std::vector<std::string>> read_series_text(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  std::map<std::string, std::vector<std::string>> cols;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k) cols[names.at(k)].push_back(c);
  }
  return cols;
}

// As Series::row writes a value.
std::string as_written(double v) {
  return v == std::trunc(v) && std::abs(v) < 9007199254740992.0 ? fmt::format("{:.0f}", v)
                                                                  : fmt::format("{:.10g}", v);
}

}  // namespace

// A short cohesive shear run (eta = 10: many contacts pull, some at the
// pull-off force -f_a) from a small compacted sample, with a series row at
// every step and a snapshot at the last step: the series' z and
// non_rattler in the last row are what cdanalysis computes from the
// snapshot, and so is its stress (the row's interval is that one step).
TEST(ObservablesEndToEnd, CohesiveRunSeriesZEqualsAnalysisOfTheSnapshot) {
  const fs::path d = cdtest::scratch_dir("test_observables", "cohesive");
  const std::string cdsim = std::string(CDLAB_BINARY_DIR "/cd/cdsim ") + CDLAB_SOURCE_DIR + "/configs/";
  // 120 disks compacted isotropically at p = 100 N/m (1.6 s).
  const auto prep = cdtest::run_command(
      cdsim + "shear-prep.toml --quiet --out " + (d / "prep").string() +
      " --set particles.n=120 --set shear.width=0.0165 --set shear.height=0.0185 --set solver.tol=1e-3");
  ASSERT_EQ(prep.code, 0) << prep.out;
  // Then 100 steps of the cohesive protocol at I = 0.1 (dt = dt_tp t_p,
  // t_p = d sqrt(rho/p)).
  const int steps = 100;
  const double dt = 0.05 * 1e-3 * std::sqrt(2.6 / 100.0);
  const fs::path run = d / "cohesive";
  const auto r = cdtest::run_command(fmt::format(
      "{}shear-cohesive.toml --quiet --out {} --set shear.start={} --set shear.strain=0"
      " --set shear.inertial_number=0.1 --set time.duration={:.17g}"
      " --set output.series_interval={:.17g} --set output.snapshot_interval={:.17g}",
      cdsim, run.string(), (d / "prep" / "checkpoint.bin").string(), steps * dt, dt, steps * dt));
  ASSERT_EQ(r.code, 0) << r.out;

  auto series = read_series_text(run / "series.csv");
  ASSERT_TRUE(series.count("z")) << "not a shear run";
  ASSERT_EQ(series["step"].back(), std::to_string(steps));
  ASSERT_EQ(cda::list_snapshots(run.string(), "contacts").size(), 2u);  // steps 0 and 100
  const auto contacts = cda::read_contacts(cda::snapshot_path(run.string(), "contacts", -1));
  const auto particles = cda::read_particles(cda::snapshot_path(run.string(), "particles", -1));

  // The run is cohesive: contacts pull, some at the pull-off force f_a =
  // eta p d = 1 N/m (the ones the former series rule, p_n + f_a dt > 0,
  // left out), and the network is a dense one.
  std::size_t pulling = 0, at_pull_off = 0;
  for (const auto& c : contacts) {
    pulling += c.fn < 0;
    at_pull_off += std::abs(c.fn + 1.0) < 1e-9;
  }
  EXPECT_GT(pulling, 5u);
  EXPECT_GT(at_pull_off, 0u);

  const auto conn = cda::connectivity(contacts, particles);
  EXPECT_GT(conn.z, 3.0);
  EXPECT_EQ(series["z"].back(), as_written(conn.z));
  EXPECT_EQ(series["non_rattler"].back(), as_written(conn.non_floating));

  // Stress: the same sum over the same forces (the normals come back from
  // the file as angles: equal to round-off). The series divides by the cell
  // at the step's midpoint, which it does not print: compare ratios.
  const auto s = cda::contact_stress(contacts, 1.0);
  const double syy = std::stod(series["syy"].back());
  EXPECT_NEAR(s.xx / s.yy, std::stod(series["sxx"].back()) / syy, 1e-8);
  EXPECT_NEAR(s.xy / s.yy, std::stod(series["sxy"].back()) / syy, 1e-8);
  EXPECT_NEAR(s.yx / s.yy, std::stod(series["syx"].back()) / syy, 1e-8);
  EXPECT_NEAR(s.q_over_p(), std::stod(series["q_over_p"].back()), 1e-8);
  if (!HasFailure()) fs::remove_all(d);
}
