// Rotation with a full inertia tensor (cd/src/3d/rigid_rotation.hpp): the
// world inverse inertia, the free angular velocity with the gyroscopic
// torque (implicit midpoint) and the orientation update, against closed
// forms of the free rigid body.
//  - Equal moments (a sphere): the inverse inertia is 1/I to round-off, the
//    gyroscopic term is exactly zero, w comes back bit for bit.
//  - I_w^-1 maps each principal axis (turned by the quaternion, not by the
//    matrix) to itself over its moment.
//  - A free symmetric top against its closed-form motion (w precessing in
//    the body at (I3 - I1)/I1 w3, the body turning about L at |L|/I1):
//    second order in dt, over three steps.
//  - A free asymmetric body: about its intermediate axis it flips at the
//    closed-form period (elliptic functions) and at a high-accuracy RK4
//    reference's times; about its major and minor axes the perturbation
//    stays on its closed-form conserved ellipse.
//  - A fast asymmetric spin (dt |w| = 0.3, 10^4 steps): the implicit
//    midpoint keeps energy and |L| to round-off, never adding energy; the
//    explicit variant adds energy at every step and blows up; the rejected
//    linearised backward Euler takes angular momentum away.
//  - Newton's iterations: a few, up to dt |w| = 3.
//  - Determinism: bit-identical results on repeated calls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include "rigid_rotation.hpp"

using namespace cd;
using Mat3 = Eigen::Matrix3d;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// A fixed, generic orientation: no axis of the world is a principal axis.
Quat generic_orientation() {
  return Quat(Eigen::AngleAxisd(0.7, Vec3(1.0, -2.0, 0.5).normalized())) *
         Quat(Eigen::AngleAxisd(-1.3, Vec3(0.3, 0.4, 1.0).normalized()));
}

// The body-frame angular velocity, energy and world angular momentum of a
// state, through the quaternion's own rotation (not rigid_rotation's matrices).
Vec3 body_w(const RotationState& s) { return s.q.conjugate() * s.w; }
double energy(const Vec3& I, const RotationState& s) {
  const Vec3 wb = body_w(s);
  return 0.5 * (I[0] * wb[0] * wb[0] + I[1] * wb[1] * wb[1] + I[2] * wb[2] * wb[2]);
}
Vec3 momentum(const Vec3& I, const RotationState& s) { return s.q * I.cwiseProduct(body_w(s)); }

// A state from a body-frame angular velocity at orientation q.
RotationState state(const Quat& q, const Vec3& wb) { return {q, q * wb}; }

RotationState run(const Vec3& I, RotationState s, double dt, int n,
                  Gyroscopic g = Gyroscopic::ImplicitMidpoint) {
  for (int k = 0; k < n; ++k) s = free_rotation_step(I, s, Vec3::Zero(), dt, g);
  return s;
}

// Euler's equations of the free body, I w' = -w x I w (principal frame),
// by classical RK4: the reference of the asymmetric body.
Vec3 euler_rhs(const Vec3& I, const Vec3& w) {
  return Vec3((I[1] - I[2]) * w[1] * w[2] / I[0], (I[2] - I[0]) * w[2] * w[0] / I[1],
              (I[0] - I[1]) * w[0] * w[1] / I[2]);
}
Vec3 rk4(const Vec3& I, const Vec3& w, double h) {
  const Vec3 k1 = euler_rhs(I, w), k2 = euler_rhs(I, w + 0.5 * h * k1), k3 = euler_rhs(I, w + 0.5 * h * k2),
             k4 = euler_rhs(I, w + h * k3);
  return w + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

// Times at which w2 (body frame) changes sign, linearly interpolated
// between steps, over [0, T]; the first n of them.
template <class Step>
std::vector<double> sign_changes(Vec3 wb, double h, double T, std::size_t n, Step step) {
  std::vector<double> t;
  for (int k = 0; k * h < T && t.size() < n; ++k) {
    const Vec3 next = step(wb);
    if ((wb[1] > 0.0) != (next[1] > 0.0)) t.push_back((k + wb[1] / (wb[1] - next[1])) * h);
    wb = next;
  }
  return t;
}

}  // namespace

