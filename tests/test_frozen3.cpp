// The four FCLib 3D problems of tests/data/contact-problems, read (local or
// condensed global), solved by the 3D NLGS (core/sweep.hpp with the exact
// local solver) and measured with Siconos' fc3d error.
//
// Thresholds: 1e-6, Siconos' default tolerance of its fc3d solvers, with
// the sweep tolerance 1e-8 (rms |dr| / mean |r|), which reaches it on three
// files (measured 2026-11-25: 1581, 93 and 485 sweeps, errors 4.5e-8,
// 6.5e-9, 6.0e-9). spheres-in-a-box converges slowly (20000 sweeps, 38 s:
// error 1.3e-5): to keep the test fast it is capped at 2000 sweeps and must
// reach 1e-3 (measured 2026-11-25: 2.1e-4 in 4 s), i.e. the test checks reading,
// condensation and steady progress there, not convergence. The global
// files' stored "solution" r has a Siconos error of 0.6 to 0.9 as read here
// (printed): not a usable reference (not investigated further).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "problem3.hpp"

namespace {

const std::string kData = std::string(CDLAB_TEST_DATA) + "/contact-problems/";

TEST(Frozen3, ReadsAndSolvesTheFclibProblems) {
  struct Case {
    const char* file;
    int nc;
    bool global;
    int max_sweeps;
    double error;
  };
  const Case cases[] = {
      {"LMGC_100_PR_PerioBox-i00361-60-03000.hdf5", 60, false, 20000, 1e-6},
      {"Box_Stacks-i0122-82-5.hdf5", 82, true, 20000, 1e-6},
      {"spheres-in-a-box-98-i10000-256-10.hdf5", 256, true, 2000, 1e-3},
      {"Spheres-i099-356-679.hdf5", 356, true, 20000, 1e-6},
  };
  for (const Case& c : cases) {
    const cd::Fclib3 f = cd::read_fclib(kData + c.file);
    const cd::Problem3& p = f.problem;
    ASSERT_EQ(p.nc, c.nc) << c.file;
    ASSERT_EQ(f.global, c.global) << c.file;
    // Condensed W must be symmetric to round-off.
    const Eigen::SparseMatrix<double> Wt = p.W.transpose();
    EXPECT_LT((p.W - Wt).norm(), 1e-12 * p.W.norm()) << c.file;
    double ref_err = -1;
    if (f.r_ref.size()) ref_err = cd::siconos_error(p, f.r_ref);
    cd::NlgsOptions opt;
    opt.tol = 1e-8;
    opt.max_sweeps = c.max_sweeps;
    Eigen::VectorXd r;
    const cd::NlgsStats st = cd::solve_nlgs(p, r, opt);
    std::printf("[ frozen3 ] %s: %d contacts, %d sweeps, rms |dr|/|r| %.2e, residual max %.2e, "
                "Siconos error %.2e (stored solution's %.2e), %.3f s\n",
                c.file, p.nc, st.sweeps, st.dr_rel, st.residual.max, st.siconos_error, ref_err, st.time);
    if (c.error <= 1e-6) {
      EXPECT_TRUE(st.converged) << c.file;
    }
    EXPECT_LT(st.siconos_error, c.error) << c.file;
    EXPECT_GT(r.cwiseAbs().maxCoeff(), 0.0) << c.file;
  }
}

TEST(Frozen3, RefusesWhatIsNotFclib) {
  EXPECT_THROW(cd::read_fclib(kData + "FC2D_SliderCrankLagrangian00000.dat"), std::runtime_error);
  EXPECT_THROW(cd::read_fclib(kData + "no-such-file.hdf5"), std::runtime_error);
}

}  // namespace
