// accuracy_cost3: the 3D part of `make accuracy-cost`: what the
// polyhedral-cone LCP (lemke3.hpp, Lemke's method on the cone replaced by e
// face pairs) costs and how far it is from the exact round cone, against
// e and as contacts grow, next to the production NLGS (exact local solver,
// problem3.hpp). Measures only; nothing is asserted.
//
// Problems: pile3d (pile3d.hpp) of N = 2, 8, 27 spheres deposited and
// settled (0.4 s at coarse settings), then one step taken from rest (every
// velocity and warm start zeroed: the solver builds the whole force network,
// the hard part of a solve) under gravity tilted by 30 degrees about y,
// beyond the friction angle atan(0.4) = 21.8 degrees, so that friction is
// mobilised and contacts slide (upright, every contact of a pile at rest
// sticks with no tangential force, and every cone gives the same answer),
// frozen as a Problem3 u = W r + q: W = H M^-1 H^T
// from the rows' frames and lever arms, q from the free velocities (the
// step's final velocities minus M^-1 H^T r) and the gap terms. Check: the
// world's own impulses satisfy the assembled problem to the world's solver
// tolerance (printed as world_residual).
//
// Reference: NLGS to tol 1e-12 or 1e5 sweeps (its law residual is printed:
// at N = 27 NLGS stalls near 4e-6, 1e6 sweeps giving no better). For each problem:
//   nlgs     NLGS at the production tolerance 1e-4 (and 1e-6): time, sweeps
//   lemke/e  Lemke on the polyhedral cone, e = 2, 4, 8, 16 face pairs: time
//            (LCP assembly included), pivots, LCP size (LCPs above 1200
//            unknowns are skipped: dense Lemke takes minutes there)
// and for each, its error: the round-cone law residual (problem_residual:
// max over contacts / mean |r|), and |r - r_ref| / |r_ref|, which measures
// accuracy only where the solution is unique: a pile between walls is
// statically indeterminate, and two solutions of one problem, each with a
// law residual of 1e-6, were measured 10 % apart.
// Writes DIR/lemke3.csv and DIR/machine.csv.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "lemke3.hpp"
#include "machine.hpp"
#include "pile3d.hpp"
#include "problem3.hpp"

