// A 3D step's contact problem taken out of the run: `cdsim
// --dump-problem STEP` on a 3D shear writes problem_STEP.cdp3 (cdlab's
// exact text form), problem_STEP.hdf5 (FCLib's local form) and the step's
// impulses; `cdproblem solve` replays the .cdp3 to the same impulses bit for
// bit, and the FCLib file, read back by the reader the frozen-problem tests
// use (read_fclib), holds the W, q and mu of the problem the step solved:
// W against H^T M^-1 H assembled here, body by body, from the .cdp3's rows
// and bodies; q against the free velocities (the bodies' less the warm
// start's impulses, one body at a time) plus the rows' offsets; and the
// step's own impulses meet the law on (W, q) to the step's residual, which a
// wrong sign of q or of a frame would not allow. The other laws (cohesive,
// orthotropic, restitution) replay exactly through a .cdp3 written and read
// in memory.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <omp.h>

#include "cli_util.hpp"
#include "contact_problem3.hpp"
#include "pile3d.hpp"
#include "problem3.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kCdproblem = CDLAB_BINARY_DIR "/cd/cdproblem";
const std::string kConfigs = CDLAB_SOURCE_DIR "/configs/";

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// [c]x: c x y = [c]x y.
Eigen::Matrix3d cross(const cd::Vec3& c) {
  Eigen::Matrix3d m;
  m << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  return m;
}

Eigen::Matrix3d frame(const cd::SphereRow& r) {
  Eigen::Matrix3d F;
  F.row(0) = r.n.transpose();
  F.row(1) = r.t1.transpose();
  F.row(2) = r.t2.transpose();
  return F;
}

// Body b's world inverse inertia: its tensor (polyhedra), else inv_I 1.
Eigen::Matrix3d inverse_inertia(const cd::ContactProblem3& p, int b) {
  return p.inv_inertia.empty() ? Eigen::Matrix3d(p.vel[b].inv_I * Eigen::Matrix3d::Identity()) : p.inv_inertia[b];
}

