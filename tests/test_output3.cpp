// 3D snapshots (cd/src/3d/output3.cpp): one point per dynamic sphere with
// radius, velocity, omega and orientation, read back through VTK; the
// polyhedra as their true faces (a turned cube's corners, outward normals
// and planar faces computed from the written polygons, not from the
// shape); the contacts' kind and lines of polyhedra; a sphere world's set
// of files and contact lines as before the polyhedra; the pile3d scene's
// layout (cd/src/3d/pile3d.hpp); cdsim's 3D outputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include "analysis/src/snapshot.hpp"
#include "cli_util.hpp"
#include "files.hpp"
#include "output3.hpp"
#include "pile3d.hpp"
#include "polyhedron.hpp"

using namespace cd;

namespace {

vtkSmartPointer<vtkPolyData> read_vtp(const std::filesystem::path& p) {
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(p.c_str());
  r->Update();
  EXPECT_EQ(r->GetErrorCode(), 0) << p;
  return r->GetOutput();
}

Vec3 point_of(vtkPolyData* pd, vtkIdType id) {
  double x[3];
  pd->GetPoint(id, x);
  return {x[0], x[1], x[2]};
}

// The points of cell c, in the cell's order.
std::vector<Vec3> cell_points(vtkPolyData* pd, vtkIdType c) {
  vtkNew<vtkIdList> ids;
  pd->GetCellPoints(c, ids);
  std::vector<Vec3> xs;
  for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) xs.push_back(point_of(pd, ids->GetId(k)));
  return xs;
}

Vec3 tuple3(vtkPolyData* pd, const char* name, vtkIdType c) {
  const double* v = pd->GetCellData()->GetArray(name)->GetTuple3(c);
  return {v[0], v[1], v[2]};
}

double tuple1(vtkPolyData* pd, const char* name, vtkIdType c) {
  return pd->GetCellData()->GetArray(name)->GetTuple1(c);
}

WorldParams3 resting_params() {
  WorldParams3 p;
  p.dt = 1e-3;
  p.gravity = Vec3(0, 0, -9.81);
  p.mu = p.mu_wall = 0.3;
  p.alert = 1e-4;
  p.solver.tol = 1e-13;
  p.solver.max_iter = 10000;
  return p;
}

}  // namespace

TEST(Output3, SpheresRoundTripThroughVtk) {
  World3 w(WorldParams3{});
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  w.bodies.add_sphere(Vec3(1, 2, 3), 0.5, 1000, Vec3(0.1, 0.2, 0.3), Vec3(-1, 0, 2));
  w.bodies.add_sphere(Vec3(-1, 0.5, 2), 0.25, 1000);
  w.bodies.orient[2] = Quat(Eigen::AngleAxisd(0.3, Vec3(0, 1, 0)));
  // In the build folder, not a fixed name in /tmp that the suites of other
  // checkouts running at the same time would share.
  const auto dir = cdtest::scratch_dir("test_output3", "vtp");
  const std::string path = (dir / "s.vtp").string();
  write_spheres_vtp(w, path);
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  vtkPolyData* pd = r->GetOutput();
  ASSERT_EQ(pd->GetNumberOfPoints(), 2);  // the plane is not a point
  double x[3];
  pd->GetPoint(0, x);
  EXPECT_EQ(Vec3(x[0], x[1], x[2]), Vec3(1, 2, 3));
  vtkPointData* d = pd->GetPointData();
  EXPECT_EQ(d->GetArray("radius")->GetTuple1(1), 0.25);
  const double* v = d->GetArray("velocity")->GetTuple3(0);
  EXPECT_EQ(Vec3(v[0], v[1], v[2]), Vec3(0.1, 0.2, 0.3));
  const double* om = d->GetArray("omega")->GetTuple3(0);
  EXPECT_EQ(Vec3(om[0], om[1], om[2]), Vec3(-1, 0, 2));
  const double* q = d->GetArray("orientation")->GetTuple4(1);
  EXPECT_EQ(q[0], w.bodies.orient[2].w());
  EXPECT_EQ(q[2], w.bodies.orient[2].y());
  std::filesystem::remove_all(dir);
}

