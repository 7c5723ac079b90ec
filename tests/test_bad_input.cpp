// Bad input never runs, and a run that goes bad stops: derived
// quantities (steps, time step, pull-off force) are checked before anything
// is written; start samples are checked against the scene; the watchdog
// stops a run whose state turns non-finite with exit 3 and a message naming
// the step, the body and the quantity; SIGTERM stops a run at a step
// boundary with a checkpoint the same command resumes from; usage errors
// exit 2 like every other bad input.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <chrono>
#include <csignal>
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "cli_util.hpp"
#include "config.hpp"
#include "derived.hpp"
#include "problem3.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";

fs::path write(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

cdtest::CmdResult cdsim(const std::string& args) { return cdtest::run_command(kCdsim + " " + args); }

// Two disks on a floor.
const std::string kScene = R"(name = "tiny"
[time]
dt = 1e-3
duration = 0.01
[[disk]]
pos = [0.0, 0.5]
radius = 0.5
[[disk]]
pos = [1.0, 0.5]
radius = 0.5
[[wall]]
a = [-5.0, 0.0]
b = [5.0, 0.0]
[output]
series_interval = 1e-3
)";

// Every value of every data row of series.csv, with its column name.
std::vector<std::vector<std::string>> csv(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> out;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(cell);
    out.push_back(row);
  }
  return out;
}

