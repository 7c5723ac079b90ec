// The rows of bodies with a full inertia tensor for the sweep (core/sweep.hpp):
// a contact point whose lever arms are not along its normal (a polyhedron's
// point, off the line of centres), so that its Delassus block is a full
// symmetric 3x3 matrix and an impulse turns its bodies about axes of their
// own. The sibling of coupling3.hpp's sphere rows, chosen once per problem
// (ContactProblem3::inv_inertia not empty: nlgs_solve3).
//
// With c_i from the centre of body i to the point, e_j the frame vectors
// (n, t1, t2) and J_i the body's world inverse inertia at the step's
// midpoint (rigid_rotation.hpp), the relative velocity in the frame is
//     u_j = e_j.(v2 - v1) + a2_j.w2 - a1_j.w1,    a_i_j = c_i x e_j,
// an impulse dr (frame components) on body 2 and -dr on body 1 changes
//     v2 += m2^-1 P,  w2 += sum_j dr_j k2_j,  (body 1: minus, with k1_j)
//     P = sum_j dr_j e_j,  k_i_j = J_i a_i_j,
// and the block is W_jk = (1/m1 + 1/m2) d_jk + a1_j.k1_k + a2_j.k2_k.
// The row keeps a_i and k_i (12 vectors), W and its inverse.
//
// The local solve is exact: from the velocity u at the current impulse r,
// the free velocity q = u - W r (the others' impulses fixed), and
// law3.hpp's solve_local3 enumerates the law on u = W r' + q (open, stick,
// slide on the cone's edge), the round or orthotropic cone and the
// adhesion shift included. This is Jean and Moreau's nonlinear block
// Gauss-Seidel with exact local solves (as LMGC90's and Siconos' NSGS); a
// diagonal approximation of W in the local solve would leave the fixed
// point the law's but converge more slowly on the strongly coupled blocks
// of a point near a face's corner, and a projection with W^-1 in place of
// a scalar would move the fixed point off the law.
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "contact3.hpp"
#include "law3.hpp"
#include "law_parts3.hpp"
#include "subspace3.hpp"

namespace cd {

struct BlockRow3 {
  Vec3 n, t1, t2;
  std::array<Vec3, 3> a1, a2;  // c_i x e_j
  std::array<Vec3, 3> k1, k2;  // J_i (c_i x e_j)
  Mat3 W;                      // the Delassus block, frame components
  Mat3 W_inv;                  // its inverse (the stick trial)
  double bn, mu;
  std::int32_t b1, b2;
  Vec3 r;
  double adh;

  Vec3 to_world(const Vec3& x) const { return x[0] * n + x[1] * t1 + x[2] * t2; }
};

// The sweep's row of a problem row: lever arms c1, c2 and the bodies' world
// inverse inertias J (a driven body's is zero).
inline BlockRow3 make_block_row3(const SphereRow& r, const BodyVel3* vel, const Mat3* J) {
  BlockRow3 b;
  b.n = r.n;
  b.t1 = r.t1;
  b.t2 = r.t2;
  const Vec3 e[3] = {r.n, r.t1, r.t2};
  for (int j = 0; j < 3; ++j) {
    b.a1[j] = r.c1.cross(e[j]);
    b.a2[j] = r.c2.cross(e[j]);
    b.k1[j] = J[r.b1] * b.a1[j];
    b.k2[j] = J[r.b2] * b.a2[j];
  }
  const double im = vel[r.b1].inv_m + vel[r.b2].inv_m;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      b.W(j, k) = (j == k ? im : 0.0) + b.a1[j].dot(b.k1[k]) + b.a2[j].dot(b.k2[k]);
  b.W = 0.5 * (b.W + b.W.transpose());  // symmetric to the bit
  b.W_inv = b.W.inverse();
  b.bn = r.bn;
  b.mu = r.mu;
  b.b1 = r.b1;
  b.b2 = r.b2;
  b.r = r.r;
  b.adh = r.adh;
  return b;
}

// A problem row's wnn and wtt from the full block (its n-n entry and the
// mean of its two tangential ones), for the records; the sweep takes the
// whole block (make_block_row3).
inline void set_block(SphereRow& r, const BodyVel3& A, const BodyVel3& B, const Mat3& JA, const Mat3& JB) {
  const double im = A.inv_m + B.inv_m;
  const auto w = [&](const Vec3& e) {
    const Vec3 a1 = r.c1.cross(e), a2 = r.c2.cross(e);
    return im + a1.dot(JA * a1) + a2.dot(JB * a2);
  };
  r.wnn = w(r.n);
  r.wtt = 0.5 * (w(r.t1) + w(r.t2));
}

inline double impulse_norm(const BlockRow3& r) { return r.r.norm(); }

template <bool Write1 = true>
inline void push_impulse(const BlockRow3& r, const Vec3& dr, BodyVel3* vel) {
  const Vec3 P = r.to_world(dr);
  BodyVel3& B = vel[r.b2];
  B.v += B.inv_m * P;
  B.w += dr[0] * r.k2[0] + dr[1] * r.k2[1] + dr[2] * r.k2[2];
  if constexpr (Write1) {
    BodyVel3& A = vel[r.b1];
    A.v -= A.inv_m * P;
    A.w -= dr[0] * r.k1[0] + dr[1] * r.k1[1] + dr[2] * r.k1[2];
  }
}

namespace sweep {

// Rows coupled through the velocities of bodies with full inertia tensors
// (rigid contacts; the compliant law is the sphere rows' only).
struct BlockCoupling3 {
  BodyVel3* vel;
  const RowExtra3* extra = nullptr;  // same index as the rows from `base`, or null
  const BlockRow3* base = nullptr;

