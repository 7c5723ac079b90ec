// A general 3x3 local solver: Alart-Curnier's semismooth Newton for one
// contact with a full symmetric positive definite Delassus block W (the
// blocks of non-spherical bodies, whose lever arms are not along n), a round
// or orthotropic cone and adhesion, with a projection fallback. law3.hpp's
// solve_local3 enumerates the same law exactly; this solver is the
// iterative alternative that extends to laws without a closed enumeration,
// and the reference the two are checked against each other with
// (tests/test_alart_curnier3.cpp).
//
// Variables: as in law3.hpp, s = r + a e_n, and with T = diag(1, mu_a, mu_b)
// p = T^-1 s, v = T u = W~ p + b~, W~ = T W T, b~ = T (q - a W e_n): the unit
// round cone |p_t| <= p_n. (An axis with mu = 0 keeps T = 1 and the
// equation p_i = 0.) Alart and Curnier's function (1991), rho > 0:
//     Phi_n = p_n - max(0, p_n - rho_n v_n)
//     Phi_t = p_t - P_B(R)(p_t - rho_t v_t),   R = max(0, p_n - rho_n v_n)
// (B(R) the disk of radius R) vanishes exactly at the law's solutions. It
// is piecewise smooth; Newton takes one element of its generalised
// Jacobian (the branch of each max and projection at the current point) and
// a backtracking line search on |Phi|^2. When the line search fails (a kink
// between branches, or a singular element), a burst of De Saxce's
// projected fixed point p <- P_K(p - rho (v + |v_t| e_n)), which is the
// law's natural map, moves the point and Newton resumes.
#pragma once
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "law3.hpp"