// A refused run: exit 2, the message names each of `words`, nothing written.
void expect_refused(const std::string& sets, const std::vector<std::string>& words,
                    const std::string& scene = kScene) {
  // A folder of the test's own: ctest runs the tests of this file in parallel.
  const fs::path dir =
      cdtest::scratch_dir("bad_input", std::string("refused_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  const fs::path sc = write(dir, "s.toml", scene);
  const cdtest::CmdResult r = cdsim(sc.string() + " " + sets + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.code, 2) << sets << "\n" << r.out;
  for (const std::string& w : words) EXPECT_NE(r.out.find(w), std::string::npos) << sets << "\n" << r.out;
  EXPECT_FALSE(fs::exists(dir / "out")) << sets << ": wrote an output folder";
}

}  // namespace

TEST(BadInput, RunsOfNoStepOrOfTooManyStepsAreRefused) {
  // Cases that would otherwise exit 0 with nothing simulated.
  expect_refused("--set time.duration=1e90", {"limit of 1000000000", "time.duration"});
  expect_refused("--set time.dt=1", {"less than one step", "time.dt"});
  expect_refused("--set time.duration=0", {"less than one step", "time.duration"});
  expect_refused("--set time.duration=inf", {"time.duration = inf", "finite"});
  expect_refused("--set 'gravity.g=[0,-inf]'", {"gravity.g", "finite"});
  expect_refused("--set 'gravity.g=[nan,-9.81]'", {"gravity.g", "nan"});
  expect_refused("--set solver.tol=inf", {"solver.tol"});
  expect_refused("--set contact.adhesion=inf", {"contact.adhesion"});
  // The orthotropic cone needs a 2D tangent plane: 3D only.
  expect_refused("--set contact.mu_b=0.5", {"contact.mu_b", "dimension = 3"});
  expect_refused("--set contact.mu_wall_b=0.5", {"contact.mu_wall_b", "dimension = 3"});
  expect_refused("--set 'contact.axis_a=[0,1,0]'", {"contact.axis_a", "dimension = 3"});
  expect_refused("--set contact.mu_b=nan", {"contact.mu_b"});
  // The subspace correction serves the 3D sphere rows only.
  expect_refused("--set solver.subspace=10", {"solver.subspace", "3D"});
  // t_p = d sqrt(rho/p): a huge dt_tp makes a step longer than the run.
  const std::string shear =
      "name = \"s\"\n[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 20\n[time]\nduration = 0.01\n"
      "[shear]\nmode = \"periodic\"\nwidth = 0.02\nheight = 0.02\npressure = 100.0\n";
  expect_refused("--set shear.dt_tp=100", {"less than one step", "shear.dt_tp"}, shear);
  expect_refused("--set shear.inertial_number=0.1 --set shear.strain=1e90", {"shear.strain", "limit of 1000000000"},
                 shear);
  // An enormous cohesion number, which would give an infinite pull-off force.
  expect_refused("--set contact.cohesion_number=1e308 --set shear.pressure=1e10",
                 {"contact.cohesion_number = 1e+308", "between 1e-100 and 1e+100"}, shear);
}

// A setting that cannot act under the scene's law, shape or protocol is
// refused by name: a reader of the scene would believe it does something.
// Each is refused where it cannot act and runs where it can (the 3D pile
// has walls and a floor; the shear cells have none).
TEST(BadInput, SettingsThatCannotActAreRefused) {
  std::ifstream f(std::string(CDLAB_SOURCE_DIR) + "/configs/pile3d.toml");
  const std::string pile3d((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(pile3d.empty());
  const std::string shear2 =
      "name = \"s\"\n[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 20\n[time]\nduration = 0.01\n"
      "[shear]\nmode = \"periodic\"\nwidth = 0.02\nheight = 0.02\npressure = 100.0\n";
  const std::string shear3 = "name = \"s\"\ndimension = 3\n[gravity]\ng = [0.0, 0.0, 0.0]\n[particles]\nn = 20\n"
                             "[shear]\nmode = \"periodic\"\npressure = 1e5\ninertial_number = 0.01\nstrain = 0.01\n"
                             "dt_tp = 0.05\n";
  // Wall friction in a cell without walls.
  expect_refused("--set contact.mu_wall=0.3", {"contact.mu_wall = 0.3", "no walls"}, shear2);
  expect_refused("--set contact.mu_wall=0.3", {"contact.mu_wall = 0.3", "no walls"}, shear3);
  expect_refused("--set contact.mu_b=0.2 --set contact.mu_wall_b=0.3", {"contact.mu_wall_b = 0.3", "no walls"},
                 shear3);
  // The orthotropic direction without the orthotropic cone.
  expect_refused("--set 'contact.axis_a=[0,1,0]'", {"contact.axis_a = [0, 1, 0]", "contact.mu_b"}, pile3d);
  // A tangential restitution without friction, on grains and walls.
  expect_refused("--set contact.mu=0 --set contact.mu_wall=0 --set contact.e_t=0.5",
                 {"contact.e_t = 0.5", "without friction"}, pile3d);
  expect_refused("--set contact.mu=0 --set contact.e_t=0.5", {"contact.e_t = 0.5", "without friction"});
  // A debonding distance without adhesion.
  expect_refused("--set contact.debond=0.02", {"contact.debond = 0.02", "adhesive"});
  expect_refused("--set contact.debond=0.02", {"contact.debond = 0.02", "adhesive"}, pile3d);
  // A cell mass for lengths held fixed.
  expect_refused("--set shear.control=volume --set shear.rate=10 --set shear.cell_mass=0.5",
                 {"shear.cell_mass = 0.5", "held fixed"}, shear2);

  // Where they can act, the same settings run (a step of each).
  const auto runs = [](const std::string& sets, const std::string& scene) {
    const fs::path dir = cdtest::scratch_dir("bad_input", "acts");
    fs::remove_all(dir / "out");
    const fs::path sc = write(dir, "s.toml", scene);
    const cdtest::CmdResult r = cdsim(sc.string() + " " + sets + " --set time.duration=3e-3 -q --out " +
                                      (dir / "out").string());
    EXPECT_EQ(r.code, 0) << sets << "\n" << r.out;
  };
  runs("--set contact.mu_wall=0.3 --set contact.mu_b=0.2 --set contact.mu_wall_b=0.3 "
       "--set 'contact.axis_a=[0,1,0]' --set contact.e_t=0.5", pile3d);
  runs("--set contact.mu=0 --set contact.mu_wall=0.3 --set contact.e_t=0.5", pile3d);
  runs("--set contact.adhesion=1e-6 --set contact.debond=0.02", pile3d);
}

// Compliant contacts (contact.stiffness, contact.stiffness_number): 3D
// only, one of the two, the number with an imposed pressure, not with
// restitution, within the scene's number range, and, with cohesion, a pull-off
// reached before the debonding distance.
TEST(BadInput, CompliantContactsAreRefusedWhereTheyCannotApply) {
  expect_refused("--set contact.stiffness=1e6", {"contact.stiffness", "3D only"});
  std::ifstream f(std::string(CDLAB_SOURCE_DIR) + "/configs/pile3d.toml");
  const std::string pile3d((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(pile3d.empty());
  expect_refused("--set contact.stiffness=-1", {"contact.stiffness"}, pile3d);
  expect_refused("--set contact.stiffness_number=1e5", {"contact.stiffness_number", "shear.pressure"}, pile3d);
  expect_refused("--set contact.stiffness=1e6 --set contact.e_n=0.5", {"contact.stiffness", "restitution"}, pile3d);
  expect_refused("--set contact.stiffness=1e-300", {"contact.stiffness"}, pile3d);
  // k_t / k: only with compliant contacts, > 0 and at most 1e3.
  expect_refused("--set contact.stiffness_ratio=0.5", {"contact.stiffness_ratio = 0.5", "without compliant"}, pile3d);
  expect_refused("--set contact.stiffness=1e6 --set contact.stiffness_ratio=0", {"contact.stiffness_ratio"}, pile3d);
  expect_refused("--set contact.stiffness=1e6 --set contact.stiffness_ratio=1e4", {"contact.stiffness_ratio", "1e3"},
                 pile3d);
  const std::string shear3 = "name = \"s\"\ndimension = 3\n[gravity]\ng = [0.0, 0.0, 0.0]\n[particles]\nn = 0\n[shear]\nmode = \"periodic\"\n"
                             "pressure = 1e5\ninertial_number = 0.01\nstrain = 0.1\ndt_tp = 0.05\n";
  expect_refused("--set contact.stiffness=1e7 --set contact.stiffness_number=1e5",
                 {"contact.stiffness or contact.stiffness_number, not both"}, shear3);
  // A compliant bond stretches by f_a/k before it pulls f_a: beyond the
  // debonding distance (0.01 d by default) it would break first. kappa =
  // 1e4 reaches eta = 100 (allowed), not 200.
  expect_refused("--set contact.stiffness_number=1e4 --set contact.cohesion_number=200",
                 {"contact.cohesion_number with contact.stiffness_number", "f_a/k = 0.02 d",
                  "cohesion_number <= stiffness_number x debond = 100"},
                 shear3);
  expect_refused("--set contact.stiffness=1e3 --set contact.adhesion=0.1 --set particles.d_mean=1e-3",
                 {"contact.adhesion with contact.stiffness", "adhesion <= 0.01 N"}, shear3);
}

TEST(BadInput, UsageErrorsExitTwo) {
  for (const std::string args : {"--bogus", "--threads x s.toml", "--dump-problem -3 s.toml"}) {
    const cdtest::CmdResult r = cdsim(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
  }
  EXPECT_EQ(cdsim("--help").code, 0);
}

// A huge, fast disk within the range a scene may give (radius 1e10,
// density 1e100, speed 1e100): its kinetic energy overflows to inf in the
// first step. The run stops with exit 3 naming the step and the quantity,
// and nothing non-finite is written.
TEST(Watchdog, NonFiniteStateStopsTheRunWithExitThree) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "watchdog");
  std::string scene = kScene;
  scene.insert(scene.find("[[disk]]\npos = [1.0"),
               "[[disk]]\npos = [1e11, 0.5]\nradius = 1e10\ndensity = 1e100\nvel = [1e100, 0.0]\n");
  scene += "checkpoint_interval = 2e-3\n";
  const fs::path sc = write(dir, "s.toml", scene);
  const cdtest::CmdResult r = cdsim(sc.string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("run diverged"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("step 1 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("kinetic_energy is inf"), std::string::npos) << r.out;
  // series.csv: no row (there is no good row before step 1).
  EXPECT_LE(csv(dir / "out" / "series.csv").size(), 1u);
  // No checkpoint was written from the bad state.
  EXPECT_FALSE(fs::exists(dir / "out" / "checkpoint.bin"));
}

// A finite state gone bad: a disk thrown at another one so fast (v dt =
// 1.2 d from a gap of 0.05 d) that it is found inside it by 0.55 d at the
// first step's midpoint (0.05 - 1.2 / 2), past the watchdog's limit of half
// the smaller diameter: exit 3 naming the step and the overlap, no row and
// no checkpoint from that state. Half that speed sinks it 0.25 d (0.05 -
// 0.6 / 2): a run that warns and ends, exit 0.
TEST(Watchdog, GrainsSunkIntoEachOtherByHalfADiameterStopTheRun) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "watchdog_overlap");
  for (const auto& [v, code] : {std::pair{"1200.0", 3}, std::pair{"600.0", 0}}) {
    SCOPED_TRACE(v);
    std::string scene = kScene;
    scene.replace(scene.find("pos = [1.0, 0.5]"), 16, std::string("pos = [0.0, 1.55]\nvel = [0.0, -") + v + "]");
    scene += "checkpoint_interval = 1e-3\n";
    const fs::path sc = write(dir, "s.toml", scene), out = dir / (std::string("out") + v);
    const cdtest::CmdResult r = cdsim(sc.string() + " -q --out " + out.string());
    EXPECT_EQ(r.code, code) << r.out;
    if (code == 3) {
      EXPECT_NE(r.out.find("run diverged: step 1 (t = 0.001 s): two grains overlap by 0.55 of the smaller one's "
                           "diameter, past the limit of 0.5"), std::string::npos) << r.out;
      EXPECT_LE(csv(out / "series.csv").size(), 1u);
      EXPECT_FALSE(fs::exists(out / "checkpoint.bin"));
    } else {
      EXPECT_NE(r.out.find("the largest overlap reached 0.25 of the smaller grain's diameter"), std::string::npos)
          << r.out;
    }
  }
}

// SIGTERM mid-run: exit 128 + 15 at a step boundary, a checkpoint written;
// the same command resumes and ends in the state of an uninterrupted run
// (kinetic energy of the last row bit-identical). The signal is sent as GNU
// timeout sends it, to the run and then to its whole process group (it
// arrives twice within microseconds, one request), once series.csv has a
// row at step 2000 of the 4000, seen by polling: mid-run whatever the
// machine's speed and load (half the wall time of a first run could land
// anywhere, or after the end).
TEST(Signals, TermStopsAtAStepBoundaryWithACheckpointTheRunResumesFrom) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "signal");
  const std::string scene =
      "name = \"pile\"\n[time]\ndt = 1e-4\nduration = 0.4\n[particles]\nn = 200\nd_mean = 1e-3\n"
      "[box]\nwidth = 0.03\nheight = 0.06\n[output]\nseries_interval = 1e-2\ncheckpoint_interval = 0.5\n";
  const fs::path sc = write(dir, "s.toml", scene);
  const std::string args = sc.string() + " -q --threads 1 --out ";
  const cdtest::CmdResult ref = cdsim(args + (dir / "ref").string());
  ASSERT_EQ(ref.code, 0) << ref.out;

  // The run in a process group of its own (as under timeout), its output to
  // a file.
  const fs::path run = dir / "run", log = dir / "run.log";
  const pid_t pid = cdtest::spawn({kCdsim, sc.string(), "-q", "--threads", "1", "--out", run.string()},
                                  log.string(), true);
  ASSERT_GT(pid, 0);
  // The step of series.csv's last whole row (-1: none yet).
  const auto last_step = [&] {
    const auto rows = csv(run / "series.csv");
    for (std::size_t i = rows.size(); i-- > 1;)
      if (rows[i].size() == rows[0].size()) return std::stol(rows[i][0]);
    return -1L;
  };
  int status = 0;
  bool ended = false;
  const auto t0 = std::chrono::steady_clock::now();
  while (!(ended = waitpid(pid, &status, WNOHANG) == pid) && last_step() < 2000 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(600))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!ended) {
    kill(pid, SIGTERM);
    kill(-pid, SIGTERM);
    waitpid(pid, &status, 0);
  }
  const std::string out = cdtest::slurp(log);
  ASSERT_FALSE(ended) << "the run ended before the signal: make it longer\n" << out;
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + 15) << status << "\n" << out;
  EXPECT_NE(out.find("stopped by signal 15"), std::string::npos) << out;
  ASSERT_TRUE(fs::exists(run / "checkpoint.bin"));
  const cdtest::CmdResult resumed = cdsim(args + run.string());
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_NE(resumed.out.find("resumed from"), std::string::npos) << resumed.out;
  const auto a = csv(dir / "ref" / "series.csv"), b = csv(run / "series.csv");
  ASSERT_GE(b.size(), a.size());
  std::size_t ke = 0;
  while (ke < a[0].size() && a[0][ke] != "kinetic_energy") ++ke;
  ASSERT_LT(ke, a[0].size());
  EXPECT_EQ(a.back()[0], b.back()[0]);    // the same last step
  EXPECT_EQ(a.back()[ke], b.back()[ke]);  // the same state
}

// A start sample must be the scene's: a periodic preparation (no wall
// grains), of the scene's density, and not overlapping by more than a
// solver-sized amount; a walls run cannot start from one.
TEST(BadInput, StartSamplesAreCheckedAgainstTheScene) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "start");
  const std::string prep =
      // 60 grains: the cell shrinks at most 0.025 d a step, and 30 (as
      // before that bound held here) reached the grid's smallest cell before
      // they jammed
      "name = \"prep\"\n[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 60\nd_mean = 1e-3\ndensity = 2.6\n"
      "[shear]\nmode = \"periodic\"\nwidth = 0.012\nheight = 0.012\npressure = 100.0\nisotropic = true\n"
      "dt_tp = 0.05\n[time]\nduration = 2e-3\n[output]\nseries_interval = 1e-3\ncheckpoint_interval = 1e-3\n";
  const fs::path sc = write(dir, "prep.toml", prep);
  const cdtest::CmdResult r = cdsim(sc.string() + " -q --out " + (dir / "prep").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string shear =
      "name = \"shear\"\n[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 0\nd_mean = 1e-3\ndensity = 2.6\n"
      "[shear]\nmode = \"periodic\"\nwidth = 0.01\nheight = 0.01\npressure = 100.0\n"
      "inertial_number = 0.01\nstrain = 0.01\ndt_tp = 0.05\nstart = \"" +
      (dir / "prep" / "checkpoint.bin").string() + "\"\n";
  {  // the reference: accepted
    const fs::path s2 = write(dir, "ok.toml", shear);
    const cdtest::CmdResult ok = cdsim(s2.string() + " -q --out " + (dir / "ok").string());
    EXPECT_EQ(ok.code, 0) << ok.out;
  }
  expect_refused("--set particles.density=5.0", {"shear.start", "density", "2.6"}, shear);
  expect_refused("--set shear.mode=walls", {"shear.start", "periodic"}, shear);
  // The shear policy's "auto" is chosen for the shapes particles.nsides
  // names: a disk sample under a polygon scene (or the reverse) is refused.
  expect_refused("--set particles.nsides=[6]", {"shear.start", "particles.nsides = [6]", "disks only"}, shear);
}

