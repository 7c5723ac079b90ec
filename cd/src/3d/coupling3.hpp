// The 3D sphere rows for the sweep (core/sweep.hpp): rows coupled through
// the velocities of their bodies (BodyCoupling3, the sibling of 2D's
// BodyCoupling) under a law from named parts (law_parts3.hpp), and what the
// sweep asks of a row (its law residual, its impulse norm; the boundary dof
// is contact_problem3.hpp's CellDof3).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "contact3.hpp"
#include "law3.hpp"
#include "law_parts3.hpp"
#include "subspace3.hpp"
#include "sweep.hpp"

namespace cd {

// A lever arm the sweep may take as l n (contact3.hpp's SweepRow3): along n
// to round-off, or of a body that neither turns nor is turned (a plane).
// Round-off in c = p - x_j grows with |x_j| / |c|; 1e-6 leaves room for
// positions 1e9 radii from the origin and still refuses a lever arm that is
// not a sphere's.
inline bool lever_along_n(const Vec3& c, double l, const Vec3& n, const BodyVel3& b) {
  if (b.inv_I == 0.0 && b.w == Vec3::Zero()) return true;
  return (c - l * n).norm() <= 1e-6 * c.norm();
}

// The sweep's row (contact3.hpp's SweepRow3) of a problem row, or false when
// the row is not a sphere's: a lever arm off the normal, a frame that is not
// orthonormal and right-handed.
inline bool make_sweep_row3(const SphereRow& r, const BodyVel3* vel, SweepRow3& s) {
  s.n = r.n;
  s.t1 = r.t1;
  s.t2 = r.t2;
  s.l1 = r.c1.dot(r.n);
  s.l2 = r.c2.dot(r.n);
  s.iwnn = 1.0 / r.wnn;
  s.iwtt = 1.0 / r.wtt;
  s.bn = r.bn;
  s.mu = r.mu;
  s.b1 = r.b1;
  s.b2 = r.b2;
  s.r = r.r;
  s.adh = r.adh;
  const bool frame = std::abs(r.n.squaredNorm() - 1.0) <= 1e-6 && std::abs(r.t1.squaredNorm() - 1.0) <= 1e-6 &&
                     std::abs(r.n.dot(r.t1)) <= 1e-6 && (r.n.cross(r.t1) - r.t2).norm() <= 1e-6;
  return frame && lever_along_n(r.c1, s.l1, r.n, vel[r.b1]) && lever_along_n(r.c2, s.l2, r.n, vel[r.b2]);
}

inline double impulse_norm(const SweepRow3& r) { return r.r.norm(); }

// The velocity change of a row's bodies under an impulse dr (frame
// components) on body 2 and -dr on body 1 (contact3.hpp's SweepRow3: P and
// T = n x P); body 1 only when Write1 (false: driven, never written).
template <bool Write1 = true>
inline void push_impulse(const SweepRow3& r, const Vec3& dr, BodyVel3* vel) {
  const Vec3 P = dr[0] * r.n + dr[1] * r.t1 + dr[2] * r.t2;
  const Vec3 T = dr[1] * r.t2 - dr[2] * r.t1;
  BodyVel3& B = vel[r.b2];
  B.v += B.inv_m * P;
  B.w += (B.inv_I * r.l2) * T;
  if constexpr (Write1) {
    BodyVel3& A = vel[r.b1];
    A.v -= A.inv_m * P;
    A.w -= (A.inv_I * r.l1) * T;
  }
}

// The velocity change of a row's bodies under an impulse dr (frame
// components) on body 2 and -dr on body 1, any lever arms (the warm start).
inline void push_impulse(const SphereRow& r, const Vec3& dr, BodyVel3* vel) {
  const Vec3 P = r.to_world(dr);
  BodyVel3& A = vel[r.b1];
  BodyVel3& B = vel[r.b2];
  B.v += B.inv_m * P;
  B.w += B.inv_I * r.c2.cross(P);
  A.v -= A.inv_m * P;
  A.w -= A.inv_I * r.c1.cross(P);
}

namespace sweep {

// Rows coupled through the velocities of their bodies (the 3D simulator).
// Compliant (contact.stiffness > 0; ContactProblem3::compliance): every
// row's law acts on u + rho (r - r0) in place of u, r0 the row's impulse at
// the solve's start (the warm start, the previous step's impulse), rho =
// 1 / (k dt^2): an implicit linear spring of stiffness k on the normal
// displacement of the step and of k_t (rho_t = 1 / (k_t dt^2)) on the
// tangential ones, Signorini and Coulomb kept (method: docs/method.md section 15). Its
// block is W + diag(rho, rho_t, rho_t), whose reciprocals the rows then
// hold (iwnn = 1 / (W_nn + rho), iwtt = 1 / (W_tt + rho_t):
// nlgs_solve3), so the stick trial is g = r - (u + rho (r - r0)) iwnn
// without a division, and the cell dofs' damped update and the law
// residual's scale see the compliant block. The rigid instance
// (law3::RigidNormal) reads neither r0 nor rho, so rigid scenes compute
// what they did before the option existed.
template <class Normal>
struct BodyCouplingT3 {
  static constexpr bool Compliant = Normal::compliant;
  BodyVel3* vel;
  // The rows' RowExtra3, same index as the rows from `base` (null in scenes
  // without them).
  const RowExtra3* extra = nullptr;
  const SweepRow3* base = nullptr;

