// The shear settings by I (cd/src/scene/shear_policy.hpp, docs/shear.md
// "Settings by I"): the documented table at its breakpoints, "auto" in a
// scene resolved to it (and refused where there is no I), and a campaign
// point and a single run at the same I resolving to the same settings: the
// command `make -n` shows for a campaign run and the single run of the same
// scene, both printed by cdsim --print-scene; and an explicit solver.tol
// keeping the "auto" mixing, with what cdsim says of the steps it leaves at
// the sweep cap.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "cli_util.hpp"
#include "config.hpp"
#include "run.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "shear_policy.hpp"

namespace {

struct Expected {
  double I, tol, residual_tol;                                // plain NLGS (and the subspace correction's residual stop)
  double tol_anderson, residual_anderson, projection_anderson;  // Anderson, cohesionless
  double tol_subspace, tol_cohesive;                          // the subspace correction; Anderson, cohesive
  double dt_tp, cell_mass;
};

// docs/shear.md's table, read at and around each breakpoint (I = 0.01 for
// the stops, 0.1 for the time step's cap, 0.5 for the cell mass).
const Expected kTable[] = {
    {0.001, 1e-4, 3e-3, 3e-4, 0.0, 0.5, 1e-4, 1e-4, 0.05, 0.1},
    {0.00999, 1e-4, 3e-3, 3e-4, 0.0, 0.5, 1e-4, 1e-4, 0.05, 0.1},
    {0.01, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.05, 0.1},
    {0.05, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.05, 0.1},
    {0.1, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.05, 0.1},
    {0.2, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.025, 0.1},
    {0.3, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.01667, 0.1},
    {0.49, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.0102, 0.1},
    {0.5, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.01, 0.01},
    {1.0, 1e-3, 0.0, 5e-4, 0.0, 0.0, 7e-4, 5e-4, 0.005, 0.01},
};

const cd::SceneKind kDisks{2, false, false};
const cd::SceneKind kSpheres{3, false, false};
const cd::SceneKind kCohesiveSpheres{3, true, false};
const cd::SceneKind kPolygons{2, false, true};

TEST(ShearPolicy, TheTableAtItsBreakpoints) {
  for (const Expected& e : kTable) {
    for (const cd::SceneKind kind : {kDisks, kSpheres, kCohesiveSpheres}) {
      const cd::ShearSettings s = cd::shear_settings(e.I, cd::Acceleration::None, kind);
      EXPECT_EQ(s.tol, e.tol) << "I = " << e.I;
      EXPECT_EQ(s.residual_tol, e.residual_tol) << "I = " << e.I;
      EXPECT_EQ(s.overlap_projection, 0.0) << "I = " << e.I;
      EXPECT_EQ(s.dt_tp, e.dt_tp) << "I = " << e.I;
      EXPECT_EQ(s.cell_mass, e.cell_mass) << "I = " << e.I;
      // dt <= 0.005 t_p / I (to the 4 digits it is written with), <= 0.05 t_p.
      EXPECT_LE(s.dt_tp, 0.005 / e.I * (1 + 5e-4)) << "I = " << e.I;
      EXPECT_LE(s.dt_tp, 0.05) << "I = " << e.I;
      // Polygons' plain solve: the Anderson stop's numbers below I = 0.01
      // (both measured at tol 3e-4 with the projection), tol 2e-3 with the
      // projection up to 0.5, the plain stop above.
      const cd::ShearSettings g = cd::shear_settings(e.I, cd::Acceleration::None, kPolygons);
      EXPECT_EQ(g.tol, e.I < 0.01 ? e.tol_anderson : e.I < 0.5 ? 2e-3 : e.tol) << "I = " << e.I;
      EXPECT_EQ(g.residual_tol, e.I < 0.01 ? e.residual_anderson : e.residual_tol) << "I = " << e.I;
      EXPECT_EQ(g.overlap_projection, e.I < 0.01 ? e.projection_anderson : e.I < 0.5 ? 0.5 : 0.0) << "I = " << e.I;
      EXPECT_EQ(g.anderson, 0) << "I = " << e.I;
      EXPECT_EQ(g.dt_tp, s.dt_tp) << "I = " << e.I;
      // An acceleration changes the stop only.
      const cd::ShearSettings a = cd::shear_settings(e.I, cd::Acceleration::Anderson, kind);
      EXPECT_EQ(a.tol, kind.cohesive ? e.tol_cohesive : e.tol_anderson) << "I = " << e.I;
      EXPECT_EQ(a.residual_tol, kind.cohesive ? e.residual_tol : e.residual_anderson) << "I = " << e.I;
      EXPECT_EQ(a.overlap_projection, kind.cohesive ? 0.0 : e.projection_anderson) << "I = " << e.I;
      const cd::ShearSettings m = cd::shear_settings(e.I, cd::Acceleration::Subspace, kind);
      EXPECT_EQ(m.tol, e.tol_subspace) << "I = " << e.I;
      EXPECT_EQ(m.residual_tol, e.residual_tol) << "I = " << e.I;
      EXPECT_EQ(m.overlap_projection, 0.0) << "I = " << e.I;
      for (const cd::ShearSettings& x : {a, m}) {
        EXPECT_EQ(x.dt_tp, s.dt_tp) << "I = " << e.I;
        EXPECT_EQ(x.cell_mass, s.cell_mass) << "I = " << e.I;
      }
    }
  }
}

const char* kAutoScene =
    "[solver]\ntol = \"auto\"\nresidual_tol = \"auto\"\n"
    "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.3\ndt_tp = \"auto\"\ncell_mass = \"auto\"\n";

TEST(ShearPolicy, AutoKeysTakeThePolicysValueForTheScenesI) {
  for (const Expected& e : kTable) {
    std::ostringstream I;
    I << e.I;
    const cd::Scene s = cd::parse_scene(kAutoScene, "a.toml", {"shear.inertial_number=" + I.str()});
    EXPECT_EQ(s.tol, e.tol) << "I = " << e.I;
    EXPECT_EQ(s.residual_tol, e.residual_tol) << "I = " << e.I;
    EXPECT_EQ(s.dt_tp, e.dt_tp) << "I = " << e.I;
    EXPECT_EQ(s.cell_mass, e.cell_mass) << "I = " << e.I;
    // The resolved scene holds the numbers, and reads back to them.
    const std::string r = cd::resolved_toml(s);
    EXPECT_EQ(r.find("= \"auto\""), std::string::npos) << r;
    const cd::Scene back = cd::parse_scene(r, "scene.toml");
    EXPECT_EQ(back.tol, s.tol);
    EXPECT_EQ(back.residual_tol, s.residual_tol);
    EXPECT_EQ(back.dt_tp, s.dt_tp);
    EXPECT_EQ(back.cell_mass, s.cell_mass);
  }
  // A number overrides the policy for its key only; a bare word works as an override.
  const cd::Scene o = cd::parse_scene(kAutoScene, "a.toml", {"solver.tol=1e-5", "shear.inertial_number=0.001"});
  EXPECT_EQ(o.tol, 1e-5);
  EXPECT_EQ(o.residual_tol, 3e-3);
  const cd::Scene w = cd::parse_scene("[shear]\ninertial_number = 0.6\n", "a.toml", {"shear.cell_mass=auto"});
  EXPECT_EQ(w.cell_mass, 0.01);
  // With Anderson's mixing on, "auto" takes the band's tol_anderson, wherever
  // solver.anderson is given (the scene or an override after the key).
  for (const Expected& e : kTable) {
    std::ostringstream I;
    I << e.I;
    const cd::Scene a =
        cd::parse_scene(kAutoScene, "a.toml", {"shear.inertial_number=" + I.str(), "solver.anderson=5"});
    EXPECT_EQ(a.tol, e.tol_anderson) << "I = " << e.I;
    EXPECT_EQ(a.residual_tol, e.residual_anderson) << "I = " << e.I;
  }
}

TEST(ShearPolicy, AutoWithoutAnInertialNumberOrOnAnotherKeyIsRefused) {
  try {
    cd::parse_scene("[solver]\ntol = \"auto\"\n", "a.toml");
    FAIL() << "no I";
  } catch (const cd::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("a.toml:2:1: solver.tol = \"auto\" is set by shear.inertial_number"),
              std::string::npos)
        << e.what();
  }
  try {
    cd::parse_scene("[contact]\nmu = \"auto\"\n[shear]\ninertial_number = 0.1\n", "a.toml");
    FAIL() << "contact.mu has no policy";
  } catch (const cd::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("contact.mu: expected a number, got a string"), std::string::npos)
        << e.what();
  }
}

