// cd/bench/peers/liggghts-shear/snapshots.py, which turns a LIGGGHTS run's
// frames into cdsim 3D snapshots of its bulk so that cdanalysis measures z
// for both codes with one estimator. A hand-made frame whose answers are
// worked out here: which grains are the bulk, each row's force on body 2
// (from either body's force), its normal and branch across the periodic
// boundary, and the coordination of the force-bearing network with the
// rattlers out (by the analysis library's own connectivity).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "analysis/src/coordination.hpp"
#include "analysis/src/snapshot.hpp"
#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kScript = std::string(CDLAB_SOURCE_DIR) + "/cd/bench/peers/liggghts-shear/snapshots.py";

struct Atom {
  double x, y, z;
};

// d = 1, L = 10 (periodic in x and z), 9 grains and one wall sphere on each
// side: the bottom one (id 10) at y = 0, the top one (11) at y = 10, so the
// bulk is 2.5 < y < 7.5. Grains 1-4: a regular tetrahedron of edge 1 with
// grain 1 at y = 3.2; 5 beside 1, 6 beside 2; 7 under 1, outside the bulk
// (y = 2.2); 8 and 9 at x = 9.6 and 0.4, neighbours across the periodic
// boundary.
const double kS3 = std::sqrt(3.0), kS23 = std::sqrt(2.0 / 3.0);
const std::map<int, Atom> kAtoms = {
    {1, {5, 3.2, 5}},           {2, {6, 3.2, 5}},        {3, {5.5, 3.2 + kS3 / 2, 5}},
    {4, {5.5, 3.2 + kS3 / 6, 5 + kS23}}, {5, {4, 3.2, 5}}, {6, {7, 3.2, 5}},
    {7, {5, 2.2, 5}},           {8, {9.6, 4, 2}},        {9, {0.4, 4, 2}},
    {10, {5, 0, 5}},            {11, {5, 10, 5}}};

Atom unit(int from, int to, double L) {
  const Atom& a = kAtoms.at(from);
  const Atom& b = kAtoms.at(to);
  double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
  dx -= L * std::round(dx / L);
  dz -= L * std::round(dz / L);
  const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
  return {dx / r, dy / r, dz / r};
}

// A pair's row as LIGGGHTS writes it: id1 id2 flag, the normal force, the
// tangential force, on body 1 (repulsive: along -n) or, on_second, on body 2.
std::string pair_row(int i, int j, double fn, bool on_second = false, Atom ft = {0, 0, 0}) {
  const Atom n = unit(i, j, 10.0);
  const double s = on_second ? fn : -fn;
  std::ostringstream o;
  o.precision(17);
  o << i << " " << j << " 0 " << s * n.x << " " << s * n.y << " " << s * n.z << " " << ft.x << " " << ft.y << " "
    << ft.z << "\n";
  return o.str();
}

void write_run(const fs::path& d, long contacts_step) {
  fs::create_directories(d);
  std::ofstream(d / "params.txt") << "N=9 nwall=1 d=1 L=10 rho=1\n";
  std::ofstream a(d / "shear.dump");
  a.precision(17);
  a << "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n11\nITEM: BOX BOUNDS pp ff pp\n0 10\n-2 12\n0 10\n"
    << "ITEM: ATOMS id radius x y z vx vy vz c_cpa\n";
  for (int k = 11; k >= 1; --k) {  // out of order: the script sorts by id
    const Atom& p = kAtoms.at(k);
    a << k << " 0.5 " << p.x << " " << p.y << " " << p.z << " 0 0 0 0\n";
  }
  std::ofstream c(d / "shear.contacts");
  c.precision(17);
  c << "ITEM: TIMESTEP\n" << contacts_step << "\nITEM: NUMBER OF ENTRIES\n11\nITEM: BOX BOUNDS pp ff pp\n"
    << "0 10\n-2 12\n0 10\nITEM: ENTRIES c_pgl[1] c_pgl[2] c_pgl[3] c_pgl[4] c_pgl[5] c_pgl[6] c_pgl[7] "
       "c_pgl[8] c_pgl[9]\n";
  c << pair_row(1, 2, 1.0, false, {0, 0.3, 0}) << pair_row(1, 3, 2.0) << pair_row(1, 4, 3.0)
    << pair_row(2, 3, 4.0) << pair_row(2, 4, 5.0) << pair_row(3, 4, 6.0, true) << pair_row(1, 5, 0.5)
    << pair_row(2, 6, 1e-14) << pair_row(1, 7, 2.5) << pair_row(8, 9, 1.5) << pair_row(10, 7, 7.0);
}

}  // namespace