// Equal moments: the world inverse inertia is 1/I (to the round-off of
// R R^T = 1: a few epsilon), the gyroscopic torque is exactly zero
// (Euler's form: differences of equal moments), so w is returned bit for
// bit and the body turns at constant w: the spheres' scalar path is the
// same motion.
TEST(RigidRotation, EqualMomentsAreTheSpheresScalarPath) {
  const double I = 0.37;
  const Vec3 m(I, I, I);
  const Quat q = generic_orientation();
  const Mat3 Winv = world_inverse_inertia(m, q);
  EXPECT_LE((Winv - Mat3::Identity() / I).cwiseAbs().maxCoeff(), 8 * kEps / I);
  EXPECT_LE((world_inertia(m, q) - I * Mat3::Identity()).cwiseAbs().maxCoeff(), 8 * kEps * I);

  const Vec3 w(3.0, -1.0, 7.5);
  const GyroscopicSolve s = solve_free_angular_velocity(m, q, w, Vec3::Zero(), 0.05);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_EQ(std::memcmp(s.w.data(), w.data(), sizeof(Vec3)), 0);
  // A torque: w + dt tau / I, as the sphere's inv_I gives.
  const Vec3 tau(0.2, 0.5, -0.1);
  const Vec3 wt = free_angular_velocity(m, q, w, tau, 0.05);
  EXPECT_LE((wt - (w + 0.05 * tau / I)).norm(), 8 * kEps * w.norm());

  // 1000 steps at dt |w| = 0.1: w unchanged, q the rotation by t |w| about w.
  RotationState st{q, w};
  const double dt = 0.1 / w.norm();
  st = run(m, st, dt, 1000);
  EXPECT_EQ(std::memcmp(st.w.data(), w.data(), sizeof(Vec3)), 0);
  const Quat exact = Quat(Eigen::AngleAxisd(1000 * dt * w.norm(), w.normalized())) * q;
  EXPECT_LT(exact.angularDistance(st.q), 1e-12);
}

// I_w^-1 (R e_k) = R e_k / I_k with R e_k the principal axis turned by the
// quaternion (q e_k q*), independent of the matrix: a transposed R fails.
// The midpoint's is the same at exp((dt/2) w) q; both exactly symmetric.
TEST(RigidRotation, WorldInverseInertiaTurnsThePrincipalAxes) {
  const Vec3 m(0.8, 1.9, 2.6);
  const Quat q = generic_orientation();
  const Mat3 Winv = world_inverse_inertia(m, q);
  const Mat3 W = world_inertia(m, q);
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = q * Vec3::Unit(k);
    EXPECT_LE((Winv * a - a / m[k]).norm(), 8 * kEps / m[0]) << "axis " << k;
    EXPECT_LE((W * a - a * m[k]).norm(), 8 * kEps * m[2]) << "axis " << k;
  }
  EXPECT_LE((W * Winv - Mat3::Identity()).cwiseAbs().maxCoeff(), 16 * kEps * m[2] / m[0]);
  EXPECT_TRUE(Winv == Winv.transpose());
  EXPECT_TRUE(W == W.transpose());

  const Vec3 w(1.0, -4.0, 2.0);
  const double dt = 0.03;
  const Quat qm = Quat(Eigen::AngleAxisd(0.5 * dt * w.norm(), w.normalized())) * q;
  const Mat3 Mm = midpoint_inverse_inertia(m, q, w, dt);
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = qm * Vec3::Unit(k);
    EXPECT_LE((Mm * a - a / m[k]).norm(), 16 * kEps / m[0]) << "axis " << k;
  }
}

// A free symmetric top, I1 = I2 != I3: in the body, w3 is constant and
// (w1, w2) turns at Omega = (I3 - I1)/I1 w3; in the world the body turns
// about the fixed L at |L|/I1: R(t) = exp(t [L/I1]x) R0 exp(-Omega t [e3]x).
// Errors at T = 5 (7 precession radians, 3 turns of the body about L)
// for dt = T/200, T/400, T/800: the scheme is second order, each halving
// divides them by 4 (3.6-4.4 allowed: the leading term dominates, the
// next is dt^2 smaller); the finest has to be small (1e-3) too.
TEST(RigidRotation, SymmetricTopPrecessesAtTheClosedFormRate) {
  const Vec3 I(1.0, 1.0, 1.7);
  const Vec3 wb0(0.6, -0.3, 2.0);
  const double Omega = (I[2] - I[0]) / I[0] * wb0[2];
  const Quat q0 = generic_orientation();
  const RotationState s0 = state(q0, wb0);
  const Vec3 L0 = momentum(I, s0);
  const double T = 5.0;
  const Quat qT = Quat(Eigen::AngleAxisd(T * L0.norm() / I[0], L0.normalized())) * q0 *
                  Quat(Eigen::AngleAxisd(-Omega * T, Vec3::UnitZ()));
  const double c = std::cos(Omega * T), s = std::sin(Omega * T);
  const Vec3 wbT(c * wb0[0] - s * wb0[1], s * wb0[0] + c * wb0[1], wb0[2]);

  double ew[3], eq[3], eL[3];
  for (int k = 0; k < 3; ++k) {
    const int n = 200 << k;
    const RotationState sT = run(I, s0, T / n, n);
    ew[k] = (body_w(sT) - wbT).norm() / wb0.norm();
    eq[k] = qT.angularDistance(sT.q);
    eL[k] = (momentum(I, sT) - L0).norm() / L0.norm();
    std::printf("symmetric top, dt = T/%d: |w_b error| %.3e, orientation %.3e rad, |L error| %.3e\n", n, ew[k],
                eq[k], eL[k]);
  }
  for (const double* e : {ew, eq, eL}) {
    EXPECT_LT(e[2], 1e-3);
    for (int k = 0; k < 2; ++k) {
      EXPECT_GT(e[k] / e[k + 1], 3.6) << "step " << k;
      EXPECT_LT(e[k] / e[k + 1], 4.4) << "step " << k;
    }
  }
}

