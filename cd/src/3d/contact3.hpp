// 3D contacts: the hot row the NLGS sweep works on and the cold record kept
// for warm starts and output (the 3D sibling of 2d/contact.hpp).
//
// Frame: n points from body 1 to body 2; (t1, t2) complete it to a
// right-handed orthonormal basis, built from n alone without a branch near
// the poles (Duff et al., "Building an orthonormal basis, revisited", JCGT
// 2017: Frisvad's construction with its singularity at n_z = -1 removed).
// The relative velocity at the contact point is
//     u = (v2 + w2 x c2) - (v1 + w1 x c1),
// c_i from the centre of body i to the contact point, and in the frame
// (rows of F = [n; t1; t2]) u_loc = F u. An impulse r (frame components) on
// body 2, -r on body 1, changes it by W r with the Delassus block
//     W = F ( (1/m1 + 1/m2) I + sum_i (1/I_i)(|c_i|^2 I - c_i c_i^T) ) F^T
// (scalar inertia). For spheres c_i is parallel to n, so W = diag(W_nn,
// W_tt, W_tt) with W_nn = 1/m1 + 1/m2 and W_tt = W_nn + |c1|^2/I1 +
// |c2|^2/I2: the row keeps these two numbers (tests/test_world3.cpp checks
// them against the assembled H^T M^-1 H).
#pragma once
#include <cmath>
#include <cstdint>

#include "bodies3.hpp"

namespace cd {

// Orthonormal t1, t2 with (n, t1, t2) right-handed, for a unit n (Duff et al. 2017).
inline void orthonormal_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  const double s = std::copysign(1.0, n.z());
  const double a = -1.0 / (s + n.z());
  const double b = n.x() * n.y() * a;
  t1 = Vec3(1.0 + s * n.x() * n.x() * a, s * b, -s * n.x());
  t2 = Vec3(b, s + n.y() * n.y() * a, -n.y());
}

// Hot row: everything one local solve reads or writes. Impulses r = f dt in
// the frame (n, t1, t2).
struct SphereRow {
  std::int32_t b1, b2;
  Vec3 n, t1, t2;
  Vec3 c1, c2;     // lever arms (centre of body i to the contact point)
  double wnn, wtt; // the Delassus block diag(wnn, wtt, wtt)
  double bn;       // constant normal velocity offset of the law (gap term,
                   // restitution, image velocity)
  Vec3 r;          // impulse over the step, frame components
  double mu;       // friction coefficient (round cone; orthotropic: along t1)
  double adh;      // adhesion impulse f_a dt (0 in non-cohesive scenes)

  Vec3 to_frame(const Vec3& x) const { return {n.dot(x), t1.dot(x), t2.dot(x)}; }
  Vec3 to_world(const Vec3& x) const { return x[0] * n + x[1] * t1 + x[2] * t2; }
};

// What a row needs only in scenes that ask for it: tangential offsets of
// the law (tangential restitution, moving periodic images) and the second
// coefficient of an orthotropic cone. Kept apart from the hot row, same
// index, filled only in such scenes and read only by the law instances that
// use it (coupling3.hpp), so that a scene without these options streams the
// same rows through the sweep as before they existed.
struct RowExtra3 {
  double bt1 = 0.0, bt2 = 0.0;  // tangential offsets, frame components
  double mu_b = 0.0;            // friction along t2 (= mu for a round cone)
};

// The row as the NLGS sweep streams it (coupling3.hpp; made from a
// SphereRow and its bodies once per solve by contact_problem3.cpp's
// nlgs_solve3, the impulse and b_n given back after). For spheres the lever
// arms are along n, c_i = l_i n with l_i = c_i.n (l1 > 0, l2 < 0 between
// spheres), so with dv = v2 - v1 and om = l2 w2 - l1 w1 the relative
// velocity in the frame is
//     u = (n.dv, t1.dv + t2.om, t2.dv - t1.om)      (n x t1 = t2)
// (w x c = l w x n, and t1.(w x n) = w.t2, t2.(w x n) = -w.t1), and an
// impulse change dr (frame components) on body 2, -dr on body 1, changes
// body 2 by (inv_m2 P, inv_I2 l2 T) and body 1 by -(inv_m1 P, inv_I1 l1 T),
//     P = dr_n n + dr_t1 t1 + dr_t2 t2,   T = n x P = dr_t1 t2 - dr_t2 t1:
// 5 dot products and 2 vector updates in place of 2 cross products, 3 dot
// products and 2 cross products again (the same quantities to round-off).
// The block enters through its reciprocals (the stick trial is r - W^-1 u).
// A plane's lever arm is not along n, but a plane neither turns nor is
// turned (w = 0, inv_I = 0): its l is never used (make_sweep_row3 checks).
// 160 bytes against SphereRow's 192; the frame stays stored (rebuilding it
// from n costs a division, and orthotropic scenes turn it).
struct SweepRow3 {
  Vec3 n, t1, t2;
  double l1, l2;      // c1.n, c2.n
  double iwnn, iwtt;  // 1 / W_nn, 1 / W_tt
  double bn, mu;
  std::int32_t b1, b2;
  Vec3 r;
  double adh;
};

// Cold record, same index as the row.
struct ContactInfo3 {
  std::uint64_t key;  // (b1, b2): one contact a pair of spheres or sphere and plane
  double gap;         // signed gap at the midpoint configuration (< 0: overlap)
  Vec3 point;         // contact point (midpoint configuration)
  Vec3 branch;        // from the centre of body 1 to the centre of body 2 (plane: to the sphere's foot)
  // Periodic image of body 2 the contact is with: its position is x2 + ix
  // L_x e_x + iy (L_y e_y + le_offset e_x) + iz L_z e_z (0, 0, 0: itself).
  std::int8_t ix = 0, iy = 0, iz = 0;
  // A polyhedron's contact point: its feature key (polyhedron_contact.hpp),
  // which names it within its pair (key) from step to step; 0 otherwise.
  std::uint64_t feature = 0;
  // A polyhedron's contact: 1 + its PolyContactKind (1 vertex-face, 2
  // edge-face, 3 face-face, 4 edge-edge; with a sphere: 1 on a face, 5 on
  // an edge, 6 on a vertex); 0: two spheres', or a sphere's and a plane's.
  std::uint8_t kind = 0;
};

inline std::uint64_t contact_key3(std::int32_t b1, std::int32_t b2) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(b1)) << 32) |
         static_cast<std::uint32_t>(b2);
}

// Relative velocity of a row's contact point, world frame.
inline Vec3 relative_velocity(const SphereRow& r, const BodyVel3& A, const BodyVel3& B) {
  return B.v + B.w.cross(r.c2) - A.v - A.w.cross(r.c1);
}

// The Delassus block of a row from its lever arms and its bodies.
inline void set_block(SphereRow& r, const BodyVel3& A, const BodyVel3& B) {
  r.wnn = A.inv_m + B.inv_m;
  r.wtt = r.wnn + A.inv_I * r.c1.squaredNorm() + B.inv_I * r.c2.squaredNorm();
}

}  // namespace cd