  const RowExtra3* extra_of(const SweepRow3& r) const { return extra ? extra + (&r - base) : nullptr; }

  // The row's relative velocity in its frame (contact3.hpp's SweepRow3),
  // with the law's offsets when L reads them.
  template <bool Offsets>
  [[gnu::always_inline]] Vec3 velocity(const SweepRow3& r, const RowExtra3* e) const {
    const BodyVel3& A = vel[r.b1];
    const BodyVel3& B = vel[r.b2];
    const Vec3 dv = B.v - A.v;
    const Vec3 om = r.l2 * B.w - r.l1 * A.w;
    Vec3 u(r.n.dot(dv) + r.bn, r.t1.dot(dv) + r.t2.dot(om), r.t2.dot(dv) - r.t1.dot(om));
    if constexpr (Offsets) {
      u[1] += e->bt1;
      u[2] += e->bt2;
    }
    return u;
  }
  Vec3 velocity(const SweepRow3& r) const {
    const RowExtra3* e = extra_of(r);
    return e ? velocity<true>(r, e) : velocity<false>(r, nullptr);
  }

  // For the sweep's Anderson acceleration (core/sweep.hpp): a row's impulse
  // as 3 numbers, and r += dx with its bodies' velocities following (one
  // thread; a driven body has zero inverse mass and inertia, so it is not
  // moved).
  static constexpr int kImpulseDim = 3;
  // update's pabs is |p_n| + |p_t1| + |p_t2|, a bound of |p| without the
  // square root (12 % of an update): the sweep sums the exact |p| only when
  // the stop may come (sweep.hpp: norm_bound, exact_psum).
  static constexpr bool kNormBound = true;
  void read_impulse(const SweepRow3& r, double* x) const {
    x[0] = r.r[0];
    x[1] = r.r[1];
    x[2] = r.r[2];
  }
  void add_impulse(SweepRow3& r, const double* dx) const {
    if (dx[0] == 0.0 && dx[1] == 0.0 && dx[2] == 0.0) return;  // an open row's mix: nothing moves
    const Vec3 d(dx[0], dx[1], dx[2]);
    r.r += d;
    push_impulse(r, d, vel);
  }

