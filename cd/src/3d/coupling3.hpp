// The 3D sphere rows for the sweep (core/sweep.hpp): rows coupled through
// the velocities of their bodies (BodyCoupling3, the sibling of 2D's
// BodyCoupling), the laws chosen once per scene, and what the sweep asks of
// a row (its law residual, its impulse norm; the boundary dof is
// contact_problem3.hpp's CellDof3).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <variant>

#include "contact3.hpp"
#include "law3.hpp"
#include "sweep.hpp"

namespace cd {

// The local law of a scene, fixed once (no test inside the sweep):
// frictionless or Coulomb, with or without adhesion, with or without
// tangential offsets (Offsets: restitution or moving periodic images put
// constant terms b_t into the tangential velocity the law sees; without them
// b_t is never read, so such scenes compute exactly what they did before),
// round or orthotropic cone (Orthotropic: |(s_t1/mu, s_t2/mu_b)| <= s_n,
// solve_sphere3_ortho). Offsets and mu_b live in the row's RowExtra3 (e,
// null for the instances that read neither). The local solve is law3's
// exact solver for the sphere block diag(W_nn, W_tt, W_tt); u = W r + q with
// q the velocity the others leave.
template <bool Friction, bool Cohesion, bool Offsets = false, bool Orthotropic = false>
struct SphereLaw3 {
  static constexpr bool tangential = Friction;
  static constexpr bool offsets = Offsets && Friction;
  static constexpr bool orthotropic = Orthotropic && Friction;
  static constexpr bool extra = offsets || orthotropic;  // reads RowExtra3
  static constexpr bool cohesive = Cohesion;
  static void solve(const SphereRow& r, [[maybe_unused]] const RowExtra3* e, const Vec3& q, Vec3& out) {
    const double a = Cohesion ? r.adh : 0.0;
    if constexpr (orthotropic) {
      solve_sphere3_ortho(r.wnn, r.wtt, q, r.mu, e->mu_b, a, out);
    } else if constexpr (Friction) {
      solve_sphere3(r.wnn, r.wtt, q, r.mu, a, out);
    } else {
      out = Vec3(std::max(-a, -q[0] / r.wnn), 0.0, 0.0);
    }
  }
};

// The laws a scene can need, one type each: the variant a ContactProblem3
// carries, resolved once per solve into a template instance of the sweep.
using LocalLaw3 =
    std::variant<SphereLaw3<false, false>, SphereLaw3<false, true>, SphereLaw3<true, false, false, false>,
                 SphereLaw3<true, false, false, true>, SphereLaw3<true, false, true, false>,
                 SphereLaw3<true, false, true, true>, SphereLaw3<true, true, false, false>,
                 SphereLaw3<true, true, false, true>, SphereLaw3<true, true, true, false>,
                 SphereLaw3<true, true, true, true>>;

// The law of a scene: friction and the two RowExtra3 options only with
// friction (a frictionless law reads neither).
inline LocalLaw3 choose_law3(bool friction, bool cohesion, bool offsets, bool orthotropic) {
  LocalLaw3 out;
  bool found = false;
  auto pick = [&]<std::size_t... I>(std::index_sequence<I...>) {
    (([&] {
       using L = std::variant_alternative_t<I, LocalLaw3>;
       if (!found && L::tangential == friction && L::cohesive == cohesion &&
           L::offsets == (friction && offsets) && L::orthotropic == (friction && orthotropic)) {
         out = L{};
         found = true;
       }
     }()),
     ...);
  };
  pick(std::make_index_sequence<std::variant_size_v<LocalLaw3>>{});
  return out;
}

// "frictionless" or "coulomb", then "+adhesion", "+offsets", "+orthotropic"
// as the law has them (the .cdp3 files' law line).
inline std::string law_name3(const LocalLaw3& l) {
  return std::visit(
      [](auto x) {
        using L = decltype(x);
        std::string s = L::tangential ? "coulomb" : "frictionless";
        if (L::cohesive) s += "+adhesion";
        if (L::offsets) s += "+offsets";
        if (L::orthotropic) s += "+orthotropic";
        return s;
      },
      l);
}

inline double impulse_norm(const SphereRow& r) { return r.r.norm(); }

// The velocity change of a row's bodies under an impulse dr (frame
// components) on body 2 and -dr on body 1 (the warm start, Anderson's mix).
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
struct BodyCoupling3 {
  BodyVel3* vel;
  // The rows' RowExtra3, same index as the rows from `base` (null in scenes
  // without them).
  const RowExtra3* extra = nullptr;
  const SphereRow* base = nullptr;