// ---- cdanalysis and cdproblem --------------------------------------------

namespace {
const std::string kCdanalysis = CDLAB_BINARY_DIR "/analysis/cdanalysis";
const std::string kCdproblem = CDLAB_BINARY_DIR "/cd/cdproblem";
}  // namespace

// A mu(I) table whose points share one I determines no curve: refused
// (exit 1), never "converged" with zero error bars. Two distinct I for three
// parameters: refused too. Four distinct I: a fit.
TEST(BadInput, DegenerateFitsAreRefused) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "fits");
  const auto fit = [&](const std::string& rows) {
    const fs::path t = write(dir, "t.csv", "I,mu,mu_err\n" + rows);
    return cdtest::run_command(kCdanalysis + " fit mu-i --table " + t.string());
  };
  cdtest::CmdResult r = fit("0.01,0.30,0.01\n0.01,0.31,0.01\n0.01,0.29,0.01\n0.01,0.30,0.01\n");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("1 distinct value of (I) for 3 parameters"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("converged"), std::string::npos) << r.out;
  r = fit("0.01,0.30,0.01\n0.01,0.31,0.01\n0.1,0.45,0.01\n0.1,0.46,0.01\n");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("2 distinct values"), std::string::npos) << r.out;
  // A constant mu at four I: mu1 = mu2 leaves I0 free (singular Jacobian).
  r = fit("0.001,0.3,0.01\n0.01,0.3,0.01\n0.1,0.3,0.01\n0.3,0.3,0.01\n");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("Jacobian is singular"), std::string::npos) << r.out;
  // mu = 0.26 + 0.34/(1 + 0.08/I) at five I: a determined fit.
  std::string rows;
  for (const double I : {0.003, 0.01, 0.03, 0.1, 0.3})
    rows += std::to_string(I) + "," + std::to_string(0.26 + 0.34 / (1 + 0.08 / I)) + ",0.005\n";
  r = fit(rows);
  EXPECT_EQ(r.code, 0) << r.out;
  // A non-finite value in the table: bad input, naming line and column.
  r = fit("0.01,0.30,0.01\n0.02,nan,0.01\n0.05,0.35,0.01\n");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("line 3, column 'mu': 'nan' is not a finite number"), std::string::npos) << r.out;
}

