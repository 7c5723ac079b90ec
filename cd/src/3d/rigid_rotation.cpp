#include "rigid_rotation.hpp"

#include <algorithm>

namespace cd {

namespace {

// R diag(d) R^T, each entry below the diagonal the mirror of the one above
// it, so that the result is exactly symmetric (it goes into W blocks).
Eigen::Matrix3d congruence(const Eigen::Matrix3d& R, const Vec3& d) {
  Eigen::Matrix3d A;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const double a = R(i, 0) * d[0] * R(j, 0) + R(i, 1) * d[1] * R(j, 1) + R(i, 2) * d[2] * R(j, 2);
      A(i, j) = a;
      A(j, i) = a;
    }
  return A;
}

// The gyroscopic torque w x (I w) in the principal frame, in Euler's form:
// each component carries a difference of moments, so that equal moments
// give exactly zero (a sphere's, or a symmetric top's about its axis).
Vec3 gyroscopic(const Vec3& I, const Vec3& w) {
  return Vec3((I[2] - I[1]) * w[1] * w[2], (I[0] - I[2]) * w[2] * w[0], (I[1] - I[0]) * w[0] * w[1]);
}

// Its Jacobian with respect to w.
Eigen::Matrix3d gyroscopic_jacobian(const Vec3& I, const Vec3& w) {
  const double a = I[2] - I[1], b = I[0] - I[2], c = I[1] - I[0];
  Eigen::Matrix3d G;
  G << 0.0, a * w[2], a * w[1],  //
      b * w[2], 0.0, b * w[0],   //
      c * w[1], c * w[0], 0.0;
  return G;
}

}  // namespace

Quat rotate_orientation(const Quat& q, const Vec3& w, double h) {
  const double a = h * w.norm();
  if (a == 0.0) return q;
  Quat r = Quat(Eigen::AngleAxisd(a, w.normalized())) * q;
  r.normalize();
  return r;
}

Eigen::Matrix3d world_inertia(const Vec3& moments, const Quat& q) {
  return congruence(q.toRotationMatrix(), moments);
}

Eigen::Matrix3d world_inverse_inertia(const Vec3& moments, const Quat& q) {
  return congruence(q.toRotationMatrix(), moments.cwiseInverse());
}

Eigen::Matrix3d midpoint_inverse_inertia(const Vec3& moments, const Quat& q, const Vec3& w, double dt) {
  return world_inverse_inertia(moments, rotate_orientation(q, w, 0.5 * dt));
}

// Newton on F(d) = I d + dt (g(w + d/2) - tau) = 0 for the increment d of the
// principal-frame angular velocity, from d = 0 (the first iterate is the
// linearised midpoint step). The increment goes back to the world frame
// alone (w + R d): with d = 0 exactly, w comes back bit for bit.
GyroscopicSolve solve_free_angular_velocity(const Vec3& moments, const Quat& q_m, const Vec3& w,
                                            const Vec3& tau, double dt) {
  // A correction below this, relative to |w|, leaves an error of its square
  // (Newton's quadratic convergence): the solution to round-off.
  constexpr double kTol = 1e-13;
  const Eigen::Matrix3d R = q_m.toRotationMatrix();
  const Vec3 wb = R.transpose() * w;
  const Vec3 tb = R.transpose() * tau;
  const Vec3& I = moments;
  GyroscopicSolve out;
  Vec3 d = Vec3::Zero();
  while (out.iterations < GyroscopicSolve::kMaxIterations) {
    const Vec3 wt = wb + 0.5 * d;
    const Vec3 F = I.cwiseProduct(d) + dt * (gyroscopic(I, wt) - tb);
    Eigen::Matrix3d J = 0.5 * dt * gyroscopic_jacobian(I, wt);
    J.diagonal() += I;
    const Vec3 delta = J.partialPivLu().solve(F);
    d -= delta;
    ++out.iterations;
    const double scale = std::max(wb.cwiseAbs().maxCoeff(), (wb + d).cwiseAbs().maxCoeff());
    if (delta.cwiseAbs().maxCoeff() <= kTol * scale) {
      out.converged = true;
      break;
    }
  }
  out.w = w + R * d;
  return out;
}

Vec3 free_angular_velocity_explicit(const Vec3& moments, const Quat& q_m, const Vec3& w, const Vec3& tau,
                                    double dt) {
  const Eigen::Matrix3d R = q_m.toRotationMatrix();
  const Vec3 wb = R.transpose() * w;
  const Vec3 d = dt * (R.transpose() * tau - gyroscopic(moments, wb)).cwiseQuotient(moments);
  return w + R * d;
}

RotationState free_rotation_step(const Vec3& moments, const RotationState& s, const Vec3& tau, double dt,
                                 Gyroscopic g) {
  const double h = 0.5 * dt;
  const Quat qm = rotate_orientation(s.q, s.w, h);
  RotationState out;
  out.w = g == Gyroscopic::Explicit ? free_angular_velocity_explicit(moments, qm, s.w, tau, dt)
                                    : free_angular_velocity(moments, qm, s.w, tau, dt);
  out.q = rotate_orientation(qm, out.w, h);
  return out;
}

}  // namespace cd