// "auto" for the overlap projection: with Anderson's stop below I = 0.01
// (cohesionless), off elsewhere.
TEST(ShearPolicy, AutoProjectionFollowsTheStop) {
  const std::string scene3 =
      "dimension = 3\ngravity.g = [0.0, 0.0, 0.0]\n[contact]\noverlap_projection = \"auto\"\n"
      "[solver]\ntol = \"auto\"\nresidual_tol = \"auto\"\nanderson = \"auto\"\nsubspace = \"auto\"\n"
      "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.01\n";
  const cd::Scene low = cd::parse_scene(scene3, "a.toml", {"shear.inertial_number=0.001"});
  EXPECT_EQ(low.overlap_projection, 0.5);
  EXPECT_EQ(low.anderson, 5);
  EXPECT_EQ(low.tol, 3e-4);
  EXPECT_EQ(low.residual_tol, 0.0);
  EXPECT_EQ(cd::parse_scene(scene3, "a.toml").overlap_projection, 0.0);  // I = 0.01
  // Plain NLGS below 0.01 keeps the band's stop, without the projection.
  const cd::Scene plain = cd::parse_scene(scene3, "a.toml", {"shear.inertial_number=0.001", "solver.anderson=0"});
  EXPECT_EQ(plain.overlap_projection, 0.0);
  EXPECT_EQ(plain.tol, 1e-4);
  EXPECT_EQ(plain.residual_tol, 3e-3);
  // 2D: disks mix (and take it), polygons do not; a cohesive scene keeps
  // the residual stop, without it.
  const std::string scene2 =
      "[contact]\noverlap_projection = \"auto\"\n[solver]\ntol = \"auto\"\nresidual_tol = \"auto\"\n"
      "anderson = \"auto\"\n[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.001\n";
  const cd::Scene disks = cd::parse_scene(scene2, "b.toml");
  EXPECT_EQ(disks.overlap_projection, 0.5);
  EXPECT_EQ(disks.tol, 3e-4);
  EXPECT_EQ(disks.residual_tol, 0.0);
  // Polygons: plain NLGS, at looser stops with the projection below
  // I = 0.5 (1000 hexagons, docs/accuracy.md), the plain stop above.
  const cd::Scene hex = cd::parse_scene(scene2, "b.toml", {"particles.nsides=[6]"});
  EXPECT_EQ(hex.anderson, 0);
  EXPECT_EQ(hex.overlap_projection, 0.5);
  EXPECT_EQ(hex.tol, 3e-4);
  EXPECT_EQ(hex.residual_tol, 0.0);
  const cd::Scene hex2 = cd::parse_scene(scene2, "b.toml", {"particles.nsides=[6]", "shear.inertial_number=0.01"});
  EXPECT_EQ(hex2.overlap_projection, 0.5);
  EXPECT_EQ(hex2.tol, 2e-3);
  EXPECT_EQ(hex2.residual_tol, 0.0);
  const cd::Scene hex3 = cd::parse_scene(scene2, "b.toml", {"particles.nsides=[6]", "shear.inertial_number=0.5"});
  EXPECT_EQ(hex3.overlap_projection, 0.0);
  EXPECT_EQ(hex3.tol, 1e-3);
  // A cohesive polygon scene keeps the plain residual stop (not measured).
  const cd::Scene hexc =
      cd::parse_scene(scene2, "b.toml", {"particles.nsides=[6]", "contact.cohesion_number=10"});
  EXPECT_EQ(hexc.tol, 1e-4);
  EXPECT_EQ(hexc.residual_tol, 3e-3);
  EXPECT_EQ(hexc.overlap_projection, 0.0);
  const cd::Scene coh = cd::parse_scene(scene3, "a.toml", {"shear.inertial_number=0.001", "contact.cohesion_number=10"});
  EXPECT_EQ(coh.anderson, 5);
  EXPECT_EQ(coh.overlap_projection, 0.0);
  EXPECT_EQ(coh.tol, 1e-4);
  EXPECT_EQ(coh.residual_tol, 3e-3);
}