  const RowExtra3* extra_of(const BlockRow3& r) const { return extra ? extra + (&r - base) : nullptr; }

  // The normal component of velocity(r), which the open-row test reads alone.
  double normal_velocity(const BlockRow3& r) const {
    const BodyVel3& A = vel[r.b1];
    const BodyVel3& B = vel[r.b2];
    const Vec3 dv = B.v - A.v;
    double un = r.n.dot(dv) + r.bn;
    un += r.a2[0].dot(B.w) - r.a1[0].dot(A.w);
    return un;
  }
  Vec3 velocity(const BlockRow3& r) const {
    const BodyVel3& A = vel[r.b1];
    const BodyVel3& B = vel[r.b2];
    const Vec3 dv = B.v - A.v;
    Vec3 u(normal_velocity(r), r.t1.dot(dv), r.t2.dot(dv));
    for (int j = 1; j < 3; ++j) u[j] += r.a2[j].dot(B.w) - r.a1[j].dot(A.w);
    if (const RowExtra3* e = extra_of(r)) {
      u[1] += e->bt1;
      u[2] += e->bt2;
    }
    return u;
  }
  Vec3 law_velocity(const BlockRow3& r) const { return velocity(r); }

  template <class L>
  static Cone3 cone(const BlockRow3& r, const RowExtra3* e) {
    if constexpr (!L::tangential) return Cone3{0.0, 0.0};
    else if constexpr (L::orthotropic) return Cone3{r.mu, e->mu_b};
    else return Cone3::round(r.mu);
  }