// The tennis racket: I = (1, 2, 3) spun at w = 10 about the intermediate
// axis, perturbed by 1e-3 w on the others, flips: w2 changes sign every
// half period. Closed form (Landau & Lifshitz, Mechanics, section 37; here
// L^2 > 2 E I2): w2 is proportional to sn(tau, k), tau = t sqrt((I3 - I2)
// (L^2 - 2 E I1)/(I1 I2 I3)), k^2 = (I2 - I1)(2 E I3 - L^2)/((I3 - I2)(L^2 -
// 2 E I1)), so successive sign changes are 2 K(k) apart in tau. The first
// one's time depends on the phase: the reference is RK4 on Euler's
// equations at dt w = 1e-4 (error ~ (dt w)^4 relative, far below what is
// checked). The scheme at dt w = 0.02 (second order: ~(dt w)^2 / 50,
// 7e-6 measured) must give the first three sign changes within 1e-4 of
// RK4's and their spacing within 1e-4 of the closed form; RK4's spacing
// agrees with it within 1e-7 (4e-9 measured).
TEST(RigidRotation, IntermediateAxisFlipsAtTheClosedFormPeriod) {
  const Vec3 I(1.0, 2.0, 3.0);
  const double w = 10.0, eps = 1e-3;
  const Vec3 wb0(eps * w, w, eps * w);
  const double E2 = I.dot(wb0.cwiseAbs2()), L2 = I.cwiseProduct(wb0).squaredNorm();
  ASSERT_GT(L2, E2 * I[1]);
  const double rate = std::sqrt((I[2] - I[1]) * (L2 - E2 * I[0]) / (I[0] * I[1] * I[2]));
  const double k = std::sqrt((I[1] - I[0]) * (E2 * I[2] - L2) / ((I[2] - I[1]) * (L2 - E2 * I[0])));
  const double half_period = 2.0 * std::comp_ellint_1(k) / rate;

  const double T = 10.0;
  const double href = 1e-4 / w;
  const auto ref = sign_changes(wb0, href, T, 3, [&](const Vec3& x) { return rk4(I, x, href); });
  ASSERT_EQ(ref.size(), 3u);
  const double h = 0.02 / w;
  RotationState s = state(generic_orientation(), wb0);
  const auto ours = sign_changes(wb0, h, T, 3, [&](const Vec3&) {
    s = free_rotation_step(I, s, Vec3::Zero(), h);
    return body_w(s);
  });
  ASSERT_EQ(ours.size(), 3u);
  for (int n = 0; n < 3; ++n) {
    std::printf("intermediate axis: sign change %d at t = %.6f (RK4 %.6f), relative error %.2e\n", n, ours[n],
                ref[n], std::abs(ours[n] / ref[n] - 1.0));
    EXPECT_LT(std::abs(ours[n] / ref[n] - 1.0), 1e-4) << "sign change " << n;
  }
  for (int n = 0; n < 2; ++n) {
    const double ours_half = ours[n + 1] - ours[n], ref_half = ref[n + 1] - ref[n];
    std::printf("half period %.6f (RK4 %.8f, closed form %.8f)\n", ours_half, ref_half, half_period);
    EXPECT_LT(std::abs(ref_half / half_period - 1.0), 1e-7);
    EXPECT_LT(std::abs(ours_half / half_period - 1.0), 1e-4);
  }
}