// "auto" for the acceleration: the band's choice, resolved before the
// tolerance that depends on it; a number wins; a 2D scene cannot take the
// subspace correction the band would choose for it.
TEST(ShearPolicy, AutoAccelerationIsTheBandsAndDecidesTheTolerance) {
  const std::string scene =
      "dimension = 3\ngravity.g = [0.0, 0.0, 0.0]\n[solver]\ntol = \"auto\"\nanderson = \"auto\"\nsubspace = \"auto\"\n"
      "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.01\n";
  for (const double I : {0.001, 0.00999, 0.01, 0.3, 0.5}) {
    std::ostringstream is;
    is << "shear.inertial_number=" << I;
    const cd::Scene s = cd::parse_scene(scene, "a.toml", {is.str()});
    const cd::ShearSettings band = cd::shear_settings(I);
    EXPECT_EQ(s.anderson, band.anderson) << "I = " << I;
    EXPECT_EQ(s.subspace, band.subspace) << "I = " << I;
    EXPECT_EQ(s.anderson, I < 0.01 ? 5 : 0) << "I = " << I;
    EXPECT_EQ(s.subspace, I < 0.01 ? 0 : 10) << "I = " << I;
    const auto acc = I < 0.01 ? cd::Acceleration::Anderson : cd::Acceleration::Subspace;
    EXPECT_EQ(s.tol, cd::shear_settings(I, acc).tol) << "I = " << I;
  }
  // A cohesive scene keeps Anderson's mixing in every band.
  for (const char* coh : {"contact.cohesion_number=10", "contact.adhesion=1e-3"}) {
    const cd::Scene c = cd::parse_scene(scene, "a.toml", {coh, "shear.inertial_number=0.01"});
    EXPECT_EQ(c.subspace, 0) << coh;
    EXPECT_EQ(c.anderson, cd::kAnderson) << coh;
    EXPECT_EQ(c.tol, cd::shear_settings(0.01, cd::Acceleration::Anderson, kCohesiveSpheres).tol) << coh;
  }
  // An orthotropic cone: the subspace correction does not act on it, so
  // "auto" gives none and the tolerance of what then runs (the band's
  // Anderson choice); a number is refused, naming both keys.
  for (const double I : {0.001, 0.01, 0.3}) {
    std::ostringstream is;
    is << "shear.inertial_number=" << I;
    for (const char* ortho : {"contact.mu_b=0.2", "contact.mu_wall_b=0.1"}) {
      const cd::Scene o = cd::parse_scene(scene, "a.toml", {is.str(), ortho});
      EXPECT_EQ(o.subspace, 0) << ortho << ", I = " << I;
      EXPECT_EQ(o.anderson, I < 0.01 ? cd::kAnderson : 0) << ortho << ", I = " << I;
      const auto acc = I < 0.01 ? cd::Acceleration::Anderson : cd::Acceleration::None;
      EXPECT_EQ(o.tol, cd::shear_settings(I, acc).tol) << ortho << ", I = " << I;
      try {
        cd::check_scene3(cd::parse_scene(scene, "a.toml", {is.str(), ortho, "solver.subspace=10"}));
        ADD_FAILURE() << "an orthotropic scene took the subspace correction";
      } catch (const std::exception& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("solver.subspace = 10"), std::string::npos) << m;
        EXPECT_NE(m.find(std::string(ortho).substr(0, std::string(ortho).find('='))), std::string::npos) << m;
      }
    }
  }
  // 2D: Anderson's mixing with disks, none with polygons, in every band;
  // the tolerance follows.
  const std::string scene2 =
      "[solver]\ntol = \"auto\"\nanderson = \"auto\"\n[shear]\nmode = \"periodic\"\npressure = 100.0\n";
  for (const double I : {0.001, 0.01, 0.5}) {
    std::ostringstream is;
    is << "shear.inertial_number=" << I;
    const cd::Scene d = cd::parse_scene(scene2, "c.toml", {is.str()});
    EXPECT_EQ(d.anderson, cd::kAnderson) << "disks, I = " << I;
    EXPECT_EQ(d.tol, cd::shear_settings(I, cd::Acceleration::Anderson, kDisks).tol) << "disks, I = " << I;
    for (const char* ns : {"particles.nsides=[6]", "particles.nsides=[3,6,0]"}) {
      const cd::Scene g = cd::parse_scene(scene2, "c.toml", {is.str(), ns});
      EXPECT_EQ(g.anderson, 0) << ns << ", I = " << I;
      EXPECT_EQ(g.tol, cd::shear_settings(I, cd::Acceleration::None, kPolygons).tol) << ns << ", I = " << I;
    }
  }
  // A number for one of them: kept, and the tolerance follows what runs.
  const cd::Scene n = cd::parse_scene(scene, "a.toml", {"solver.subspace=0", "shear.inertial_number=0.01"});
  EXPECT_EQ(n.subspace, 0);
  EXPECT_EQ(n.anderson, 0);  // the band's own choice for anderson at 0.01
  EXPECT_EQ(n.tol, cd::shear_settings(0.01).tol);
  // 2D: "auto" never takes the subspace correction; a number is refused,
  // with the key named.
  const std::string two = "[solver]\nsubspace = \"auto\"\n[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.01\n";
  EXPECT_EQ(cd::parse_scene(two, "b.toml").subspace, 0);
  try {
    cd::parse_scene(two, "b.toml", {"solver.subspace=10"});
    FAIL() << "a 2D scene took the subspace correction";
  } catch (const cd::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.subspace = 10: the subspace correction serves 3D spheres only"),
              std::string::npos)
        << e.what();
  }
}

