// Rotation of a rigid body with a full inertia tensor: the world-frame
// inverse inertia at an orientation, the free angular velocity of one
// Moreau-Jean step with the gyroscopic torque, and the orientation update.
// Used by no body of the engine yet (spheres keep their scalar inertia,
// BodyVel3::inv_I); the polyhedra will use it (docs/3d.md, "Rotation with a
// full inertia tensor").
//
// Frames. The body's principal moments (I1, I2, I3) are given in its
// principal frame; the orientation q maps principal-frame coordinates to the
// world, R = R(q), so that I_w = R diag(I) R^T. (A ConvexPolyhedron's
// principal_axes() is the rotation from the principal frame to the centroid
// frame: the body's q is then its centroid frame's orientation times that.)
//
// The step (the midpoint scheme of docs/method.md, section 6, in 3D): q_m =
// exp((dt/2) w-) q; the contacts and I_w^-1 are taken at q_m; the free
// velocity solves, at the fixed inertia I_m = I_w(q_m),
//     I_m (w_free - w-) = dt (tau - w_t x I_m w_t),   w_t = (w- + w_free)/2,
// the implicit midpoint rule, solved by Newton's method to round-off (in the
// principal frame, where I_m is diagonal); then q+ = exp((dt/2) w+) q_m.
// The midpoint rule conserves the energy w^T I_m w and |I_m w| of a free
// body exactly (both are quadratic invariants of the frozen-inertia Euler
// equations), and the two half rotations about w- and w+ leave them as they
// are, so the energy and |L| at the ends of the steps stay those of the
// first step to round-off at any step. Rejected: one linearised step of
// backward Euler (Bullet's integrateGyroscopicImplicit), stable but
// dissipative: a free body spun near its intermediate axis at dt |w| = 0.3
// kept 0.31 of its angular momentum after 10^4 steps and ended spinning
// about its major axis, a torque where there is none (test_rigid_rotation);
// one linearised step of the midpoint rule keeps the second order but
// neither invariant (its energy moves by O((dt |w|)^3) E a step, both
// ways). Newton, from that linearised step, takes at most 4 solves of 3x3
// systems at dt |w| <= 0.5 (2 for a symmetric top, whose equation is
// linear), 7 at dt |w| = 3, and may not converge beyond; only bodies that
// are not spheres pay for it.
#pragma once
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "bodies3.hpp"

namespace cd {

// exp(h w) q: the rotation by the angle h |w| about w (world frame), then
// renormalised; the same as World3's orientation update.
Quat rotate_orientation(const Quat& q, const Vec3& w, double h);

// I_w = R diag(moments) R^T and its inverse R diag(1/moments) R^T, R = R(q)
// (moments > 0). For equal moments I, the inverse is 1/I times the identity
// to round-off: a sphere needs none of this.
Eigen::Matrix3d world_inertia(const Vec3& moments, const Quat& q);
Eigen::Matrix3d world_inverse_inertia(const Vec3& moments, const Quat& q);

// The inverse inertia where the contacts of a step of dt are built: at the
// midpoint q_m = exp((dt/2) w) q.
Eigen::Matrix3d midpoint_inverse_inertia(const Vec3& moments, const Quat& q, const Vec3& w, double dt);

// The implicit midpoint solve: the free angular velocity (world frame) and
// the Newton iterations it took. converged is false if the correction was
// not below round-off after kMaxIterations (dt |w| of order 1 and more: a
// step far beyond what contacts allow); w is then the last iterate, and a
// caller should refuse the step.
struct GyroscopicSolve {
  Vec3 w = Vec3::Zero();
  int iterations = 0;
  bool converged = false;
  static constexpr int kMaxIterations = 20;
};

// w_free of a step of dt from w- = w under the external torque tau (world
// frame), the inertia taken at q_m (the step's midpoint orientation), the
// gyroscopic torque by the implicit midpoint rule (above).
GyroscopicSolve solve_free_angular_velocity(const Vec3& moments, const Quat& q_m, const Vec3& w,
                                            const Vec3& tau, double dt);
inline Vec3 free_angular_velocity(const Vec3& moments, const Quat& q_m, const Vec3& w, const Vec3& tau,
                                  double dt) {
  return solve_free_angular_velocity(moments, q_m, w, tau, dt).w;
}

// The explicit variant, w + dt I_m^-1 (tau - w x I_m w): it adds the energy
// dt^2 sum_k g_k^2 / (2 I_k) to a free body at every step (g the gyroscopic
// torque, principal frame) and blows up a fast asymmetric spin. For the
// tests, which show the difference; not for the engine.
Vec3 free_angular_velocity_explicit(const Vec3& moments, const Quat& q_m, const Vec3& w, const Vec3& tau,
                                    double dt);

enum class Gyroscopic : std::uint8_t { ImplicitMidpoint, Explicit };

// One whole step of a body without contacts: predict q_m, free velocity at
// q_m, integrate. What the engine's stages will do for such a body.
struct RotationState {
  Quat q = Quat::Identity();
  Vec3 w = Vec3::Zero();
};
RotationState free_rotation_step(const Vec3& moments, const RotationState& s, const Vec3& tau, double dt,
                                 Gyroscopic g = Gyroscopic::ImplicitMidpoint);

}  // namespace cd
