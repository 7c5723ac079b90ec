// Regular polygons: exact inertia, resting, sliding and tipping with
// closed-form thresholds, stacks, piles, vertex-vertex encounters and the
// hard cases of method.md section 7.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "detect.hpp"
#include "world_util.hpp"

using cd::Vec2;
using cdtest::params;
constexpr double kPi = std::numbers::pi;

using cdtest::total_mass;

namespace {

// A polygon of n sides and side s resting with a face on a line through the
// origin inclined at theta (downhill along (cos, -sin)).
int place_on_incline(cd::World& w, int n, double s, double theta_rad, double density = 1.0) {
  const Vec2 down(std::cos(theta_rad), -std::sin(theta_rad)), up(std::sin(theta_rad), std::cos(theta_rad));
  w.bodies.add_wall(-5.0 * down, 5.0 * down);
  const double R = s / (2 * std::sin(kPi / n)), ap = R * std::cos(kPi / n);
  // Face k = n - 1 ... choose the orientation whose face normal points along -up.
  const double face_angle = std::atan2(-up.y(), -up.x());       // outward normal of the bottom face
  const double th = face_angle - kPi * (2 * 0 + 1) / n;        // face 0 normal at th + pi/n
  return w.bodies.add_polygon(ap * up, R, n, th, density);
}

}  // namespace

TEST(Polygon, MassAndInertiaAreExact) {
  cd::Bodies b;
  const double s = 2.0;
  b.add_polygon({0, 0}, s / std::sqrt(2.0), 4, 0.0, 3.0);        // square of side 2
  b.add_polygon({0, 0}, s / std::sqrt(3.0), 3, 0.0, 3.0);        // triangle of side 2
  EXPECT_NEAR(b.mass[0], 3.0 * s * s, 1e-12);
  EXPECT_NEAR(b.inertia[0], b.mass[0] * s * s / 6.0, 1e-12);
  EXPECT_NEAR(b.mass[1], 3.0 * std::sqrt(3.0) / 4.0 * s * s, 1e-12);
  EXPECT_NEAR(b.inertia[1], b.mass[1] * s * s / 12.0, 1e-12);
}

TEST(Polygon, SquareRestsOnTwoPointsWithoutDriftOrSpin) {
  // Two side-side points; their normal forces sum to the weight; 1e4 steps
  // leave position and angle unchanged to round-off.
  auto p = params(1e-3, 9.81, 0.5);
  cd::World w(p);
  w.bodies.add_wall({-5, 0}, {5, 0});
  const int q = w.bodies.add_polygon({0.3, 0.5}, 1 / std::sqrt(2.0), 4, kPi / 4, 1.0);
  for (int k = 0; k < 10000; ++k) w.step();
  ASSERT_EQ(w.rows().size(), 2u);
  double sum = 0;
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(w.infos()[k].type, cd::ContactType::SideSide);
    sum += w.rows()[k].pn / p.dt;
  }
  const double mg = w.bodies.mass[q] * 9.81;
  EXPECT_NEAR(sum, mg, 1e-9 * mg);
  EXPECT_NEAR(w.bodies.pos[q].x(), 0.3, 1e-12);
  EXPECT_NEAR(w.bodies.pos[q].y(), 0.5, 1e-12);
  EXPECT_NEAR(w.bodies.angle[q], kPi / 4, 1e-12);
  EXPECT_NEAR(w.bodies.vel[q].w, 0.0, 1e-12);
}

struct SlopeCase {
  int n;
  double deg, mu;
};
class PolygonOnIncline : public ::testing::TestWithParam<SlopeCase> {};