// The policy's keys of a resolved scene printed by cdsim --print-scene.
std::map<std::string, std::string> settings_of(const std::string& printed) {
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : cdtest::printed_keys(printed))
    if (name == "solver.tol" || name == "solver.residual_tol" || name == "shear.dt_tp" || name == "shear.cell_mass" ||
        name == "shear.inertial_number" || name == "contact.overlap_projection")
      out[name] = value;
  return out;
}

// The shear command `make -n` gives for a campaign point, run with
// --print-scene (it reads the scene only: no sample needed).
std::map<std::string, std::string> campaign_settings(const std::string& I, const std::string& dim) {
  const std::string camp = (cdtest::scratch_dir("test_shear_policy", "campaigns" + dim)).string();
  const auto made = cdtest::run_command(std::string("make --no-print-directory -n -C ") + CDLAB_SOURCE_DIR +
                                        " BUILD=" + CDLAB_BINARY_DIR + " DIM=" + dim + " CAMPAIGNS=" + camp +
                                        " " + camp + "/inertial/I_" + I + "/.done");
  EXPECT_EQ(made.code, 0) << made.out;
  // Each command, its continued lines (ending in a backslash) joined.
  std::istringstream in(made.out);
  std::string cmd, joined;
  for (std::string line; std::getline(in, line);) {
    if (line.ends_with("\\")) {
      joined += line.substr(0, line.size() - 1);
      continue;
    }
    joined += line;
    if (joined.find("--set shear.inertial_number=" + I + " ") != std::string::npos) cmd = joined;
    joined.clear();
  }
  EXPECT_FALSE(cmd.empty()) << made.out;
  EXPECT_EQ(cmd.find("solver.tol"), std::string::npos) << "the Makefile decides no setting: " << cmd;
  const auto r = cdtest::run_command(std::string("cd ") + CDLAB_SOURCE_DIR + " && " + cmd + " --print-scene");
  EXPECT_EQ(r.code, 0) << cmd << "\n" << r.out;
  return settings_of(r.out);
}

