// The 2D couplings' shared pieces for the sweep (core/sweep.hpp): rows
// coupled through the velocities of their bodies (the simulator), and what
// the sweep asks of a 2D row (its law residual, its impulse norm).
#pragma once
#include <cmath>

#include "contact.hpp"
#include "law.hpp"
#include "nlgs.hpp"
#include "sweep.hpp"

namespace cd {

// The law residual of a row (law.hpp) at the velocity its coupling gives.
template <class C>
double row_residual(const C& c, const ContactRow& r) {
  double un, ut;
  c.velocity(r, un, ut);
  return law_residual(un, ut, r.pn, r.pt, r.mu, r.adh, 1.0 / r.wnn);
}

inline double impulse_norm(const ContactRow& r) { return std::sqrt(r.pn * r.pn + r.pt * r.pt); }

namespace sweep {

// Rows coupled through the velocities of their bodies (the simulator).
template <bool Rot>
struct BodyCoupling {
  BodyVel* vel;

  // For the sweep's Anderson acceleration (core/sweep.hpp): a row's impulse
  // as (p_n, p_t), and r += dx with its bodies' velocities following (one
  // thread; a driven body has zero inverse mass and inertia, so it is not
  // moved).
  static constexpr int kImpulseDim = 2;
  // update's pabs is |p_n| + |p_t|, a bound of |p| without the square root:
  // the sweep sums the exact |p| only when the stop may come (core/sweep.hpp).
  static constexpr bool kNormBound = true;
  void read_impulse(const ContactRow& r, double* x) const {
    x[0] = r.pn;
    x[1] = r.pt;
  }
  void add_impulse(ContactRow& r, const double* dx) const {
    const double dpn = dx[0], dpt = dx[1];
    r.pn += dpn;
    r.pt += dpt;
    BodyVel& A = vel[r.b1];
    BodyVel& B = vel[r.b2];
    const double px = r.nx * dpn - r.ny * dpt, py = r.ny * dpn + r.nx * dpt;
    B.vx += B.inv_m * px;
    B.vy += B.inv_m * py;
    A.vx -= A.inv_m * px;
    A.vy -= A.inv_m * py;
    if constexpr (Rot) {
      B.w += B.inv_I * (r.c2n * dpt - r.c2t * dpn);
      A.w -= A.inv_I * (r.c1n * dpt - r.c1t * dpn);
    }
  }

  // One row update. Write1 = false when body 1 is driven (a wall): it is
  // read, never written, so rows of one colour may share a wall without a
  // data race.
  template <class L, bool Write1>
  void update(ContactRow& r, double& dp2, double& pabs) const {
    BodyVel& A = vel[r.b1];
    BodyVel& B = vel[r.b2];
    const double dx = B.vx - A.vx, dy = B.vy - A.vy;
    double un = r.nx * dx + r.ny * dy + r.bn;
    if constexpr (Rot) un += -B.w * r.c2t + A.w * r.c1t;
    // A row at the open impulse (-a, 0) that its solve keeps there (the
    // normal velocity alone decides: L::stays_open, false on a NaN) takes
    // the solve's impulse (its bits: -0.0 without adhesion) and moves
    // nothing: its push would add zeros, which change no velocity but a
    // -0.0, and velocities are sums, which make -0.0 only from a -0.0
    // start. So no tangential velocity, solve or push. Half the rows of a
    // dense shear step are open (within the alert distance). A law without
    // stays_open (cd/bench/solvers.cpp's relaxed ones) takes the full update.
    if constexpr (requires { L::stays_open(r, un); }) {
      const double a = L::cohesive ? r.adh : 0.0;
      if (r.pn == -a && (!L::tangential || r.pt == 0.0) && L::stays_open(r, un)) {
        r.pn = -a;
        if constexpr (L::tangential) r.pt = 0.0;
        dp2 = 0.0;
        pabs = std::abs(a);
        return;
      }
    }
    double ut = 0.0;
    if constexpr (L::tangential) {
      ut = -r.ny * dx + r.nx * dy + r.bt;
      if constexpr (Rot) ut += B.w * r.c2n - A.w * r.c1n;
    }
    double pn, pt;
    L::solve(r, un, ut, pn, pt);
    const double dpn = pn - r.pn;
    const double dpt = L::tangential ? pt - r.pt : 0.0;
    r.pn = pn;
    if constexpr (L::tangential) {
      r.pt = pt;
      pabs = std::abs(pn) + std::abs(pt);  // >= |p|: kNormBound
    } else {
      pabs = std::abs(pn);
    }
    dp2 = dpn * dpn + dpt * dpt;
    const double px = r.nx * dpn - r.ny * dpt, py = r.ny * dpn + r.nx * dpt;
    B.vx += B.inv_m * px;
    B.vy += B.inv_m * py;
    if constexpr (Rot) B.w += B.inv_I * (r.c2n * dpt - r.c2t * dpn);
    if constexpr (Write1) {
      A.vx -= A.inv_m * px;
      A.vy -= A.inv_m * py;
      if constexpr (Rot) A.w -= A.inv_I * (r.c1n * dpt - r.c1t * dpn);
    }
  }

  void velocity(const ContactRow& r, double& un, double& ut) const {
    const BodyVel& A = vel[r.b1];
    const BodyVel& B = vel[r.b2];
    const double dx = B.vx - A.vx, dy = B.vy - A.vy;
    un = r.nx * dx + r.ny * dy;
    ut = -r.ny * dx + r.nx * dy;
    if constexpr (Rot) {
      un += -B.w * r.c2t + A.w * r.c1t;
      ut += B.w * r.c2n - A.w * r.c1n;
    }
    un += r.bn;
    ut += r.bt;
  }
};

}  // namespace sweep
}  // namespace cd