// A cube of side a at x0, turned by q, and a tetrahedron: the polyhedra
// file holds the cube as 6 quadrilaterals on its own 8 points, which are
// the corners x0 + q (+-a/2, +-a/2, +-a/2) computed here from the side and
// the rotation; each face is planar, its normal from the written polygon
// (Newell's sum of cross products, the loop's own orientation) points away
// from the centroid along one of q's axes, and its edges are a long. Cell
// data: the body, its shape, velocity and omega on every face.
TEST(Output3, PolyhedraAreTheirTrueFaces) {
  World3 w(WorldParams3{});
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02;
  const int tet = w.bodies.add_shape(platonic(Platonic::Tetrahedron, 0.01));
  const int cube = w.bodies.add_shape(cuboid(a, a, a));
  const Vec3 x0(0.1, -0.05, 0.3), v0(0.5, -0.25, 1.0), w0(3.0, -1.0, 2.0);
  const Quat q(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  w.bodies.add_polyhedron(Vec3(-1, 0, 1), tet, 2600);
  const int c = w.bodies.add_polyhedron(x0, cube, 2600, q, v0, w0);
  const auto dir = cdtest::scratch_dir("test_output3", "polyhedra");
  write_polyhedra_vtp(w, (dir / "p.vtp").string());
  const auto pd = read_vtp(dir / "p.vtp");
  ASSERT_EQ(pd->GetNumberOfPolys(), 4 + 6);
  ASSERT_EQ(pd->GetNumberOfCells(), 4 + 6);
  ASSERT_EQ(pd->GetNumberOfPoints(), 4 + 8);  // no point shared between bodies

  const Eigen::Matrix3d R = q.toRotationMatrix();
  std::vector<Vec3> corners;
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) corners.push_back(x0 + R * Vec3(sx, sy, sz) * (a / 2));
  std::set<int> seen_corners, seen_axes;
  std::set<vtkIdType> cube_points;
  const double tol = 1e-15 * x0.norm();
  for (vtkIdType f = 4; f < 10; ++f) {
    EXPECT_EQ(tuple1(pd, "id", f), c);
    EXPECT_EQ(tuple1(pd, "shape_id", f), cube);
    EXPECT_EQ(tuple3(pd, "velocity", f), v0);
    EXPECT_EQ(tuple3(pd, "omega", f), w0);
    vtkNew<vtkIdList> ids;
    pd->GetCellPoints(f, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 4);
    for (vtkIdType k = 0; k < 4; ++k) cube_points.insert(ids->GetId(k));
    const std::vector<Vec3> xs = cell_points(pd, f);
    Vec3 n = Vec3::Zero(), mid = Vec3::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec3& p = xs[k];
      const Vec3& r = xs[(k + 1) % 4];
      n += p.cross(r);
      mid += p / 4;
      EXPECT_NEAR((r - p).norm(), a, 1e-14 * a);
      int hit = -1;
      for (int j = 0; j < 8; ++j)
        if ((p - corners[static_cast<std::size_t>(j)]).norm() <= tol) hit = j;
      ASSERT_GE(hit, 0) << "face " << f << " point " << k << " is not a corner";
      seen_corners.insert(hit);
    }
    n.normalize();
    EXPECT_GT(n.dot(mid - x0), 0.49 * a);  // outward: a/2 from the centroid
    for (const Vec3& p : xs) EXPECT_LT(std::abs(n.dot(p - mid)), 1e-14 * a);  // planar
    int axis = -1;
    for (int j = 0; j < 3; ++j)
      if (std::abs(std::abs(n.dot(R.col(j))) - 1) < 1e-14) axis = j;
    ASSERT_GE(axis, 0) << "face " << f << " is not normal to an axis of the cube";
    seen_axes.insert(axis + 3 * (n.dot(R.col(axis)) > 0));
  }
  EXPECT_EQ(seen_corners.size(), 8u);
  EXPECT_EQ(seen_axes.size(), 6u);  // the six faces, each once
  EXPECT_EQ(cube_points, (std::set<vtkIdType>{4, 5, 6, 7, 8, 9, 10, 11}));
  for (vtkIdType f = 0; f < 4; ++f) {  // the tetrahedron: triangles on points 0-3
    EXPECT_EQ(tuple1(pd, "id", f), 1);
    EXPECT_EQ(tuple1(pd, "shape_id", f), tet);
    vtkNew<vtkIdList> ids;
    pd->GetCellPoints(f, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 3);
    for (vtkIdType k = 0; k < 3; ++k) EXPECT_LT(ids->GetId(k), 4);
  }
  EXPECT_THROW(write_polyhedra_vtp(w, (dir / "missing" / "p.vtp").string()), WriteError);
  std::filesystem::remove_all(dir);
}