std::map<std::string, std::string> single_run_settings(const std::string& scene, const std::string& I) {
  const auto r = cdtest::run_command(std::string(CDLAB_BINARY_DIR) + "/cd/cdsim " + CDLAB_SOURCE_DIR +
                                     "/configs/" + scene + " --set shear.inertial_number=" + I + " --print-scene");
  EXPECT_EQ(r.code, 0) << r.out;
  return settings_of(r.out);
}

TEST(ShearPolicy, ACampaignPointAndASingleRunAtTheSameIRunTheSameSettings) {
  for (const char* I : {"0.003", "0.01", "0.3", "0.5"}) {
    const auto c = campaign_settings(I, "2"), s = single_run_settings("shear-inertial.toml", I);
    EXPECT_EQ(c.size(), 6u) << I;
    EXPECT_EQ(c, s) << "I = " << I;
    const cd::ShearSettings p = cd::shear_settings(std::stod(I), cd::Acceleration::Anderson, kDisks);  // the scene mixes (anderson = 5)
    EXPECT_EQ(std::stod(s.at("solver.tol")), p.tol) << I;
    EXPECT_EQ(std::stod(s.at("solver.residual_tol")), p.residual_tol) << I;
    EXPECT_EQ(std::stod(s.at("shear.dt_tp")), p.dt_tp) << I;
    EXPECT_EQ(std::stod(s.at("shear.cell_mass")), p.cell_mass) << I;
  }
  const auto c3 = campaign_settings("0.001", "3"), s3 = single_run_settings("shear3-inertial.toml", "0.001");
  EXPECT_EQ(c3.size(), 6u);
  EXPECT_EQ(c3, s3);
  // Anderson's mixing at I = 1e-3, with the spheres' stop.
  const cd::ShearSettings p3 = cd::shear_settings(0.001, cd::Acceleration::Anderson, kSpheres);
  EXPECT_EQ(std::stod(s3.at("solver.residual_tol")), p3.residual_tol);
  EXPECT_EQ(std::stod(s3.at("contact.overlap_projection")), p3.overlap_projection);
  // The 3D scene lets the band choose its acceleration: the subspace
  // correction at I = 0.01 (tolerance tol_subspace), Anderson's mixing at
  // 1e-3 (tol_anderson), the same for a campaign point.
  const auto c3b = campaign_settings("0.01", "3"), s3b = single_run_settings("shear3-inertial.toml", "0.01");
  EXPECT_EQ(c3b, s3b);
  EXPECT_EQ(std::stod(s3b.at("solver.tol")), cd::shear_settings(0.01, cd::Acceleration::Subspace, kSpheres).tol);
  EXPECT_EQ(std::stod(s3.at("solver.tol")), p3.tol);
}

