// 3D contact detection at the midpoint configuration: an O(N) cell list
// (uniform grid of side 2 r_max + alert over the spheres' bounding box)
// for sphere-sphere pairs, then every plane against every sphere. Output
// order is fixed whatever the thread count: sphere pairs in cell order
// (z, y, x slabs; each thread takes a contiguous range of z slabs and the
// per-thread lists are joined in thread order), then planes in index order
// with spheres in index order.
#pragma once
#include <array>
#include <vector>

#include "bodies3.hpp"
#include "cell_grid.hpp"
#include "contact3.hpp"

namespace cd {

// A periodic cell for detection: along each axis a with periodic[a], body
// j is also met through its images x_j + kx L_x e_x + ky (L_y e_y +
// le_offset e_x) + kz L_z e_z (Lees-Edwards: the images across y are
// shifted along x by le_offset; 0 without shear). Each periodic length must
// be >= 2 (2 r_max + alert), so that a pair meets through one image at most
// (std::invalid_argument otherwise).
struct PeriodicCell3 {
  Vec3 origin = Vec3::Zero(), size = Vec3::Zero();
  std::array<bool, 3> periodic{false, false, false};
  double le_offset = 0.0;
  bool any() const { return periodic[0] || periodic[1] || periodic[2]; }
  // The image counts (kx, ky, kz) of x2 nearest to x1, and that image.
  Vec3 nearest_image(const Vec3& x1, const Vec3& x2, std::array<int, 3>& k) const;
  // x moved into the cell along the periodic axes (an image of x), with its counts.
  Vec3 wrap(const Vec3& x, std::array<int, 3>& k) const;
  Vec3 shift(const std::array<int, 3>& k) const {
    return {k[0] * size.x() + k[1] * le_offset, k[1] * size.y(), k[2] * size.z()};
  }
};

// Scratch kept between steps to avoid reallocation (core/cell_grid.hpp).
using CellGrid3 = CellGridScratch<SphereRow, ContactInfo3>;

// Candidate contacts with gap <= alert among the bodies at positions x.
// Fills geometry only (b1, b2, frame, lever arms, gap, point, branch; r,
// bn, adh zero); the caller fills W blocks, offsets and impulses. A driven
// body is always body 1. Loops run on one thread below min_parallel bodies.
void detect3(const Bodies3& bodies, const std::vector<Vec3>& x, double alert, CellGrid3& grid,
             std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info, int min_parallel);
// The same with a periodic cell (cell.any(); otherwise the call above): each
// sphere pair once, with body 2's nearest image (info.ix, iy, iz; the frame,
// lever arms, gap and branch are those with that image). Planes are not
// imaged. Output order fixed whatever the thread count (cells in (z, y, x)
// order, a pair at the cell of its lower-index sphere).
void detect3(const Bodies3& bodies, const std::vector<Vec3>& x, double alert, const PeriodicCell3& cell,
             CellGrid3& grid, std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info,
             int min_parallel);

// The largest overlap among the spheres and planes at their positions (depth
// 0 if none) and a pair that has it, through the periodic cell (if
// cell.any()): a state's consistency (a checkpoint's against the depth it
// recorded). Polyhedra are taken as their bounding spheres: for sphere
// worlds only.
struct Overlap3 {
  double depth = 0.0;
  std::int32_t b1 = -1, b2 = -1;
};
Overlap3 largest_overlap3(const Bodies3& bodies, const PeriodicCell3& cell, int min_parallel);

// Narrow phase: spheres i, j (frame from i to j). False if the gap exceeds alert.
bool sphere_sphere(int i, int j, const Vec3& xi, const Vec3& xj, double ri, double rj,
                   double alert, SphereRow& row, ContactInfo3& info);
// Plane p (body 1, point xp, unit normal np) and sphere k (body 2).
bool plane_sphere(int p, int k, const Vec3& xp, const Vec3& np, const Vec3& xk, double rk,
                  double alert, SphereRow& row, ContactInfo3& info);

}  // namespace cd