namespace {

// [c]x: the cross-product matrix, c x y = [c]x y.
cd::Mat3 cross(const cd::Vec3& c) {
  cd::Mat3 m;
  m << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  return m;
}

// The last step's contact problem of w (see the header), and the world's
// impulses in the problem's layout.
cd::Problem3 frozen(const cd::World3& w, Eigen::VectorXd& r_world) {
  const auto& rows = w.rows();
  const cd::Bodies3& b = w.bodies;
  const int nc = static_cast<int>(rows.size());
  std::vector<cd::BodyVel3> vfree(b.vel.begin(), b.vel.end());
  r_world.resize(3 * nc);
  for (int k = 0; k < nc; ++k) {
    const cd::SphereRow& r = rows[k];
    r_world.segment<3>(3 * k) = r.r;
    const cd::Vec3 P = r.to_world(r.r);
    cd::BodyVel3& A = vfree[r.b1];
    cd::BodyVel3& B = vfree[r.b2];
    B.v -= B.inv_m * P;
    B.w -= B.inv_I * r.c2.cross(P);
    A.v += A.inv_m * P;
    A.w += A.inv_I * r.c1.cross(P);
  }
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(3 * nc, 3 * nc);
  cd::Problem3 p;
  p.nc = nc;
  p.q.resize(3 * nc);
  p.mu.resize(nc);
  const auto frame = [](const cd::SphereRow& r) {
    cd::Mat3 F;
    F.row(0) = r.n.transpose();
    F.row(1) = r.t1.transpose();
    F.row(2) = r.t2.transpose();
    return F;
  };
  // The body-side term of row k for body `body`: sign and lever arm.
  const auto side = [](const cd::SphereRow& r, int body, double& s, cd::Vec3& c) {
    if (r.b2 == body) { s = 1; c = r.c2; return true; }
    if (r.b1 == body) { s = -1; c = r.c1; return true; }
    return false;
  };
  for (int k = 0; k < nc; ++k) {
    const cd::SphereRow& rk = rows[k];
    const cd::Mat3 Fk = frame(rk);
    p.q.segment<3>(3 * k) =
        Fk * cd::relative_velocity(rk, vfree[rk.b1], vfree[rk.b2]) + cd::Vec3(rk.bn, 0, 0);
    p.mu[k] = rk.mu;
    for (int l = 0; l < nc; ++l) {
      const cd::SphereRow& rl = rows[l];
      cd::Mat3 blk = cd::Mat3::Zero();
      for (int body : {rk.b1, rk.b2}) {
        double sk, sl;
        cd::Vec3 ck, cl;
        if (!side(rk, body, sk, ck) || !side(rl, body, sl, cl)) continue;
        const cd::BodyVel3& V = b.vel[body];
        if (V.inv_m == 0 && V.inv_I == 0) continue;
        blk += sk * sl * (V.inv_m * cd::Mat3::Identity() - V.inv_I * cross(ck) * cross(cl));
      }
      if (!blk.isZero(0)) W.block<3, 3>(3 * k, 3 * l) = Fk * blk * frame(rl).transpose();
    }
  }
  p.W = W.sparseView();
  return p;
}

double secs(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string load_start = cdbench::load_average();
  CLI::App app{"accuracy_cost3: polyhedral-cone Lemke against the exact NLGS on 3D pile problems"};
  std::string out = "outputs/accuracy-cost/3d";
  bool quick = false;
  app.add_option("--out", out, "output folder");
  app.add_flag("--quick", quick, "N = 2, 8 and e = 2, 4, 8 only (seconds)");
  CLI11_PARSE(app, argc, argv);
  std::vector<int> ns = quick ? std::vector<int>{2, 8} : std::vector<int>{2, 8, 27};
  std::vector<int> es = quick ? std::vector<int>{2, 4, 8} : std::vector<int>{2, 4, 8, 16};
  constexpr int kMaxLcp = 1200;  // dense Lemke: 1100 unknowns take ~6 s, 2000 minutes: skipped

  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/lemke3.csv");
  csv << "N,contacts,solver,e,lcp_size,time_s,iterations,rel_error,law_residual,world_residual\n";
  std::printf("%5s %8s %-10s %6s %10s %8s %10s %10s\n", "N", "contacts", "solver", "size", "time_s", "iters",
              "rel_err", "residual");
  for (int n : ns) {
    cd::Pile3dParams q;
    q.n_spheres = n;
    q.solver.tol = 1e-2;
    q.solver.max_iter = 200;
    cd::World3 w = cd::make_pile3d(q);
    for (int k = 0; k < 400; ++k) w.step();
    // One step from rest, no warm start, converged.
    for (auto& v : w.bodies.vel) v.v = v.w = cd::Vec3::Zero();
    w.set_warm_start({});
    cd::WorldParams3 p = w.params();
    const double tilt = 30.0 * 3.141592653589793 / 180.0;
    p.gravity = 9.81 * cd::Vec3(std::sin(tilt), 0.0, -std::cos(tilt));
    p.solver.tol = 1e-10;
    p.solver.max_iter = 20000;
    w.set_params(p);
    w.step();
    Eigen::VectorXd r_world;
    const cd::Problem3 P = frozen(w, r_world);
    const double world_res = cd::problem_residual(P, r_world).max;

    Eigen::VectorXd r_ref;
    cd::NlgsOptions ref;
    ref.tol = 1e-12;
    ref.max_sweeps = 100000;  // N = 27 stalls at a law residual ~4e-6 (1e6 sweeps: the same)
    const cd::NlgsStats rs = cd::solve_nlgs(P, r_ref, ref);
    std::printf("      reference: NLGS tol 1e-12, %d sweeps, law residual %.3g\n", rs.sweeps, rs.residual.max);
    const double ref_norm = r_ref.norm();
    const auto row = [&](const std::string& solver, int e, int size, double t, int it, const Eigen::VectorXd& r) {
      const double err = (r - r_ref).norm() / ref_norm, res = cd::problem_residual(P, r).max;
      csv << fmt::format("{},{},{},{},{},{:.4g},{},{:.4g},{:.4g},{:.3g}\n", n, P.nc, solver, e, size, t, it, err,
                         res, world_res);
      std::printf("%5d %8d %-10s %6d %10.3g %8d %10.3g %10.3g\n", n, P.nc,
                  (solver + (e ? "/" + std::to_string(e) : "")).c_str(), size, t, it, err, res);
      std::fflush(stdout);
    };
    for (double tol : {1e-4, 1e-6}) {
      Eigen::VectorXd r;
      cd::NlgsOptions o;
      o.tol = tol;
      o.max_sweeps = 100000;
      const auto t0 = std::chrono::steady_clock::now();
      const cd::NlgsStats st = cd::solve_nlgs(P, r, o);
      row(fmt::format("nlgs{:.0e}", tol), 0, 3 * P.nc, secs(t0), st.sweeps, r);
    }
    for (int e : es) {
      const int size = P.nc * (2 * e + 2);
      if (size > kMaxLcp) continue;
      const cd::Lemke3Result L = cd::solve_lemke(P, e);
      if (L.status != cd::LemkeStatus::Solved) {
        std::printf("%5d %8d lemke/%d: not solved (%s after %d pivots)\n", n, P.nc, e, cd::to_string(L.status),
                    L.pivots);
        csv << fmt::format("{},{},lemke_{},{},{},{:.4g},{},nan,nan,{:.3g}\n", n, P.nc, cd::to_string(L.status), e,
                           P.nc * (2 * e + 2), L.time, L.pivots, world_res);
        continue;
      }
      row("lemke", e, size, L.time, L.pivots, L.r);
    }
    std::printf("      world's impulses on the assembled problem: law residual %.3g (world: tol 1e-10, cap 2e4 sweeps)\n",
                world_res);
  }
  cdbench::write_machine_csv(out + "/machine.csv", cdbench::machine(load_start));
  std::printf("accuracy_cost3: wrote %s/{lemke3,machine}.csv\n", out.c_str());
  return 0;
}