// An explicit solver.tol keeps the "auto" acceleration's mixing (measured:
// at an explicit tol 1e-4, 300 disks at I = 0.01, plain NLGS stopped 7x as
// many steps at the sweep cap, docs/accuracy.md), and a run whose mixing
// leaves steps at the cap says how many of them had it stalled and off,
// and names the settings that end such steps: a law-residual stop
// (solver.residual_tol) or more sweeps. 100 disks compacted (the
// preparation's stop rule), sheared at tol 1e-5 with a cap of 300 sweeps for 100 steps: C steps at
// the cap, K of them with the mixing off, both counted again on a world
// stepped here.
TEST(ShearPolicy, AnExplicitTolKeepsTheAutoMixingAndCappedStepsNameTheSetting) {
  const std::filesystem::path dir = cdtest::scratch_dir("test_shear_policy", "explicit_tol");
  const std::string ckpt = (dir / "prep" / "checkpoint.bin").string();
  {  // compacted to the preparation's stop rule, which writes the sample
    const cd::Scene p = cd::load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/shear-prep.toml",
                                       {"particles.n=100", "shear.width=0.016", "shear.height=0.016",
                                        "output.snapshot_interval=0"});
    cd::World w = cd::build_world(p);
    cd::RunOptions opt;
    opt.out = (dir / "prep").string();
    opt.quiet = true;
    EXPECT_TRUE(cd::run(w, p, opt).settled);
  }
  const std::string scene = std::string(CDLAB_SOURCE_DIR) + "/configs/shear-inertial.toml";
  const std::vector<std::string> set = {"shear.start=\"" + ckpt + "\"", "shear.inertial_number=0.01",
                                        "solver.tol=1e-5", "solver.max_iter=300", "output.snapshot_interval=0"};
  const cd::Scene s = cd::load_scene(scene, set);
  EXPECT_EQ(s.tol, 1e-5);
  EXPECT_EQ(s.anderson, cd::kAnderson);  // disks: the band's mixing, kept
  cd::World w = cd::build_world(s);
  long cap = 0, cap_off = 0;
  for (int k = 0; k < 100; ++k) {
    w.step();
    const cd::SolveStats& st = w.last().solve;
    cap += st.cap_hit;
    cap_off += st.cap_hit && st.anderson_off > 0;
  }
  ASSERT_GT(cap, 1) << "more than 1 % of the steps at the cap";
  ASSERT_GT(cap_off, 0);

  const auto cdsim = [&](const std::string& out) {
    std::string cmd = std::string(CDLAB_BINARY_DIR) + "/cd/cdsim " + scene + " --quiet --max-steps 100 --threads 1 " +
                      "--out " + (dir / out).string();
    for (const auto& a : set) cmd += " --set '" + a + "'";
    return cmd;
  };
  const auto r = cdtest::run_command(cdsim("anderson"));
  EXPECT_EQ(r.code, 0) << r.out;
  // The resolved scene says what ran.
  const auto resolved = cdtest::printed_keys(cdtest::slurp(dir / "anderson" / "scene.toml"));
  EXPECT_EQ(std::stod(resolved.at("solver.tol")), 1e-5);
  EXPECT_EQ(std::stoi(resolved.at("solver.anderson")), cd::kAnderson);
  EXPECT_NE(r.out.find(fmt::format("cdsim: warning: of this session's {} steps at the sweep cap, {} ended as plain "
                                   "NLGS after Anderson's mixing (solver.anderson = 5) stalled and went off, and {} "
                                   "with it on; the setting that ends such steps is a law-residual stop, "
                                   "solver.residual_tol (0.003 is the policy's with plain NLGS below I = 0.01), or a "
                                   "larger solver.max_iter",
                                   cap, cap_off, cap - cap_off)),
            std::string::npos)
      << r.out;
  EXPECT_EQ(std::stod(resolved.at("solver.residual_tol")), 0.0) << "the band's stop from I = 0.01 has none";
  EXPECT_NE(r.out.find(fmt::format(", on {} of the {} steps at the sweep cap\n", cap_off, cap)), std::string::npos)
      << r.out;
  // Plain NLGS: no word of the mixing.
  const auto p = cdtest::run_command(cdsim("plain") + " --set solver.anderson=0");
  EXPECT_EQ(p.code, 0) << p.out;
  EXPECT_NE(p.out.find("stopped at the sweep cap"), std::string::npos) << p.out;
  EXPECT_EQ(p.out.find("Anderson"), std::string::npos) << p.out;
  // What the warning says, on this sample: plain NLGS at the same stop
  // stops more steps at the cap (100 of 100 against 46 with the mixing),
  // the law-residual stop fewer (26, at this small cap).
  const auto residual = cdtest::run_command(cdsim("residual") + " --set solver.residual_tol=3e-3");
  EXPECT_EQ(residual.code, 0) << residual.out;
  const auto capped = [&](const std::string& out) {
    return std::stod(cdtest::summary_fields(dir / out / "summary.toml").at("cap_steps"));
  };
  EXPECT_EQ(capped("anderson"), static_cast<double>(cap));
  EXPECT_GT(capped("plain"), capped("anderson"));
  EXPECT_LT(capped("residual"), capped("anderson"));
}

}  // namespace