  // For the sweep's subspace correction (core/sweep.hpp, Subspace): the
  // laws with the round cone (or none), with or without adhesion. The
  // products W p go through a copy of the bodies (masses kept, velocities
  // zeroed each time); nbodies is the size of vel.
  int nbodies = 0;
  // The normal part (law_parts3.hpp). Compliant: the impulses at the
  // solve's start (r0, same index as the rows from `base`), rho (velocity
  // per impulse), rho_t of the tangential springs (k_t = k: rho_t = rho).
  [[no_unique_address]] Normal normal{};
  // The velocity the law sees: u, and rho (r - r0) on a compliant row
  // (rho_t on the tangential components).
  Vec3 law_velocity(const SweepRow3& r) const {
    const Vec3 u = velocity(r);
    if constexpr (Compliant) {
      const Vec3 d = r.r - normal.r0[&r - base];
      return Vec3(u[0] + normal.rho * d[0], u[1] + normal.rho_t * d[1], u[2] + normal.rho_t * d[2]);
    }
    return u;
  }
  template <class L>
  static constexpr bool kSubspaceLaw = !L::orthotropic;
  using Scratch = std::vector<BodyVel3>;
  Scratch subspace_scratch() const { return Scratch(vel, vel + nbodies); }
  // The row's free components (subspace3.hpp), its velocity, W's diagonal.
  template <class L>
  void subspace_row(const SweepRow3& r, double* free, double* diag, double* u) const {
    subspace3::free_components<L>(r.r, r.mu, r.adh, free);
    if (free[0] == 0.0) return;  // open: u and diag unread (block_coupling3.hpp)
    const Vec3 v = law_velocity(r);
    u[0] = v[0];
    u[1] = v[1];
    u[2] = v[2];
    diag[0] = 1.0 / r.iwnn;  // compliant: W_nn + rho (the row's iwnn)
    diag[1] = diag[2] = 1.0 / r.iwtt;
  }
  // y = W p on the rows listed in live, through s (offsets and b_n left
  // out; compliant: (W + diag(rho, rho_t, rho_t)) p); the other rows' p is
  // zero and their y is not read.
  [[gnu::flatten]] void subspace_apply(const SweepRow3* R, const std::vector<int>& live, const double* p, double* y,
                                       Scratch& s) const {
    subspace3::scatter(R, live, p, s);
    for (const int i : live) {
      const SweepRow3& r = R[i];
      const BodyVel3& A = s[r.b1];
      const BodyVel3& B = s[r.b2];
      const Vec3 dv = B.v - A.v;
      const Vec3 om = r.l2 * B.w - r.l1 * A.w;
      y[3 * i] = r.n.dot(dv);
      y[3 * i + 1] = r.t1.dot(dv) + r.t2.dot(om);
      y[3 * i + 2] = r.t2.dot(dv) - r.t1.dot(om);
      if constexpr (Compliant) {
        y[3 * i] += normal.rho * p[3 * i];
        y[3 * i + 1] += normal.rho_t * p[3 * i + 1];
        y[3 * i + 2] += normal.rho_t * p[3 * i + 2];
      }
    }
  }
  // r <- the law's projection (its local solve's, L::solve) of the trial
  // r + d (subspace3.hpp).
  template <class L>
  void subspace_put(SweepRow3& r, const double* d, bool sticking) const {
    const Vec3 y = subspace3::trial<L>(r.r, r.adh, d, sticking);
    Vec3 out;
    L::solve(r, extra_of(r), y, out);
    const Vec3 dr = out - r.r;
    r.r = out;
    push_impulse<true>(r, dr, vel);
  }

