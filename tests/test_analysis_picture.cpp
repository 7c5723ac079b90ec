// cdanalysis draw (picture.hpp): a snapshot drawn as a PNG without ParaView,
// read back pixel by pixel. Synthetic snapshots with known geometry: the
// force chains must be drawn where the contacts are, in the colour of their
// force class, polygons with their true sides (not their circumcircle), and
// in 3D only the slice's spheres and contacts, and polyhedra as their
// sections by the slice.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "analysis/src/image.hpp"
#include "analysis/src/picture.hpp"
#include "analysis/src/snapshot.hpp"
#include "cli_util.hpp"
#include "output3.hpp"
#include "polyhedron.hpp"
#include "world3.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

fs::path scratch(const std::string& name) { return cdtest::scratch_dir("test_analysis_picture", name); }

// gnuplot-nox is one of the packages `make deps` installs: without it the
// picture cannot be drawn, and that is a failure, not a reason to skip.
bool have_gnuplot() { return std::system("gnuplot --version > /dev/null 2>&1") == 0; }

std::array<int, 3> hex(const char* c) {
  std::array<int, 3> v{};
  for (int k = 0; k < 3; ++k) v[k] = std::stoi(std::string(c + 1 + 2 * k, 2), nullptr, 16);
  return v;
}

// The pixel of a data point (the picture maps [x0, x1] x [y0, y1] onto the
// whole image, no margins).
std::pair<int, int> pixel(const Picture& p, double x, double y) {
  return {static_cast<int>(std::floor((x - p.x0) / (p.x1 - p.x0) * p.width)),
          static_cast<int>(std::floor((p.y1 - y) / (p.y1 - p.y0) * p.height))};
}

// Some pixel within 2 px of (x, y) has colour c within tol per channel.
bool near_colour(const Image& im, const Picture& p, double x, double y, std::array<int, 3> c, int tol = 30) {
  const auto [px, py] = pixel(p, x, y);
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const int X = px + dx, Y = py + dy;
      if (X < 0 || Y < 0 || X >= im.width || Y >= im.height) continue;
      const auto v = im.at(X, Y);
      if (std::abs(v[0] - c[0]) <= tol && std::abs(v[1] - c[1]) <= tol && std::abs(v[2] - c[2]) <= tol) return true;
    }
  return false;
}

// Every pixel within 2 px of (x, y) is white (nothing drawn there).
bool blank(const Image& im, const Picture& p, double x, double y) {
  const auto [px, py] = pixel(p, x, y);
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const auto v = im.at(px + dx, py + dy);
      if (v[0] < 250 || v[1] < 250 || v[2] < 250) return false;
    }
  return true;
}

Particle grain(int id, double x, double y, double z, double r, int nsides = 0, double angle = 0) {
  Particle p;
  p.id = id, p.x = x, p.y = y, p.z = z, p.radius = r, p.nsides = nsides, p.angle = angle;
  return p;
}

}  // namespace