// W = H^T M^-1 H, dense: for each pair of rows and each body they share,
// F_k (s_k s_l) (inv_m I - [c_k]x J [c_l]x) F_l^T (the velocity at k
// that an impulse at l gives through that body), and for each cell dof
// inv_mass a_k a_l^T.
Eigen::MatrixXd assembled_W(const cd::ContactProblem3& p) {
  const int nc = static_cast<int>(p.rows.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(3 * nc, 3 * nc);
  for (int k = 0; k < nc; ++k)
    for (int l = 0; l < nc; ++l) {
      const cd::SphereRow &a = p.rows[k], &b = p.rows[l];
      Eigen::Matrix3d blk = Eigen::Matrix3d::Zero();
      for (int body : {a.b1, a.b2}) {
        if (body == a.b1 && body == a.b2) continue;
        const double sa = body == a.b2 ? 1.0 : -1.0;
        const cd::Vec3 ca = body == a.b2 ? a.c2 : a.c1;
        if (body != b.b1 && body != b.b2) continue;
        const double sb = body == b.b2 ? 1.0 : -1.0;
        const cd::Vec3 cb = body == b.b2 ? b.c2 : b.c1;
        const cd::BodyVel3& V = p.vel[body];
        const Eigen::Matrix3d J = inverse_inertia(p, body);
        blk += sa * sb * (V.inv_m * Eigen::Matrix3d::Identity() - cross(ca) * J * cross(cb));
      }
      W.block<3, 3>(3 * k, 3 * l) = frame(a) * blk * frame(b).transpose();
    }
  for (const cd::CellDof3& d : p.dofs)
    for (std::size_t i = 0; i < d.rows.size(); ++i)
      for (std::size_t j = 0; j < d.rows.size(); ++j)
        W.block<3, 3>(3 * d.rows[i], 3 * d.rows[j]) += d.inv_mass * d.a[i] * d.a[j].transpose();
  return W;
}

// q: the relative velocity of each row at the free velocities (every row's
// warm-start impulse taken out of its bodies), plus its offsets.
Eigen::VectorXd free_q(const cd::ContactProblem3& p) {
  std::vector<cd::BodyVel3> v = p.vel;
  for (const cd::SphereRow& r : p.rows) {
    const cd::Vec3 P = r.to_world(r.r);
    v[r.b2].v -= v[r.b2].inv_m * P;
    v[r.b2].w -= inverse_inertia(p, r.b2) * r.c2.cross(P);
    v[r.b1].v += v[r.b1].inv_m * P;
    v[r.b1].w += inverse_inertia(p, r.b1) * r.c1.cross(P);
  }
  Eigen::VectorXd q(3 * p.rows.size());
  for (std::size_t k = 0; k < p.rows.size(); ++k) {
    const cd::SphereRow& r = p.rows[k];
    const cd::Vec3 b(r.bn, p.extra.empty() ? 0.0 : p.extra[k].bt1, p.extra.empty() ? 0.0 : p.extra[k].bt2);
    q.segment<3>(3 * k) = frame(r) * cd::relative_velocity(r, v[r.b1], v[r.b2]) + b;
  }
  return q;
}

// `cdproblem solve` on the .cdp3, on one and two threads: the step's
// impulses, byte for byte.
void expect_replays(const fs::path& cdp, const fs::path& imp, const fs::path& dir) {
  for (int t : {1, 2}) {
    const fs::path out = dir / ("replay" + std::to_string(t) + ".txt");
    const auto r = cdtest::run_command("OMP_NUM_THREADS=" + std::to_string(t) + " " + kCdproblem + " solve " +
                                       cdp.string() + " --out " + out.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(slurp(out), slurp(imp)) << "threads " << t;
  }
}

// The FCLib file of the step whose .cdp3 is p: W against the assembly, q
// against the free velocities, mu, and the stored solution the step's
// impulses to the bit, meeting the law on (W, q) to `residual_max` (in
// mean |r|); a wrong sign in q or a frame would leave O(1).
void expect_fclib_is_the_step(const cd::ContactProblem3& p, const fs::path& h5, const fs::path& imp,
                              double residual_max) {
  const int nc = static_cast<int>(p.rows.size());
  const cd::Fclib3 f = cd::read_fclib(h5.string());
  ASSERT_FALSE(f.global);
  ASSERT_EQ(f.problem.nc, nc);
  // W: the same matrix to round-off (sums in another order).
  const Eigen::MatrixXd W = assembled_W(p), Wf = Eigen::MatrixXd(f.problem.W);
  const double wscale = W.cwiseAbs().maxCoeff();
  EXPECT_LT((W - Wf).cwiseAbs().maxCoeff(), 1e-13 * wscale);
  // q: the free velocities' scale is the bodies' speeds (cancellation in
  // taking the warm start out costs a few ulps of them).
  const Eigen::VectorXd q = free_q(p);
  double vscale = 0;
  for (const cd::BodyVel3& v : p.vel) vscale = std::max(vscale, v.v.norm());
  EXPECT_LT((q - f.problem.q).cwiseAbs().maxCoeff(), 1e-12 * vscale);
  for (int k = 0; k < nc; ++k) EXPECT_EQ(f.problem.mu[k], p.rows[k].mu);
  ASSERT_EQ(f.r_ref.size(), 3 * nc);
  std::istringstream in(slurp(imp));
  for (int k = 0; k < 3 * nc; ++k) {
    std::string s;
    in >> s;
    const double v = std::strtod(s.c_str(), nullptr);
    EXPECT_EQ(std::memcmp(&v, &f.r_ref[k], sizeof v), 0) << "impulse " << k;
  }
  const cd::Residual res = cd::problem_residual(f.problem, f.r_ref);
  std::printf("[ dump3 ] %d rows: step's impulses on the FCLib problem: law residual max %.2e, Siconos error %.2e\n",
              nc, res.max, cd::siconos_error(f.problem, f.r_ref));
  EXPECT_LT(res.max, residual_max);
  EXPECT_LT(cd::siconos_error(f.problem, f.r_ref), 1e-4);
}

}  // namespace

// 100 spheres compacted, then sheared at I = 0.1 with the height at imposed
// stress (Lees-Edwards images and a cell dof coupled to the crossing rows),
// step 20 dumped; solver.tol 1e-4 given (the bounds below are for it, not
// for whatever the scene's policy picks), with the scene's subspace
// correction (10 CG iterations), which the file records, so that the replay
// is the step's own solve.
TEST(ProblemDump3, ShearStepReplaysExactlyAndItsFclibFileIsTheStep) {
  const fs::path dir = cdtest::scratch_dir("problem_dump3", "shear");
  const std::string prep = (dir / "prep").string(), shear = (dir / "shear").string();
  auto r = cdtest::run_command(kCdsim + " " + kConfigs +
                               "shear3-prep.toml --set particles.n=100 --set time.duration=0.005 --quiet --out " +
                               prep);
  ASSERT_EQ(r.code, 0) << r.out;
  r = cdtest::run_command(kCdsim + " " + kConfigs + "shear3-inertial.toml --set shear.start=" + prep +
                          "/checkpoint.bin --set shear.strain=0.3 --set shear.inertial_number=0.1 --set solver.tol=1e-4 "
                          "--quiet "
                          "--dump-problem 20 --out " + shear);
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path cdp = fs::path(shear) / "problem_20.cdp3", h5 = fs::path(shear) / "problem_20.hdf5",
                 imp = fs::path(shear) / "problem_20.impulses";
  ASSERT_TRUE(fs::exists(cdp) && fs::exists(h5) && fs::exists(imp)) << r.out;
  // A run with the correction says what it cost (cdsim's summary).
  EXPECT_NE(r.out.find("cdsim: subspace corrections: "), std::string::npos) << r.out;

  expect_replays(cdp, imp, dir);

  cd::SolverParams prm;
  const cd::ContactProblem3 p = cd::read_contact_problem3(cdp.string(), prm);
  EXPECT_EQ(prm.subspace, 10);
  ASSERT_GT(p.rows.size(), 100u);
  ASSERT_EQ(p.dofs.size(), 1u);
  ASSERT_GT(p.dofs[0].rows.size(), 5u);
  // tol 1e-4 in rms |dp|/|p|: law residuals of a few 1e-3 of mean |r|.
  expect_fclib_is_the_step(p, h5, imp, 2e-2);
}

// A step of polyhedra (27 blocks of sides 1 : 1.5 : 2 settling on the
// floor, 4 points a face contact, every body's inverse inertia a full
// tensor): the .cdp3 (version
// 4, the tensors after the bodies) replays bit for bit on 1 and 2 threads,
// and the FCLib file holds W = H^T M^-1 H with the tensors' angular blocks,
// checked against the assembly above; a tensor that is not positive
// semidefinite is refused, by line. The step's stop over the loaded rows
// (solver.stop_rows) travels in the file: the replay is the step's solve.
TEST(ProblemDump3, PolyhedraStepReplaysExactlyAndItsFclibFileIsTheStep) {
  const fs::path dir = cdtest::scratch_dir("problem_dump3", "polyhedra");
  const auto r = cdtest::run_command(kCdsim + " " + kConfigs +
                                     "pile-polyhedra.toml --set particles.n=27 --set time.duration=0.2 "
                                     "--set particles.shape=cuboid --set particles.aspect=[1,1.5,2] "
                                     "--set solver.stop_rows=loaded "
                                     "--set output.snapshot_interval=0 --quiet --dump-problem 150 --out " +
                                     dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path cdp = dir / "problem_150.cdp3", h5 = dir / "problem_150.hdf5", imp = dir / "problem_150.impulses";
  ASSERT_TRUE(fs::exists(cdp) && fs::exists(h5) && fs::exists(imp)) << r.out;
  const std::string text = slurp(cdp);
  EXPECT_EQ(text.rfind("cdlab-contact-problem3 4\n", 0), 0u);
  expect_replays(cdp, imp, dir);

  cd::SolverParams prm;
  const cd::ContactProblem3 p = cd::read_contact_problem3(cdp.string(), prm);
  EXPECT_EQ(prm.stop_rows, cd::StopRows::Loaded);
  ASSERT_EQ(p.inv_inertia.size(), p.vel.size());
  // Resting blocks: more rows than bodies (face contacts of 4 points), and
  // tensors that are not multiples of the identity (a cube's would be).
  ASSERT_GT(p.rows.size(), p.vel.size());
  int anisotropic = 0;
  for (const cd::Mat3& J : p.inv_inertia) {
    const cd::Mat3 dev = J - J.trace() / 3 * cd::Mat3::Identity();
    anisotropic += dev.norm() > 0.1 * J.norm();
  }
  EXPECT_GE(anisotropic, 20);
  // The pile's tolerance 1e-4 (rms |dp|/|p|); hyperstatic face contacts
  // leave a larger law residual than spheres' at the same tol.
  expect_fclib_is_the_step(p, h5, imp, 5e-2);

  // A tensor with a negative eigenvalue, named with its line.
  const std::size_t at = text.find("inertia\n");
  ASSERT_NE(at, std::string::npos);
  const std::size_t line_end = text.find('\n', at + 8);
  const std::string bad = text.substr(0, at + 8) + "-0x1p+0 0x0p+0 0x0p+0 0x1p+0 0x0p+0 0x1p+0" + text.substr(line_end);
  std::istringstream in(bad);
  cd::SolverParams s;
  try {
    cd::read_contact_problem3(in, "bad.cdp3", s);
    ADD_FAILURE() << "accepted a negative inverse inertia";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not positive semidefinite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.cdp3:"), std::string::npos) << e.what();
  }
}

// A dump that cannot be written is a write failure (exit 4, "could not
// write" naming the option and the file), not a divergence (exit 3),
// although the .cdp3 is written inside the step; the FCLib file after it,
// whose rename into place fails here, likewise. A folder in the file's place
// makes the write fail, as root too; the run resumes from its checkpoint
// once it is free. (FCLib failing to write its temporary file is a write
// failure too, not bad input, exit 2; no test makes HDF5 fail short of
// filling the disk.)
TEST(ProblemDump3, ADumpThatCannotBeWrittenIsAWriteFailure) {
  const fs::path dir = cdtest::scratch_dir("problem_dump3", "unwritable");
  const std::string cdsim = kCdsim + " " + kConfigs + "pile3d.toml --set particles.n=64 --set time.duration=0.04 "
                            "--set output.snapshot_interval=0 --set output.checkpoint_interval=0.01 --quiet "
                            "--threads 1 --out " + dir.string();
  auto r = cdtest::run_command(cdsim + " --max-steps 10");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"problem_20.cdp3", "problem_20.hdf5"}) {
    SCOPED_TRACE(f);
    fs::create_directories(dir / f / "x");
    r = cdtest::run_command(cdsim + " --dump-problem 20");
    EXPECT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find("cdsim: --dump-problem 20: could not write '" + (dir / f).string() + "'"), std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("diverged"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("error:"), std::string::npos) << r.out;
    fs::remove_all(dir / f);
  }
  r = cdtest::run_command(cdsim + " --dump-problem 20");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  for (const char* f : {"problem_20.cdp3", "problem_20.hdf5", "problem_20.impulses"})
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
}

