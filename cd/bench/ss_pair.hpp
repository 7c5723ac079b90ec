// Side-side (ss) contacts solved as one block: the experiment of "forcing
// equal sliding at both points of an ss contact", kept in the benchmarks
// rather than the solver because the measurement (ss_pair.cpp, "Result")
// found that it cuts no sweeps and makes every solve slower.
//
// An ss contact is two rows (points 1 and 2) on the same bodies with the same
// frame (n, t). Per-row NLGS solves each point with the other frozen. Here the
// pair is one local problem with three unknowns
//     x = (p_n1, p_n2, P_t),
// P_t the pair's tangential impulse, applied at the two points with fixed
// weights (alpha_1, alpha_2), alpha_1 + alpha_2 = 1:  p_ti = alpha_i P_t.
// Its conjugate velocity is u_t = alpha_1 u_t1 + alpha_2 u_t2: one sliding
// velocity for the pair ("equal sliding"). The law of the pair, with
// adhesion impulses a_i (0: plain Signorini-Coulomb) and z_i = p_ni + a_i:
//     0 <= z_i  _|_  u_ni >= 0                       (i = 1, 2)
//     |P_t| <= mu (z_1 + z_2),  P_t = -mu (z_1 + z_2) sign(u_t) if u_t != 0.
// With u = b + W x (W the 3x3 reduced Delassus block, see reduce_pair) the
// local problem is solved exactly by enumerating the cases
//     open (both normals open: x = (-a_1, -a_2, 0)),
//     closed set C in {1}, {2}, {1, 2} x {stick, slide+, slide-},
// each a linear system of at most 3 unknowns, and returning the first whose
// (x, u) satisfies the law; a natural-map residual (pair_residual) picks the
// best candidate if round-off rejects every case (counted as a fallback).
//
// Choice of alpha: proportional to the normal impulses of the previous
// iterate (1/2 each when both are zero). After the solve the stored per-row
// tangential impulses are split in proportion to the new normal impulses,
// p_ti = P_t z_i / (z_1 + z_2), so every row satisfies its own Coulomb cone
// at every iterate, and at a fixed point alpha is the stored split. Rejected:
// alpha = 1/2 always (a pair with one point open would keep half of P_t on
// the open point, violating that row's law), and solving the 4x4 per-row
// problem exactly (its tangential rows are nearly equal on a common side,
// so the stick system is nearly singular).
//
// What the pair law gives up: the rows' own tangential velocities differ
// from the common u_t by the lever-arm differences of the two points along n
// (under 1 % of the side: detection types a pair ss only when the two points'
// separations differ by <= 2 % of the side) times the bodies' angular
// velocities, so the per-row law residual of a converged pair is small but
// not zero.
#pragma once
#include <algorithm>
#include <cmath>

#include "bodies.hpp"
#include "contact.hpp"
#include "coupling.hpp"