// Two disks and a hexagon (apothem 1) in a row and a column; a strong
// contact A-B (fn = 10), a weak one A-C (fn = 1) and B on a floor (body 99,
// not a grain; fn = 5.5, its branch to the wall's middle): <fn> = 5.5, so
// A-B is in class [1.5, 2), A-C in [0, 1) and the floor contact in [1, 1.5),
// drawn from B's centre down to its edge, not along its branch.
TEST(Picture, TwoDimensionalGrainsAndForceChains) {
  ASSERT_TRUE(have_gnuplot()) << "gnuplot is not installed (make deps installs gnuplot-nox)";
  const auto d = scratch("2d");
  const double R6 = 2 / std::sqrt(3.0);  // circumradius of the hexagon of apothem 1
  ParticleSet ps = {grain(0, 0, 0, 0, 1), grain(1, 2, 0, 0, 1), grain(2, 0, 2, 0, R6, 6, 0)};
  ContactSet cs(3);
  cs[0].b1 = 0, cs[0].b2 = 1, cs[0].lx = 2, cs[0].ly = 0, cs[0].fn = 10, cs[0].status = 1;
  cs[1].b1 = 0, cs[1].b2 = 2, cs[1].lx = 0, cs[1].ly = 2, cs[1].theta = std::numbers::pi / 2, cs[1].fn = 1,
  cs[1].status = 1;
  cs[2].b1 = 99, cs[2].b2 = 1, cs[2].lx = -2, cs[2].ly = -1, cs[2].theta = std::numbers::pi / 2, cs[2].fn = 5.5,
  cs[2].status = 1;
  write_particles((d / "particles_00000.vtp").string(), ps);
  write_contacts((d / "contacts_00000.vtp").string(), cs, ps, true);
  const Picture p = draw_snapshot(d.string(), (d / "pic.png").string());
  ASSERT_TRUE(p.gnuplot_ok);
  EXPECT_EQ(p.grains, 3u);
  EXPECT_EQ(p.bars, 3u);
  const Image im = read_png(p.png);
  // The size: the width asked for, the height from the drawn region's aspect.
  EXPECT_EQ(im.width, 1000);
  EXPECT_EQ(im.height, p.height);
  EXPECT_NEAR(static_cast<double>(im.height) / im.width, (p.y1 - p.y0) / (p.x1 - p.x0), 1.0 / im.width);
  // The chains where the contacts are, each in its class' colour.
  for (const double t : {0.3, 0.5, 0.7}) {
    EXPECT_TRUE(near_colour(im, p, 2 * t, 0, hex(kForceClassColour[2]))) << "strong bar at x = " << 2 * t;
  }
  EXPECT_TRUE(near_colour(im, p, 0, 0.5, hex(kForceClassColour[0]))) << "weak bar";
  EXPECT_FALSE(near_colour(im, p, 0, 0.5, hex(kForceClassColour[2]))) << "weak bar drawn as strong";
  EXPECT_TRUE(near_colour(im, p, 2, -0.5, hex(kForceClassColour[1]))) << "floor contact";
  EXPECT_TRUE(blank(im, p, 3, 0.5)) << "floor contact drawn along its branch to the wall's middle";
  // Away from bars and outlines: nothing.
  EXPECT_TRUE(blank(im, p, 2.5, 0.5));
  EXPECT_TRUE(blank(im, p, 1.4, 1.6));
  // The hexagon's true outline: the middle of its side at 30 degrees is
  // drawn (dark), its circumcircle there is not.
  const double a = std::numbers::pi / 6;
  EXPECT_TRUE(near_colour(im, p, std::cos(a), 2 + std::sin(a), {64, 64, 64}, 60));
  EXPECT_TRUE(blank(im, p, R6 * std::cos(a), 2 + R6 * std::sin(a)));
  // The disk's outline.
  EXPECT_TRUE(near_colour(im, p, 2 + std::cos(0.3), std::sin(0.3), {64, 64, 64}, 60));
}

// 3D: spheres A, B at z = 0.1 and C, D at z = -0.1 in the slice through
// z = 0 (the middle of the spheres' z extent), E and F at z = +-2.5 out of
// it. Contacts A-B and C-D lie in the slab and are drawn; A-E leaves it and
// is not; E and F are not cut by the plane.
TEST(Picture, ThreeDimensionalSlice) {
  ASSERT_TRUE(have_gnuplot()) << "gnuplot is not installed (make deps installs gnuplot-nox)";
  const auto d = scratch("3d");
  std::ofstream(d / "scene.toml") << "dimension = 3\n";
  ParticleSet ps = {grain(0, 0, 0, 0.1, 1), grain(1, 2, 0, 0.1, 1), grain(2, 0, 3, -0.1, 1),
                    grain(3, 2, 3, -0.1, 1), grain(4, 1, 1.5, 2.5, 1), grain(5, 1, 1.5, -2.5, 1)};
  ContactSet3 cs(3);
  const auto contact = [&](Contact3& c, int b1, int b2) {
    c.c.b1 = b1, c.c.b2 = b2;
    for (int k = 0; k < 3; ++k) c.c.l[k] = (k == 0 ? ps[b2].x - ps[b1].x : k == 1 ? ps[b2].y - ps[b1].y : ps[b2].z - ps[b1].z);
    const double n = std::sqrt(c.c.l[0] * c.c.l[0] + c.c.l[1] * c.c.l[1] + c.c.l[2] * c.c.l[2]);
    for (int k = 0; k < 3; ++k) c.c.n[k] = c.c.l[k] / n;
    c.c.fn = 4;
    c.status = 1;
  };
  contact(cs[0], 0, 1);
  contact(cs[1], 2, 3);
  contact(cs[2], 0, 4);
  write_particles((d / "spheres_00000.vtp").string(), ps);
  write_contacts3((d / "contacts_00000.vtp").string(), cs, ps);
  const Picture p = draw_snapshot(d.string(), (d / "slice.png").string(), {-1, 800});
  ASSERT_TRUE(p.gnuplot_ok);
  EXPECT_NEAR(p.z_mid, 0, 1e-12);
  EXPECT_EQ(p.grains, 4u);  // E, F not cut
  EXPECT_EQ(p.bars, 2u);    // A-E leaves the slab
  const Image im = read_png(p.png);
  EXPECT_EQ(im.width, 800);
  EXPECT_EQ(im.height, p.height);
  // All three contacts have fn = <fn> of the two drawn: class [1, 1.5).
  EXPECT_TRUE(near_colour(im, p, 1, 0, hex(kForceClassColour[1])));
  EXPECT_TRUE(near_colour(im, p, 1, 3, hex(kForceClassColour[1])));
  EXPECT_TRUE(blank(im, p, 0.5, 0.75));  // where A-E's projection would pass
  // A's cut circle, radius sqrt(1 - 0.1^2), drawn; E's (not cut) absent.
  const double rc = std::sqrt(1 - 0.01);
  EXPECT_TRUE(near_colour(im, p, -rc, 0, {64, 64, 64}, 60));
  EXPECT_TRUE(blank(im, p, 1, 1.5 + 0.9));
}