// The laws FCLib cannot hold replay exactly through the .cdp3 text, and
// the FCLib file is not written for them (to_matrix refuses cohesion,
// write_fclib an orthotropic cone).
TEST(ProblemDump3, EveryLawReplaysExactly) {
  omp_set_num_threads(1);
  struct Variant {
    const char* name;
    void (*change)(cd::WorldParams3&);
  };
  const Variant variants[] = {
      {"coulomb", [](cd::WorldParams3&) {}},
      {"frictionless", [](cd::WorldParams3& p) { p.mu = p.mu_wall = 0.0; }},
      {"cohesive", [](cd::WorldParams3& p) {
         p.adhesion = 1e-3;
         p.debond = 5e-4;
       }},
      {"restitution", [](cd::WorldParams3& p) {
         p.e_n = 0.5;
         p.e_t = 0.2;
       }},
      {"orthotropic", [](cd::WorldParams3& p) {
         p.orthotropic = true;
         p.axis_a = cd::Vec3(1, 1, 0);
         p.mu_b = 0.2;
         p.mu_wall_b = 0.6;
       }},
      // Compliant contacts: the file's version 2, its compliance line; with
      // k_t != k version 3, a compliance_t line too.
      {"compliant", [](cd::WorldParams3& p) { p.stiffness = 1e4; }},
      {"compliant_kt", [](cd::WorldParams3& p) {
         p.stiffness = 1e4;
         p.stiffness_ratio = 0.5;
       }},
  };
  for (const Variant& v : variants) {
    cd::Pile3dParams q;
    q.n_spheres = 200;
    q.solver.tol = 1e-6;
    q.solver.max_iter = 300;
    cd::World3 w = cd::make_pile3d(q);
    cd::WorldParams3 prm = w.params();
    v.change(prm);
    w.set_params(prm);
    for (int k = 0; k < 79; ++k) w.step();
    std::string text;
    w.set_problem_hook([&](const cd::ContactProblem3& p, const cd::SolverParams& s) {
      std::ostringstream o;
      cd::write_contact_problem(p, s, o);
      text = o.str();
    });
    w.step();
    std::istringstream in(text);
    cd::SolverParams s;
    cd::ContactProblem3 p = cd::read_contact_problem3(in, v.name, s);
    const cd::SolveStats st = cd::nlgs_solve3(p, s);
    EXPECT_EQ(st.iterations, w.last().solve.iterations) << v.name;
    ASSERT_EQ(p.rows.size(), w.rows().size());
    ASSERT_GT(p.rows.size(), 100u) << v.name;
    int differ = 0;
    for (std::size_t k = 0; k < p.rows.size(); ++k)
      differ += std::memcmp(p.rows[k].r.data(), w.rows()[k].r.data(), 3 * sizeof(double)) != 0;
    EXPECT_EQ(differ, 0) << v.name;
    std::printf("[ dump3 ] %-12s law %-24s %zu rows, %d sweeps, replay bit-identical: %s\n", v.name,
                cd::law_name3(p.law).c_str(), p.rows.size(), st.iterations, differ ? "no" : "yes");
    // Braces: EXPECT_THROW is an if-else of its own (-Wdangling-else).
    const bool compliant = std::string(v.name).starts_with("compliant");
    if (std::string(v.name) == "cohesive" || compliant) {
      EXPECT_THROW(cd::to_matrix(p), std::invalid_argument);
    }
    EXPECT_EQ(p.compliance > 0, compliant) << v.name;
    const char* header = !compliant                               ? "cdlab-contact-problem3 1\n"
                         : std::string(v.name) == "compliant_kt" ? "cdlab-contact-problem3 3\n"
                                                                 : "cdlab-contact-problem3 2\n";
    EXPECT_EQ(text.rfind(header, 0), 0u) << v.name;
    if (std::string(v.name) == "compliant_kt") {
      EXPECT_EQ(p.tangential_compliance(), 2 * p.compliance);  // rho_t = rho / (k_t / k)
    }
    if (std::string(v.name) == "orthotropic") {
      EXPECT_THROW(cd::write_fclib(cd::to_matrix(p), "unused.hdf5", "", ""), std::invalid_argument);
    }
  }
}

