// Output round trip: snapshots written through VTK's XML writers read back
// with VTK's reader hold exactly the world's data (binary Float64 is exact),
// the .pvd collections list every frame, and the file helpers fail loudly.
#include <unistd.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include "output.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh folder per test, removed afterwards.
struct TmpDir {
  fs::path path;
  explicit TmpDir(const std::string& name)
      : path(fs::temp_directory_path() / ("cdlab_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TmpDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& p) {
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(p.c_str());
  r->Update();
  EXPECT_EQ(r->GetErrorCode(), 0) << p;
  return r->GetOutput();
}

// The array must exist with the expected VTK type and component count.
vtkDataArray* array(vtkFieldData* fd, const char* name, int type, int comps) {
  vtkDataArray* a = fd->GetArray(name);
  EXPECT_NE(a, nullptr) << name;
  if (!a) return nullptr;
  EXPECT_EQ(a->GetDataType(), type) << name;
  EXPECT_EQ(a->GetNumberOfComponents(), comps) << name;
  return a;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); }

// Four disks in a row on a floor, a fifth resting on two of them, and two
// side walls: disk-disk and wall-disk contacts within the alert distance.
cd::World small_world() {
  cd::WorldParams p;
  p.dt = 1e-3;
  p.gravity = {0, -9.81};
  p.mu = 0.5;
  p.mu_wall = 0.3;
  p.alert = 0.1;
  cd::World w(p);
  w.bodies.add_wall({-2.5, 0}, {2.5, 0});
  for (int i = 0; i < 4; ++i) w.bodies.add_disk({-1.5 + i * 1.0, 0.5}, 0.5, 1.0);
  w.bodies.add_disk({-1.0, 0.5 + std::sqrt(0.75)}, 0.5, 1.0, {0.1, 0.0}, 0.2);
  w.bodies.add_wall({-2.0, 0}, {-2.0, 3});
  w.bodies.add_wall({2.0, 3}, {2.0, 0});
  return w;
}

}  // namespace