namespace cd {

struct NewtonStats3 {
  int iterations = 0;     // Newton steps
  int projections = 0;    // fixed-point steps of the fallback
  double residual = 0.0;  // |Phi| at exit, in units of the scaled impulse p
  bool converged = false;
};

namespace ac3_detail {

// Phi at p, and (J != nullptr) one element of its generalised Jacobian.
inline Vec3 phi(const Mat3& W, const Vec3& b, const bool fr[3], double rn, double rho, const Vec3& p,
                Mat3* J) {
  const Vec3 v = W * p + b;
  const double xn = p[0] - rn * v[0];
  const double R = std::max(0.0, xn);
  Vec3 F;
  F[0] = p[0] - R;
  if (J) {
    J->setZero();
    if (xn > 0.0) J->row(0) = rn * W.row(0);
    else (*J)(0, 0) = 1.0;
  }
  double x2 = 0.0;
  for (int i = 1; i < 3; ++i)
    if (fr[i]) x2 += (p[i] - rho * v[i]) * (p[i] - rho * v[i]);
  const double nx = std::sqrt(x2);
  for (int i = 1; i < 3; ++i) {
    if (!fr[i]) {
      F[i] = p[i];
      if (J) (*J)(i, i) = 1.0;
      continue;
    }
    const double xi = p[i] - rho * v[i];
    if (nx <= R) {  // inside the disk: Phi_t = rho v_t
      F[i] = rho * v[i];
      if (J) J->row(i) = rho * W.row(i);
    } else {  // on its rim: Phi_t = p_t - R x_t / |x_t|
      F[i] = p[i] - R * xi / nx;
      if (J) {
        // d(x_j) = dp_j - rho (W dp)_j; dR = d(x_n) when x_n > 0.
        Eigen::RowVector3d row = Eigen::RowVector3d::Zero();
        row[i] = 1.0;
        for (int j = 1; j < 3; ++j) {
          if (!fr[j]) continue;
          const double xj = p[j] - rho * v[j];
          const double dij = (i == j ? 1.0 : 0.0) - xi * xj / (nx * nx);
          Eigen::RowVector3d dx = -rho * W.row(j);
          dx[j] += 1.0;
          row -= (R / nx) * dij * dx;
        }
        if (xn > 0.0) {
          Eigen::RowVector3d dR = -rn * W.row(0);
          dR[0] += 1.0;
          row -= (xi / nx) * dR;
        }
        J->row(i) = row;
      }
    }
  }
  return F;
}

// Projection onto the unit cone restricted to the frictional axes.
inline Vec3 project(const Vec3& x, const bool fr[3]) {
  Vec3 y = x;
  for (int i = 1; i < 3; ++i)
    if (!fr[i]) y[i] = 0.0;
  return law3_detail::project_cone(y, 1.0);
}

}  // namespace ac3_detail

// One Newton run at a given rho from the best start; returns the stats and
// the final p.
inline NewtonStats3 newton_run(const Mat3& Wt, const Vec3& bt, const bool fr[3], double rn, double rho,
                               const Vec3* starts, int nstarts, double tol, int max_iter, Vec3& p) {
  using namespace ac3_detail;
  NewtonStats3 st;
  const double scale = std::max(rn, rho) * bt.norm();
  const double rfp = 1.0 / Wt.trace();  // the fixed point's step
  Mat3 J;
  p = starts[0];
  Vec3 F = phi(Wt, bt, fr, rn, rho, p, &J);
  double f2 = F.squaredNorm();
  for (int k = 1; k < nstarts && f2 > 0.0; ++k) {
    Mat3 J0;
    const Vec3 F0 = phi(Wt, bt, fr, rn, rho, starts[k], &J0);
    if (F0.squaredNorm() < f2) {
      p = starts[k];
      F = F0;
      J = J0;
      f2 = F0.squaredNorm();
    }
  }
  auto met = [&] { return std::sqrt(f2) <= tol * (scale + p.norm()); };
  while (st.iterations < max_iter && !(st.converged = met())) {
    ++st.iterations;
    Eigen::FullPivLU<Mat3> lu(J);
    bool moved = false;
    if (lu.isInvertible()) {
      const Vec3 d = lu.solve(-F);
      double alpha = 1.0;
      for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
        const Vec3 pn = p + alpha * d;
        Mat3 Jn;
        const Vec3 Fn = phi(Wt, bt, fr, rn, rho, pn, &Jn);
        const double fn2 = Fn.squaredNorm();
        if (fn2 <= (1.0 - 1e-4 * alpha) * f2 || fn2 == 0.0) {
          p = pn;
          F = Fn;
          J = Jn;
          f2 = fn2;
          moved = true;
          break;
        }
      }
    }
    if (!moved) {
      // Fallback: the projected fixed point (De Saxce's natural map).
      for (int k = 0; k < 50; ++k, ++st.projections) {
        const Vec3 v = Wt * p + bt;
        double vt = 0.0;
        for (int i = 1; i < 3; ++i)
          if (fr[i]) vt += v[i] * v[i];
        p = project(p - rfp * Vec3(v[0] + std::sqrt(vt), v[1], v[2]), fr);
      }
      F = phi(Wt, bt, fr, rn, rho, p, &J);
      f2 = F.squaredNorm();
    }
  }
  // Polish: Newton converges quadratically, so a full step or two past the
  // test reach round-off (the test is relative to |p|, and p_t = s_t / mu
  // is large for a small mu); kept only while |Phi| decreases.
  for (int k = 0; st.converged && k < 2 && f2 > 0.0; ++k) {
    Eigen::FullPivLU<Mat3> lu(J);
    if (!lu.isInvertible()) break;
    const Vec3 pn = p + lu.solve(-F);
    Mat3 Jn;
    const Vec3 Fn = phi(Wt, bt, fr, rn, rho, pn, &Jn);
    if (!(Fn.squaredNorm() < f2)) break;
    p = pn;
    F = Fn;
    J = Jn;
    f2 = Fn.squaredNorm();
  }
  st.residual = std::sqrt(f2) / (scale + p.norm() > 0 ? scale + p.norm() : 1.0);
  return st;
}