// A malformed .cdp3 is refused with the file and line named.
TEST(ProblemDump3, MalformedFileNamesTheLine) {
  std::istringstream in("cdlab-contact-problem3 1\nlaw coulomb\ntol 0x1p-10\nmax_iter 0\n");
  cd::SolverParams s;
  try {
    cd::read_contact_problem3(in, "bad.cdp3", s);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.cdp3:4:"), std::string::npos) << e.what();
  }
  std::istringstream law("cdlab-contact-problem3 1\nlaw sticky\n");
  EXPECT_THROW(cd::read_contact_problem3(law, "law.cdp3", s), std::runtime_error);
  // Version 2 needs its compliance line, a finite number >= 0; version 3
  // its compliance_t line too, a finite number > 0; version 4 its inertia
  // tensors after the bodies; there is no version 5.
  for (const char* bad : {"cdlab-contact-problem3 2\nlaw coulomb\ntol 0x1p-10\n",
                          "cdlab-contact-problem3 2\nlaw coulomb\ncompliance -0x1p+0\n",
                          "cdlab-contact-problem3 2\nlaw coulomb\ncompliance inf\n",
                          "cdlab-contact-problem3 3\nlaw coulomb\n",
                          "cdlab-contact-problem3 3\nlaw coulomb\ncompliance 0x1p+0\ntol 0x1p-10\n",
                          "cdlab-contact-problem3 3\nlaw coulomb\ncompliance 0x1p+0\ncompliance_t 0x0p+0\n",
                          "cdlab-contact-problem3 5\nlaw coulomb\n"}) {
    std::istringstream v(bad);
    try {
      cd::read_contact_problem3(v, "v.cdp3", s);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_TRUE(m.find("v.cdp3:2:") != std::string::npos || m.find("v.cdp3:3:") != std::string::npos ||
                  m.find("v.cdp3:4:") != std::string::npos ||
                  m.find("v.cdp3:1:") != std::string::npos)
          << m;
    }
  }
}