// solver.stop_rows = "loaded": an "auto" stop is the band's, measured over
// every row of sphere packings (2.13 rows per loaded row), expressed over
// the loaded rows: tol / sqrt(2.13), residual_tol / 2.13 (the residual's
// scale, mean |p|, taken over the rows with an impulse); the acceleration
// is the band's as before. A 2D scene refuses it (not measured there),
// naming both keys; a number for the tolerance is taken as given.
TEST(ShearPolicy, TheLoadedStopTakesTheBandsStopOverTheLoadedRows) {
  const std::string scene =
      "dimension = 3\ngravity.g = [0.0, 0.0, 0.0]\n[solver]\ntol = \"auto\"\nresidual_tol = \"auto\"\n"
      "anderson = \"auto\"\nsubspace = \"auto\"\nstop_rows = \"loaded\"\n"
      "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.01\n";
  for (const double I : {0.001, 0.01, 0.3}) {
    const std::string is = fmt::format("shear.inertial_number={}", I);
    const cd::Scene s = cd::parse_scene(scene, "a.toml", {is});
    const cd::Scene all = cd::parse_scene(scene, "a.toml", {is, "solver.stop_rows=all"});
    EXPECT_EQ(s.stop_rows, cd::StopRows::Loaded);
    EXPECT_EQ(all.stop_rows, cd::StopRows::All);
    EXPECT_EQ(s.anderson, all.anderson) << I;
    EXPECT_EQ(s.subspace, all.subspace) << I;
    EXPECT_NEAR(s.tol, all.tol / std::sqrt(2.13), 1e-15) << I;
    EXPECT_NEAR(s.residual_tol, all.residual_tol / 2.13, 1e-15) << I;
    // The subspace band's 7e-4 over every row is 4.796e-4 over the loaded ones.
    if (I == 0.01) {
      EXPECT_NEAR(s.tol, 4.796e-4, 1e-7);
    }
  }
  const cd::Scene given = cd::parse_scene(scene, "a.toml", {"solver.tol=2e-3", "solver.residual_tol=0"});
  EXPECT_EQ(given.tol, 2e-3);
  const std::string two = "dimension = 2\n[solver]\ntol = \"auto\"\nstop_rows = \"loaded\"\n"
                          "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.01\n";
  try {
    cd::parse_scene(two, "b.toml", {});
    ADD_FAILURE() << "a 2D auto stop over the loaded rows was accepted";
  } catch (const cd::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("b.toml"), std::string::npos) << m;
    EXPECT_NE(m.find("solver.tol"), std::string::npos) << m;
    EXPECT_NE(m.find("solver.stop_rows"), std::string::npos) << m;
  }
  EXPECT_EQ(cd::parse_scene(two, "b.toml", {"solver.tol=1e-3"}).stop_rows, cd::StopRows::Loaded);
  // Not a name of it: refused with the names.
  try {
    cd::parse_scene(scene, "a.toml", {"solver.stop_rows=forces"});
    ADD_FAILURE() << "solver.stop_rows = forces was accepted";
  } catch (const cd::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("loaded"), std::string::npos) << m;
  }
}
