// Scene files: defaults, every key, error messages, overrides, the resolved
// scene.toml round trip and the parameter table.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config.hpp"

namespace {

using cd::ConfigError;
using cd::DiskSpec;
using cd::Scene;
using cd::WallSpec;

const std::string kFull = std::string(CDLAB_SOURCE_DIR) + "/tests/data/config/full.toml";

// Field-by-field comparison: same = true expects equality, false expects every
// field to differ. The structured bindings stop compiling when a member is added
// to Scene, DiskSpec or WallSpec: add it here, to full.toml, to nondefault() and
// to the table in config.cpp.
#define CHECK_FIELD(f) \
  if (same) { EXPECT_EQ(f, y.f) << #f; } else { EXPECT_NE(f, y.f) << #f; }

void compare(const DiskSpec& x, const DiskSpec& y, bool same) {
  const auto& [pos, vel, radius, omega, density, nsides, angle, force] = x;
  CHECK_FIELD(pos); CHECK_FIELD(vel); CHECK_FIELD(radius); CHECK_FIELD(omega); CHECK_FIELD(density);
  CHECK_FIELD(nsides); CHECK_FIELD(angle); CHECK_FIELD(force);
}

void compare(const WallSpec& x, const WallSpec& y, bool same) {
  const auto& [a, b, vel, omega] = x;
  CHECK_FIELD(a); CHECK_FIELD(b); CHECK_FIELD(vel); CHECK_FIELD(omega);
}

void compare(const Scene& x, const Scene& y, bool same) {
  const auto& [name, source, dimension, dt, duration, gravity, mu, mu_wall, mu_b, mu_wall_b, axis_a, e_n, e_t, alert, rotation, overlap_correction, overlap_projection, adhesion, stiffness, debond, tol,
               max_iter, residual_tol, anderson, subspace, stop_rows, threads, n, d_mean, size_ratio, size_dist, diameters, diameters_file, density, seed, nsides, shape, shape_fractions, aspect, vertices, region,
               box_width, box_height, box_depth, disks, walls, series_interval, snapshot_interval, series_strain, snapshot_strain,
               checkpoint_interval, checkpoint_strain, checkpoint_wall, quiet, shear_mode, cell_width, cell_height, cell_depth, shear_control, pressure,
               imposed_rate, rate_tp, volume_fraction, inertial_number, cell_mass, isotropic, compaction_rate, settle_stress, settle_phi, settle_time, strain, dt_tp, start, cohesion_number, stiffness_number, stiffness_ratio] = x;
  (void)source;  // not a parameter: the file the scene was read from
  CHECK_FIELD(name); CHECK_FIELD(dimension); CHECK_FIELD(dt); CHECK_FIELD(duration); CHECK_FIELD(gravity);
  CHECK_FIELD(mu); CHECK_FIELD(mu_wall); CHECK_FIELD(mu_b); CHECK_FIELD(mu_wall_b); CHECK_FIELD(axis_a); CHECK_FIELD(e_n); CHECK_FIELD(e_t); CHECK_FIELD(alert);
  CHECK_FIELD(rotation); CHECK_FIELD(overlap_correction); CHECK_FIELD(overlap_projection); CHECK_FIELD(adhesion); CHECK_FIELD(stiffness); CHECK_FIELD(debond); CHECK_FIELD(tol); CHECK_FIELD(max_iter); CHECK_FIELD(residual_tol); CHECK_FIELD(anderson); CHECK_FIELD(subspace); CHECK_FIELD(stop_rows); CHECK_FIELD(threads);
  CHECK_FIELD(n); CHECK_FIELD(d_mean); CHECK_FIELD(size_ratio); CHECK_FIELD(size_dist);
  CHECK_FIELD(diameters); CHECK_FIELD(diameters_file);
  CHECK_FIELD(density); CHECK_FIELD(seed); CHECK_FIELD(nsides); CHECK_FIELD(shape); CHECK_FIELD(shape_fractions); CHECK_FIELD(aspect); CHECK_FIELD(vertices); CHECK_FIELD(region); CHECK_FIELD(box_width);
  CHECK_FIELD(box_height); CHECK_FIELD(box_depth); CHECK_FIELD(series_interval); CHECK_FIELD(snapshot_interval);
  CHECK_FIELD(series_strain); CHECK_FIELD(snapshot_strain);
  CHECK_FIELD(checkpoint_interval); CHECK_FIELD(checkpoint_strain); CHECK_FIELD(checkpoint_wall);
  CHECK_FIELD(quiet);
  CHECK_FIELD(shear_mode); CHECK_FIELD(cell_width); CHECK_FIELD(cell_height); CHECK_FIELD(cell_depth); CHECK_FIELD(shear_control); CHECK_FIELD(pressure);
  CHECK_FIELD(imposed_rate); CHECK_FIELD(rate_tp); CHECK_FIELD(volume_fraction);
  CHECK_FIELD(inertial_number); CHECK_FIELD(cell_mass); CHECK_FIELD(isotropic); CHECK_FIELD(compaction_rate);
  CHECK_FIELD(settle_stress); CHECK_FIELD(settle_phi); CHECK_FIELD(settle_time); CHECK_FIELD(strain);
  CHECK_FIELD(dt_tp); CHECK_FIELD(start); CHECK_FIELD(cohesion_number); CHECK_FIELD(stiffness_number); CHECK_FIELD(stiffness_ratio);
  if (same) {
    ASSERT_EQ(disks.size(), y.disks.size());
    ASSERT_EQ(walls.size(), y.walls.size());
  }
  for (std::size_t i = 0; i < std::min(disks.size(), y.disks.size()); ++i) compare(disks[i], y.disks[i], same);
  for (std::size_t i = 0; i < std::min(walls.size(), y.walls.size()); ++i) compare(walls[i], y.walls[i], same);
}

// The scene of tests/data/config/full.toml.
Scene nondefault() {
  Scene s;
  s.name = "silo \"A\"\\1 é";
  s.dimension = 3;  // the parser reads 3D keys into the same Scene; build_world3 checks the rest
  s.dt = 2.5e-5;
  s.duration = 1.0 / 3.0;
  s.gravity = {0.1, -9.80665, 0.5};
  s.mu = 0.3;
  s.mu_wall = 0.7;
  s.mu_b = 0.45;
  s.mu_wall_b = 0.55;
  s.axis_a = {0.0, 2.0, 0.0};
  s.e_n = 0.2;
  s.e_t = 1.0;
  s.alert = 0.05;
  s.rotation = false;
  s.overlap_correction = 0.25;
  s.overlap_projection = 0.3;
  s.adhesion = 2.5e-3;
  s.stiffness = 4.0e6;
  s.debond = 0.02;
  s.tol = 1e-6;
  s.max_iter = 500;
  s.residual_tol = 2e-3;
  s.anderson = 4;
  s.subspace = 7;
  s.stop_rows = cd::StopRows::Loaded;
  s.threads = 2;
  s.n = 3;
  s.d_mean = 2e-3;
  s.size_ratio = 1.5;
  s.size_dist = cd::SizeDist::Uniform;
  // read from tests/data/config/diameters.txt (the file wins over a list);
  // the path is made absolute when read
  s.diameters = {1e-3, 2.5e-3, 4e-3};
  s.diameters_file = std::string(CDLAB_SOURCE_DIR) + "/tests/data/config/diameters.txt";
  s.density = 7.8;
  s.seed = 4294967295u;
  s.nsides = {0.0, 6.0};
  s.shape = {cd::Shape3d::Irregular, cd::Shape3d::Cube};
  s.shape_fractions = {0.25, 0.75};
  s.aspect = {1.0, 2.0, 3.0};
  s.vertices = 20;
  s.region = {0.0, 0.01, 0.1, 0.2};
  s.box_width = 0.1;
  s.box_height = 0.2;
  s.box_depth = 0.3;
  s.series_interval = 1e-3;
  s.snapshot_interval = 0.0;
  s.series_strain = 0.02;
  s.snapshot_strain = 0.3;
  s.checkpoint_interval = 0.05;
  s.checkpoint_strain = 0.1;
  s.checkpoint_wall = 300.5;
  s.quiet = true;
  s.shear_mode = cd::ShearMode::Walls;
  s.cell_width = 0.05;
  s.cell_height = 0.02;
  s.cell_depth = 0.03;
  s.shear_control = cd::ShearControl::Volume;
  s.pressure = 100.0;
  s.imposed_rate = 12.5;
  s.rate_tp = 0.02;
  s.volume_fraction = 0.7;
  s.inertial_number = 0.01;
  s.cell_mass = 2.0;
  s.isotropic = true;
  s.compaction_rate = 0.02;
  s.settle_stress = 0.02;
  s.settle_phi = 2e-3;
  s.settle_time = 3.0;
  s.strain = 3.0;
  s.dt_tp = 0.1;
  s.start = "prep/checkpoint.bin";
  s.cohesion_number = 5.0;
  s.stiffness_number = 3.0e4;
  s.stiffness_ratio = 0.5;
  s.disks = {{{0.05, 0.1}, {1.0, -2.0}, 1e-3, 3.0, 5.0, 4, 0.25, {0.5, -0.5}},
             {{0.02, 0.03}, {0.0, 0.5}, 2e-3, -1.0, -1.0, 60, -1.5, {-1.0, 2.0}}};
  s.walls = {{{0.0, 0.3}, {0.1, 0.25}, {0.0, -0.01}, 0.5}, {{-1.0, 0.0}, {-1.0, 1.0}, {0.2, 0.0}, -0.5}};
  return s;
}

// The message of the ConfigError thrown by parse_scene (fails if none).
std::string error(const std::string& text, const std::vector<std::string>& sets = {}) {
  try {
    cd::parse_scene(text, "x.toml", sets);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError for:\n" << text;
  return "";
}

TEST(Defaults, EmptyFileGivesSceneDefaults) {
  const Scene s = cd::parse_scene("", "empty.toml");
  compare(s, Scene{}, true);
  EXPECT_EQ(s.source, "empty.toml");
  EXPECT_TRUE(s.disks.empty());
  EXPECT_TRUE(s.walls.empty());
}

TEST(FullFile, EveryKeyIsReadAndDiffersFromItsDefault) {
  const Scene s = cd::load_scene(kFull);
  EXPECT_EQ(s.source, kFull);
  compare(s, nondefault(), true);
  // Every field of the file differs from its default, so each key was bound.
  compare(nondefault(), Scene{}, false);
  compare(nondefault().disks[0], DiskSpec{}, false);
  compare(nondefault().walls[0], WallSpec{}, false);
}

TEST(FullFile, IntegersAreAcceptedForFloats) {
  const Scene s = cd::parse_scene("[time]\ndt = 1\n[gravity]\ng = [0, -10]\n", "x.toml");
  EXPECT_EQ(s.dt, 1.0);
  EXPECT_EQ(s.gravity, (std::vector<double>{0.0, -10.0}));
}

TEST(Errors, UnknownKeyNamesLineColumnAndClosestKey) {
  EXPECT_EQ(error("[time]\ndt = 1e-3\n\n[contact]\n  muu = 0.3\n"),
            "x.toml:5:3: unknown key 'contact.muu' (did you mean 'contact.mu'?)");
  EXPECT_EQ(error("[particles]\ndesnity = 2\n"),
            "x.toml:2:1: unknown key 'particles.desnity' (did you mean 'particles.density'?)");
}

TEST(Errors, KeyInTheWrongSectionSuggestsTheRightOne) {
  EXPECT_EQ(error("[solver]\nmu = 0.3\n"),
            "x.toml:2:1: unknown key 'solver.mu' (did you mean 'contact.mu'?)");
  EXPECT_EQ(error("dt = 1e-3\n"), "x.toml:1:1: unknown key 'dt' (did you mean 'time.dt'?)");
}

TEST(Errors, NoSuggestionWhenNothingIsClose) {
  EXPECT_EQ(error("[contact]\nhardness = 1e6\n"), "x.toml:2:1: unknown key 'contact.hardness'");
}

TEST(Errors, UnknownSection) {
  EXPECT_EQ(error("[time]\ndt = 1e-3\n[contct]\nmu = 0.3\n"),
            "x.toml:3:1: unknown section 'contct' (did you mean 'contact'?)");
  EXPECT_EQ(error("[[disks]]\nradius = 1\n"),
            "x.toml:1:1: unknown section 'disks' (did you mean 'disk'?)");
}

// TOML text is UTF-8: any other byte is refused by position before the
// parser sees it (toml11 3.7 read outside its buffer reporting one inside a
// string; tests/data/fuzz/scene/), overlong forms and surrogates included;
// valid multi-byte text (a comment, a name) still reads.
TEST(Errors, TextThatIsNotUtf8) {
  EXPECT_EQ(error("'\xA9'~"), "'x.toml' is not a scene file (TOML text): invalid UTF-8 byte 0xa9 at line 1, byte 2");
  EXPECT_EQ(error("# ok\nname = \"a\xC0\xAF\"\n"),
            "'x.toml' is not a scene file (TOML text): invalid UTF-8 byte 0xc0 at line 2, byte 15");
  EXPECT_EQ(error("name = 'a\xED\xA0\x80'\n"),
            "'x.toml' is not a scene file (TOML text): invalid UTF-8 byte 0xed at line 1, byte 10");
  EXPECT_EQ(error("", {"name=a\xFF"}), "--set name: the value: invalid UTF-8 byte 0xff at line 1, byte 2");
  EXPECT_EQ(cd::parse_scene("# \xC3\xA9t\xC3\xA9 \xE2\x86\x92 \xF0\x9F\x99\x82\nname = \"gr\xC3\xA4in\"\n", "x.toml").name,
            "gr\xC3\xA4in");
}

TEST(Errors, WrongType) {
  EXPECT_EQ(error("[time]\ndt = \"fast\"\n"), "x.toml:2:1: time.dt: expected a number, got a string");
  EXPECT_EQ(error("[solver]\nmax_iter = 100.0\n"),
            "x.toml:2:1: solver.max_iter: expected an integer, got a float");
  EXPECT_EQ(error("[contact]\nrotation = 1\n"),
            "x.toml:2:1: contact.rotation: expected true or false, got an integer");
  EXPECT_EQ(error("[gravity]\ng = [0, -9.81, 0]\n"),
            "x.toml:2:1: gravity.g = [0, -9.81, 0]: a dimension = 2 scene needs 2 components ([gx, gy])");
  EXPECT_EQ(error("dimension = 3\n[gravity]\ng = [0, -9.81]\n"),
            "x.toml:3:1: gravity.g = [0, -9.81]: a dimension = 3 scene needs 3 components ([gx, gy, gz], z up)");
  EXPECT_EQ(error("[gravity]\ng = [0, -9.81, 0, 1]\n"),
            "x.toml:2:1: gravity.g = [0, -9.81, 0, 1]: must be a list of 2 or 3 numbers");
  EXPECT_EQ(error("[box]\ndepth = 0.1\n"),
            "x.toml:2:1: box.depth = 0.1: only a dimension = 3 scene has a depth");
  EXPECT_EQ(error("[gravity]\ng = [0, \"down\"]\n"),
            "x.toml:2:1: gravity.g: expected an array of numbers, got an array containing a string");
  EXPECT_EQ(error("name = 3\n"), "x.toml:1:1: name: expected a string, got an integer");
  EXPECT_EQ(error("time = 3\n"), "x.toml:1:1: time: expected a [time] table, got an integer");
  EXPECT_EQ(error("[disk]\nradius = 1\n"),
            "x.toml:1:1: disk: expected [[disk]] tables, got a table");
}

// TOML spells inf and nan; no scene value may be either, in any position.
TEST(Errors, NonFiniteNumbers) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[time]\nduration = inf", "x.toml:2:1: time.duration = inf: must be a finite number"},
      {"[time]\ndt = nan", "x.toml:2:1: time.dt = nan: must be a finite number"},
      {"[contact]\nadhesion = +inf", "x.toml:2:1: contact.adhesion = inf: must be a finite number"},
      {"[contact]\nmu_wall = nan", "x.toml:2:1: contact.mu_wall = nan: must be a finite number"},
      {"[solver]\ntol = inf", "x.toml:2:1: solver.tol = inf: must be a finite number"},
      {"[shear]\nstrain = inf", "x.toml:2:1: shear.strain = inf: must be a finite number"},
      {"[shear]\ncompaction_rate = nan", "x.toml:2:1: shear.compaction_rate = nan: must be a finite number"},
      {"[contact]\noverlap_projection = inf", "x.toml:2:1: contact.overlap_projection = inf: must be a finite number"},
      {"[gravity]\ng = [0, -inf]", "x.toml:2:1: gravity.g: element 1 is -inf: must be finite numbers"},
      {"[gravity]\ng = [nan, -9.81]", "x.toml:2:1: gravity.g: element 0 is nan: must be finite numbers"},
      {"[[disk]]\npos = [0, 0]\nradius = inf", "x.toml:3:1: disk[0].radius = inf: must be a finite number"},
      {"[[disk]]\npos = [0, 0]\nvel = [inf, 0]\nradius = 1",
       "x.toml:3:1: disk[0].vel: element 0 is inf: must be finite numbers"},
      {"[particles]\nregion = [0, 0, inf, 1]",
       "x.toml:2:1: particles.region: element 2 is inf: must be finite numbers"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(error(text), message) << text;
}

TEST(Errors, ValueOutOfRange) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[contact]\ne_n = 1.5", "x.toml:2:1: contact.e_n = 1.5: must be in [0, 1]"},
      {"[contact]\ne_t = -0.1", "x.toml:2:1: contact.e_t = -0.1: must be in [0, 1]"},
      {"[contact]\noverlap_projection = 1.5", "x.toml:2:1: contact.overlap_projection = 1.5: must be in [0, 1]"},
      {"[shear]\ncompaction_rate = -0.01", "x.toml:2:1: shear.compaction_rate = -0.01: must be in [0, 1]"},
      {"[contact]\nmu = -0.1", "x.toml:2:1: contact.mu = -0.1: must be >= 0"},
      {"[time]\ndt = 0", "x.toml:2:1: time.dt = 0: must be > 0"},
      {"[time]\nduration = -1", "x.toml:2:1: time.duration = -1: must be >= 0"},
      {"[solver]\ntol = 0.0", "x.toml:2:1: solver.tol = 0: must be in (0, 1]"},
      {"[solver]\nmax_iter = 0", "x.toml:2:1: solver.max_iter = 0: must be in [1, 100000000]"},
      {"[solver]\nthreads = -2", "x.toml:2:1: solver.threads = -2: must be in [0, 1024]"},
      {"[particles]\nsize_ratio = 0.5", "x.toml:2:1: particles.size_ratio = 0.5: must be >= 1"},
      {"[particles]\nd_mean = -1e-3", "x.toml:2:1: particles.d_mean = -0.001: must be > 0"},
      {"[particles]\nsize_dist = \"gaussian\"",
       "x.toml:2:1: particles.size_dist = \"gaussian\": must be \"uniform\" or \"uniform_area\""},
      {"[particles]\nseed = -1", "x.toml:2:1: particles.seed = -1: must be an integer in [0, 4294967295]"},
      {"[particles]\nregion = [0, 0, 1]",
       "x.toml:2:1: particles.region = [0, 0, 1]: must be [] or [xmin, ymin, xmax, ymax] with "
       "xmin < xmax, ymin < ymax"},
      {"[particles]\nregion = [1, 0, 0, 1]",
       "x.toml:2:1: particles.region = [1, 0, 0, 1]: must be [] or [xmin, ymin, xmax, ymax] with "
       "xmin < xmax, ymin < ymax"},
      {"[output]\nseries_interval = 0", "x.toml:2:1: output.series_interval = 0: must be > 0"},
      {"[output]\nsnapshot_interval = -1", "x.toml:2:1: output.snapshot_interval = -1: must be >= 0"},
      {"[output]\ncheckpoint_interval = -1", "x.toml:2:1: output.checkpoint_interval = -1: must be >= 0"},
      {"[output]\ncheckpoint_strain = -0.1", "x.toml:2:1: output.checkpoint_strain = -0.1: must be >= 0"},
      {"[output]\ncheckpoint_wall = -5", "x.toml:2:1: output.checkpoint_wall = -5: must be >= 0"},
      {"name = \"\"", "x.toml:1:1: name = \"\": must be a folder name: non-empty, no '/', not '.' or '..'"},
      {"[solver]\ntol = 2.0", "x.toml:2:1: solver.tol = 2: must be in (0, 1]"},
      {"[particles]\nn = 200000000", "x.toml:2:1: particles.n = 200000000: must be in [0, 100000000]"},
      {"[box]\nwidth = 1", "x.toml:1:1: box.width = 1, box.height = 0: must be both 0 (no box) or both > 0"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(error(text), message) << text;
}

TEST(Errors, BoundaryValuesAreAccepted) {
  const Scene s = cd::parse_scene(
      "[contact]\ne_n = 1\ne_t = 0\nmu = 0\nmu_wall = -1\n[solver]\nmax_iter = 1\n"
      "[particles]\nsize_ratio = 1\nregion = []\n[output]\nsnapshot_interval = 0\n",
      "x.toml");
  EXPECT_EQ(s.e_n, 1.0);
  EXPECT_EQ(s.mu_w(), 0.0);  // mu_wall < 0: same as mu
  EXPECT_EQ(s.max_iter, 1);
}

TEST(Errors, DiskAndWallEntriesAreNamedByIndex) {
  const std::string disks =
      "[[disk]]\nradius = 1e-3\n[[disk]]\nradius = 1e-3\n[[disk]]\nradius = 1e-3\n"
      "[[disk]]\npos = [0, 1]\nradius = -1\n";
  EXPECT_EQ(error(disks), "x.toml:9:1: disk[3].radius = -1: must be > 0");
  EXPECT_EQ(error("[[disk]]\ndensity = 0\n"),
            "x.toml:2:1: disk[0].density = 0: must be > 0, or -1 (particles.density)");
  EXPECT_EQ(error("[[disk]]\nradus = 1e-3\n"),
            "x.toml:2:1: unknown key 'disk[0].radus' (did you mean 'disk[0].radius'?)");
  EXPECT_EQ(error("[[wall]]\na = [0, 0]\n[[wall]]\na = [1, 1]\nb = [1, 1]\n"),
            "x.toml:3:1: wall[1]: a = b = [1, 1]: the end points must differ");
  EXPECT_EQ(cd::parse_scene("disk = [{radius = 1e-3}, {radius = 2e-3}]", "x.toml").disks.at(1).radius, 2e-3);
}

TEST(Errors, AllProblemsAreReportedInFileOrder) {
  EXPECT_EQ(error("[time]\ndt = -1\n[contact]\nmuu = 1\ne_n = 2\n"),
            "x.toml:2:1: time.dt = -1: must be > 0\n"
            "x.toml:4:1: unknown key 'contact.muu' (did you mean 'contact.mu'?)\n"
            "x.toml:5:1: contact.e_n = 2: must be in [0, 1]");
}

TEST(Errors, SyntaxErrorNamesFileAndLineAndKeepsTomlMessage) {
  const std::string e = error("[time]\ndt = 1e-3\nduration = = 2\n");
  EXPECT_EQ(e.rfind("x.toml:3: TOML syntax error: ", 0), 0u) << e;
  EXPECT_NE(e.find("duration = = 2"), std::string::npos) << e;  // toml11's excerpt
  EXPECT_EQ(error("[time]\ndt = 1\ndt = 2\n").rfind("x.toml:", 0), 0u);  // duplicate key
}

TEST(Errors, MissingFile) {
  try {
    cd::load_scene("no/such/scene.toml");
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "cannot open scene file 'no/such/scene.toml'");
  }
}

TEST(Errors, PositionsInARealFile) {
  try {
    cd::load_scene(kFull, {"contact.e_n=2"});
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "--set contact.e_n=2: contact.e_n = 2: must be in [0, 1]");
  }
}

TEST(Overrides, AreAppliedAfterTheFile) {
  const Scene s = cd::parse_scene("[contact]\nmu = 0.2\n", "x.toml",
                                  {"contact.mu=0.3", "gravity.g=[0,-1]", "name=\"x y\"",
                                   "particles.size_dist = uniform", "solver.max_iter=7",
                                   "output.quiet=true", "time.dt=1e-5", "time.dt=2e-5"});
  EXPECT_EQ(s.mu, 0.3);
  EXPECT_EQ(s.gravity, (std::vector<double>{0.0, -1.0}));
  EXPECT_EQ(s.name, "x y");
  EXPECT_EQ(s.size_dist, cd::SizeDist::Uniform);  // a bare word (the shell ate the quotes) is a name
  EXPECT_EQ(s.max_iter, 7);
  EXPECT_TRUE(s.quiet);
  EXPECT_EQ(s.dt, 2e-5);  // the last one wins
  EXPECT_EQ(s.duration, Scene{}.duration);
}

TEST(Overrides, UnknownKeyOrBadValueIsAnError) {
  EXPECT_EQ(error("", {"contact.muu=0.3"}),
            "--set contact.muu=0.3: unknown key 'contact.muu' (did you mean 'contact.mu'?)");
  EXPECT_EQ(error("", {"mu=0.3"}), "--set mu=0.3: unknown key 'mu' (did you mean 'contact.mu'?)");
  EXPECT_EQ(error("", {"contact.e_n=1.5"}), "--set contact.e_n=1.5: contact.e_n = 1.5: must be in [0, 1]");
  EXPECT_EQ(error("", {"solver.max_iter=1e3"}),
            "--set solver.max_iter=1e3: solver.max_iter: expected an integer, got a float");
  EXPECT_EQ(error("", {"time.dt=fast"}),
            "--set time.dt=fast: 'fast' is not a TOML value (a number, true, false, \"string\" or [array])");
  EXPECT_EQ(error("", {"gravity.g=[0,-1"}),
            "--set gravity.g=[0,-1: '[0,-1' is not a TOML value (a number, true, false, \"string\" or [array])");
  EXPECT_EQ(error("", {"time.dt=\"fast\""}), "--set time.dt=\"fast\": time.dt: expected a number, got a string");
  EXPECT_EQ(error("", {"contact.mu"}), "--set contact.mu: expected section.key=value");
}

TEST(Resolved, RoundTripsANonDefaultSceneExactly) {
  Scene s = nondefault();
  // Doubles that need 17 digits or an exponent, at the ends of the range a
  // scene may give (0 or 1e-100 to 1e100 in magnitude).
  s.gravity = {0.1 + 0.2, -1e-100, 1e100};
  s.disks[0].pos = {9.8765432109876543e99, 1.2345678901234567e-99};
  s.disks[1].vel = {-0.0, 2.0 / 3.0};
  s.walls[1].omega = 1e22;
  s.name = "tab\there, newline\nthere";
  s.source = "scene.toml";  // named in the first comment line
  const std::string toml = cd::resolved_toml(s);
  const Scene r = cd::parse_scene(toml, "scene.toml");
  compare(r, s, true);
  EXPECT_EQ(r.source, "scene.toml");
  EXPECT_EQ(cd::resolved_toml(r), cd::resolved_toml(s)) << toml;  // stable
}

TEST(Resolved, DefaultsRoundTripAndShowUnitsAndMeaning) {
  const std::string toml = cd::resolved_toml(Scene{});
  compare(cd::parse_scene(toml, "scene.toml"), Scene{}, true);
  EXPECT_NE(toml.find("\n[time]\ndt = 0.0001"), std::string::npos) << toml;
  EXPECT_NE(toml.find("# [s] time step\n"), std::string::npos) << toml;
  EXPECT_NE(toml.find("size_ratio = 2.0 "), std::string::npos) << toml;  // a float stays a float
  EXPECT_NE(toml.find("max_iter = 2000 "), std::string::npos) << toml;
  EXPECT_EQ(toml.find("[[disk]]"), std::string::npos);
}

TEST(Markdown, OneRowPerParameter) {
  const std::string md = cd::parameter_table_markdown();
  EXPECT_EQ(md.rfind("| key | default | unit | rule | meaning |\n|---|---|---|---|---|\n", 0), 0u);
  std::size_t rows = 0;
  for (std::size_t k = 0; (k = md.find("\n| `", k)) != std::string::npos; ++k) ++rows;
  // 73 scene keys + 8 per [[disk]] + 4 per [[wall]]: the members of Scene,
  // DiskSpec and WallSpec but Scene::source, disks and walls.
  EXPECT_EQ(rows, 73u + 8u + 4u) << md;
  EXPECT_NE(md.find("| `contact.e_n` | `0.0` |  | in [0, 1] | normal restitution coefficient |"),
            std::string::npos) << md;
  EXPECT_NE(md.find("| `solver.max_iter` | `2000` |  | integer in [1, 100000000] |"), std::string::npos) << md;
  EXPECT_NE(md.find("| `contact.rotation` | `true` |  |  | integrate"), std::string::npos) << md;
  EXPECT_NE(md.find("| `disk[i].radius` | `0.0005` | m | > 0 | radius |"), std::string::npos) << md;
  EXPECT_NE(md.find("`particles.size_dist` | `\"uniform_area\"`"), std::string::npos) << md;
}

}  // namespace
