// 3D snapshots (cd/src/3d/output3.cpp): one point per dynamic sphere with
// radius, velocity, omega and orientation, read back through VTK; the
// pile3d scene's layout (cd/src/3d/pile3d.hpp); cdsim's 3D outputs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include "cli_util.hpp"
#include "output3.hpp"
#include "pile3d.hpp"

using namespace cd;

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