TEST(PeerSnapshots, LiggghtsFramesAsTheBulksSnapshot) {
  const fs::path top = cdtest::scratch_dir("test_peer_snapshots", "frame");
  write_run(top / "run", 100);
  const auto r = cdtest::run_command("/usr/bin/python3 " + kScript + " " + (top / "run").string() + " " +
                                     (top / "snap").string());
  ASSERT_EQ(r.code, 0) << r.out;
  // The bulk: grains 1-6, 8, 9 (7 lies under it, the wall spheres outside).
  const cda::ParticleSet ps = cda::read_particles((top / "snap" / "spheres_00000.vtp").string());
  std::map<int, int> ids;
  for (const auto& p : ps) ids[p.id] = 1;
  EXPECT_EQ(ids, (std::map<int, int>{{1, 1}, {2, 1}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {8, 1}, {9, 1}}));
  // Every pair with a bulk grain, the wall's pair with grain 7 left out.
  const cda::ContactSet3 cs = cda::read_contacts3((top / "snap" / "contacts_00000.vtp").string());
  ASSERT_EQ(cs.size(), 10u);
  const std::map<std::pair<int, int>, double> fn = {{{1, 2}, 1.0}, {{1, 3}, 2.0}, {{1, 4}, 3.0}, {{2, 3}, 4.0},
                                                    {{2, 4}, 5.0}, {{3, 4}, 6.0}, {{1, 5}, 0.5}, {{2, 6}, 1e-14},
                                                    {{1, 7}, 2.5}, {{8, 9}, 1.5}};
  for (const auto& c : cs) {
    const std::pair<int, int> key{c.c.b1, c.c.b2};
    ASSERT_EQ(fn.count(key), 1u) << c.c.b1 << "-" << c.c.b2;
    // Repulsive on body 2 whichever body LIGGGHTS gave the force of (3-4: body 2's).
    EXPECT_NEAR(c.c.fn, fn.at(key), 1e-12 * fn.at(key)) << c.c.b1 << "-" << c.c.b2;
    const Atom n = unit(key.first, key.second, 10.0);
    EXPECT_NEAR(c.c.n[0], n.x, 1e-12);
    EXPECT_NEAR(c.c.n[1], n.y, 1e-12);
    EXPECT_NEAR(c.c.n[2], n.z, 1e-12);
    if (key == std::pair<int, int>{8, 9}) {
      // Across the periodic boundary: 0.8 along +x, not 9.2 along -x.
      EXPECT_NEAR(c.c.l[0], 0.8, 1e-12);
      EXPECT_NEAR(c.c.l[1], 0.0, 1e-12);
    }
    if (key == std::pair<int, int>{1, 2}) {
      // The tangential force on body 1 was +0.3 y: on body 2, -0.3 y.
      EXPECT_NEAR(c.c.ft[1], -0.3, 1e-12);
      EXPECT_NEAR(c.c.ft[0], 0.0, 1e-12);
    }
  }
  // The force-bearing network: 2-6 bears 1e-14 of a mean |f_n| of 2.55,
  // under the 1e-9 threshold; 5 (one contact), 6 (none), 8 and 9 (one
  // each) are rattlers; 1 keeps 2, 3, 4 and 7 (a boundary body for the
  // bulk), 2, 3 and 4 three each: z = 13 / 4.
  const cda::Connectivity k = cda::connectivity(cs, ps);
  EXPECT_EQ(k.particles, 8u);
  EXPECT_EQ(k.rattlers, 4u);
  EXPECT_DOUBLE_EQ(k.z, 13.0 / 4.0);
}

TEST(PeerSnapshots, RefusesFramesOfDifferentSteps) {
  const fs::path top = cdtest::scratch_dir("test_peer_snapshots", "steps");
  write_run(top / "run", 200);
  const auto r = cdtest::run_command("/usr/bin/python3 " + kScript + " " + (top / "run").string() + " " +
                                     (top / "snap").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("frame 0: the atoms' step 100 is not the contacts' 200"), std::string::npos) << r.out;
}