  const RowExtra3* extra_of(const SphereRow& r) const { return extra ? extra + (&r - base) : nullptr; }

  // The row's relative velocity in its frame, with the law's offsets.
  Vec3 velocity(const SphereRow& r) const {
    const Vec3 du = relative_velocity(r, vel[r.b1], vel[r.b2]);
    Vec3 u(r.n.dot(du) + r.bn, r.t1.dot(du), r.t2.dot(du));
    if (const RowExtra3* e = extra_of(r)) {
      u[1] += e->bt1;
      u[2] += e->bt2;
    }
    return u;
  }

  // For the sweep's Anderson acceleration (core/sweep.hpp): a row's impulse
  // as 3 numbers, and r += dx with its bodies' velocities following (one
  // thread; a driven body has zero inverse mass and inertia, so it is not
  // moved).
  static constexpr int kImpulseDim = 3;
  void read_impulse(const SphereRow& r, double* x) const {
    x[0] = r.r[0];
    x[1] = r.r[1];
    x[2] = r.r[2];
  }
  void add_impulse(SphereRow& r, const double* dx) const {
    const Vec3 d(dx[0], dx[1], dx[2]);
    r.r += d;
    push_impulse(r, d, vel);
  }

  // One row update. Write1 = false when body 1 is driven (a wall): read,
  // never written, so rows of one colour may share it without a data race.
  template <class L, bool Write1>
  [[gnu::flatten]] void update(SphereRow& r, double& dp2, double& pabs) const {
    BodyVel3& A = vel[r.b1];
    BodyVel3& B = vel[r.b2];
    const RowExtra3* e = nullptr;
    if constexpr (L::extra) e = extra + (&r - base);
    const Vec3 du = relative_velocity(r, A, B);
    Vec3 q;
    q[0] = r.n.dot(du) + r.bn - r.wnn * r.r[0];
    if constexpr (L::tangential) {
      q[1] = r.t1.dot(du) - r.wtt * r.r[1];
      q[2] = r.t2.dot(du) - r.wtt * r.r[2];
      if constexpr (L::offsets) {
        q[1] += e->bt1;
        q[2] += e->bt2;
      }
    } else {
      q[1] = q[2] = 0.0;
    }
    Vec3 rn;
    L::solve(r, e, q, rn);
    const Vec3 dr = rn - r.r;
    r.r = rn;
    dp2 = dr.squaredNorm();
    pabs = rn.norm();
    const Vec3 P = r.to_world(dr);
    B.v += B.inv_m * P;
    B.w += B.inv_I * r.c2.cross(P);
    if constexpr (Write1) {
      A.v -= A.inv_m * P;
      A.w -= A.inv_I * r.c1.cross(P);
    }
  }
};

}  // namespace sweep

// The law residual of a row (law3.hpp, rho = 1/W_nn) at the velocity its
// coupling gives, with its RowExtra3 when the scene has them.
inline double row_residual(const sweep::BodyCoupling3& c, const SphereRow& r) {
  const RowExtra3* e = c.extra_of(r);
  return law_residual3(c.velocity(r), r.r, Cone3{r.mu, e ? e->mu_b : r.mu}, r.adh, 1.0 / r.wnn);
}

}  // namespace cd