// About the major (3) and minor (1) axes the spin is stable: with the
// energy and |L| conserved, I_i (I_k - I_i) w_i^2 + I_j (I_k - I_j) w_j^2 =
// L^2 - 2 E I_k is conserved too (k the spin axis, i, j the others): an
// ellipse, whose largest radius bounds the perturbation. 10^4 steps at
// dt w = 0.1: the perturbation stays on it within 1e-9 (round-off of the
// cancellation L^2 - 2 E I_k between numbers 10^6 times larger: 3e-11 to
// 7e-11 measured), never beyond its largest radius, and w_k keeps its sign.
TEST(RigidRotation, MajorAndMinorAxesAreStable) {
  const Vec3 I(1.0, 2.0, 3.0);
  const double w = 10.0, eps = 1e-3;
  for (const int k : {0, 2}) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    Vec3 wb = Vec3::Constant(eps * w);
    wb[k] = w;
    const double ci = I[i] * std::abs(I[k] - I[i]), cj = I[j] * std::abs(I[k] - I[j]);
    const auto ellipse = [&](const Vec3& x) { return ci * x[i] * x[i] + cj * x[j] * x[j]; };
    const double C0 = ellipse(wb);
    const double radius = std::sqrt(C0 / std::min(ci, cj));
    RotationState s = state(generic_orientation(), wb);
    const double h = 0.1 / w;
    double worst = 0.0, largest = 0.0;
    for (int n = 0; n < 10000; ++n) {
      s = free_rotation_step(I, s, Vec3::Zero(), h);
      const Vec3 b = body_w(s);
      worst = std::max(worst, std::abs(ellipse(b) / C0 - 1.0));
      largest = std::max(largest, std::hypot(b[i], b[j]));
      ASSERT_GT(b[k], 0.0) << "axis " << k << ", step " << n;
    }
    std::printf("axis %d: ellipse kept within %.2e, largest perturbation %.3e w (ellipse's radius %.3e w)\n", k,
                worst, largest / w, radius / w);
    EXPECT_LT(worst, 1e-9) << "axis " << k;
    EXPECT_LT(largest, radius * (1.0 + 1e-9)) << "axis " << k;
  }
}

// The step rejected for the engine (rigid_rotation.hpp): one linearised
// backward Euler step in the principal frame, (I + dt (w x I - (I w) x)) d =
// -dt w x I w (Bullet's integrateGyroscopicImplicit), kept here to measure
// what it does to a free body.
Vec3 linearised_backward_euler(const Vec3& I, const Vec3& wb, double dt) {
  const auto skew = [](const Vec3& a) {
    Mat3 S;
    S << 0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0;
    return S;
  };
  const Mat3 J = Mat3(I.asDiagonal()) + dt * (skew(wb) * I.asDiagonal() - skew(I.cwiseProduct(wb)));
  return wb + J.partialPivLu().solve(-dt * wb.cross(I.cwiseProduct(wb)));
}