// Solves u = W r + q with the law of cone c and adhesion a >= 0 (law3.hpp).
// r on entry is ignored unless warm = true (then it is a candidate start);
// tol bounds |Phi| relative to |p|, |rho b~| (round-off is ~1e-16).
inline NewtonStats3 solve_alart_curnier3(const Mat3& W, const Vec3& q, const Cone3& c, double a, Vec3& r,
                                         bool warm = false, double tol = 1e-14, int max_iter = 60) {
  using namespace ac3_detail;
  const bool fr[3] = {true, c.mu_a > 0.0, c.mu_b > 0.0};
  const Vec3 T(1.0, fr[1] ? c.mu_a : 1.0, fr[2] ? c.mu_b : 1.0);
  const Mat3 Wt = T.asDiagonal() * W * T.asDiagonal();
  const Vec3 bt = T.cwiseProduct(q - a * W.col(0));
  // Starts (the one of least |Phi| is taken): zero (the open solution when
  // b~_n >= 0, where Phi(0) = 0 exactly), the stick trial on the axes that
  // carry impulse (u = 0 there, p = 0 on a frictionless tangential axis)
  // projected on the cone, a sliding guess (the frictionless p_n on the
  // rim, opposite to the slip it leaves), and the caller's r (warm).
  Vec3 starts[4];
  int ns = 0;
  starts[ns++] = Vec3::Zero();
  {
    Mat3 Ws = Wt;
    Vec3 bs = bt;
    for (int i = 1; i < 3; ++i)
      if (!fr[i]) {
        Ws.row(i).setZero();
        Ws.col(i).setZero();
        Ws(i, i) = 1.0;
        bs[i] = 0.0;
      }
    starts[ns++] = project(-Ws.ldlt().solve(bs), fr);
  }
  if (bt[0] < 0.0) {  // sliding start: the frictionless normal impulse, slip opposite to u_t there
    const double pn = -bt[0] / Wt(0, 0);
    const Vec3 v = Wt * Vec3(pn, 0.0, 0.0) + bt;
    const double vt = std::hypot(fr[1] ? v[1] : 0.0, fr[2] ? v[2] : 0.0);
    starts[ns++] = vt > 0.0 ? Vec3(pn, fr[1] ? -pn * v[1] / vt : 0.0, fr[2] ? -pn * v[2] / vt : 0.0)
                            : Vec3(pn, 0.0, 0.0);
  }
  if (warm) starts[ns++] = Vec3(r[0] + a, r[1] / T[1], r[2] / T[2]);
  // Newton can stall where |Phi|^2 is stationary without being zero (near
  // the cone's apex, typically); Phi changes with rho, and so do those
  // points. The runs go through (rho_n, rho_t) = (1/W~_nn, 1/mean W~_tt)
  // (each equation scaled by its own block: a small mu makes W~_tt small),
  // then 1/tr W~ for both, then 10/tr W~, keeping the first that converges.
  // Measured on 200000 random blocks (tests/test_alart_curnier3.cpp's
  // distribution): 22 stalled with the best start alone at all three rho;
  // with every start in turn, none of 1.2 million.
  double wt = 0.0;
  int nt = 0;
  for (int i = 1; i < 3; ++i)
    if (fr[i]) wt += Wt(i, i), ++nt;
  const double tr = 1.0 / Wt.trace();
  const double rhos[3][2] = {{1.0 / Wt(0, 0), nt ? nt / wt : 1.0 / Wt(0, 0)}, {tr, tr}, {10 * tr, 10 * tr}};
  NewtonStats3 st, best;
  Vec3 p, pbest = Vec3::Zero();
  int total_it = 0, total_proj = 0;
  best.residual = std::numeric_limits<double>::infinity();
  // First from the start of least |Phi|; if that stalls, from each start
  // in turn.
  for (int k = -1; k < ns && !best.converged; ++k)
    for (const auto& rho : rhos) {
      st = k < 0 ? newton_run(Wt, bt, fr, rho[0], rho[1], starts, ns, tol, max_iter, p)
                 : newton_run(Wt, bt, fr, rho[0], rho[1], starts + k, 1, tol, max_iter, p);
      total_it += st.iterations;
      total_proj += st.projections;
      if (st.converged || st.residual < best.residual) {
        best = st;
        pbest = p;
      }
      if (st.converged) break;
    }
  best.iterations = total_it;
  best.projections = total_proj;
  r = T.cwiseProduct(pbest);
  for (int i = 1; i < 3; ++i)
    if (!fr[i]) r[i] = 0.0;
  r[0] -= a;
  return best;
}

}  // namespace cd