TEST(VtkRoundTrip, SnapshotsMatchWorld) {
  TmpDir dir("vtk_roundtrip");
  cd::World w = small_world();
  cd::Snapshots snap(dir.path.string());
  for (int f = 0; f < 3; ++f) {
    for (int s = 0; s < 5; ++s) w.step();
    snap.write(w);
  }
  EXPECT_EQ(snap.count(), 3);
  ASSERT_FALSE(w.rows().empty());

  // Binary appended, zlib compressed.
  const std::string text = slurp(dir.path / "particles_00002.vtp");
  EXPECT_NE(text.find("vtkZLibDataCompressor"), std::string::npos);
  EXPECT_NE(text.find("encoding=\"raw\""), std::string::npos);

  // particles: one point per dynamic body.
  const cd::Bodies& b = w.bodies;
  auto pd = read_vtp(dir.path / "particles_00002.vtp");
  int ndyn = 0;
  for (std::size_t i = 0; i < b.size(); ++i) ndyn += b.is_dynamic(i);
  ASSERT_EQ(pd->GetNumberOfPoints(), ndyn);
  EXPECT_EQ(pd->GetNumberOfVerts(), ndyn);
  vtkPointData* pt = pd->GetPointData();
  auto* id = array(pt, "id", VTK_INT, 1);
  auto* radius = array(pt, "radius", VTK_DOUBLE, 1);
  auto* vel = array(pt, "velocity", VTK_DOUBLE, 3);
  auto* omega = array(pt, "omega", VTK_DOUBLE, 1);
  auto* angle = array(pt, "angle", VTK_DOUBLE, 1);
  auto* mass = array(pt, "mass", VTK_DOUBLE, 1);
  ASSERT_TRUE(id && radius && vel && omega && angle && mass);
  for (vtkIdType k = 0; k < ndyn; ++k) {
    const int i = static_cast<int>(id->GetComponent(k, 0));
    ASSERT_TRUE(i >= 0 && i < static_cast<int>(b.size()) && b.is_dynamic(i));
    double x[3];
    pd->GetPoint(k, x);
    EXPECT_TRUE(close(x[0], b.pos[i].x()) && close(x[1], b.pos[i].y())) << i;
    EXPECT_EQ(x[2], 0.0);
    EXPECT_TRUE(close(radius->GetComponent(k, 0), b.radius[i]));
    EXPECT_TRUE(close(vel->GetComponent(k, 0), b.vel[i].vx));
    EXPECT_TRUE(close(vel->GetComponent(k, 1), b.vel[i].vy));
    EXPECT_EQ(vel->GetComponent(k, 2), 0.0);
    EXPECT_TRUE(close(omega->GetComponent(k, 0), b.vel[i].w));
    EXPECT_TRUE(close(angle->GetComponent(k, 0), b.angle[i]));
    EXPECT_TRUE(close(mass->GetComponent(k, 0), b.mass[i]));
  }

  // contacts: one line per row, forces = impulses / dt.
  auto cd_ = read_vtp(dir.path / "contacts_00002.vtp");
  const auto& rows = w.rows();
  const auto& infos = w.infos();
  ASSERT_EQ(cd_->GetNumberOfLines(), static_cast<vtkIdType>(rows.size()));
  ASSERT_EQ(cd_->GetNumberOfCells(), static_cast<vtkIdType>(rows.size()));
  vtkCellData* cl = cd_->GetCellData();
  auto* fn = array(cl, "fn", VTK_DOUBLE, 1);
  auto* ft = array(cl, "ft", VTK_DOUBLE, 1);
  auto* force = array(cl, "force", VTK_DOUBLE, 3);
  auto* normal = array(cl, "normal", VTK_DOUBLE, 3);
  auto* status = array(cl, "status", VTK_UNSIGNED_CHAR, 1);
  auto* type = array(cl, "type", VTK_UNSIGNED_CHAR, 1);
  auto* gap = array(cl, "gap", VTK_DOUBLE, 1);
  auto* b1 = array(cl, "b1", VTK_INT, 1);
  auto* b2 = array(cl, "b2", VTK_INT, 1);
  ASSERT_TRUE(fn && ft && force && normal && status && type && gap && b1 && b2);
  const double dt = w.params().dt;
  int walls = 0, disks = 0, loaded = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const cd::ContactRow& r = rows[k];
    EXPECT_EQ(b1->GetComponent(k, 0), r.b1);
    EXPECT_EQ(b2->GetComponent(k, 0), r.b2);
    EXPECT_TRUE(close(fn->GetComponent(k, 0), r.pn / dt));
    EXPECT_TRUE(close(ft->GetComponent(k, 0), r.pt / dt));
    const double fx = (r.pn * r.nx - r.pt * r.ny) / dt, fy = (r.pn * r.ny + r.pt * r.nx) / dt;
    EXPECT_NEAR(force->GetComponent(k, 0), fx, 1e-9 * (1 + std::abs(fx)));
    EXPECT_NEAR(force->GetComponent(k, 1), fy, 1e-9 * (1 + std::abs(fy)));
    EXPECT_EQ(normal->GetComponent(k, 0), r.nx);
    EXPECT_EQ(normal->GetComponent(k, 1), r.ny);
    EXPECT_EQ(status->GetComponent(k, 0), static_cast<double>(w.status(k)));
    EXPECT_EQ(type->GetComponent(k, 0), static_cast<double>(infos[k].type));
    EXPECT_EQ(gap->GetComponent(k, 0), infos[k].gap);
    loaded += r.pn > 0;

    // End points: body centres, or the contact point on a wall.
    vtkCell* c = cd_->GetCell(k);
    ASSERT_EQ(c->GetCellType(), VTK_LINE);
    double x1[3], x2[3];
    cd_->GetPoint(c->GetPointId(0), x1);
    cd_->GetPoint(c->GetPointId(1), x2);
    const bool wall = b.shape[r.b1] == cd::Shape::Segment;
    const cd::Vec2 e1 = wall ? cd::Vec2(infos[k].px, infos[k].py) : b.pos[r.b1];
    EXPECT_TRUE(close(x1[0], e1.x()) && close(x1[1], e1.y())) << k;
    EXPECT_TRUE(close(x2[0], b.pos[r.b2].x()) && close(x2[1], b.pos[r.b2].y())) << k;
    (wall ? walls : disks)++;
  }
  EXPECT_GT(walls, 0);
  EXPECT_GT(disks, 0);
  EXPECT_GT(loaded, 0);

  // walls: one line per segment, between its ends.
  auto wd = read_vtp(dir.path / "walls_00002.vtp");
  ASSERT_EQ(wd->GetNumberOfLines(), 3);
  auto* wid = array(wd->GetCellData(), "id", VTK_INT, 1);
  ASSERT_TRUE(wid);
  for (vtkIdType c = 0; c < 3; ++c) {
    const int i = static_cast<int>(wid->GetComponent(c, 0));
    ASSERT_EQ(b.shape[i], cd::Shape::Segment);
    cd::Vec2 a, e;
    b.segment_ends(i, a, e);
    double x[3];
    wd->GetPoint(wd->GetCell(c)->GetPointId(0), x);
    EXPECT_TRUE(close(x[0], a.x()) && close(x[1], a.y()));
    wd->GetPoint(wd->GetCell(c)->GetPointId(1), x);
    EXPECT_TRUE(close(x[0], e.x()) && close(x[1], e.y()));
  }

  // Collections: three frames each, increasing times, every file loads; no
  // temporary file left behind.
  for (const char* stem : {"particles", "contacts", "walls"}) {
    const std::string pvd = slurp(dir.path / (std::string(stem) + ".pvd"));
    EXPECT_NE(pvd.find("type=\"Collection\""), std::string::npos);
    const std::regex ds(R"re(<DataSet timestep="([^"]+)"[^>]*file="([^"]+)")re");
    int n = 0;
    double last = -1;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), ds); it != std::sregex_iterator();
         ++it, ++n) {
      const double t = std::stod((*it)[1]);
      EXPECT_GT(t, last);
      last = t;
      const std::string file = (*it)[2];
      EXPECT_EQ(file, fmt::format("{}_{:05d}.vtp", stem, n));
      ASSERT_TRUE(fs::is_regular_file(dir.path / file)) << file;
      EXPECT_GE(read_vtp(dir.path / file)->GetNumberOfPoints(), 0);
    }
    EXPECT_EQ(n, 3) << stem;
    EXPECT_DOUBLE_EQ(last, w.time);
  }
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
}