  // One row update: the stick trial g = r - W^-1 u from the velocity at
  // the current impulse, the law's projection, the change into the bodies.
  // Write1 = false when body 1 is driven (a wall): read, never written, so
  // rows of one colour may share it without a data race. Inlined whole
  // (flatten): at -O2 the small Eigen operations would otherwise stay calls;
  // and inlined into the sweep's loop (always_inline): with the open rows'
  // early exit GCC made it a call, whose spills cost 7 % at I = 1e-3.
  template <class L, bool Write1>
  [[gnu::flatten, gnu::always_inline]] inline void update(SweepRow3& r, double& dp2, double& pabs) const {
    // A row open at its start that stays open (its normal trial at or below
    // -a) keeps its impulse and moves nothing: the normal velocity alone
    // decides it (the same operations as velocity()'s, so the same bits),
    // without the tangential velocity or the push. The law still writes the
    // open impulse, whose zero carries its own sign (+0 from the cone, -0
    // from the frictionless clamp), so the state is the full update's to the
    // bit. Half the rows of a dense shear step are open (the alert distance).
    const RowExtra3* e = nullptr;
    if constexpr (L::extra) e = extra + (&r - base);
    // Compliant: only a row also open at the solve's start (r0 = r), whose
    // rho term is then zero (the same sign of the trial, so the same open
    // impulse).
    const Vec3* z0 = nullptr;
    if constexpr (Compliant) z0 = normal.r0 + (&r - base);
    {
      const double a = L::cohesive ? r.adh : 0.0;
      if (r.r[0] == -a && r.r[1] == 0.0 && r.r[2] == 0.0 && (!Compliant || *z0 == r.r)) {
        const Vec3 dv = vel[r.b2].v - vel[r.b1].v;
        const double gn = r.r[0] - (r.n.dot(dv) + r.bn) * r.iwnn;
        if (a + gn <= 0.0) {
          L::solve(r, e, Vec3(gn, 0.0, 0.0), r.r);
          dp2 = 0.0;
          pabs = a;
          return;
        }
      }
    }
    const Vec3 u = velocity<L::offsets>(r, e);
    Vec3 g;
    if constexpr (Compliant) {
      const Vec3 d = r.r - *z0;
      g[0] = r.r[0] - (u[0] + normal.rho * d[0]) * r.iwnn;
      if constexpr (L::tangential) {
        g[1] = r.r[1] - (u[1] + normal.rho_t * d[1]) * r.iwtt;
        g[2] = r.r[2] - (u[2] + normal.rho_t * d[2]) * r.iwtt;
      } else {
        g[1] = g[2] = 0.0;
      }
    } else {
      g[0] = r.r[0] - u[0] * r.iwnn;
      if constexpr (L::tangential) {
        g[1] = r.r[1] - u[1] * r.iwtt;
        g[2] = r.r[2] - u[2] * r.iwtt;
      } else {
        g[1] = g[2] = 0.0;
      }
    }
    Vec3 rn;
    L::solve(r, e, g, rn);
    const Vec3 dr = rn - r.r;
    r.r = rn;
    dp2 = dr.squaredNorm();
    pabs = std::abs(rn[0]) + std::abs(rn[1]) + std::abs(rn[2]);  // >= |rn|: kNormBound
    if constexpr (L::tangential) {
      push_impulse<Write1>(r, dr, vel);
    } else {  // a normal impulse through the centres turns nothing
      const Vec3 P = dr[0] * r.n;
      BodyVel3& B = vel[r.b2];
      B.v += B.inv_m * P;
      if constexpr (Write1) {
        BodyVel3& A = vel[r.b1];
        A.v -= A.inv_m * P;
      }
    }
  }
};

using BodyCoupling3 = BodyCouplingT3<law3::RigidNormal>;
using CompliantCoupling3 = BodyCouplingT3<law3::CompliantNormal>;

}  // namespace sweep

// The law residual of a row (law3.hpp, rho = 1/W_nn) at the velocity its
// coupling gives the law (compliant: with rho (r - r0)), with its RowExtra3
// when the scene has them.
template <class Normal>
double row_residual(const sweep::BodyCouplingT3<Normal>& c, const SweepRow3& r) {
  const RowExtra3* e = c.extra_of(r);
  return law_residual3(c.law_velocity(r), r.r, Cone3{r.mu, e ? e->mu_b : r.mu}, r.adh, r.iwnn);
}

}  // namespace cd
