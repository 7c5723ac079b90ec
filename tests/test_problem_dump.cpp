// A step's contact problem taken out of the run and solved again:
// the problem a World hands its solver is plain data; written in cdlab's
// own format (.cdp) and read back, the production solver gives the same
// impulses to the bit; in Siconos' matrix form (.dat, boundary dofs
// eliminated into W), the matrix replay of the same sweep agrees to the
// tolerance. Scenes: a pile (walls, friction) and a Lees-Edwards shear at
// imposed pressure (a boundary dof coupled to the crossing rows).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "config.hpp"
#include "nlgs.hpp"
#include "problem.hpp"
#include "setup.hpp"
#include "world_util.hpp"

namespace {

struct Captured {
  cd::ContactProblem problem;
  cd::SolverParams prm;
  std::vector<cd::ContactRow> solved;  // the step's rows after its solve
  cd::SolveStats stats;
};

// Runs `steps` steps of the scene and captures the last one's problem
// (before its solve) and its solved rows.
Captured capture(const std::string& file, const std::vector<std::string>& set, int steps) {
  cd::World w = cd::build_world(cd::load_scene(std::string(CDLAB_SOURCE_DIR) + "/configs/" + file, set));
  Captured c;
  for (int k = 0; k < steps - 1; ++k) w.step();
  w.set_problem_hook([&](const cd::ContactProblem& p, const cd::SolverParams& prm) {
    c.problem = p;
    c.prm = prm;
  });
  w.step();
  c.solved = w.rows();
  c.stats = w.last().solve;
  return c;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_replays_exactly(const Captured& c, const char* name) {
  ASSERT_GT(c.problem.rows.size(), 50u) << name;
  std::stringstream file;
  cd::write_contact_problem(c.problem, c.prm, file);
  cd::SolverParams prm;
  cd::ContactProblem p = cd::read_contact_problem(file, name, prm);
  EXPECT_EQ(prm.tol, c.prm.tol);
  EXPECT_EQ(prm.max_iter, c.prm.max_iter);
  const cd::SolveStats st = cd::nlgs_solve(p, prm);
  EXPECT_EQ(st.iterations, c.stats.iterations) << name;
  ASSERT_EQ(p.rows.size(), c.solved.size());
  int differ = 0;
  for (std::size_t k = 0; k < p.rows.size(); ++k)
    differ += !same_bits(p.rows[k].pn, c.solved[k].pn) || !same_bits(p.rows[k].pt, c.solved[k].pt);
  EXPECT_EQ(differ, 0) << name << ": rows whose replayed impulses differ from the step's";
  std::printf("[ dump ] %s: %zu rows, %zu dofs, %d sweeps: replay bit-identical: %s\n", name,
              p.rows.size(), p.dofs.size(), st.iterations, differ ? "no" : "yes");
}

// The same problem solved tightly in body form and in matrix form (the
// production sweep on W's blocks): the law has a unique solution on these
// (dense, frictional, not at the sliding bound everywhere), so the impulses
// agree to the distance both are from it; 1e-6 of the largest impulse is
// far below any change of contact status.
void expect_matrix_form_agrees(const Captured& c, const char* name) {
  cd::SolverParams tight;
  tight.tol = 1e-12;
  tight.max_iter = 200000;
  cd::ContactProblem body = c.problem;
  ASSERT_FALSE(cd::nlgs_solve(body, tight).cap_hit) << name;
  const cd::Problem m = cd::to_matrix(c.problem);
  Eigen::VectorXd r(2 * m.nc);
  for (int k = 0; k < m.nc; ++k) r.segment<2>(2 * k) << c.problem.rows[k].pn, c.problem.rows[k].pt;
  cd::NlgsOptions opt;
  opt.tol = 1e-12;
  opt.max_sweeps = 200000;
  const cd::NlgsStats st = cd::solve_nlgs(m, r, opt);
  ASSERT_TRUE(st.converged) << name;
  double scale = 0, diff = 0;
  for (int k = 0; k < m.nc; ++k) {
    scale = std::max({scale, std::abs(body.rows[k].pn), std::abs(body.rows[k].pt)});
    diff = std::max({diff, std::abs(body.rows[k].pn - r[2 * k]),
                     std::abs(body.rows[k].pt - r[2 * k + 1])});
  }
  std::printf("[ dump ] %s: matrix form %d sweeps, max |r_matrix - r_body| = %.2e of max |r|, "
              "law residual %.2e, Siconos error %.2e\n",
              name, st.sweeps, diff / scale, st.residual.max, st.siconos_error);
  EXPECT_LT(diff, 1e-6 * scale) << name;
  EXPECT_LT(st.residual.max, 1e-8) << name;
}

TEST(ProblemDump, PileStepReplaysBitForBitAndAsAMatrix) {
  const Captured c = capture("default.toml",
                             {"particles.n=150", "box.width=0.012", "box.height=0.03"}, 200);
  EXPECT_TRUE(c.problem.dofs.empty());
  expect_replays_exactly(c, "pile");
  expect_matrix_form_agrees(c, "pile");
}

TEST(ProblemDump, ShearStepWithBoundaryDofReplaysBitForBitAndAsAMatrix) {
  const Captured c = capture("shear-prep.toml",
                             {"particles.n=120", "shear.width=0.0165", "shear.height=0.0185",
                              "shear.isotropic=false", "shear.inertial_number=0.1",
                              "solver.tol=1e-3",
                              // a shear step: without the preparation's compaction bound,
                              // projection and stop rule
                              "shear.compaction_rate=0", "contact.overlap_projection=0",
                              "shear.settle_stress=0", "shear.settle_phi=0", "shear.settle_time=0"},
                             // the lattice compacts at most 0.025 d a step: 300
                             // steps for the rows (as test_state_hash's lees_edwards)
                             300);
  ASSERT_EQ(c.problem.dofs.size(), 1u);
  EXPECT_GT(c.problem.dofs[0].rows.size(), 3u);
  expect_replays_exactly(c, "shear");
  expect_matrix_form_agrees(c, "shear");
}

// As a user would: cdsim --dump-problem writes the step, cdproblem replays
// the .cdp to the same bytes of impulses and solves the .dat.
TEST(ProblemDump, CdsimDumpsAndCdproblemReplaysTheSameImpulses) {
  const auto dir = cdtest::scratch_dir("problem_dump", "cli");
  const std::string bin = std::string(CDLAB_BINARY_DIR) + "/cd/";
  const cdtest::CmdResult sim = cdtest::run_command(
      bin + "cdsim " + CDLAB_SOURCE_DIR + "/configs/default.toml --set particles.n=150 "
      "--set box.width=0.012 --set box.height=0.03 --set time.duration=0.02 -q --out " +
      dir.string() + " --dump-problem 60");
  ASSERT_EQ(sim.code, 0) << sim.out;
  for (const char* f : {"problem_60.cdp", "problem_60.dat", "problem_60.impulses"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  const cdtest::CmdResult rep = cdtest::run_command(
      bin + "cdproblem solve " + (dir / "problem_60.cdp").string() + " --out " +
      (dir / "replay.impulses").string());
  ASSERT_EQ(rep.code, 0) << rep.out;
  auto slurp = [](const std::filesystem::path& f) {
    std::ifstream in(f);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  const std::string a = slurp(dir / "problem_60.impulses"), b = slurp(dir / "replay.impulses");
  EXPECT_GT(a.size(), 100u);
  EXPECT_EQ(a, b) << "the replayed impulses differ from the step's";
  const cdtest::CmdResult dat =
      cdtest::run_command(bin + "cdproblem solve " + (dir / "problem_60.dat").string() +
                          " --tol 1e-8 --max-sweeps 100000");
  EXPECT_EQ(dat.code, 0) << dat.out;
  EXPECT_NE(dat.out.find("Siconos error"), std::string::npos) << dat.out;
  const cdtest::CmdResult bad = cdtest::run_command(bin + "cdsim " + CDLAB_SOURCE_DIR +
                                                    "/configs/default.toml --dump-problem 0");
  EXPECT_NE(bad.code, 0) << bad.out;
}

// "last" and "last-K" name steps from the run's end (0.02 s at dt = 2e-4 s:
// 100 steps), so that a campaign need not compute its run's step count;
// a step before the first is refused before anything is written.
TEST(ProblemDump, LastAndLastKCountFromTheRunsEnd) {
  const auto dir = cdtest::scratch_dir("problem_dump", "last");
  const std::string cdsim = std::string(CDLAB_BINARY_DIR) + "/cd/cdsim " + CDLAB_SOURCE_DIR +
                            "/configs/default.toml --set particles.n=150 --set box.width=0.012 "
                            "--set box.height=0.03 --set time.duration=0.02 -q --fresh ";
  const cdtest::CmdResult sim =
      cdtest::run_command(cdsim + "--out " + dir.string() + " --dump-problem last --dump-problem last-10");
  ASSERT_EQ(sim.code, 0) << sim.out;
  for (const char* f : {"problem_100.cdp", "problem_90.cdp"}) EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  EXPECT_FALSE(std::filesystem::exists(dir / "problem_0.cdp"));
  const auto none = dir / "none";
  const cdtest::CmdResult past = cdtest::run_command(cdsim + "--out " + none.string() + " --dump-problem last-100");
  EXPECT_EQ(past.code, 2) << past.out;
  EXPECT_NE(past.out.find("--dump-problem last-100: the run has 100 steps"), std::string::npos) << past.out;
  EXPECT_FALSE(std::filesystem::exists(none));
  for (const char* word : {"last-0", "last-", "lastx", "last-x", "last+1"}) {
    const cdtest::CmdResult r = cdtest::run_command(cdsim + "--out " + none.string() + " --dump-problem " + word);
    EXPECT_EQ(r.code, 2) << word << "\n" << r.out;
    EXPECT_NE(r.out.find("\"last\" or \"last-K\""), std::string::npos) << word << "\n" << r.out;
  }
}

// A dump that cannot be written is a write failure (exit 4, "could not
// write" naming the option and the file), not a divergence, although the
// .cdp is written inside the step, before its solve, whose errors the run
// loop reports as a diverged run (exit 3); the .impulses, written after the
// step, likewise. A folder in the dump's place makes the write fail, as root
// too (permissions would not); the run resumes from its checkpoint once the
// place is free.
TEST(ProblemDump, ADumpThatCannotBeWrittenIsAWriteFailure) {
  const auto dir = cdtest::scratch_dir("problem_dump", "unwritable");
  const std::string cdsim = std::string(CDLAB_BINARY_DIR) + "/cd/cdsim " + CDLAB_SOURCE_DIR +
                            "/configs/default.toml --set particles.n=150 --set box.width=0.012 "
                            "--set box.height=0.03 --set time.duration=0.02 --set output.snapshot_interval=0 "
                            "--set output.checkpoint_interval=0.005 -q --threads 1 --out " + dir.string();
  cdtest::CmdResult r = cdtest::run_command(cdsim + " --max-steps 40");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"problem_60.cdp", "problem_60.impulses"}) {
    SCOPED_TRACE(f);
    std::filesystem::create_directories(dir / f / "x");
    r = cdtest::run_command(cdsim + " --dump-problem 60");
    EXPECT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find("cdsim: --dump-problem 60: could not write '" + (dir / f).string() + "'"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("diverged"), std::string::npos) << r.out;
    std::filesystem::remove_all(dir / f);
  }
  r = cdtest::run_command(cdsim + " --dump-problem 60");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  for (const char* f : {"problem_60.cdp", "problem_60.dat", "problem_60.impulses"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / f)) << f;
}

TEST(ProblemDump, MalformedFilesAreClearErrors) {
  const Captured c = capture("default.toml",
                             {"particles.n=150", "box.width=0.012", "box.height=0.03"}, 20);
  std::stringstream file;
  cd::write_contact_problem(c.problem, c.prm, file);
  const std::string good = file.str();
  auto error_of = [](const std::string& text) {
    std::istringstream in(text);
    cd::SolverParams prm;
    try {
      cd::read_contact_problem(in, "bad.cdp", prm);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of(good), "");
  EXPECT_NE(error_of(good.substr(0, good.size() / 2)).find("end of file"), std::string::npos);
  std::string bad = good;
  bad.replace(bad.find("law coulomb"), 11, "law coulombx");
  EXPECT_NE(error_of(bad).find("unknown law 'coulombx'"), std::string::npos) << error_of(bad);
  EXPECT_NE(error_of("2\n5\n").find("bad.cdp:1"), std::string::npos);
  EXPECT_NE(error_of(good + "1\n").find("after the last dof"), std::string::npos);
}

}  // namespace
