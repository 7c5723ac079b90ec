// view.py, the ParaView script cdsim writes into every run folder with
// snapshots (cd/src/core/paraview/view_main.py after docs/figures/chains.py,
// put together at build time). ParaView is not a dependency, so the test
// checks what can go wrong without it: the file is there in 2D and 3D runs,
// is the two sources verbatim (one copy of the force-chain pipeline), is
// valid Python (python3's parser; python3 comes with libvtk9-dev), and every
// collection it opens for that dimension exists in the folder. Rendering it
// was checked by hand with Debian's ParaView 5.11 (pvbatch view.py out.png
// under xvfb-run, as `make figures` runs ParaView) on the default scene, a
// 300-sphere pile, and the polyhedra branch on the two cubes below.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "output3.hpp"
#include "polyhedron.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs cdsim on `scene` with `sets` into a fresh folder and returns it.
fs::path run(const std::string& name, const std::string& scene, const std::string& sets) {
  const fs::path dir = fs::path(CDLAB_BINARY_DIR) / "test_view_script" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  const std::string cmd = std::string(CDLAB_BINARY_DIR "/cd/cdsim ") + CDLAB_SOURCE_DIR + "/configs/" + scene +
                          " " + sets + " --threads 1 --quiet --out " + dir.string() + " > " + dir.string() +
                          ".log 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return dir;
}

void check(const fs::path& dir, const std::set<std::string>& opened) {
  const fs::path view = dir / "view.py";
  ASSERT_TRUE(fs::exists(view));
  const std::string text = slurp(view);
  EXPECT_NE(text.find(slurp(fs::path(CDLAB_SOURCE_DIR) / "docs/figures/chains.py")), std::string::npos);
  EXPECT_NE(text.find(slurp(fs::path(CDLAB_SOURCE_DIR) / "cd/src/core/paraview/view_main.py")), std::string::npos);
  const std::string parse =
      "python3 -c 'import ast, sys; ast.parse(open(sys.argv[1]).read())' " + view.string() + " 2>&1";
  EXPECT_EQ(std::system(parse.c_str()), 0);
  for (const std::string& stem : opened) EXPECT_TRUE(fs::exists(dir / (stem + ".pvd"))) << stem;
  // Every last_frame("...") of the script names one of the collections
  // expected for some dimension: a renamed output file fails here.
  const std::regex re("last_frame\\(\"([a-z]+)\"\\)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it) {
    const std::string stem = (*it)[1];
    EXPECT_TRUE(stem == "shapes" || stem == "walls" || stem == "contacts" || stem == "particles" ||
                stem == "spheres" || stem == "polyhedra")
        << stem;
  }
}

}  // namespace

TEST(ViewScript, TwoDimensionalRunGetsIt) {
  const fs::path dir = run("2d", "default.toml", "--set time.duration=0.02 --set output.snapshot_interval=0.01");
  check(dir, {"shapes", "walls", "contacts", "particles"});
}

TEST(ViewScript, ThreeDimensionalRunGetsIt) {
  const fs::path dir = run("3d", "pile3d.toml",
                           "--set particles.n=27 --set time.duration=0.05 --set output.snapshot_interval=0.025");
  check(dir, {"spheres", "contacts"});
  EXPECT_FALSE(fs::exists(dir / "shapes.pvd"));  // the script's 3D branch is taken
}

// No scene places polyhedra yet: a world of two cubes on a floor, written
// through the 3D snapshot writer as a run would, takes the script's
// polyhedra branch.
TEST(ViewScript, PolyhedraWorldGetsIt) {
  cd::WorldParams3 p;
  p.gravity = cd::Vec3(0, 0, -9.81);
  cd::World3 w(p);
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(0, 0, 1));
  const int cube = w.bodies.add_shape(cd::cuboid(0.02, 0.02, 0.02));
  w.bodies.add_polyhedron(cd::Vec3(0, 0, 0.01), cube, 2600);
  w.bodies.add_polyhedron(cd::Vec3(0.005, 0, 0.03), cube, 2600);
  w.step();
  const fs::path dir = fs::path(CDLAB_BINARY_DIR) / "test_view_script" / "polyhedra";
  fs::remove_all(dir);
  fs::create_directories(dir);
  cd::Snapshots3(dir.string()).write(w);
  check(dir, {"polyhedra", "contacts"});
  fs::remove_all(dir);
}

TEST(ViewScript, NoSnapshotsNoScript) {
  const fs::path dir = run("none", "default.toml", "--set time.duration=0.02 --set output.snapshot_interval=0");
  EXPECT_FALSE(fs::exists(dir / "view.py"));
}