TEST(BadInput, AnalysisOptionsAndDamagedSnapshots) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "analysis");
  // A run with snapshots.
  std::string scene = kScene;
  scene += "snapshot_interval = 5e-3\n";
  const fs::path sc = write(dir, "s.toml", scene);
  ASSERT_EQ(cdsim(sc.string() + " -q --out " + (dir / "run").string()).code, 0);
  const std::string run = (dir / "run").string();
  cdtest::CmdResult r = cdtest::run_command(kCdanalysis + " fabric " + run + " --volume -1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--volume"), std::string::npos) << r.out;
  r = cdtest::run_command(kCdanalysis + " fabric " + run + " --bins 1");
  EXPECT_EQ(r.code, 2) << r.out;
  r = cdtest::run_command(kCdanalysis + " steady");  // the run folder is required
  EXPECT_EQ(r.code, 2) << r.out;
  // A damaged contacts file: one message naming it, not pages of VTK errors.
  fs::path last;
  for (const auto& e : fs::directory_iterator(dir / "run"))
    if (e.path().filename().string().starts_with("contacts_") && (last.empty() || e.path() > last)) last = e.path();
  ASSERT_FALSE(last.empty());
  std::string text;
  {
    std::ifstream in(last);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  std::ofstream(last) << text.substr(0, text.size() / 2);
  r = cdtest::run_command(kCdanalysis + " fabric " + run);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(last.filename().string()), std::string::npos) << r.out;
  EXPECT_LT(std::count(r.out.begin(), r.out.end(), '\n'), 3) << r.out;
}

TEST(BadInput, CdproblemRefusesBadOptionsAndTrailingText) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "cdproblem");
  // One contact: a disk on the floor, W = diag(1, 1), q = (-1, 0), mu = 0.5.
  const std::string ok = "2\n1\n0\n2 2\n2 2\n1 0\n0 1\n-1 0\n0.5\n";
  const fs::path good = write(dir, "ok.dat", ok);
  EXPECT_EQ(cdtest::run_command(kCdproblem + " solve " + good.string()).code, 0);
  const fs::path bad = write(dir, "bad.dat", ok + "garbage\n");
  cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + bad.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("garbage"), std::string::npos) << r.out;
  for (const std::string opt : {"--tol -1", "--tol 0", "--tol 2", "--tol nan", "--max-sweeps 0", "--bogus"}) {
    r = cdtest::run_command(kCdproblem + " solve " + good.string() + " " + opt);
    EXPECT_EQ(r.code, 2) << opt << "\n" << r.out;
  }
}

// The .cdp3 reader bounds its counts by the file as the .cdp reader does:
// "bodies 2000000000" is refused naming the file and the line before
// anything is allocated (it was std::bad_alloc, no file, no line).
TEST(BadInput, Cdp3CountsAreBoundedByTheFile) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "cdp3");
  const cdtest::CmdResult run = cdsim(std::string(CDLAB_SOURCE_DIR) + "/configs/pile3d.toml -q --set particles.n=8 "
                                      "--set time.duration=0.02 --dump-problem 5 --out " + (dir / "run").string());
  ASSERT_EQ(run.code, 0) << run.out;
  std::vector<std::string> lines;
  {
    std::ifstream in(dir / "run" / "problem_5.cdp3");
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  std::size_t bodies = lines.size();
  for (std::size_t i = 0; i < lines.size() && bodies == lines.size(); ++i)
    if (lines[i].rfind("bodies ", 0) == 0) bodies = i;
  ASSERT_LT(bodies, lines.size());
  lines[bodies] = "bodies 2000000000";
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  const fs::path p = write(dir, "bad.cdp3", text);
  const cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + p.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(p.string() + ":" + std::to_string(bodies + 1) +
                       ": the number of bodies is 2000000000: unexpected end of file"),
            std::string::npos)
      << r.out;
}

// The .cdp reader refuses what no step can hold: a
// negative mu, adhesion or inverse mass, a contact of a body with itself, a
// tolerance outside (0, 1], a residual tolerance <= 0, and counts the rest
// of the file cannot hold (refused before anything is allocated); each
// names the file, the line and the quantity.
TEST(BadInput, CdpReaderRefusesWhatNoStepCanHold) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "cdp");
  const fs::path sc = write(dir, "s.toml", kScene);
  ASSERT_EQ(cdsim(sc.string() + " -q --dump-problem 3 --out " + (dir / "run").string()).code, 0);
  const fs::path cdp = dir / "run" / "problem_3.cdp";
  std::vector<std::string> lines;
  {
    std::ifstream in(cdp);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  const auto at = [&](const std::string& head) {
    for (std::size_t i = 0; i < lines.size(); ++i)
      if (lines[i].rfind(head, 0) == 0) return i;
    return lines.size();
  };
  const std::size_t tol = at("tol "), bodies = at("bodies "), rows = at("rows ");
  ASSERT_LT(rows + 1, lines.size());
  ASSERT_EQ(std::count(lines[rows + 1].begin(), lines[rows + 1].end(), ' '), 16) << lines[rows + 1];
  // A line's tokens, one replaced.
  const auto with_token = [](std::string line, int k, const std::string& v) {
    std::vector<std::string> t;
    std::stringstream ss(line);
    for (std::string x; ss >> x;) t.push_back(x);
    t.at(k) = v;
    std::string out;
    for (std::size_t i = 0; i < t.size(); ++i) out += (i ? " " : "") + t[i];
    return out;
  };
  const cdtest::CmdResult good = cdtest::run_command(kCdproblem + " solve " + cdp.string());
  ASSERT_EQ(good.code, 0) << good.out;
  struct Case {
    std::size_t line;
    std::string text, named;
  };
  const std::vector<Case> cases = {
      {tol, "tol 0x0p+0", "the tolerance is 0"},
      {tol, "tol -0x1p-10", "the tolerance is"},
      {tol, "tol 0x1p+1", "the tolerance is 2, expected in (0, 1]"},
      {0, "", ""},  // residual_tol 0: inserted below
      {bodies, "bodies 2000000000", "the number of bodies is 2000000000: unexpected end of file"},
      {bodies + 1, with_token(lines[bodies + 1], 3, "-0x1p+0"), "inv_m of body 0 is -1"},
      {bodies + 1, with_token(lines[bodies + 1], 4, "-0x1p+0"), "inv_I of body 0 is -1"},
      {rows, "rows 2000000000", "the number of rows is 2000000000: unexpected end of file"},
      {rows + 1, with_token(with_token(lines[rows + 1], 0, "1"), 1, "1"), "the contact of row 0 joins body 1 to itself"},
      {rows + 1, with_token(lines[rows + 1], 15, "-0x1p-2"), "the friction coefficient mu of row 0 is -0.25"},
      {rows + 1, with_token(lines[rows + 1], 16, "-0x1p-2"), "the adhesion impulse of row 0 is -0.25"},
  };
  for (Case c : cases) {
    std::vector<std::string> bad = lines;
    if (c.named.empty()) {  // residual_tol 0, inserted where the reader looks for it
      const std::size_t mp = at("min_parallel ");
      bad.insert(bad.begin() + static_cast<long>(mp) + 1, "residual_tol 0x0p+0");
      c.named = "the residual tolerance is 0";
      c.line = mp + 1;
    } else {
      bad[c.line] = c.text;
    }
    std::string text;
    for (const std::string& l : bad) text += l + "\n";
    const fs::path p = write(dir, "bad.cdp", text);
    const cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + p.string());
    EXPECT_EQ(r.code, 2) << c.named << "\n" << r.out;
    EXPECT_NE(r.out.find(p.string() + ":" + std::to_string(c.line + 1) + ": " + c.named), std::string::npos)
        << c.named << "\n" << r.out;
  }
}