TEST_P(PolygonOnIncline, SticksSlidesOrTipsAtTheClosedFormThresholds) {
  // A polygon on its face: sticks if tan(theta) < mu and theta < pi/n (the
  // tipping angle: the weight's line leaves the face when theta > pi/n);
  // slides without turning at a = g (sin - mu cos) if tan(theta) > mu and
  // theta < pi/n; tips (turns downhill) if theta > pi/n and mu is large.
  const auto [n, deg, mu] = GetParam();
  const double th = deg * kPi / 180, g = 9.81, dt = 1e-3;
  auto p = params(dt, g, mu);
  cd::World w(p);
  const int q = place_on_incline(w, n, 1.0, th);
  const double a0 = w.bodies.angle[q];
  for (int k = 0; k < 1000; ++k) w.step();
  const Vec2 down(std::cos(th), -std::sin(th));
  const Vec2 v(w.bodies.vel[q].vx, w.bodies.vel[q].vy);
  const double t = w.time;
  const bool tips = th > kPi / n;
  const bool slides = !tips && std::tan(th) > mu;
  if (tips) {
    // Turning downhill (clockwise for a downhill to the right) by now.
    EXPECT_LT(w.bodies.angle[q] - a0, -0.05) << "should have tipped";
  } else if (slides) {
    // Two-point contact solved to tol 1e-10: acceleration to 1e-6 relative.
    const double a = g * (std::sin(th) - mu * std::cos(th));
    EXPECT_NEAR(v.dot(down), a * t, 1e-6 * a * t);
    EXPECT_NEAR(w.bodies.vel[q].w, 0.0, 1e-6);
  } else {
    EXPECT_NEAR(v.norm(), 0.0, 1e-9);
    EXPECT_NEAR(w.bodies.angle[q], a0, 1e-9);
  }
}
INSTANTIATE_TEST_SUITE_P(
    Thresholds, PolygonOnIncline,
    ::testing::Values(SlopeCase{4, 20, 0.5},     // square sticks: tan 20 = 0.36 < 0.5
                      SlopeCase{4, 30, 0.2},     // square slides
                      SlopeCase{4, 44, 2.0},     // large mu: stands just below 45 degrees
                      SlopeCase{4, 46, 2.0},     // and tips just above
                      SlopeCase{6, 10, 0.3},     // hexagon sticks
                      SlopeCase{6, 25, 0.3},     // hexagon slides (below its 30-degree tip)
                      SlopeCase{6, 32, 2.0}));   // hexagon tips above 30 degrees

TEST(Polygon, StackOfTenSquaresStands) {
  auto p = params(1e-3, 9.81, 0.5);
  p.solver.tol = 1e-8;
  cd::World w(p);
  w.bodies.add_wall({-5, 0}, {5, 0});
  for (int k = 0; k < 10; ++k) w.bodies.add_polygon({0, 0.5 + k}, 1 / std::sqrt(2.0), 4, kPi / 4, 1.0);
  for (int k = 0; k < 2000; ++k) w.step();
  // Impulses exact to tol = 1e-8: velocities to ~tol g dt a step, so
  // positions to ~tol g dt T = 2e-7 after 2000 steps; bounds 1e-6.
  for (int k = 1; k <= 10; ++k) {
    EXPECT_NEAR(w.bodies.pos[k].x(), 0.0, 1e-6);
    EXPECT_NEAR(w.bodies.pos[k].y(), 0.5 + (k - 1), 1e-6);
    EXPECT_NEAR(w.bodies.angle[k], kPi / 4, 1e-6);
  }
  // Each interface is side-side: 2 points each, 20 in all.
  EXPECT_EQ(w.rows().size(), 20u);
}

class VertexVertex : public ::testing::TestWithParam<int> {};