namespace cdbench {

// Off-diagonal Delassus entries between the two rows of a pair (same bodies,
// same frame); the diagonal blocks are the rows' own wnn, wnt, wtt. From
// contact.hpp's velocities, W_ab = J_a M^-1 J_b^T with
//   J_n = (-n, c1t, n, -c2t),  J_t = (-t, -c1n, t, c2n)  on (U1, w1, U2, w2).
struct PairCross {
  double n1n2, n1t2, t1n2, t1t2;
};

inline PairCross pair_cross(const cd::ContactRow& r1, const cd::ContactRow& r2,
                            const cd::BodyVel& A, const cd::BodyVel& B, bool rotation) {
  const double iI1 = rotation ? A.inv_I : 0.0, iI2 = rotation ? B.inv_I : 0.0;
  const double im = A.inv_m + B.inv_m;
  return {im + r1.c1t * r2.c1t * iI1 + r1.c2t * r2.c2t * iI2,
          -(r1.c1t * r2.c1n * iI1 + r1.c2t * r2.c2n * iI2),
          -(r1.c1n * r2.c1t * iI1 + r1.c2n * r2.c2t * iI2),
          im + r1.c1n * r2.c1n * iI1 + r1.c2n * r2.c2n * iI2};
}

// Reduced 3x3 block, order (n1, n2, t), for the tangential weights alpha.
struct PairBlock {
  double w[3][3];
};

inline PairBlock reduce_pair(const cd::ContactRow& r1, const cd::ContactRow& r2,
                             const PairCross& X, double al1, double al2) {
  PairBlock P;
  P.w[0][0] = r1.wnn;
  P.w[1][1] = r2.wnn;
  P.w[0][1] = P.w[1][0] = X.n1n2;
  P.w[0][2] = P.w[2][0] = al1 * r1.wnt + al2 * X.n1t2;
  P.w[1][2] = P.w[2][1] = al1 * X.t1n2 + al2 * r2.wnt;
  P.w[2][2] = al1 * al1 * r1.wtt + 2 * al1 * al2 * X.t1t2 + al2 * al2 * r2.wtt;
  return P;
}

// Cases: mask of closed normals (bit 0: point 1, bit 1: point 2; 0 = open)
// and tangential mode (0 stick, 1 slide with P_t > 0, 2 slide with P_t < 0;
// unused when mask = 0).
struct PairCase {
  int mask = 0, tang = 0;
  bool fallback = false;
};

// Natural-map residual of the pair law at (x, u), in impulse units:
//   r_ni = z_i - max(0, z_i - rho u_ni),
//   r_t  = P_t - clamp(P_t - rho u_t, -mu (z_1+ + z_2+), mu (z_1+ + z_2+)).
inline double pair_residual(const double x[3], const double u[3], double mu, double a1, double a2,
                            double rho) {
  const double z1 = x[0] + a1, z2 = x[1] + a2;
  const double r1 = z1 - std::max(0.0, z1 - rho * u[0]);
  const double r2 = z2 - std::max(0.0, z2 - rho * u[1]);
  const double lim = mu * (std::max(z1, 0.0) + std::max(z2, 0.0));
  const double rt = x[2] - std::clamp(x[2] - rho * u[2], -lim, lim);
  return std::sqrt(r1 * r1 + r2 * r2 + rt * rt);
}

namespace detail {

// Solves A y = r (k <= 3) by Gaussian elimination with partial pivoting;
// false if a pivot vanishes relative to the matrix scale.
inline bool small_solve(int k, double A[3][3], double r[3], double y[3]) {
  double scale = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) scale = std::max(scale, std::abs(A[i][j]));
  if (scale == 0.0) return false;
  for (int c = 0; c < k; ++c) {
    int p = c;
    for (int i = c + 1; i < k; ++i)
      if (std::abs(A[i][c]) > std::abs(A[p][c])) p = i;
    if (std::abs(A[p][c]) <= 1e-13 * scale) return false;
    if (p != c) {
      for (int j = 0; j < k; ++j) std::swap(A[p][j], A[c][j]);
      std::swap(r[p], r[c]);
    }
    for (int i = c + 1; i < k; ++i) {
      const double f = A[i][c] / A[c][c];
      for (int j = c; j < k; ++j) A[i][j] -= f * A[c][j];
      r[i] -= f * r[c];
    }
  }
  for (int i = k - 1; i >= 0; --i) {
    double s = r[i];
    for (int j = i + 1; j < k; ++j) s -= A[i][j] * y[j];
    y[i] = s / A[i][i];
  }
  return true;
}

// One case: x = x0 + T y with y the free unknowns (closed normals, and P_t
// when sticking), and one equation (zero velocity) per free unknown.
// Returns false if the system is singular; x and u are then unset.
inline bool pair_case(const PairBlock& P, const double b[3], double mu, double a1, double a2,
                      int mask, int tang, double x[3], double u[3]) {
  const double a[2] = {a1, a2};
  double x0[3] = {-a1, -a2, 0.0};
  double T[3][3] = {};
  int eq[3];
  int k = 0;
  const double s = tang == 1 ? 1.0 : -1.0;
  for (int i = 0; i < 2; ++i)
    if (mask & (1 << i)) {
      x0[i] = 0.0;
      T[i][k] = 1.0;
      eq[k] = i;
      if (tang != 0) {  // slide: P_t = s mu sum over closed (p_ni + a_i)
        T[2][k] = s * mu;
        x0[2] += s * mu * a[i];
      }
      ++k;
    }
  if (mask != 0 && tang == 0) {
    T[2][k] = 1.0;
    eq[k] = 2;
    ++k;
  }
  double y[3] = {0, 0, 0};
  if (k > 0) {
    double A[3][3], r[3];
    for (int e = 0; e < k; ++e) {
      const double* W = P.w[eq[e]];
      r[e] = -(b[eq[e]] + W[0] * x0[0] + W[1] * x0[1] + W[2] * x0[2]);
      for (int c = 0; c < k; ++c) A[e][c] = W[0] * T[0][c] + W[1] * T[1][c] + W[2] * T[2][c];
    }
    if (!small_solve(k, A, r, y)) return false;
  }
  for (int i = 0; i < 3; ++i) x[i] = x0[i] + T[i][0] * y[0] + T[i][1] * y[1] + T[i][2] * y[2];
  for (int i = 0; i < 3; ++i) u[i] = b[i] + P.w[i][0] * x[0] + P.w[i][1] * x[1] + P.w[i][2] * x[2];
  return true;
}

// Does (x, u) of case (mask, tang) satisfy the pair law? Sign tests as in
// cd::solve_coulomb: exact, no tolerance.
inline bool pair_valid(const double x[3], const double u[3], double mu, double a1, double a2,
                       int mask, int tang) {
  const double z[2] = {x[0] + a1, x[1] + a2};
  double S = 0;
  for (int i = 0; i < 2; ++i) {
    if (mask & (1 << i)) {
      if (z[i] < 0.0) return false;
      S += z[i];
    } else if (u[i] < 0.0) {
      return false;
    }
  }
  if (mask == 0) return true;
  if (tang == 0) return std::abs(x[2]) <= mu * S;
  const double s = tang == 1 ? 1.0 : -1.0;
  return s * u[2] <= 0.0;
}

}  // namespace detail

