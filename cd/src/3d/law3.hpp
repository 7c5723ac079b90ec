// 3D contact laws and their exact local solver (method.md section 13).
//
// One contact, others frozen: u = W r + q, W the 3x3 Delassus block
// (symmetric positive definite), frame (n, t1, t2), r the impulse. The law,
// with adhesion impulse a >= 0 and s = r + a e_n the shifted impulse:
//     0 <= s_n  _|_  u_n >= 0
//     s in K = { |D^-1 s_t| <= s_n },   D = diag(mu_a, mu_b)
//     u_t != 0  =>  s_t = -s_n D (D u_t) / |D u_t|      (maximal dissipation)
// mu_a = mu_b = mu is the round Coulomb cone |s_t| <= mu s_n with s_t
// opposite to u_t; mu_a != mu_b the orthotropic (elliptic) cone, whose
// sliding impulse is NOT opposite to u_t but normal to the ellipse.
//
// Why a change of variables: with T = diag(1, mu_a, mu_b), s = T p and
// v = T u turn any of these cones into the unit round cone |p_t| <= p_n
// with p_t opposite to v_t, and v = (T W T) p + T b. So one solver, for the
// unit cone, serves round and orthotropic laws; adhesion is the shift
// b = q - a W e_n (u = W s + b). A zero coefficient makes T singular: that
// axis carries no friction (r = 0 along it) and the problem is solved in the
// remaining plane (mu_a = mu_b = 0: frictionless).
//
// The solve enumerates open (s = 0 if b_n >= 0), stick (s = -W^-1 b in K)
// and sliding. Sliding, on the unit cone: p = p_n (1, d), d = (cos f, sin f),
// u_n = 0 gives p_n(d) = -b_n / (W_nn + W_nt.d), and v_t(d) = p_n (W_tn +
// W_tt d) + b_t must be -alpha d, alpha >= 0. Multiplied by the positive
// denominator, d x v_t(d) = 0 is
//     h(f) = (W_nn + W_nt.d) (d x b_t) - b_n d x (W_tn + W_tt d) = 0,
// a trigonometric polynomial of degree 2 in f (the quartic in tan(f/2) of
// the enumerative solvers: Bonnefon/De Saxce; Siconos' fc3d "unitary
// enumerative"): at most 4 roots. They are bracketed by sampling h at 96
// angles, and each bracket refined by safeguarded Newton (bisection when
// Newton leaves the bracket) to round-off; local minima of |h| between
// samples are tried with Newton as well, so that a pair of close roots
// (near tangency) is not lost. Rejected: the complex companion matrix of the
// quartic (roots off the unit circle by round-off must then be accepted by a
// tolerance, and a vanishing leading coefficient needs its own case).
// Every root with p_n >= 0 and alpha >= 0 is a solution; the one with the
// smallest law residual is returned (several exist only for large mu).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Cholesky>