TEST(VtkRoundTrip, EmptyContactsStillWrite) {
  TmpDir dir("vtk_empty");
  cd::WorldParams p;
  p.dt = 1e-3;
  cd::World w(p);
  w.bodies.add_disk({0, 5}, 0.5, 1.0);  // alone, far from everything: no rows
  w.step();
  ASSERT_TRUE(w.rows().empty());
  cd::Snapshots snap(dir.path.string());
  snap.write(w);
  EXPECT_EQ(read_vtp(dir.path / "particles_00000.vtp")->GetNumberOfPoints(), 1);
  EXPECT_EQ(read_vtp(dir.path / "contacts_00000.vtp")->GetNumberOfCells(), 0);
  EXPECT_EQ(read_vtp(dir.path / "walls_00000.vtp")->GetNumberOfCells(), 0);
}

TEST(Output, WriteFileAtomic) {
  TmpDir dir("atomic");
  const fs::path f = dir.path / "a.txt";
  cd::write_file_atomic(f.string(), "one\n");
  cd::write_file_atomic(f.string(), "two\n");
  EXPECT_EQ(slurp(f), "two\n");
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path)) ++n;
  EXPECT_EQ(n, 1);  // no temporary left
  EXPECT_THROW(cd::write_file_atomic((dir.path / "no" / "b.txt").string(), "x"), cd::OutputError);
  EXPECT_FALSE(fs::exists(dir.path / "no"));
}

TEST(Output, CheckOutputDir) {
  TmpDir dir("checkdir");
  // Fresh nested path under a writable folder: accepted, nothing created.
  const fs::path fresh = dir.path / "a" / "b" / "c";
  EXPECT_NO_THROW(cd::check_output_dir(fresh.string()));
  EXPECT_FALSE(fs::exists(dir.path / "a"));
  EXPECT_NO_THROW(cd::check_output_dir(dir.path.string()));
  EXPECT_NO_THROW(cd::check_output_dir(dir.path.string() + "/"));

  // Below a regular file: fails even for root.
  const fs::path file = dir.path / "file";
  std::ofstream(file) << "x";
  try {
    cd::check_output_dir((file / "out").string());
    ADD_FAILURE() << "no error below a regular file";
  } catch (const cd::OutputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find((file / "out").string()), std::string::npos) << m;
    EXPECT_NE(m.find("not a folder"), std::string::npos) << m;
  }
  // The path itself is a file.
  EXPECT_THROW(cd::check_output_dir(file.string()), cd::OutputError);

  // Read-only folder (root bypasses permissions, so only checked otherwise).
  const fs::path ro = dir.path / "ro";
  fs::create_directory(ro);
  ::chmod(ro.c_str(), 0555);
  if (::geteuid() != 0) {
    try {
      cd::check_output_dir((ro / "out").string());
      ADD_FAILURE() << "no error below a read-only folder";
    } catch (const cd::OutputError& e) {
      EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
    }
  }
  ::chmod(ro.c_str(), 0755);
}

TEST(Output, Series) {
  TmpDir dir("series");
  const fs::path f = dir.path / "series.csv";
  {
    std::ofstream(f) << "stale\n";  // an old run's file is replaced
  }
  cd::Series s(f.string());
  s.row({{"step", 0}, {"time", 0.0}, {"ek", 0.125}});
  s.row({{"step", 100}, {"time", 0.1}, {"ek", 1.0 / 3.0}});
  s.flush();
  EXPECT_EQ(slurp(f), "step,time,ek\n0,0,0.125\n100,0.1,0.3333333333\n");
  s.row({{"step", 200}, {"time", 0.2}, {"ek", -2.5e-7}});
  s.flush();
  s.flush();  // nothing buffered: no change
  EXPECT_EQ(slurp(f), "step,time,ek\n0,0,0.125\n100,0.1,0.3333333333\n200,0.2,-2.5e-07\n");

  EXPECT_THROW(s.row({{"step", 1}, {"time", 0.0}}), std::logic_error);
  EXPECT_THROW(s.row({{"time", 0.0}, {"step", 1}, {"ek", 0}}), std::logic_error);
  s.flush();
  EXPECT_EQ(slurp(f), "step,time,ek\n0,0,0.125\n100,0.1,0.3333333333\n200,0.2,-2.5e-07\n");
}