// Exact solve of the pair's local problem u = b + W x (see the top of the
// file). Case order: open first (cheapest, frequent in the alert band), then
// both points closed (the common case in a dense packing), then one point
// closed; sliding in the direction the stick solution pushes first, as in
// cd::solve_coulomb.
inline PairCase solve_pair(const PairBlock& P, const double b[3], double mu, double a1, double a2,
                           double x[3], double u[3]) {
  // Open.
  x[0] = -a1;
  x[1] = -a2;
  x[2] = 0.0;
  for (int i = 0; i < 3; ++i) u[i] = b[i] + P.w[i][0] * x[0] + P.w[i][1] * x[1];
  if (u[0] >= 0.0 && u[1] >= 0.0) return {0, 0, false};
  // Both closed, stick: W x = -b, by the adjugate of the symmetric W (the
  // common case gets a closed form; pair_case does the same by elimination).
  const auto& w = P.w;
  const double c00 = w[1][1] * w[2][2] - w[1][2] * w[1][2];
  const double c01 = w[0][2] * w[1][2] - w[0][1] * w[2][2];
  const double c02 = w[0][1] * w[1][2] - w[0][2] * w[1][1];
  const double c11 = w[0][0] * w[2][2] - w[0][2] * w[0][2];
  const double c12 = w[0][1] * w[0][2] - w[0][0] * w[1][2];
  const double c22 = w[0][0] * w[1][1] - w[0][1] * w[0][1];
  const double det = w[0][0] * c00 + w[0][1] * c01 + w[0][2] * c02;
  int s0 = 1;  // slide direction tried first: the sign of the stick P_t
  const bool closed_form = det > 1e-13 * w[0][0] * w[1][1] * w[2][2];
  if (closed_form) {
    const double id = -1.0 / det;
    x[0] = id * (c00 * b[0] + c01 * b[1] + c02 * b[2]);
    x[1] = id * (c01 * b[0] + c11 * b[1] + c12 * b[2]);
    x[2] = id * (c02 * b[0] + c12 * b[1] + c22 * b[2]);
    const double S = x[0] + a1 + x[1] + a2;
    if (x[0] + a1 >= 0.0 && x[1] + a2 >= 0.0 && std::abs(x[2]) <= mu * S) {
      for (int i = 0; i < 3; ++i) u[i] = b[i] + w[i][0] * x[0] + w[i][1] * x[1] + w[i][2] * x[2];
      return {3, 0, false};
    }
    s0 = x[2] >= 0.0 ? 1 : 2;
  }
  static constexpr int kMasks[3] = {3, 1, 2};
  for (int m : kMasks) {
    if ((m != 3 || !closed_form) && detail::pair_case(P, b, mu, a1, a2, m, 0, x, u)) {
      if (detail::pair_valid(x, u, mu, a1, a2, m, 0)) return {m, 0, false};
      s0 = x[2] >= 0.0 ? 1 : 2;
    }
    for (int t : {s0, 3 - s0})
      if (detail::pair_case(P, b, mu, a1, a2, m, t, x, u) &&
          detail::pair_valid(x, u, mu, a1, a2, m, t))
        return {m, t, false};
  }
  // Round-off rejected every case (or an ill-posed block): the candidate of
  // least natural-map residual.
  const double rho = 1.0 / std::max(P.w[0][0], P.w[1][1]);
  double best = INFINITY, bx[3] = {-a1, -a2, 0.0};
  PairCase bc{0, 0, true};
  for (int m = 0; m < 4; ++m)
    for (int t = 0; t < (m ? 3 : 1); ++t) {
      double cx[3], cu[3];
      if (!detail::pair_case(P, b, mu, a1, a2, m, t, cx, cu)) continue;
      const double e = pair_residual(cx, cu, mu, a1, a2, rho);
      if (e < best) {
        best = e;
        std::copy(cx, cx + 3, bx);
        bc = {m, t, true};
      }
    }
  std::copy(bx, bx + 3, x);
  for (int i = 0; i < 3; ++i) u[i] = b[i] + P.w[i][0] * x[0] + P.w[i][1] * x[1] + P.w[i][2] * x[2];
  return bc;
}