TEST_P(VertexVertex, CornerToCornerStaysStable) {
  // Two polygons with corners pointing at each other collide head on (and
  // slightly off centre), no gravity, e = 0. The corner contact is resolved
  // on one face (the frame does not flip), the pair turns and rolls over
  // each other in side-side contact, then separates. Checks: no NaN, no
  // energy gain, and overlap bounded. The overlap does creep while the pair
  // turns in contact: the midpoint frame is exact to first order, so a
  // contact turning at w drifts by ~ w^2 R dt^2 a step (measured 8e-4 ->
  // 1.7e-3 over ~1500 steps at w ~ 1 rad/s); bound 3e-3 = 2.5e-3 d.
  const int n = GetParam();
  for (double offset : {0.0, 0.05}) {
    auto p = params(1e-3, 0.0, 0.4);
    p.solver.tol = 1e-6;
    cd::World w(p);
    const double R = 0.6;
    // vertex 0 of A points along +x, one vertex of B along -x
    w.bodies.add_polygon({-1.0, 0.0}, R, n, 0.0, 1.0, {1.0, 0.0});
    w.bodies.add_polygon({1.0, offset}, R, n, kPi, 1.0, {-1.0, 0.0});
    const double e0 = w.kinetic_energy();
    double ov = 0;
    for (int k = 0; k < 3000; ++k) {
      w.step();
      ASSERT_TRUE(cdtest::all_finite(w));
      EXPECT_LE(w.kinetic_energy(), e0 * (1 + 1e-9));
      ov = std::max(ov, w.last().max_overlap);
    }
    EXPECT_LT(ov, 3e-3);
    EXPECT_GT(ov, 0.0);  // they did collide
  }
}
INSTANTIATE_TEST_SUITE_P(Shapes, VertexVertex, ::testing::Values(3, 4));

TEST(Polygon, DetectionTypesAndCounts) {
  // Direct narrow-phase checks: face to face gives two SideSide points;
  // a tilted square gives one SideVertex point; a disk on a face one point
  // with the right gap.
  std::vector<cd::ContactRow> rows;
  std::vector<cd::ContactInfo> info;
  const double R = 1 / std::sqrt(2.0);
  cd::PolyView A{{0, 0}, R, kPi / 4, 4}, B{{1.0, 0.0}, R, kPi / 4, 4};
  ASSERT_EQ(cd::polygon_polygon(0, 1, A, B, 0.1, rows, info), 2);
  EXPECT_EQ(info[0].type, cd::ContactType::SideSide);
  EXPECT_NEAR(info[0].gap, 0.0, 1e-12);
  rows.clear();
  info.clear();
  // A diamond (square turned 45 degrees) whose left vertex is 0.01 inside
  // A's right face (x = 0.5): one side-vertex point, gap -0.01, normal +x.
  cd::PolyView C{{0.5 + R - 0.01, 0.0}, R, 0.0, 4};
  ASSERT_EQ(cd::polygon_polygon(0, 1, A, C, 0.1, rows, info), 1);
  EXPECT_EQ(info[0].type, cd::ContactType::SideVertex);
  EXPECT_NEAR(info[0].gap, -0.01, 1e-12);
  EXPECT_NEAR(rows[0].nx, 1.0, 1e-12);
  cd::ContactRow row;
  cd::ContactInfo inf;
  ASSERT_TRUE(cd::polygon_disk(0, 1, A, {0.0, 0.5 + 0.3 - 0.02}, 0.3, 0.1, row, inf));
  EXPECT_NEAR(inf.gap, -0.02, 1e-12);
  EXPECT_NEAR(row.ny, 1.0, 1e-12);
}

namespace {

// n-gons (0 = disks) of circumradius in [rmin, rmax] on a loose lattice in a box.
void fill_polygons(cd::World& w, int count, int n, double W, double rmin, double rmax, unsigned seed,
                   int every_small = 0, double small_r = 0.0) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double pitch = 2.04 * rmax;
  const int nx = static_cast<int>(W / pitch);
  for (int k = 0; k < count; ++k) {
    const Vec2 c((k % nx + 0.5) * pitch, (k / nx + 0.5) * pitch);
    if (every_small && k % every_small == 0) {
      // a cluster of small disks in this lattice site
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
          w.bodies.add_disk(c + Vec2(a, b) * 2.2 * small_r, small_r, 1.0);
      continue;
    }
    const double r = rmin + (rmax - rmin) * U(g);
    w.bodies.add_polygon(c, r, n, 2 * kPi * U(g), 1.0);
  }
  w.bodies.add_wall({0, 0}, {W, 0});
  w.bodies.add_wall({0, 1e3}, {0, 0});
  w.bodies.add_wall({W, 0}, {W, 1e3});
}