// A fast asymmetric spin, I = (1, 2, 3), w near the intermediate axis
// (it tumbles), dt |w| = 0.3, 10^4 steps. The implicit midpoint conserves
// the energy and |L|: no step adds more than 1e-14 E0 (the round-off of E
// itself, computed from q and w: ~10 epsilon measured), and both end within
// 1e-12 of their start (1.3e-14 and 1.1e-14 measured); at most 5 Newton
// iterations (4 measured). The explicit variant adds dt^2 sum g_k^2/(2 I_k)
// at every step: the energy rises at every step and has gained more than
// 10% within 200 steps (x10 measured). The rejected linearised backward Euler
// never adds energy but takes angular momentum away: more than 10%
// (|L| = 0.31 |L0|, E = 0.07 E0 at the end, spinning about the major axis).
TEST(RigidRotation, ImplicitNeverAddsEnergyExplicitDoes) {
  const Vec3 I(1.0, 2.0, 3.0);
  const Vec3 wb0(0.1, 10.0, 0.3);
  const double h = 0.3 / wb0.norm();
  const RotationState s0 = state(generic_orientation(), wb0);
  const double E0 = energy(I, s0), L0 = momentum(I, s0).norm();

  RotationState s = s0;
  double E = E0, worst_rise = 0.0, worst_L = 0.0;
  int most_iterations = 0, flips = 0;
  for (int n = 0; n < 10000; ++n) {
    const Quat qm = rotate_orientation(s.q, s.w, 0.5 * h);
    most_iterations =
        std::max(most_iterations, solve_free_angular_velocity(I, qm, s.w, Vec3::Zero(), h).iterations);
    const double w2 = body_w(s)[1];
    s = free_rotation_step(I, s, Vec3::Zero(), h);
    if ((w2 > 0.0) != (body_w(s)[1] > 0.0)) ++flips;
    const double En = energy(I, s);
    worst_rise = std::max(worst_rise, (En - E) / E0);
    worst_L = std::max(worst_L, std::abs(momentum(I, s).norm() / L0 - 1.0));
    E = En;
  }
  std::printf("implicit: largest rise in a step %.2e E0, E/E0 - 1 = %.2e, |L| within %.2e, <= %d Newton "
              "iterations, %d flips\n",
              worst_rise, E / E0 - 1.0, worst_L, most_iterations, flips);
  EXPECT_LE(worst_rise, 1e-14);
  EXPECT_LT(std::abs(E / E0 - 1.0), 1e-12);
  EXPECT_LT(worst_L, 1e-12);
  EXPECT_LE(most_iterations, 5);
  EXPECT_GT(flips, 10);  // it tumbles: not a steady spin, the gyroscopic term works

  s = s0;
  E = E0;
  int rises = 0, n = 0;
  for (; n < 200 && std::isfinite(E); ++n) {
    s = free_rotation_step(I, s, Vec3::Zero(), h, Gyroscopic::Explicit);
    const double En = energy(I, s);
    if (En > E) ++rises;
    E = En;
  }
  std::printf("explicit: energy rose at %d of %d steps, E/E0 = %.3g\n", rises, n, E / E0);
  EXPECT_EQ(rises, n);
  EXPECT_TRUE(!std::isfinite(E) || E > 1.1 * E0);

  Vec3 wb = wb0;
  for (int m = 0; m < 10000; ++m) wb = linearised_backward_euler(I, wb, h);
  const double Lbe = I.cwiseProduct(wb).norm() / L0, Ebe = 0.5 * I.dot(wb.cwiseAbs2()) / E0;
  std::printf("linearised backward Euler: |L|/|L0| = %.3f, E/E0 = %.3f\n", Lbe, Ebe);
  EXPECT_LT(Lbe, 0.9);
}

// Newton's iterations, over 200 directions of w (|w| = 10): at most 4 at
// dt |w| <= 0.5 and 7 at dt |w| = 3 for I = (1, 2, 3) and a flat (0.2, 1,
// 1.1); 2 for a symmetric top (1, 1, 10), whose midpoint equation is
// linear in w (w3 constant); always converged.
TEST(RigidRotation, NewtonConvergesInAFewIterations) {
  struct Case {
    Vec3 I;
    double hw;
    int most;
  };
  for (const Case& c : {Case{{1.0, 2.0, 3.0}, 0.5, 4}, Case{{1.0, 2.0, 3.0}, 3.0, 7},
                        Case{{0.2, 1.0, 1.1}, 0.5, 4}, Case{{0.2, 1.0, 1.1}, 3.0, 7},
                        Case{{1.0, 1.0, 10.0}, 3.0, 2}}) {
    int most = 0;
    for (int a = 0; a < 200; ++a) {
      const Vec3 w =
          10.0 * Vec3(std::sin(1.3 * a), std::cos(0.7 * a), std::sin(2.1 * a + 1.0)).normalized();
      const GyroscopicSolve s =
          solve_free_angular_velocity(c.I, generic_orientation(), w, Vec3::Zero(), c.hw / 10.0);
      ASSERT_TRUE(s.converged) << "I = " << c.I.transpose() << ", dt |w| = " << c.hw;
      most = std::max(most, s.iterations);
    }
    EXPECT_LE(most, c.most) << "I = " << c.I.transpose() << ", dt |w| = " << c.hw;
  }
}

// The same input gives the same bits: one solve twice, and 1000 steps twice.
TEST(RigidRotation, Deterministic) {
  const Vec3 I(1.0, 2.0, 3.0);
  const Quat q = generic_orientation();
  const Vec3 w(0.3, 9.0, -1.1), tau(0.5, -0.2, 0.1);
  const Vec3 a = free_angular_velocity(I, q, w, tau, 0.02);
  const Vec3 b = free_angular_velocity(I, q, w, tau, 0.02);
  EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(Vec3)), 0);
  const RotationState s0{q, w};
  const RotationState r1 = run(I, s0, 0.02, 1000), r2 = run(I, s0, 0.02, 1000);
  EXPECT_EQ(std::memcmp(r1.w.data(), r2.w.data(), sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(r1.q.coeffs().data(), r2.q.coeffs().data(), 4 * sizeof(double)), 0);
}