namespace cd {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// Friction coefficients along the frame's t1 and t2 (mu_a = mu_b: round).
struct Cone3 {
  double mu_a = 0, mu_b = 0;
  static Cone3 round(double mu) { return {mu, mu}; }
  bool is_round() const { return mu_a == mu_b; }
};

enum class Branch3 { Open, Stick, Slide, Fallback };

namespace law3_detail {

// Projection onto the cone |x_t| <= mu x_n (mu >= 0).
inline Vec3 project_cone(const Vec3& x, double mu) {
  const double xt = std::hypot(x[1], x[2]);
  if (xt <= mu * x[0]) return x;
  if (mu * xt <= -x[0]) return Vec3::Zero();
  const double yn = (mu * xt + x[0]) / (mu * mu + 1.0);
  const double f = mu * yn / xt;
  return {yn, f * x[1], f * x[2]};
}

// The sliding branch on the unit cone |p_t| <= p_n: p = p_n (1, cos f,
// sin f) with u = W p + b, u_n = 0 (so p_n = -b_n / (W_nn + w_t.d)) and
// u_t opposite to d. h(f) = 0 is the alignment condition (u_t x d = 0,
// times the positive W_nn + w_t.d); candidate() checks the rest (p_n >= 0,
// u_t against d, not along it) and measures what the root's accuracy
// leaves (misalignment and |u_n|).
struct SlideUnit {
  double wnn, bn;
  Eigen::Vector2d wt, bt;
  Eigen::Matrix2d Wt;
  const Mat3& W;
  const Vec3& b;
  SlideUnit(const Mat3& W_, const Vec3& b_)
      : wnn(W_(0, 0)), bn(b_[0]), wt(W_(1, 0), W_(2, 0)), bt(b_[1], b_[2]), Wt(W_.bottomRightCorner<2, 2>()),
        W(W_), b(b_) {}
  static double cross(const Eigen::Vector2d& x, const Eigen::Vector2d& y) { return x[0] * y[1] - x[1] * y[0]; }
  double h(double f, double* dh) const { return h_at(Eigen::Vector2d(std::cos(f), std::sin(f)), dh); }
  // h at the unit direction d = (cos f, sin f), and its derivative in f.
  double h_at(const Eigen::Vector2d& d, double* dh) const {
    const Eigen::Vector2d dd(-d[1], d[0]);
    const double den = wnn + wt.dot(d);
    const Eigen::Vector2d g = wt + Wt * d;
    if (dh) *dh = wt.dot(dd) * cross(d, bt) + den * cross(dd, bt) - bn * (cross(dd, g) + cross(d, Wt * dd));
    return den * cross(d, bt) - bn * cross(d, g);
  }
  // The impulse at angle f and its error, or false if it is not a slide.
  bool candidate(double f, Vec3& q, double& err) const {
    return candidate_at(Eigen::Vector2d(std::cos(f), std::sin(f)), q, err);
  }
  bool candidate_at(const Eigen::Vector2d& d, Vec3& q, double& err) const {
    const double den = wnn + wt.dot(d);
    if (!(den > 0.0)) return false;
    const double pn = -bn / den;
    if (pn < 0.0) return false;
    q = Vec3(pn, pn * d[0], pn * d[1]);
    const Vec3 v = W * q + b;
    const double alpha = -(d[0] * v[1] + d[1] * v[2]);
    if (alpha < -1e-12 * scale(q)) return false;
    err = std::abs(cross(d, v.tail<2>())) + std::abs(v[0]);
    return true;
  }
  double scale(const Vec3& q) const { return b.norm() + W.norm() * q.norm(); }
};

// Sliding on the unit cone: returns whether a valid candidate was found,
// the best one in p (shifted, scaled impulse): h's roots, bracketed on 96
// angles and refined by safeguarded Newton, and its near-tangent minima.
inline bool slide_unit(const Mat3& W, const Vec3& b, Vec3& p) {
  const SlideUnit su(W, b);
  auto h = [&](double f, double* dh) { return su.h(f, dh); };
  // Candidate evaluation: the full law at angle f.
  double best = std::numeric_limits<double>::infinity();
  bool found = false;
  auto consider = [&](double f) {
    Vec3 q;
    double err;
    if (!su.candidate(f, q, err)) return;
    if (err < best) {
      best = err;
      p = q;
      found = true;
    }
  };
  // Safeguarded Newton in [a, c] with h(a), h(c) of opposite signs.
  auto refine = [&](double a, double ha, double c) {
    double x = 0.5 * (a + c);
    for (int it = 0; it < 100; ++it) {
      double dh;
      const double hx = h(x, &dh);
      if (hx == 0.0) break;
      if ((hx > 0) == (ha > 0)) a = x, ha = hx;
      else c = x;
      double xn = x - hx / dh;
      if (!(xn > std::min(a, c) && xn < std::max(a, c))) xn = 0.5 * (a + c);
      if (std::abs(xn - x) <= 1e-15 * (1.0 + std::abs(x))) {
        x = xn;
        break;
      }
      x = xn;
    }
    consider(x);
  };
  constexpr int kN = 96;
  constexpr double step = 2.0 * std::numbers::pi / kN;
  std::array<double, kN + 1> hs;
  for (int i = 0; i <= kN; ++i) hs[i] = h(i * step, nullptr);
  for (int i = 0; i < kN; ++i) {
    if (hs[i] == 0.0) consider(i * step);
    else if ((hs[i] > 0) != (hs[i + 1] > 0) && hs[i + 1] != 0.0)
      refine(i * step, hs[i], (i + 1) * step);
  }
  // Near-tangent pairs: local minima of |h| without a sign change.
  for (int i = 0; i < kN; ++i) {
    const double hm = std::abs(hs[(i + kN - 1) % kN]), h0 = std::abs(hs[i]), hp = std::abs(hs[i + 1]);
    if (h0 < hm && h0 < hp) {
      double x = i * step;
      for (int it = 0; it < 50; ++it) {
        double dh;
        const double hx = h(x, &dh);
        if (dh == 0.0) break;
        const double xn = x - hx / dh;
        if (std::abs(xn - x) > step) break;
        x = xn;
      }
      consider(x);
    }
  }
  return found;
}

// Sliding from a guess of the slip direction, d0 (the sweep's previous
// impulse; any length but 0): Newton on h from d0, kept if it converges
// (the step below 1e-14 rad) to a valid slide whose error is round-off
// (1e-12 of the problem's scale); false otherwise, and the caller scans
// (slide_unit). A row's slip turns little from one sweep to the next, so
// this takes 2 to 4 evaluations where the scan takes over a hundred. The
// direction is carried as a unit vector, not an angle: each Newton step
// turns d by dx = h / h' along its tangent and normalises it again, d <-
// (d - dx d_perp) / |d - dx d_perp| (a turn by atan(dx), which is dx to
// third order: Newton's in the tangent's coordinate, quadratic as in the
// angle), with a square root where the angle took a sine and a cosine
// (perf, 1000 cubes in shear: sincos and atan2 were a tenth of a step).
inline bool slide_unit_from(const Mat3& W, const Vec3& b, const Eigen::Vector2d& d0, Vec3& p) {
  const SlideUnit su(W, b);
  const double len = d0.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return false;
  Eigen::Vector2d d = d0 / len;
  for (int it = 0; it < 12; ++it) {
    double dh;
    const double hx = su.h_at(d, &dh);
    if (!(dh != 0.0) || !std::isfinite(hx)) return false;
    const double dx = hx / dh;
    if (std::abs(dx) > 0.5) return false;  // far from the guess: leave it to the scan
    const Eigen::Vector2d e(d[0] + dx * d[1], d[1] - dx * d[0]);  // d - dx (-d1, d0)
    d = e / std::sqrt(e[0] * e[0] + e[1] * e[1]);
    if (std::abs(dx) <= 1e-14) {
      double err;
      return su.candidate_at(d, p, err) && err <= 1e-12 * su.scale(p);
    }
  }
  return false;
}

// One tangential axis with friction mu (the other carries none): the 2D
// enumeration on the (n, t) block of W and b. Returns s = (s_n, s_t).
inline Branch3 solve_plane(double wnn, double wnt, double wtt, double bn, double bt, double mu,
                           double& sn, double& st) {
  const double det = wnn * wtt - wnt * wnt;
  const double gt = (-bt * wnn + bn * wnt) / det, gn = -(bn + wnt * gt) / wnn;
  if (gn >= 0.0 && std::abs(gt) <= mu * gn) {
    sn = gn;
    st = gt;
    return Branch3::Stick;
  }
  const double s0 = gt >= 0.0 ? 1.0 : -1.0;
  for (double s : {s0, -s0}) {
    const double den = wnn + s * mu * wnt;
    if (den <= 0.0) continue;
    const double qn = -bn / den, qt = s * mu * qn;
    if (qn >= 0.0 && s * (bt + wnt * qn + wtt * qt) <= 0.0) {
      sn = qn;
      st = qt;
      return Branch3::Slide;
    }
  }
  sn = std::max(gn, 0.0);
  st = std::clamp(gt, -mu * sn, mu * sn);
  return Branch3::Fallback;
}

}  // namespace law3_detail

// The exact local solve: r (3) from W (3x3 SPD), q, the cone and the
// adhesion impulse a >= 0. Returns the branch taken. guess (optional): an
// impulse near the answer (the sweep's previous one); a slide is then
// sought first from its slip direction (slide_unit_from), the scan only
// if that fails. The answer is a solution of the law either way; where the
// law has several slides (a strongly coupled block and a large mu), the
// guess picks the one nearest the sweep's path; with a guess, the stick
// trial's direction is tried next. W_inv (optional): W's
// inverse, for the stick trial (a row's, computed once per solve).
inline Branch3 solve_local3(const Mat3& W, const Vec3& q, const Cone3& c, double a, Vec3& r,
                            const Vec3* guess = nullptr, const Mat3* W_inv = nullptr) {
  using namespace law3_detail;
  const Vec3 b = q - a * W.col(0);  // u = W s + b, s = r + a e_n
  Vec3 s = Vec3::Zero();
  Branch3 br = Branch3::Open;
  if (b[0] >= 0.0) {
    // open: s = 0 leaves u_n = b_n >= 0
  } else if (c.mu_a == 0.0 && c.mu_b == 0.0) {
    s[0] = -b[0] / W(0, 0);
    br = Branch3::Slide;  // frictionless: slides freely
  } else if (c.mu_a == 0.0 || c.mu_b == 0.0) {
    const int k = c.mu_a == 0.0 ? 2 : 1;  // the axis with friction
    br = solve_plane(W(0, 0), W(0, k), W(k, k), b[0], b[k], std::max(c.mu_a, c.mu_b), s[0], s[k]);
  } else {
    const Vec3 g = W_inv ? Vec3(-(*W_inv * b)) : Vec3(-W.ldlt().solve(b));
    // The stick trial's tangential part in the unit cone's scale, D^-1 g_t
    // (the stick test, the slide's second guess, the fallback). Inside the
    // cone: |D^-1 g_t| <= g_n, on the squares (no hypot: impulses are far
    // from where the squares leave the double range, as in project_sphere3).
    const double ga = g[1] / c.mu_a, gb = g[2] / c.mu_b;
    if (g[0] >= 0.0 && ga * ga + gb * gb <= g[0] * g[0]) {
      s = g;
      br = Branch3::Stick;
    } else {
      const Vec3 T(1.0, c.mu_a, c.mu_b);
      const Mat3 Wt = T.asDiagonal() * W * T.asDiagonal();
      const Vec3 bt = T.cwiseProduct(b);
      Vec3 p;
      bool warm = false;
      if (guess) {
        if ((*guess)[1] != 0.0 || (*guess)[2] != 0.0)
          warm = slide_unit_from(Wt, bt, Eigen::Vector2d((*guess)[1] / c.mu_a, (*guess)[2] / c.mu_b), p);
        // A slide that starts (the guess sticks) or turned far: from the
        // stick trial's direction, the slide's own for an isotropic block
        // and near it otherwise; the scan only if that fails too.
        if (!warm) warm = slide_unit_from(Wt, bt, Eigen::Vector2d(ga, gb), p);
      }
      if (warm || slide_unit(Wt, bt, p)) {
        s = T.cwiseProduct(p);
        br = Branch3::Slide;
      } else {  // not seen for W SPD; kept so that the sweep never stalls
        s[0] = std::max(g[0], 0.0);
        const double gt = std::hypot(ga, gb);
        const double f = gt > s[0] ? s[0] / gt : 1.0;
        s[1] = f * g[1];
        s[2] = f * g[2];
        br = Branch3::Fallback;
      }
    }
  }
  r = s;
  r[0] -= a;
  return br;
}

// The exact local solve for a block W = diag(W_nn, W_tt, W_tt) and a round
// cone (spheres: the lever arms are along n, so rotation adds to W_tt only
// and there is no normal-tangential coupling). solve_local3's enumeration
// then has a closed form in the stick trial g = -W^-1 q (the impulse that
// zeroes u = W r + q): the normal impulse decouples, s_n = max(0, a + g_n),
// and the sliding impulse is g_t projected radially onto the disk of radius
// mu s_n (u_t = W_tt (r_t - g_t) is then parallel to -r_t, as maximal
// dissipation wants). Adhesion a shifts the normal impulse as in
// solve_local3. The sweep (coupling3.hpp) forms g from the current impulse,
// g = r - W^-1 u, and calls project_sphere3; tests/test_world3.cpp checks
// solve_sphere3 against solve_local3 on such blocks.
//
// |g_t| is sqrt(g_t1^2 + g_t2^2), not std::hypot (a libm call, 18 % of a
// 3D row update): impulses are far from the 1e+-154 where the squares
// leave the double range (the scene magnitude rule).
inline Branch3 project_sphere3(const Vec3& g, double mu, double a, Vec3& r) {
  const double sn = std::max(0.0, a + g[0]);  // shifted normal impulse
  r[0] = sn - a;
  if (sn == 0.0) {
    r[1] = r[2] = 0.0;
    return Branch3::Open;
  }
  const double gt2 = g[1] * g[1] + g[2] * g[2], lim = mu * sn;
  if (gt2 <= lim * lim) {
    r[1] = g[1];
    r[2] = g[2];
    return Branch3::Stick;
  }
  const double f = lim / std::sqrt(gt2);
  r[1] = f * g[1];
  r[2] = f * g[2];
  return Branch3::Slide;
}

inline Branch3 solve_sphere3(double wnn, double wtt, const Vec3& q, double mu, double a, Vec3& r) {
  return project_sphere3(Vec3(-q[0] / wnn, -q[1] / wtt, -q[2] / wtt), mu, a, r);
}

// Euclidean projection of y onto the ellipse {(x1/e1)^2 + (x2/e2)^2 <= 1}
// (semi-axes e1, e2 > 0). Outside, the closest point is x_i = e_i^2 y_i /
// (e_i^2 + t) with t > 0 the root of
//     F(t) = (e1 y1 / (e1^2 + t))^2 + (e2 y2 / (e2^2 + t))^2 - 1,
// decreasing and convex on t >= 0 with F(0) > 0: Newton from t = 0 climbs
// monotonically to the root (the tangent of a convex function lies below
// it). Safeguarded anyway: the root is bracketed by [0, |(e1 y1, e2 y2)|]
// (there every term is <= (e_i y_i / t)^2, so F <= 0), and a Newton step
// that leaves the bracket is replaced by bisection. Converges to round-off in
// a handful of steps.
inline Eigen::Vector2d project_ellipse(const Eigen::Vector2d& y, double e1, double e2) {
  const double a1 = e1 * y[0], a2 = e2 * y[1];
  const double z1 = y[0] / e1, z2 = y[1] / e2;
  if (z1 * z1 + z2 * z2 <= 1.0) return y;
  const double s1 = e1 * e1, s2 = e2 * e2;
  double lo = 0.0, hi = std::hypot(a1, a2), t = 0.0;
  for (int it = 0; it < 200; ++it) {
    const double d1 = 1.0 / (s1 + t), d2 = 1.0 / (s2 + t);
    const double f1 = a1 * d1, f2 = a2 * d2;
    const double F = f1 * f1 + f2 * f2 - 1.0;
    if (F == 0.0) break;
    if (F > 0.0) lo = t;
    else hi = t;
    const double dF = -2.0 * (f1 * f1 * d1 + f2 * f2 * d2);
    double tn = t - F / dF;
    if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    if (std::abs(tn - t) <= 4e-16 * t || hi - lo <= 4e-16 * hi) {
      t = tn;
      break;
    }
    t = tn;
  }
  return {s1 * y[0] / (s1 + t), s2 * y[1] / (s2 + t)};
}

// The sphere block diag(W_nn, W_tt, W_tt) with an orthotropic cone
// |(s_t1/mu_a, s_t2/mu_b)| <= s_n, from the stick trial g = -W^-1 q as in
// project_sphere3: the normal impulse decouples. Sliding: u_t = W_tt (s_t -
// g_t), and maximal dissipation puts -u_t in the normal cone of the ellipse
// E = {|D^-1 s_t| <= s_n} at s_t, i.e. g_t - s_t is normal to E there: s_t
// is the Euclidean projection of g_t onto E (project_ellipse). Not opposite
// to u_t unless mu_a = mu_b. A zero coefficient leaves that axis
// frictionless and the other a 1D clamp. tests/test_world3_physics.cpp
// checks solve_sphere3_ortho against solve_local3.
inline Branch3 project_sphere3_ortho(const Vec3& g, double mu_a, double mu_b, double a, Vec3& r) {
  const double sn = std::max(0.0, a + g[0]);
  r[0] = sn - a;
  if (sn == 0.0) {
    r[1] = r[2] = 0.0;
    return Branch3::Open;
  }
  const Eigen::Vector2d gt(g[1], g[2]);
  if (mu_a == 0.0 || mu_b == 0.0) {
    const double la = mu_a * sn, lb = mu_b * sn;
    r[1] = std::clamp(gt[0], -la, la);
    r[2] = std::clamp(gt[1], -lb, lb);
    return (r[1] == gt[0] && r[2] == gt[1]) ? Branch3::Stick : Branch3::Slide;
  }
  const Eigen::Vector2d s = project_ellipse(gt, mu_a * sn, mu_b * sn);
  r[1] = s[0];
  r[2] = s[1];
  return (s[0] == gt[0] && s[1] == gt[1]) ? Branch3::Stick : Branch3::Slide;
}

inline Branch3 solve_sphere3_ortho(double wnn, double wtt, const Vec3& q, double mu_a, double mu_b,
                                   double a, Vec3& r) {
  return project_sphere3_ortho(Vec3(-q[0] / wnn, -q[1] / wtt, -q[2] / wtt), mu_a, mu_b, a, r);
}

// Natural-map residual of the law at (u, r), in impulse units, with De
// Saxce's modified velocity, written in the cone's own metric (the unit
// cone after the change of variables above):
//     p = T^-1 s,  v = T u,  e = T (p - P_K1(p - rho (v + |v_t| e_n)))
// and |e| returned; zero exactly when (u, r) satisfies the law. For a round
// cone this is the Siconos fc3d natural map up to the scaling of r_t by mu
// (siconos_error3 in problem3.hpp is Siconos' own, unscaled). An axis with
// mu = 0 must carry no impulse: its |r_t| is added.
inline double law_residual3(const Vec3& u, const Vec3& r, const Cone3& c, double a, double rho) {
  const Vec3 s(r[0] + a, r[1], r[2]);
  const Vec3 T(1.0, c.mu_a, c.mu_b);
  Vec3 p(s[0], c.mu_a > 0 ? s[1] / c.mu_a : 0.0, c.mu_b > 0 ? s[2] / c.mu_b : 0.0);
  const Vec3 v = T.cwiseProduct(u);
  Vec3 x = p - rho * Vec3(v[0] + std::hypot(v[1], v[2]), v[1], v[2]);
  const Vec3 e = T.cwiseProduct(p - law3_detail::project_cone(x, 1.0));
  double e2 = e.squaredNorm();
  if (c.mu_a == 0) e2 += s[1] * s[1];
  if (c.mu_b == 0) e2 += s[2] * s[2];
  return std::sqrt(e2);
}

// Siconos' per-contact fc3d error term (round cone, rho = 1, no adhesion):
// |r - P_Kmu(r - (u_n + mu |u_t|, u_t))|^2.
inline double siconos_term3(const Vec3& u, const Vec3& r, double mu) {
  const Vec3 x = r - Vec3(u[0] + mu * std::hypot(u[1], u[2]), u[1], u[2]);
  return (r - law3_detail::project_cone(x, mu)).squaredNorm();
}

}  // namespace cd