// Two cubes of side a stacked on a floor under gravity along -y, their
// faces parallel to the axes: the slice z = 0 through their centres cuts
// each along its true square (not its circumscribed sphere's circle), and
// each face-to-face contact's four points are drawn as one bar, centre to
// centre (the floor's from the floor to the lower centre).
TEST(Picture, PolyhedraAreDrawnAsTheirSections) {
  ASSERT_TRUE(have_gnuplot()) << "gnuplot is not installed (make deps installs gnuplot-nox)";
  cd::WorldParams3 prm;
  prm.dt = 1e-3;
  prm.gravity = cd::Vec3(0, -9.81, 0);
  prm.mu = prm.mu_wall = 0.5;
  prm.alert = 1e-4;
  prm.solver.tol = 1e-10;
  prm.solver.max_iter = 10000;
  cd::World3 w(prm);
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(0, 1, 0));
  const double a = 0.02;
  const int shape = w.bodies.add_shape(cd::cuboid(a, a, a));
  w.bodies.add_polyhedron(cd::Vec3(0, a / 2, 0), shape, 2600);
  w.bodies.add_polyhedron(cd::Vec3(0, 1.5 * a, 0), shape, 2600);
  for (int k = 0; k < 20; ++k) w.step();
  int rows = 0;
  for (const auto& r : w.rows()) rows += r.r[0] > 0;
  ASSERT_EQ(rows, 8) << "four points under each cube";
  const auto d = scratch("polyhedra");
  std::ofstream(d / "scene.toml") << "dimension = 3\n";
  cd::write_spheres_vtp(w, (d / "spheres_00000.vtp").string());
  cd::write_polyhedra_vtp(w, (d / "polyhedra_00000.vtp").string());
  cd::write_contacts3_vtp(w, (d / "contacts_00000.vtp").string());
  const Picture p = draw_snapshot(d.string(), (d / "slice.png").string(), {-1, 600});
  ASSERT_TRUE(p.gnuplot_ok);
  EXPECT_NEAR(p.z_mid, 0, 1e-12);
  EXPECT_EQ(p.grains, 2u);
  EXPECT_EQ(p.bars, 2u);
  const Image im = read_png(p.png);
  // The squares' sides, at half a side from the centres; nothing on the
  // circle of the circumscribed sphere's section (radius a sqrt(3)/2)
  // beside the lower cube, nor at its centre but the bars.
  EXPECT_TRUE(near_colour(im, p, a / 2, a / 2, {64, 64, 64}, 60));
  EXPECT_TRUE(near_colour(im, p, -a / 2, 1.5 * a, {64, 64, 64}, 60));
  EXPECT_TRUE(near_colour(im, p, 0, 2 * a, {64, 64, 64}, 60));  // the upper cube's top side
  EXPECT_TRUE(blank(im, p, 0.8 * a, 0.5 * a));
  EXPECT_TRUE(blank(im, p, 0.3 * a, 1.5 * a));
  // The bars: the cubes' contact (m g, below <fn> = 1.5 m g: the weak
  // class, its thin line) centre to centre, x = 0 from y = a/2 to 3a/2;
  // the floor's (2 m g: class [1, 1.5)) from the floor to the lower centre.
  // (the 1-pixel line is antialiased: some pixel there reddish, not grey)
  bool reddish = false;
  const auto [bx, by] = pixel(p, 0, 1.25 * a);
  for (int dx = -2; dx <= 2; ++dx) {
    const auto v = im.at(bx + dx, by);
    reddish = reddish || (v[0] - v[2] > 25 && v[0] > 200);
  }
  EXPECT_TRUE(reddish);
  EXPECT_TRUE(near_colour(im, p, 0, 0.25 * a, hex(kForceClassColour[1])));
  EXPECT_TRUE(blank(im, p, 0.25 * a, 1.25 * a));
}