  // For the sweep's Anderson acceleration (core/sweep.hpp).
  static constexpr int kImpulseDim = 3;
  void read_impulse(const BlockRow3& r, double* x) const {
    x[0] = r.r[0];
    x[1] = r.r[1];
    x[2] = r.r[2];
  }
  void add_impulse(BlockRow3& r, const double* dx) const {
    if (dx[0] == 0.0 && dx[1] == 0.0 && dx[2] == 0.0) return;
    const Vec3 d(dx[0], dx[1], dx[2]);
    r.r += d;
    push_impulse(r, d, vel);
  }
  // For the sweep's subspace correction (core/sweep.hpp, Subspace), as
  // coupling3.hpp's sphere rows: the laws with the round cone (or none),
  // with or without adhesion; the products W p go through a copy of the
  // bodies (nbodies: the size of vel), W's diagonal is the blocks'.
  int nbodies = 0;
  template <class L>
  static constexpr bool kSubspaceLaw = !L::orthotropic;
  using Scratch = std::vector<BodyVel3>;
  Scratch subspace_scratch() const { return Scratch(vel, vel + nbodies); }
  // The row's free components (subspace3.hpp), its velocity, W's diagonal;
  // an open row (no free component: most rows of a polyhedra step) leaves
  // the last two unwritten, as the correction reads them on free ones only.
  template <class L>
  void subspace_row(const BlockRow3& r, double* free, double* diag, double* u) const {
    subspace3::free_components<L>(r.r, r.mu, r.adh, free);
    if (free[0] == 0.0) return;
    const Vec3 v = velocity(r);
    for (int j = 0; j < 3; ++j) {
      u[j] = v[j];
      diag[j] = r.W(j, j);
    }
  }
  // y = W p on the rows listed in live, through s (no offsets, no b_n);
  // the other rows' p is zero and their y is not read.
  void subspace_apply(const BlockRow3* R, const std::vector<int>& live, const double* p, double* y,
                      Scratch& s) const {
    subspace3::scatter(R, live, p, s);
    for (const int i : live) {
      const BlockRow3& r = R[i];
      const BodyVel3& A = s[r.b1];
      const BodyVel3& B = s[r.b2];
      const Vec3 dv = B.v - A.v;
      y[3 * i] = r.n.dot(dv) + r.a2[0].dot(B.w) - r.a1[0].dot(A.w);
      y[3 * i + 1] = r.t1.dot(dv) + r.a2[1].dot(B.w) - r.a1[1].dot(A.w);
      y[3 * i + 2] = r.t2.dot(dv) + r.a2[2].dot(B.w) - r.a1[2].dot(A.w);
    }
  }
  // r <- the cone's projection of the trial r + d (subspace3.hpp), the
  // bodies following.
  template <class L>
  void subspace_put(BlockRow3& r, const double* d, bool sticking) const {
    const Vec3 y = subspace3::trial<L>(r.r, r.adh, d, sticking);
    Vec3 out;
    project_sphere3(y, L::tangential ? r.mu : 0.0, L::cohesive ? r.adh : 0.0, out);
    const Vec3 dr = out - r.r;
    r.r = out;
    push_impulse(r, dr, vel);
  }

  // One row update: the free velocity q = u - W r, the exact local solve,
  // the change into the bodies (body 1 only when Write1).
  template <class L, bool Write1>
  void update(BlockRow3& r, double& dp2, double& pabs) const {
    // A row at zero impulse whose normal velocity stays >= 0 stays open
    // (most of a polyhedra step's rows: the points within the alert
    // distance). solve_local3 would find that from the whole velocity and
    // W r, with r = 0 (q = u, and b = q without adhesion): its open branch
    // returns s = +0, r = s - 0 e_n = +0. The normal component alone
    // decides it, at a third of the velocity's products and none of W r's.
    if (r.r[0] == 0.0 && r.r[1] == 0.0 && r.r[2] == 0.0 && (!L::cohesive || r.adh == 0.0) &&
        normal_velocity(r) >= 0.0) {
      r.r = Vec3::Zero();
      dp2 = 0.0;
      pabs = 0.0;
      return;
    }
    const RowExtra3* e = extra_of(r);
    const Vec3 q = velocity(r) - r.W * r.r;
    Vec3 rn;
    solve_local3(r.W, q, cone<L>(r, e), L::cohesive ? r.adh : 0.0, rn, &r.r, &r.W_inv);
    const Vec3 dr = rn - r.r;
    r.r = rn;
    dp2 = dr.squaredNorm();
    pabs = rn.norm();
    // A row that stays open (most of a polyhedra step's rows: the points
    // within the alert distance) changes nothing: its push would add zeros.
    // Skipping it keeps the bits: x + (+-0) is x for every x but -0 (a
    // velocity component that is exactly -0 would have become +0, which no
    // later result can tell apart but by its sign bit). The polyhedra state
    // hashes (test_world3_hashes) are the same with and without the push.
    if (dr[0] == 0.0 && dr[1] == 0.0 && dr[2] == 0.0) return;
    push_impulse<Write1>(r, dr, vel);
  }
};

}  // namespace sweep

// The law residual of a row (law3.hpp, rho = 1/W_nn).
inline double row_residual(const sweep::BlockCoupling3& c, const BlockRow3& r) {
  const RowExtra3* e = c.extra_of(r);
  return law_residual3(c.velocity(r), r.r, Cone3{r.mu, e ? e->mu_b : r.mu}, r.adh, 1.0 / r.W(0, 0));
}

}  // namespace cd