// The hard-case piles: dt = 2e-3 (1/160 of sqrt(d/g)), tol 1e-4, cap 1000.
cd::WorldParams pile_params(double alert) {
  auto p = params(2e-3, 9.81, 0.4);
  p.solver.tol = 1e-4;
  p.solver.max_iter = 1000;
  p.alert = alert;
  return p;
}

void expect_hard_case(const char* name, cd::World& w, int steps, double overlap_bound) {
  const double mgd = total_mass(w) * 9.81;
  const cdtest::Watch r = cdtest::run_watched(w, steps);
  cdtest::report(name, r, mgd);
  EXPECT_LT(r.max_overlap, overlap_bound) << name;
  // Energy: a converged step only dissipates; capped steps may return ~tol
  // of it (see test_pile.cpp): 1e-5 m g d.
  EXPECT_LT(r.max_energy_gain, 1e-5 * mgd) << name;
}

}  // namespace

TEST(PolygonHardCases, DensePileOfTriangles) {
  cd::World w(pile_params(0.2));
  fill_polygons(w, 60, 3, 8, 0.4, 0.6, 11);
  // Overlap: triangles land at ~sqrt(2 g h) ~ 12 d/s, 0.02 d per half step.
  expect_hard_case("pile of triangles", w, 1200, 5e-2);
}

TEST(PolygonHardCases, DensePileOfSixtyGons) {
  cd::World w(pile_params(0.2));
  fill_polygons(w, 60, 60, 8, 0.4, 0.6, 12);
  expect_hard_case("pile of 60-gons", w, 1200, 5e-2);
}

TEST(PolygonHardCases, SquaresWithDisksTenTimesSmaller) {
  cd::World w(pile_params(0.1));
  // squares of circumradius ~0.5 and clusters of 9 disks of radius 0.05
  fill_polygons(w, 48, 4, 8, 0.45, 0.55, 13, 4, 0.05);
  expect_hard_case("squares with small disks", w, 1200, 5e-2);
}

#include <vtkCellArray.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <filesystem>

#include "cli_util.hpp"
#include "output.hpp"

TEST(PolygonOutput, ShapesCarryTrueOutlines) {
  // A hexagon and a disk: the shapes file has one cell each, the hexagon's
  // six points at its vertices (read back through VTK's XML reader).
  namespace fs = std::filesystem;
  const fs::path dir = cdtest::scratch_dir("test_polygon", "shapes");  // not /tmp: kept by a failure
  cd::World w(params(1e-3, 9.81, 0.4));
  const int h = w.bodies.add_polygon({0.0, 2.0}, 0.5, 6, 0.3, 1.0);
  w.bodies.add_disk({3.0, 2.0}, 0.5, 1.0);
  cd::Snapshots snaps(dir.string());
  snaps.write(w);
  auto r = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  r->SetFileName((dir / "shapes_00000.vtp").string().c_str());
  r->Update();
  vtkPolyData* pd = r->GetOutput();
  ASSERT_EQ(pd->GetNumberOfPolys(), 2);
  vtkNew<vtkIdList> ids;
  pd->GetPolys()->InitTraversal();
  ASSERT_TRUE(pd->GetPolys()->GetNextCell(ids));
  ASSERT_EQ(ids->GetNumberOfIds(), 6);
  for (int k = 0; k < 6; ++k) {
    double p[3];
    pd->GetPoint(ids->GetId(k), p);
    const double a = 0.3 + k * kPi / 3;
    EXPECT_NEAR(p[0], w.bodies.pos[h].x() + 0.5 * std::cos(a), 1e-12);
    EXPECT_NEAR(p[1], w.bodies.pos[h].y() + 0.5 * std::sin(a), 1e-12);
  }
  ASSERT_TRUE(pd->GetPolys()->GetNextCell(ids));
  EXPECT_EQ(ids->GetNumberOfIds(), 36);  // the disk
  EXPECT_TRUE(fs::exists(dir / "shapes.pvd"));
  fs::remove_all(dir);
}
