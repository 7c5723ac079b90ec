// Contact laws and their exact local solver (method.md sections 2 and 4).
//
// One contact, others frozen: the law sees the affine relation
//     u = b + W p
// between the (restitution-weighted) relative velocity u = (u_n, u_t) and the
// impulse p = f dt, with W the 2x2 Delassus block. The law, with adhesion
// impulse a = f_a dt >= 0 (a = 0: plain Signorini-Coulomb):
//     0 <= p_n + a  _|_  u_n >= 0
//     |p_t| <= mu (p_n + a),   p_t = -mu (p_n + a) sign(u_t) if u_t != 0.
// The solver enumerates the candidates open / stick / slide+ / slide- and
// returns the first one whose (u, p) satisfies the law. Enumeration rather
// than the "stick, then test g_n" shortcut because the shortcut is exact only
// for W_nt = 0; polygons have W_nt != 0.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <variant>

#include "contact.hpp"

namespace cd {

struct Block {
  double wnn, wnt, wtt;
};

enum class LocalBranch { Open, Stick, SlidePlus, SlideMinus, Fallback };

// The open branch of solve_coulomb: p = (-a, 0) leaves u_n = b_n - W_nn a
// >= 0. Its own function because the sweep asks it alone (Coulomb::stays_open).
inline bool coulomb_open(double bn, double wnn, double a) { return bn - wnn * a >= 0.0; }

// Frictional local solve. Returns the branch taken (tests check every one).
inline LocalBranch solve_coulomb(double bn, double bt, const Block& W, double mu, double a,
                                 double& pn, double& pt) {
  // Open: p = (-a, 0) is valid if the normal velocity it leaves is >= 0.
  if (coulomb_open(bn, W.wnn, a)) {
    pn = -a;
    pt = 0.0;
    return LocalBranch::Open;
  }
  // Stick: both velocities zero.
  // g_n from the first row of W g = -b given g_t: with W_nt = 0 it is
  // exactly -b_n / W_nn, so mu = 0 here matches the frictionless path to
  // the bit (tests/test_pile.cpp).
  const double det = W.wnn * W.wtt - W.wnt * W.wnt;
  const double gt = (-bt * W.wnn + bn * W.wnt) / det;
  const double gn = -(bn + W.wnt * gt) / W.wnn;
  const double bound = mu * (gn + a);
  if (gn + a >= 0.0 && std::abs(gt) <= bound) {
    pn = gn;
    pt = gt;
    return LocalBranch::Stick;
  }
  // Slide: p_t = s mu (p_n + a), u_n = 0; valid if p_n + a >= 0 and s u_t <= 0.
  const double s0 = gt >= 0.0 ? 1.0 : -1.0;
  for (double s : {s0, -s0}) {
    const double den = W.wnn + s * mu * W.wnt;
    if (den <= 0.0) continue;
    const double qn = -(bn + s * mu * W.wnt * a) / den;
    const double qt = s * mu * (qn + a);
    const double ut = bt + W.wnt * qn + W.wtt * qt;
    if (qn + a >= 0.0 && s * ut <= 0.0) {
      pn = qn;
      pt = qt;
      return s > 0 ? LocalBranch::SlidePlus : LocalBranch::SlideMinus;
    }
  }
  // Only reachable for an ill-posed block (mu |W_nt| >= W_nn, a Painleve-like
  // case): keep the stick normal impulse, clamp the tangential one.
  pn = std::max(gn, -a);
  pt = std::clamp(gt, -mu * (pn + a), mu * (pn + a));
  return LocalBranch::Fallback;
}

// Frictionless local solve: p_t stays 0.
inline void solve_frictionless(double bn, const Block& W, double a, double& pn) {
  pn = std::max(-a, -bn / W.wnn);
}

// Whether solve_frictionless gives p_n = -a, its bits (std::max keeps its
// first argument on a tie): the same quotient; false on a NaN one, which
// std::max would turn into -a too, so that a NaN row takes the full update.
inline bool frictionless_open(double bn, double wnn, double a) { return -bn / wnn <= -a; }

// Natural-map residual of the law at (u, p), in impulse units (rho = 1/W_nn):
//   r_n = (p_n + a) - max(0, p_n + a - rho u_n)
//   r_t = p_t - clamp(p_t - rho u_t, -mu (p_n + a), mu (p_n + a))
// r = 0 exactly when (u, p) satisfies the law.
inline double law_residual(double un, double ut, double pn, double pt, double mu, double a,
                           double rho) {
  const double sn = pn + a;
  const double rn = sn - std::max(0.0, sn - rho * un);
  const double lim = mu * std::max(sn, 0.0);
  const double rt = pt - std::clamp(pt - rho * ut, -lim, lim);
  return std::sqrt(rn * rn + rt * rt);
}

// ---- The local law of a scene, as a type --------------------------------
// Chosen once per scene (World::configure, from mu, mu_wall and the
// adhesion), never tested inside the sweep: the sweep is a template over the
// law (nlgs.cpp), so a frictionless or non-cohesive scene carries no friction
// or adhesion work in its inner loop. A law's data are per row, filled by the
// build stage from the scene (ContactRow::mu: mu or mu_wall; ContactRow::adh:
// f_a dt within the debonding distance), so that one type serves grains and
// walls. Each law solves the local problem of one row from its relative
// velocity u (everything in it, the row's own impulse included) and its
// current impulse, as nlgs.cpp's row update and the matrix replay need.
// Adding an effect adds a type here and to LocalLaw, not a branch in a kernel.
// `tangential`: the law has a tangential impulse (the sweep computes u_t).
// `cohesive`: its open impulse is (-a, 0) with a = ContactRow::adh (else a = 0).
// stays_open(r, un): for a row at the open impulse, whether solve gives it
// again (the sweep then skips the row: coupling.hpp). It is solve's own open
// test on solve's own b_n (bn_of), so it answers as solve does, not as a
// bound; u_t is not needed, Coulomb's open branch reading b_n alone.
// The cohesive laws are the same two with the open impulse shifted to
// (-a, 0): one template each, `Cohesive` reading the row's a.
template <bool Cohesive>
struct FrictionlessLaw {
  static constexpr bool tangential = false;
  static constexpr bool cohesive = Cohesive;
  static constexpr const char* name = Cohesive ? "cohesive-frictionless" : "frictionless";
  static double adh(const ContactRow& r) { return Cohesive ? r.adh : 0.0; }
  static double bn_of(const ContactRow& r, double un) { return un - r.wnn * r.pn; }
  static bool stays_open(const ContactRow& r, double un) {
    return frictionless_open(bn_of(r, un), r.wnn, adh(r));
  }
  static void solve(const ContactRow& r, double un, double /*ut*/, double& pn, double& pt) {
    solve_frictionless(bn_of(r, un), Block{r.wnn, r.wnt, r.wtt}, adh(r), pn);
    pt = 0.0;
  }
};

// Coulomb; cohesive: adhesion-shifted Signorini with the shifted cone
// |p_t| <= mu (p_n + a).
template <bool Cohesive>
struct CoulombLaw {
  static constexpr bool tangential = true;
  static constexpr bool cohesive = Cohesive;
  static constexpr const char* name = Cohesive ? "cohesive-coulomb" : "coulomb";
  static double adh(const ContactRow& r) { return Cohesive ? r.adh : 0.0; }
  static double bn_of(const ContactRow& r, double un) { return un - (r.wnn * r.pn + r.wnt * r.pt); }
  static bool stays_open(const ContactRow& r, double un) {
    return coulomb_open(bn_of(r, un), r.wnn, adh(r));
  }
  static void solve(const ContactRow& r, double un, double ut, double& pn, double& pt) {
    const double bn = bn_of(r, un);
    const double bt = ut - (r.wnt * r.pn + r.wtt * r.pt);
    solve_coulomb(bn, bt, Block{r.wnn, r.wnt, r.wtt}, r.mu, adh(r), pn, pt);
  }
};

using Frictionless = FrictionlessLaw<false>;
using Coulomb = CoulombLaw<false>;
using CohesiveFrictionless = FrictionlessLaw<true>;  // adhesion-shifted Signorini, without friction
using CohesiveCoulomb = CoulombLaw<true>;

using LocalLaw = std::variant<Frictionless, Coulomb, CohesiveFrictionless, CohesiveCoulomb>;

// The law a scene needs: friction if any coefficient is > 0, adhesion if
// the pull-off force is > 0.
inline LocalLaw choose_law(bool friction, bool adhesion) {
  if (adhesion) return friction ? LocalLaw{CohesiveCoulomb{}} : LocalLaw{CohesiveFrictionless{}};
  return friction ? LocalLaw{Coulomb{}} : LocalLaw{Frictionless{}};
}

inline std::string law_name(const LocalLaw& l) {
  return std::visit([](const auto& x) { return std::string(x.name); }, l);
}

}  // namespace cd
