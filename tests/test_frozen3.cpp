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
// files' stored "solution" is r = 0, v = 0 (GlobalFilesStoreZeroAsSolution):
// its Siconos error of 0.6 to 0.9 is that of zero impulses. Siconos' own
// 3D text form (.dat) is read too (ReadsSiconosDat3D).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
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

// Why the stored solutions of the FCLib global files give a Siconos error
// of 0.6-0.9 (docs/accuracy.md asked): the files store r = 0 and v = 0, to
// the last bit, as their "solution" (and the same as their one guess):
// their /solution/r and /solution/v are declared and never written, so HDF5
// reads its fill value, 0. So the error is that of zero impulses,
// sqrt(sum_k |P_K(-u~_k(q))|^2) / |q|:
// neither the condensation W = H^T M^-1 H, q = H^T M^-1 f + w nor the reading
// is at fault, and the same (W, q) is solved to a Siconos error below 1e-6 by
// NLGS (ReadsAndSolvesTheFclibProblems, Box_Stacks and Spheres). Checked
// independently with h5py and scipy: r and v are zero, and the stored u is
// neither H^T v + w (zero here: w = 0) nor q (|u - q| / |q| = 0.97-1.02).
TEST(Frozen3, GlobalFilesStoreZeroAsSolution) {
  for (const char* file : {"Box_Stacks-i0122-82-5.hdf5", "spheres-in-a-box-98-i10000-256-10.hdf5",
                           "Spheres-i099-356-679.hdf5"}) {
    const cd::Fclib3 f = cd::read_fclib(kData + file);
    ASSERT_TRUE(f.global) << file;
    ASSERT_EQ(f.r_ref.size(), 3 * f.problem.nc) << file;
    ASSERT_EQ(f.v_ref.size(), f.bodies_dofs) << file;
    EXPECT_EQ(f.r_ref.cwiseAbs().maxCoeff(), 0.0) << file;
    EXPECT_EQ(f.v_ref.cwiseAbs().maxCoeff(), 0.0) << file;
    const double e = cd::siconos_error(f.problem, f.r_ref);
    EXPECT_EQ(e, cd::siconos_error(f.problem, Eigen::VectorXd::Zero(3 * f.problem.nc))) << file;
    EXPECT_GT(e, 0.5) << file;
    std::printf("[ frozen3 ] %s: stored r and v are zero; Siconos error of r = 0: %.3f\n", file, e);
  }
}

// Siconos' text form in 3D (core/siconos_dat.hpp), from Siconos' fc3d test
// data: FC3D_Example1 has W = I, q_k = (-1, 1, 3) and mu = 0.1 at its three
// contacts, so each contact is alone and slides: r_n = 1 and r_t the stick
// trial -q_t projected onto the disk of radius mu r_n, r_t = -0.1 (1, 3) /
// sqrt(10). Its dense (storage 0) and sparse-block (1) files hold the same
// problem. Rover1039 (dense, 4 contacts) and Confeti-ex03 (sparse block, 54
// contacts) are solved to Siconos' default tolerance 1e-6; Confeti's W is
// symmetric to its file's 7 printed digits (Rover's is not: 1e-6 apart in
// the file itself).
TEST(Frozen3, ReadsSiconosDat3D) {
  const cd::Problem3 dense = cd::read_dat3(kData + "FC3D_Example1.dat");
  const cd::Problem3 sbm = cd::read_dat3(kData + "FC3D_Example1_SBM.dat");
  ASSERT_EQ(dense.nc, 3);
  ASSERT_EQ(sbm.nc, 3);
  EXPECT_EQ(Eigen::MatrixXd(dense.W), Eigen::MatrixXd::Identity(9, 9));
  EXPECT_EQ(Eigen::MatrixXd(sbm.W), Eigen::MatrixXd::Identity(9, 9));
  EXPECT_EQ(dense.q, sbm.q);
  EXPECT_EQ(dense.mu, sbm.mu);
  Eigen::VectorXd r;
  cd::NlgsOptions opt;
  opt.tol = 1e-12;
  const cd::NlgsStats st = cd::solve_nlgs(sbm, r, opt);
  EXPECT_TRUE(st.converged);
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(r[3 * k], 1.0);
    EXPECT_NEAR(r[3 * k + 1], -0.1 / std::sqrt(10.0), 1e-15);
    EXPECT_NEAR(r[3 * k + 2], -0.3 / std::sqrt(10.0), 1e-15);
  }
  for (const auto& [file, nc] : {std::pair{"Rover1039.dat", 4}, std::pair{"Confeti-ex03-Fc3D-SBM.dat", 54}}) {
    const cd::Problem3 p = cd::read_dat3(kData + file);
    ASSERT_EQ(p.nc, nc) << file;
    if (nc == 54) {
      // Symmetric to the digits the file prints (7 significant digits, so
      // two mirrored entries may differ by 1e-6 of their size; entries of
      // 1e-20 are round-off of zeros).
      const Eigen::MatrixXd W(p.W);
      const Eigen::MatrixXd asym = (W - W.transpose()).cwiseAbs(),
                            size = W.cwiseAbs().cwiseMax(W.transpose().cwiseAbs());
      EXPECT_TRUE((asym.array() <= 1.1e-6 * size.array() + 1e-15 * W.cwiseAbs().maxCoeff()).all())
          << file << ": largest |W - W^T| " << asym.maxCoeff();
    }
    cd::NlgsOptions o;
    o.tol = 1e-10;
    o.max_sweeps = 100000;
    Eigen::VectorXd x;
    const cd::NlgsStats s = cd::solve_nlgs(p, x, o);
    std::printf("[ frozen3 ] %s: %d contacts, %d sweeps, Siconos error %.2e\n", file, p.nc, s.sweeps, s.siconos_error);
    EXPECT_LT(s.siconos_error, 1e-6) << file;
  }
  EXPECT_THROW(cd::read_dat3(kData + "FC2D_SliderCrankLagrangian00000.dat"), std::runtime_error);
}

TEST(Frozen3, RefusesWhatIsNotFclib) {
  EXPECT_THROW(cd::read_fclib(kData + "FC2D_SliderCrankLagrangian00000.dat"), std::runtime_error);
  EXPECT_THROW(cd::read_fclib(kData + "no-such-file.hdf5"), std::runtime_error);
}

}  // namespace