// Two cubes stacked on a plane (the upper one shifted by a/4), at rest:
// every contact is face-face (kind 3) with four points; a floor point's
// line runs from the contact point to the lower centroid, a point between
// the cubes from the lower centroid through the point to the upper one; branch is centroid to centroid (the
// floor: from the centroid's foot), which cdanalysis reads as the branch.
// Snapshots3 adds polyhedra_NNNNN.vtp and polyhedra.pvd to the files of a
// sphere world.
TEST(Output3, PolyhedraContactsAreFaceFaceLinesThroughThePoints) {
  World3 w(resting_params());
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double a = 0.02;
  const int shape = w.bodies.add_shape(cuboid(a, a, a));
  const int lo = w.bodies.add_polyhedron(Vec3(0.1, -0.05, a / 2), shape, 2600);
  const int hi = w.bodies.add_polyhedron(Vec3(0.1 + a / 4, -0.05, 1.5 * a), shape, 2600);
  for (int k = 0; k < 20; ++k) w.step();
  ASSERT_EQ(w.rows().size(), 8u);
  const auto dir = cdtest::scratch_dir("test_output3", "polyhedra_contacts");
  Snapshots3 snaps(dir.string());
  snaps.write(w);
  for (const char* f : {"spheres_00000.vtp", "contacts_00000.vtp", "polyhedra_00000.vtp", "spheres.pvd",
                        "contacts.pvd", "polyhedra.pvd", "view.py"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  const auto pd = read_vtp(dir / "contacts_00000.vtp");
  ASSERT_EQ(pd->GetNumberOfCells(), 8);
  ASSERT_NE(pd->GetCellData()->GetArray("kind"), nullptr);
  int floor = 0, between = 0;
  for (vtkIdType k = 0; k < 8; ++k) {
    const ContactInfo3& c = w.infos()[static_cast<std::size_t>(k)];
    EXPECT_EQ(tuple1(pd, "kind", k), 3);  // face-face
    EXPECT_EQ(tuple3(pd, "branch", k), c.branch);
    const std::vector<Vec3> xs = cell_points(pd, k);
    const int b1 = static_cast<int>(tuple1(pd, "b1", k)), b2 = static_cast<int>(tuple1(pd, "b2", k));
    // The lines are at the step's midpoint configuration: the centroids
    // there, which at rest are where they stand, to round-off.
    if (b1 == 0) {
      ++floor;
      EXPECT_EQ(b2, lo);
      ASSERT_EQ(xs.size(), 2u);
      EXPECT_EQ(xs[0], c.point);
      EXPECT_LT((xs[1] - w.bodies.pos[lo]).norm(), 1e-12 * a);
      EXPECT_NEAR(c.point.z(), 0.0, 1e-3 * a);
      EXPECT_NEAR(c.branch.z(), a / 2, 1e-12 * a);
    } else {
      ++between;
      EXPECT_EQ(b1, lo);
      EXPECT_EQ(b2, hi);
      ASSERT_EQ(xs.size(), 3u);
      EXPECT_LT((xs[0] - w.bodies.pos[lo]).norm(), 1e-12 * a);
      EXPECT_EQ(xs[1], c.point);
      EXPECT_LT((xs[2] - w.bodies.pos[hi]).norm(), 1e-12 * a);
      EXPECT_NEAR(c.point.z(), a, 1e-3 * a);
      EXPECT_LT((c.branch - Vec3(a / 4, 0, a)).norm(), 1e-12 * a);
    }
  }
  EXPECT_EQ(floor, 4);
  EXPECT_EQ(between, 4);
  // cdanalysis reads the polylines, its branch from the `branch` array.
  const cda::ContactSet3 back = cda::read_contacts3((dir / "contacts_00000.vtp").string());
  ASSERT_EQ(back.size(), 8u);
  for (std::size_t k = 0; k < 8; ++k)
    EXPECT_EQ(Vec3(back[k].c.l[0], back[k].c.l[1], back[k].c.l[2]), w.infos()[k].branch);
  std::filesystem::remove_all(dir);
}

// A sphere world writes the files it wrote before the polyhedra (no
// polyhedra file or collection) and its contact lines as before: two
// points each, from x2 - branch to the centre of body 2, every kind 0.
TEST(Output3, SphereWorldFilesAndContactLinesAsBefore) {
  World3 w(resting_params());
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  const double r = 0.005;
  for (int k = 0; k < 3; ++k) w.bodies.add_sphere(Vec3(2 * r * k, 0, r), r, 2600);
  w.bodies.add_sphere(Vec3(r, 0, (1 + std::sqrt(3.0)) * r), r, 2600);
  for (int k = 0; k < 10; ++k) w.step();
  ASSERT_EQ(w.rows().size(), 3u + 2u + 2u);  // 3 on the floor, 2 side by side, 2 under the top one
  const auto dir = cdtest::scratch_dir("test_output3", "spheres_as_before");
  Snapshots3 snaps(dir.string());
  snaps.write(w);
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files.insert(e.path().filename().string());
  EXPECT_EQ(files, (std::set<std::string>{"spheres_00000.vtp", "contacts_00000.vtp", "spheres.pvd",
                                          "contacts.pvd", "view.py"}));
  const auto pd = read_vtp(dir / "contacts_00000.vtp");
  ASSERT_EQ(pd->GetNumberOfCells(), static_cast<vtkIdType>(w.rows().size()));
  std::vector<std::string> names;
  for (int k = 0; k < pd->GetCellData()->GetNumberOfArrays(); ++k)
    names.emplace_back(pd->GetCellData()->GetArrayName(k));
  EXPECT_EQ(names, (std::vector<std::string>{"fn", "ft", "force", "normal", "gap", "status", "b1", "b2", "kind",
                                             "branch"}));  // the two last ones new
  for (vtkIdType k = 0; k < pd->GetNumberOfCells(); ++k) {
    const SphereRow& row = w.rows()[static_cast<std::size_t>(k)];
    const ContactInfo3& c = w.infos()[static_cast<std::size_t>(k)];
    const std::vector<Vec3> xs = cell_points(pd, k);
    ASSERT_EQ(xs.size(), 2u);
    const Vec3 x2 = w.bodies.pos[static_cast<std::size_t>(row.b2)];
    EXPECT_EQ(xs[0], Vec3(x2 - c.branch));
    EXPECT_EQ(xs[1], x2);
    EXPECT_EQ(tuple1(pd, "kind", k), 0);
    EXPECT_EQ(tuple1(pd, "fn", k), row.r[0] * (1.0 / w.params().dt));
  }
  std::filesystem::remove_all(dir);
}

TEST(Output3, Pile3dLayout) {
  Pile3dParams q;
  q.n_spheres = 130;  // n = 6: 6 x 6 x 4 lattice, last layer partial
  const World3 w = make_pile3d(q);
  ASSERT_EQ(w.bodies.size(), 135u);  // 5 planes
  double zmin = 1e9, rmin = 1e9, rmax = 0;
  for (std::size_t i = 5; i < w.bodies.size(); ++i) {
    zmin = std::min(zmin, w.bodies.pos[i].z());
    rmin = std::min(rmin, w.bodies.radius[i]);
    rmax = std::max(rmax, w.bodies.radius[i]);
    EXPECT_GT(w.bodies.pos[i].x() - w.bodies.radius[i], 0.0);
    EXPECT_LT(w.bodies.pos[i].x() + w.bodies.radius[i], 6 * 0.011);
  }
  EXPECT_NEAR(zmin, 1.1 * 0.005, 0.05 * 0.005 + 1e-15);
  EXPECT_GE(rmin, 0.0025);
  EXPECT_LE(rmax, 0.005);
}

// cdsim runs a small pile3d scene (configs/pile3d.toml, dimension = 3) and
// writes its series and snapshots (spheres and contacts, with .pvd).
TEST(Output3, CdsimSmallPileWritesSeriesAndSnapshots) {
  const auto scratch = cdtest::scratch_dir("test_output3", "cdsim"), dir = scratch / "out";
  const std::string cmd = std::string(CDLAB_BINARY_DIR "/cd/cdsim ") + CDLAB_SOURCE_DIR +
                          "/configs/pile3d.toml --set particles.n=27 --set time.duration=0.05 "
                          "--set output.snapshot_interval=0.025 --threads 1 --quiet --out " +
                          dir.string() + " > " + (scratch / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "series.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "spheres_00000.vtp"));
  EXPECT_TRUE(std::filesystem::exists(dir / "contacts_00000.vtp"));
  EXPECT_TRUE(std::filesystem::exists(dir / "spheres_00002.vtp"));  // steps 25 and 50
  EXPECT_FALSE(std::filesystem::exists(dir / "spheres_00003.vtp"));
  EXPECT_TRUE(std::filesystem::exists(dir / "spheres.pvd"));
  EXPECT_TRUE(std::filesystem::exists(dir / "contacts.pvd"));
  std::filesystem::remove_all(scratch);
}