// ---- FCLib .hdf5 problems -------------------------------------------------
//
// A small local problem written by write_fclib (what cdsim --dump-problem
// writes: W in compressed columns), then damaged with the HDF5 API. The
// reader checks every dataset's length against the header (W's m, n, nz,
// nzmax; 3 values of q and 1 of mu a contact), W's structure, and that the
// values are finite, before it allocates or uses anything: exit 2 with one
// line naming the file and the dataset, never a crash (these files aborted
// in malloc, segfaulted, read past W's arrays or were solved from memory the
// reader never filled).

namespace {

// Two contacts coupled through W(0, 3): 8 entries (nzmax 8), W 6x6.
fs::path write_hdf5_problem(const fs::path& dir) {
  cd::Problem3 p;
  p.nc = 2;
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(6, 6);
  W(0, 3) = W(3, 0) = 0.25;
  p.W = W.sparseView();
  p.W.makeCompressed();
  p.q.resize(6);
  p.q << -1, 0.2, 0.1, -0.5, 0, 0.3;
  p.mu.resize(2);
  p.mu << 0.5, 0.3;
  const fs::path path = dir / "ok.hdf5";
  cd::write_fclib(p, path.string(), "two contacts", "a test problem");
  return path;
}

std::vector<double> h5_doubles(const fs::path& file, const std::string& name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT), s = H5Dget_space(d);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

std::vector<int> h5_ints(const fs::path& file, const std::string& name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT), s = H5Dget_space(d);
  std::vector<int> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  H5Dread(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

// A copy of `src` as `name` in dir, with dataset `ds` replaced by `values`
// (1-D, of their length and type).
template <class T>
fs::path h5_with(const fs::path& src, const fs::path& dir, const std::string& name, const std::string& ds,
                 const std::vector<T>& values) {
  const fs::path out = dir / name;
  fs::copy_file(src, out, fs::copy_options::overwrite_existing);
  const hid_t type = std::is_same_v<T, double> ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT;
  const hid_t f = H5Fopen(out.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  EXPECT_GE(f, 0) << out;
  EXPECT_GE(H5Ldelete(f, ds.c_str(), H5P_DEFAULT), 0) << ds;
  const hsize_t n = values.size();
  const hid_t s = H5Screate_simple(1, &n, nullptr);
  const hid_t d = H5Dcreate2(f, ds.c_str(), type, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << ds;
  H5Dclose(d);
  H5Sclose(s);
  H5Fclose(f);
  return out;
}

// A copy of `src` as `name` in dir whose dataset `ds` has n doubles declared
// and none written (HDF5 would read its fill value).
fs::path h5_unwritten(const fs::path& src, const fs::path& dir, const std::string& name, const std::string& ds,
                      hsize_t n) {
  const fs::path out = dir / name;
  fs::copy_file(src, out, fs::copy_options::overwrite_existing);
  const hid_t f = H5Fopen(out.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  EXPECT_GE(H5Ldelete(f, ds.c_str(), H5P_DEFAULT), 0) << ds;
  const hid_t s = H5Screate_simple(1, &n, nullptr);
  H5Dclose(H5Dcreate2(f, ds.c_str(), H5T_NATIVE_DOUBLE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  H5Sclose(s);
  H5Fclose(f);
  return out;
}

// cdproblem on each file: exit 2 and one line "cdproblem: error: FILE:
// MESSAGE". A crash shows as exit -1 (killed by a signal).
void expect_hdf5_refused(const std::vector<std::pair<fs::path, std::string>>& cases) {
  for (const auto& [file, message] : cases) {
    const cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + file.string());
    EXPECT_EQ(r.code, 2) << file << "\n" << r.out;
    EXPECT_EQ(r.out, "cdproblem: error: " + file.string() + ": " + message + "\n") << file;
  }
}

std::vector<double> one_more(std::vector<double> v, double x) {
  v.push_back(x);
  return v;
}
std::vector<double> one_less(std::vector<double> v) {
  v.pop_back();
  return v;
}

}  // namespace

// The valid file solves (exit 0), in-process as through cdproblem.
TEST(BadInputHdf5, TheValidFileSolves) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "hdf5_valid");
  const fs::path ok = write_hdf5_problem(dir);
  const cd::Fclib3 f = cd::read_fclib(ok.string());
  EXPECT_EQ(f.problem.nc, 2);
  EXPECT_EQ(f.problem.W.nonZeros(), 8);
  EXPECT_EQ(f.problem.q.size(), 6);
  const cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + ok.string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("dim 3, 2 contacts (local)"), std::string::npos) << r.out;
}

// Longer q or mu than the header says (they overran the buffers FCLib had
// allocated from W/m: "malloc(): invalid size", exit 134); a longer x.
TEST(BadInputHdf5, LongerDatasetsThanTheHeaderAreRefused) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "hdf5_longer");
  const fs::path ok = write_hdf5_problem(dir);
  const std::string q = "/fclib_local/vectors/q", mu = "/fclib_local/vectors/mu", x = "/fclib_local/W/x";
  expect_hdf5_refused({
      {h5_with(ok, dir, "q.hdf5", q, one_more(h5_doubles(ok, q), 1.0)),
       "dataset /fclib_local/vectors/q has 7 values, the header says 6 (3 × 2 contacts)"},
      {h5_with(ok, dir, "q2.hdf5", q, std::vector<double>(4000, 1.0)),
       "dataset /fclib_local/vectors/q has 4000 values, the header says 6 (3 × 2 contacts)"},
      {h5_with(ok, dir, "mu.hdf5", mu, one_more(h5_doubles(ok, mu), 0.1)),
       "dataset /fclib_local/vectors/mu has 3 values, the header says 2 (2 contacts)"},
      {h5_with(ok, dir, "x.hdf5", x, one_more(h5_doubles(ok, x), 1.0)),
       "dataset /fclib_local/W/x has 9 values, the header says 8 (/fclib_local/W/nzmax)"},
  });
}