// One NLGS update of an ss pair (rows r1, r2 on bodies b1, b2, same frame),
// with rotation, Coulomb friction and the rows' adhesion impulses: the pair's
// free velocities from the current body velocities, alpha from the current
// normal impulses, the exact pair solve, the per-row split of P_t, and the
// velocity increments of both rows added to the bodies (driven bodies have
// inv_m = inv_I = 0 and are left unchanged). dp2 = sum over both rows of
// |dp|^2, pabs = sum of |p|: what the per-row sweep accumulates for two rows.
// alpha_passes > 1: re-solve with alpha from the new normal impulses until
// alpha stops changing (at most alpha_passes solves), so that the split the
// solve assumed is the split stored (an ablation: see ss_pair.cpp).
inline PairCase update_pair(cd::ContactRow& r1, cd::ContactRow& r2, const PairCross& X,
                            cd::BodyVel* vel, double& dp2, double& pabs, int alpha_passes = 1) {
  cd::BodyVel& A = vel[r1.b1];
  cd::BodyVel& B = vel[r1.b2];
  const double nx = r1.nx, ny = r1.ny;
  // The rows' velocities, offsets included, as the production sweep has them.
  const cd::sweep::BodyCoupling<true> coupling{vel};
  double un1, ut1, un2, ut2;
  coupling.velocity(r1, un1, ut1);
  coupling.velocity(r2, un2, ut2);
  // Velocities with the pair's own impulses removed (full 4x4 block).
  const double pn1 = r1.pn, pt1 = r1.pt, pn2 = r2.pn, pt2 = r2.pt;
  const double bn1 = un1 - (r1.wnn * pn1 + r1.wnt * pt1 + X.n1n2 * pn2 + X.n1t2 * pt2);
  const double bt1 = ut1 - (r1.wnt * pn1 + r1.wtt * pt1 + X.t1n2 * pn2 + X.t1t2 * pt2);
  const double bn2 = un2 - (X.n1n2 * pn1 + X.t1n2 * pt1 + r2.wnn * pn2 + r2.wnt * pt2);
  const double bt2 = ut2 - (X.n1t2 * pn1 + X.t1t2 * pt1 + r2.wnt * pn2 + r2.wtt * pt2);
  const double a1 = r1.adh, a2 = r2.adh;
  const double z1o = std::max(pn1 + a1, 0.0), z2o = std::max(pn2 + a2, 0.0);
  const double So = z1o + z2o;
  double al1 = So > 0.0 ? z1o / So : 0.5;
  double x[3], u[3], z1, z2, S;
  PairCase c;
  for (int pass = 0;; ++pass) {
    const PairBlock P = reduce_pair(r1, r2, X, al1, 1.0 - al1);
    const double b[3] = {bn1, bn2, al1 * bt1 + (1.0 - al1) * bt2};
    c = solve_pair(P, b, r1.mu, a1, a2, x, u);
    z1 = std::max(x[0] + a1, 0.0);
    z2 = std::max(x[1] + a2, 0.0);
    S = z1 + z2;
    if (pass + 1 >= alpha_passes || S <= 0.0 || std::abs(z1 / S - al1) <= 1e-12) break;
    al1 = z1 / S;
  }
  const double qt1 = S > 0.0 ? x[2] * (z1 / S) : 0.0, qt2 = S > 0.0 ? x[2] - qt1 : 0.0;
  const double dn1 = x[0] - pn1, dt1 = qt1 - pt1, dn2 = x[1] - pn2, dt2 = qt2 - pt2;
  r1.pn = x[0];
  r1.pt = qt1;
  r2.pn = x[1];
  r2.pt = qt2;
  dp2 = dn1 * dn1 + dt1 * dt1 + dn2 * dn2 + dt2 * dt2;
  pabs = std::sqrt(x[0] * x[0] + qt1 * qt1) + std::sqrt(x[1] * x[1] + qt2 * qt2);
  const double dn = dn1 + dn2, dt = dt1 + dt2;
  const double px = nx * dn - ny * dt, py = ny * dn + nx * dt;
  B.vx += B.inv_m * px;
  B.vy += B.inv_m * py;
  B.w += B.inv_I * (r1.c2n * dt1 - r1.c2t * dn1 + r2.c2n * dt2 - r2.c2t * dn2);
  A.vx -= A.inv_m * px;
  A.vy -= A.inv_m * py;
  A.w -= A.inv_I * (r1.c1n * dt1 - r1.c1t * dn1 + r2.c1n * dt2 - r2.c1t * dn2);
  return c;
}

}  // namespace cdbench
