// Contacts: the hot row the NLGS sweep works on, and the cold record kept for
// warm starts and output.
//
// Frame: n points from body 1 to body 2, t = n rotated by +90 degrees. The
// relative velocity at the contact point is
//   u = (U2 + w2 x c2) - (U1 + w1 x c1),
// with c_i the vector from the centre of body i to the contact point; in the
// frame (c_in = c_i.n, c_it = c_i.t):
//   u_n = n.(U2 - U1) - w2 c2t + w1 c1t
//   u_t = t.(U2 - U1) + w2 c2n - w1 c1n
// so that the Delassus block W = H^T M^-1 H of one contact is
//   W_nn = 1/m1 + 1/m2 + c1t^2/I1 + c2t^2/I2
//   W_tt = 1/m1 + 1/m2 + c1n^2/I1 + c2n^2/I2
//   W_nt = -(c1n c1t/I1 + c2n c2t/I2)
// (tests/test_local_solver.cpp checks this against the assembled H^T M^-1 H).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

namespace cd {

// Hot row: everything one local solve reads or writes. Impulses p = f dt.
struct ContactRow {
  std::int32_t b1, b2;
  double nx, ny;
  double c1n, c1t, c2n, c2t;
  double wnn, wnt, wtt;
  double bn, bt;   // constant velocity offsets of the law: restitution and gap terms
  double pn, pt;   // impulses over the step
  double mu;       // friction coefficient
  double adh;      // adhesion impulse f_a dt (0 in non-cohesive scenes)
};

enum class ContactType : std::uint8_t { Disk = 0, SideVertex = 1, SideSide = 2 };

// Cold record, same index as the row.
struct ContactInfo {
  std::uint64_t key;     // (b1, b2, point) for warm start
  double gap;            // signed gap at the midpoint configuration (< 0: overlap)
  double px, py;         // contact point (midpoint configuration)
  ContactType type;
  // Branch vector from the centre of body 1 to the centre of body 2, or of
  // the periodic image of body 2 that is touched (midpoint configuration).
  double lx = 0.0, ly = 0.0;
  // That image, in cells: body 2 is seen shifted by ix widths and iy heights
  // (iy = +-1 across a Lees-Edwards boundary also shifts x by the offset).
  std::int8_t ix = 0, iy = 0;
};

inline std::uint64_t contact_key(std::int32_t b1, std::int32_t b2, int point) {
  return (static_cast<std::uint64_t>(b1) << 34) | (static_cast<std::uint64_t>(b2) << 4) |
         static_cast<std::uint64_t>(point);
}

// The same contact seen from its other body: body 1 and 2 swapped, n and t
// reversed, lever arms re-expressed in the reversed frame (c1' = c2, so
// c1n' = c2.(-n) = -c2n). Impulses must still be zero (detection only).
inline void reverse_contact(ContactRow& r, ContactInfo& f) {
  std::swap(r.b1, r.b2);
  r.nx = -r.nx;
  r.ny = -r.ny;
  const double c1n = r.c1n, c1t = r.c1t;
  r.c1n = -r.c2n;
  r.c1t = -r.c2t;
  r.c2n = -c1n;
  r.c2t = -c1t;
  f.key = contact_key(r.b1, r.b2, static_cast<int>(f.key & 0xF));
}

// Status of a solved contact, for output: 0 open, 1 stick, 2 slide.
enum class ContactStatus : std::uint8_t { Open = 0, Stick = 1, Slide = 2 };

}  // namespace cd