// Counts of W that disagree with its arrays (nz = 5: triplets where there
// are compressed columns; nzmax = 10; m = n = 0): they segfaulted.
TEST(BadInputHdf5, CountsThatDisagreeWithTheArraysAreRefused) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "hdf5_counts");
  const fs::path ok = write_hdf5_problem(dir);
  const fs::path zero = h5_with(h5_with(ok, dir, "m0.hdf5", "/fclib_local/W/m", std::vector<int>{0}), dir,
                                "mn0.hdf5", "/fclib_local/W/n", std::vector<int>{0});
  expect_hdf5_refused({
      {h5_with(ok, dir, "nz.hdf5", "/fclib_local/W/nz", std::vector<int>{5}),
       "dataset /fclib_local/W/p has 7 values, the header says 5 (/fclib_local/W/nz)"},
      {h5_with(ok, dir, "nzmax.hdf5", "/fclib_local/W/nzmax", std::vector<int>{10}),
       "dataset /fclib_local/W/i has 8 values, the header says 10 (/fclib_local/W/nzmax)"},
      {zero, "dataset /fclib_local/vectors/q has 6 values, the header says 0 (3 × 0 contacts)"},
      {h5_with(ok, dir, "m.hdf5", "/fclib_local/W/m", std::vector<int>{7}),
       "W is 7x6 (datasets /fclib_local/W/m and n): expected square, 3 rows a contact"},
      {h5_with(ok, dir, "nz2.hdf5", "/fclib_local/W/nz", std::vector<int>{-3}),
       "dataset /fclib_local/W/nz is -3: expected -1 (compressed columns), -2 (compressed rows) or a number of "
       "triplets >= 0"},
      {h5_with(ok, dir, "nz3.hdf5", "/fclib_local/W/nz", std::vector<int>{9}),
       "dataset /fclib_local/W/nz is 9, more than /fclib_local/W/nzmax = 8"},
      {h5_with(ok, dir, "nzmax2.hdf5", "/fclib_local/W/nzmax", std::vector<int>{2, 8}),
       "dataset /fclib_local/W/nzmax has 2 values, expected 1 (a count)"},
      {h5_with(ok, dir, "dim.hdf5", "/fclib_local/spacedim", std::vector<int>{2}),
       "dataset /fclib_local/spacedim is 2: space dimension 2, expected 3"},
  });
}

// W's structure: a column pointer past nzmax (the reader read past W's
// arrays), pointers that decrease or do not start at 0, a row index outside
// W.
TEST(BadInputHdf5, PointersAndIndicesOutsideWAreRefused) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "hdf5_pointers");
  const fs::path ok = write_hdf5_problem(dir);
  const std::string p = "/fclib_local/W/p", i = "/fclib_local/W/i";
  const std::vector<int> p0 = h5_ints(ok, p), i0 = h5_ints(ok, i);
  ASSERT_EQ(p0, (std::vector<int>{0, 2, 3, 4, 6, 7, 8}));
  std::vector<int> past = p0, down = p0, start = p0, row = i0;
  past.back() = 1000;
  down[2] = 1;
  start[0] = 1;
  row[3] = 6;
  expect_hdf5_refused({
      {h5_with(ok, dir, "past.hdf5", p, past),
       "dataset /fclib_local/W/p: value 6 is 1000, past the 8 entries of /fclib_local/W/nzmax"},
      {h5_with(ok, dir, "down.hdf5", p, down),
       "dataset /fclib_local/W/p: value 2 is 1, less than value 1 (2): pointers never decrease"},
      {h5_with(ok, dir, "start.hdf5", p, start), "dataset /fclib_local/W/p: value 0 is 1, expected 0"},
      {h5_with(ok, dir, "row.hdf5", i, row),
       "dataset /fclib_local/W/i: value 3 is 6, outside the 6 rows of W (6x6)"},
  });
}

// Shorter q, mu or (global) f than the header says: they were solved from
// memory the reader never filled. A q declared but never written (which
// would read as zeros, and with a large header would have the reader
// allocate for data the file does not hold) is refused too; a non-finite or
// negative value is named.
TEST(BadInputHdf5, ShorterDatasetsAndNonFiniteValuesAreRefused) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "hdf5_shorter");
  const fs::path ok = write_hdf5_problem(dir);
  const fs::path global = std::string(CDLAB_TEST_DATA) + "/contact-problems/Box_Stacks-i0122-82-5.hdf5";
  const std::string q = "/fclib_local/vectors/q", mu = "/fclib_local/vectors/mu", f = "/fclib_global/vectors/f";
  std::vector<double> nan = h5_doubles(ok, q), neg = h5_doubles(ok, mu);
  nan[4] = std::nan("");
  neg[1] = -0.5;
  expect_hdf5_refused({
      {h5_with(ok, dir, "q.hdf5", q, one_less(h5_doubles(ok, q))),
       "dataset /fclib_local/vectors/q has 5 values, the header says 6 (3 × 2 contacts)"},
      {h5_with(ok, dir, "mu.hdf5", mu, one_less(h5_doubles(ok, mu))),
       "dataset /fclib_local/vectors/mu has 1 value, the header says 2 (2 contacts)"},
      {h5_with(global, dir, "f.hdf5", f, one_less(h5_doubles(global, f))),
       "dataset /fclib_global/vectors/f has 449 values, the header says 450 (/fclib_global/M/m, the body dofs)"},
      {h5_unwritten(ok, dir, "unwritten.hdf5", q, 6),
       "dataset /fclib_local/vectors/q has 6 values but the file stores only 0 bytes of them"},
      {h5_with(ok, dir, "nan.hdf5", q, nan), "dataset /fclib_local/vectors/q: value 4 is nan, not a finite number"},
      {h5_with(ok, dir, "neg.hdf5", mu, neg),
       "dataset /fclib_local/vectors/mu: value 1 is -0.5, a friction coefficient is >= 0"},
  });
}

