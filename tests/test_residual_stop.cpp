// solver.residual_tol: the optional second stopping test on the
// law residual itself. On a frozen dense-shear step (disks, I = 1e-3, from
// tests/data/frozen-shear) the rms |dp| test at tol = 1e-4 runs into the
// 2000-sweep cap although the laws are met to ~1.5e-3 long before; with
// residual_tol the solve stops as soon as the largest law residual is below
// it, checked every 10 sweeps, and says so. Off (0), nothing changes.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_util.hpp"
#include "nlgs.hpp"
#include "problem.hpp"

namespace fs = std::filesystem;

namespace {

cd::ContactProblem frozen(const std::string& name, cd::SolverParams& prm) {
  const fs::path dir = cdtest::scratch_dir("residual_stop", name);
  const fs::path cdp = dir / (name + ".cdp");
  const auto r = cdtest::run_command("zcat '" + std::string(CDLAB_SOURCE_DIR) + "/tests/data/frozen-shear/" +
                                     name + ".cdp.gz' > '" + cdp.string() + "'");
  EXPECT_EQ(r.code, 0) << r.out;
  return cd::read_contact_problem(cdp.string(), prm);
}

}  // namespace

TEST(ResidualStop, StopsOnTheLawResidualBeforeTheCap) {
  cd::SolverParams prm;
  cd::ContactProblem p = frozen("ns0_I1e-3_step400", prm);
  ASSERT_GT(p.rows.size(), 2000u);
  ASSERT_EQ(prm.residual_tol, 0.0);  // the step was dumped with the criterion off
  cd::ContactProblem q = p;
  const cd::SolveStats off = cd::nlgs_solve(p, prm);
  EXPECT_TRUE(off.cap_hit);  // the rms |dp| test alone: at the cap
  EXPECT_EQ(off.iterations, prm.max_iter);

  prm.residual_tol = 3e-3;
  const cd::SolveStats on = cd::nlgs_solve(q, prm);
  EXPECT_FALSE(on.cap_hit);
  EXPECT_TRUE(on.residual_met);
  EXPECT_LT(on.residual_max, 3e-3);       // what the criterion promises
  EXPECT_EQ(on.iterations % 10, 0);       // checked every 10 sweeps
  EXPECT_LT(on.iterations, off.iterations / 2);
  std::printf("[ residual stop ] %d sweeps (residual max %.3g) against %d at the cap (%.3g)\n",
              on.iterations, on.residual_max, off.iterations, off.residual_max);
}