// Options refused by name, NaN included (CLI11's ranges let NaN through, and
// it then meant "not given"), and --threads, which the run's scene.toml
// records, in solver.threads' range; a dump past the run's end is refused
// before anything is written.
TEST(BadInput, NanAndOutOfRangeOptionsAreRefusedByName) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "options");
  const std::string ok = "2\n1\n0\n2 2\n2 2\n1 0\n0 1\n-1 0\n0.5\n";
  const fs::path good = write(dir, "ok.dat", ok);
  for (const std::string opt : {"--residual-tol nan", "--residual-tol -1", "--residual-tol inf", "--tol inf",
                                "--tol nan", "--anderson -1", "--anderson 51", "--anderson nan"}) {
    const cdtest::CmdResult r = cdtest::run_command(kCdproblem + " solve " + good.string() + " " + opt);
    EXPECT_EQ(r.code, 2) << opt << "\n" << r.out;
    EXPECT_NE(r.out.find(opt.substr(0, opt.find(' '))), std::string::npos) << opt << "\n" << r.out;
  }
  const fs::path sc = write(dir, "s.toml", kScene);
  for (const std::string opt : {"--threads -1", "--threads 100000", "--threads nan", "--dump-problem 11"}) {
    const fs::path out = dir / "out";
    const cdtest::CmdResult r = cdsim(sc.string() + " -q " + opt + " --out " + out.string());
    EXPECT_EQ(r.code, 2) << opt << "\n" << r.out;
    EXPECT_NE(r.out.find(opt.substr(0, opt.find(' '))), std::string::npos) << opt << "\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << opt;
  }
  const cdtest::CmdResult r = cdsim(sc.string() + " -q --dump-problem 11 --out " + (dir / "out").string());
  EXPECT_NE(r.out.find("the run's last step is 10"), std::string::npos) << r.out;
  // In range: the run's scene.toml records it and reads back.
  ASSERT_EQ(cdsim(sc.string() + " -q --threads 1024 --out " + (dir / "t").string()).code, 0);
  EXPECT_EQ(cdsim((dir / "t" / "scene.toml").string() + " -q --out " + (dir / "t2").string()).code, 0);
}

// Finite but absurd values: every scene
// number is 0 or between 1e-100 and 1e100 in magnitude (docs/errors.md
// says why); a grain whose mass or inertia under- or overflows is refused
// in 2D as in 3D; a body outside the box, which would fall for ever, is
// refused; a name that would write outside outputs/ is refused; a region of
// more lattice sites than an int holds is no overflow in a message.
TEST(BadInput, AbsurdValuesAndBodiesOutsideTheBoxAreRefused) {
  const std::string box = "name = \"box\"\n[time]\ndt = 1e-3\nduration = 0.01\n[box]\nwidth = 4.0\nheight = 4.0\n";
  const std::string range = "between 1e-100 and 1e+100 in magnitude";
  expect_refused("--set gravity.g=[0,-1e308]", {"gravity.g: element 1 is -1e+308", range});
  expect_refused("--set contact.mu=1e300", {"contact.mu = 1e+300", range});
  expect_refused("--set particles.density=1e-300", {"particles.density = 1e-300", range});
  expect_refused("--set particles.density=1e300", {"particles.density = 1e+300", range});
  expect_refused("", {"disk[0].omega = 1e+308", range}, box + "[[disk]]\npos = [1.0, 1.0]\nradius = 0.5\nomega = 1e308\n");
  expect_refused("--set particles.d_mean=1e-300 --set particles.n=10 --set particles.region=[0,0,1,1]",
                 {"particles.d_mean = 1e-300", range});
  // Within the range, but a grain of zero moment of inertia (1e-160 x 1e-160).
  expect_refused("", {"disk[0] of diameter 2e-80 m", "moment of inertia 1.5706e-320"},
                 box + "[[disk]]\npos = [1.0, 1.0]\nradius = 1e-80\ndensity = 1.0\n");
  expect_refused("", {"disk[0].pos = [5, 1] is outside the box [0, 4] x [0, 4]"},
                 box + "[[disk]]\npos = [5.0, 1.0]\nradius = 0.5\n");
  expect_refused("", {"particles.region = [0, 0, 5, 2] reaches outside the box [0, 4] x [0, 4]"},
                 box + "[particles]\nn = 4\nregion = [0.0, 0.0, 5.0, 2.0]\n");
  expect_refused("--set name=\"../x\"", {"name = \"../x\": must be a folder name"});
  expect_refused("--set name=\"/tmp/x\"", {"must be a folder name"});
  // 1e60 lattice sites: placed, not an int overflow.
  const fs::path dir = cdtest::scratch_dir("bad_input", "absurd");
  const fs::path sc = write(dir, "s.toml", box + "[particles]\nn = 10\nd_mean = 1e-60\n");
  EXPECT_EQ(cdsim(sc.string() + " -q --max-steps 1 --out " + (dir / "out").string()).code, 0);
  const fs::path full = write(dir, "f.toml", box + "[particles]\nn = 100000\nd_mean = 0.1\n");
  const cdtest::CmdResult r = cdsim(full.string() + " -q --out " + (dir / "out2").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("room for 729 disks"), std::string::npos) << r.out;
}

// A 3D contact.axis_a whose norm under- or overflows:
// [1e-300, 0, 0] and [1e308, 1e308, 0] are refused by name (a plain norm
// dropped the orthotropic cone silently); at the ends of the range a scene
// may give, [1e-100, 0, 0] runs as [1, 0, 0] and [1e100, 1e100, 0] as
// [1, 1, 0], byte for byte; [0, 1, 0] differs, so the axis is seen.
TEST(BadInput, AxisAOfExtremeLengthIsItsDirection) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "axis_a");
  const auto series = [&](const std::string& axis) {
    const fs::path out = dir / "out";
    fs::remove_all(out);
    const cdtest::CmdResult r = cdsim(std::string(CDLAB_SOURCE_DIR) + "/configs/pile3d.toml -q --threads 1 "
                                      "--set particles.n=27 --set time.duration=0.06 --set gravity.g=[0,0,-2000] "
                                      "--set output.series_interval=0.002 --set contact.mu_b=0.05 "
                                      "--set contact.axis_a=" + axis + " --out " + out.string());
    EXPECT_EQ(r.code, 0) << axis << "\n" << r.out;
    std::ifstream in(out / "series.csv");
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string x = series("[1,0,0]"), xy = series("[1,1,0]");
  EXPECT_EQ(series("[1e-100,0,0]"), x);
  EXPECT_EQ(series("[1e100,1e100,0]"), xy);
  EXPECT_NE(series("[0,1,0]"), x);
  const std::string pile = std::string(CDLAB_SOURCE_DIR) + "/configs/pile3d.toml";
  for (const std::string axis : {"[1e-300,0,0]", "[1e308,1e308,0]"}) {
    const cdtest::CmdResult r = cdsim(pile + " -q --set contact.mu_b=0.05 --set contact.axis_a=" + axis +
                                      " --out " + (dir / "refused").string());
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("contact.axis_a: element 0 is 1e"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "refused"));
  }
}

// Continuation: a run may start from a sheared run's checkpoint.
// The Lees-Edwards offset and the cell rates are carried, the mean flow is
// replaced by the new rate's profile, and the first rows overlap no more than
// the old run did (resetting the offset would overlap grains across the
// sheared boundary by up to a diameter; a start overlapping by more than
// 0.05 d is refused).
TEST(Continuation, AShearRunStartsFromAnotherAtANewRate) {
  const fs::path dir = cdtest::scratch_dir("bad_input", "continuation");
  const std::string common =
      "[gravity]\ng = [0.0, 0.0]\n[solver]\ntol = 1e-4\n[particles]\nd_mean = 1e-3\ndensity = 2.6\n";
  const fs::path prep = write(dir, "prep.toml",
      "name = \"prep\"\n" + common + "n = 60\n[shear]\nmode = \"periodic\"\nwidth = 0.0\nheight = 0.0\n"
      "pressure = 100.0\nisotropic = true\ndt_tp = 0.05\n[time]\nduration = 0.02\n[output]\n"
      "series_interval = 1e-3\ncheckpoint_interval = 0.02\n");
  ASSERT_EQ(cdsim(prep.string() + " -q --out " + (dir / "prep").string()).code, 0);
  const auto shear = [&](const std::string& name, const std::string& start, double I) {
    const fs::path sc = write(dir, name + ".toml",
        "name = \"" + name + "\"\n" + common + "n = 0\n[shear]\nmode = \"periodic\"\nwidth = 0.0\n"
        "height = 0.0\npressure = 100.0\ninertial_number = " + std::to_string(I) + "\nstrain = 0.3\n"
        "dt_tp = 0.05\nstart = \"" + start + "\"\n[output]\nseries_interval = 1e-5\ncheckpoint_interval = 1.0\n");
    return cdsim(sc.string() + " -q --out " + (dir / name).string());
  };
  const cdtest::CmdResult a = shear("a", (dir / "prep" / "checkpoint.bin").string(), 0.1);
  ASSERT_EQ(a.code, 0) << a.out;
  const cdtest::CmdResult b = shear("b", (dir / "a" / "checkpoint.bin").string(), 0.05);
  ASSERT_EQ(b.code, 0) << b.out;
  const auto ra = csv(dir / "a" / "series.csv"), rb = csv(dir / "b" / "series.csv");
  const auto col = [](const std::vector<std::vector<std::string>>& t, const std::string& name) {
    std::size_t c = 0;
    while (c < t[0].size() && t[0][c] != name) ++c;
    EXPECT_LT(c, t[0].size()) << name;
    std::vector<double> v;
    for (std::size_t r = 1; r < t.size(); ++r) v.push_back(std::stod(t[r][c]));
    return v;
  };
  const auto oa = col(ra, "max_overlap"), ob = col(rb, "max_overlap");
  const double a_max = *std::max_element(oa.begin(), oa.end());
  // The first rows of b: no overlap beyond what a had.
  for (std::size_t k = 0; k < std::min<std::size_t>(5, ob.size()); ++k) EXPECT_LE(ob[k], a_max) << k;
  // The new rate applies from the first step (shear rate = I / t_p).
  const double tp = 1e-3 * std::sqrt(2.6 / 100.0);
  EXPECT_NEAR(col(rb, "shear_rate").front(), 0.05 / tp, 1e-9 / tp);
  // The cell continues: b's first height is a's last (within one step's change).
  const double ha = col(ra, "cell_height").back(), hb = col(rb, "cell_height").front();
  EXPECT_NEAR(hb, ha, 1e-3 * ha);
}

// The limit of 1e9 steps includes 1e9 (the run plan's count, the nearest
// integer of duration/dt), and a count just past it is printed whole, not
// as "1e+09" beside "more than the limit of 1e+09".
TEST(BadInput, TheStepLimitIsInclusiveAndItsMessageExact) {
  const std::string base = "name = \"s\"\n[particles]\nn = 20\n[time]\ndt = 1e-3\n";
  EXPECT_NO_THROW(cd::check_derived(cd::parse_scene(base + "duration = 1e6\n", "s.toml")));
  try {
    cd::check_derived(cd::parse_scene(base + "duration = 1000000.001\n", "s.toml"));
    ADD_FAILURE() << "1000000001 steps were accepted";
  } catch (const cd::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("would take 1000000001 steps"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("limit of 1000000000"), std::string::npos) << e.what();
  }
}

// Messages that showed another value than the one given, or echoed bytes
// that are not text: a seed past 64 bits (the TOML reader holds it at
// 2^63 - 1), a folder given as a checkpoint (read as a truncated file), a
// byte 0xFF in a scene (quoted raw by the TOML reader), and an output
// folder whose name holds a newline (accepted, and then in every log line).
TEST(BadInput, MessagesShowWhatWasGivenAndOnlyText) {
  expect_refused("--set particles.seed=9223372036854775808", {"particles.seed = > 2^63 - 1", "[0, 4294967295]"});
  const fs::path dir = cdtest::scratch_dir("bad_input", "messages");
  const fs::path run = dir / "run";
  fs::create_directories(run);
  const std::string shear = "name = \"s\"\n[gravity]\ng = [0.0, 0.0]\n[particles]\nn = 0\n"
                            "[shear]\nmode = \"periodic\"\npressure = 100.0\ninertial_number = 0.1\nstrain = 1.0\n"
                            "start = \"" + run.string() + "\"\n";
  expect_refused("", {"shear.start", "is a folder, not a checkpoint file"}, shear);
  // Not UTF-8, or a control byte: refused before the TOML reader sees it,
  // the byte named by its value.
  const fs::path ff = write(dir, "ff.toml", "name = \"\xff\"\n");
  cdtest::CmdResult r = cdsim(ff.string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("invalid UTF-8 byte 0xff at line 1"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\xff'), std::string::npos) << "the raw byte reached the message";
  const fs::path c1 = write(dir, "c1.toml", "name = \"a\x01" "b\"\n");
  r = cdsim(c1.string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("control byte 0x01 at line 1"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\x01'), std::string::npos) << "the raw byte reached the message";
  const cdtest::CmdResult nl = cdsim(std::string(CDLAB_SOURCE_DIR) + "/configs/default.toml -q --out '" +
                                     (dir / "a\nb").string() + "'");
  EXPECT_EQ(nl.code, 2) << nl.out;
  EXPECT_NE(nl.out.find("control character (\\x0A)"), std::string::npos) << nl.out;
  EXPECT_FALSE(fs::exists(dir / "a\nb"));
}
