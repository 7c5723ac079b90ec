// 3D contact detection at the midpoint configuration: an O(N) cell list
// (uniform grid of side 2 r_max + alert over the spheres' bounding box)
// for sphere-sphere pairs, then every plane against every sphere. Output
// order is fixed whatever the thread count: sphere pairs in cell order
// (z, y, x slabs; each thread takes a contiguous range of z slabs and the
// per-thread lists are joined in thread order), then planes in index order
// with spheres in index order.
#pragma once
#include <vector>

#include "bodies3.hpp"
#include "contact3.hpp"

namespace cd {

struct CellGrid3 {  // scratch kept between steps to avoid reallocation
  std::vector<int> cell_start, items, cell_of;
  std::vector<std::vector<SphereRow>> rows_t;
  std::vector<std::vector<ContactInfo3>> info_t;
};

// Candidate contacts with gap <= alert among the bodies at positions x.
// Fills geometry only (b1, b2, frame, lever arms, gap, point, branch; r,
// bn, adh zero); the caller fills W blocks, offsets and impulses. A driven
// body is always body 1. Loops run on one thread below min_parallel bodies.
void detect3(const Bodies3& bodies, const std::vector<Vec3>& x, double alert, CellGrid3& grid,
             std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info, int min_parallel);

// Narrow phase: spheres i, j (frame from i to j). False if the gap exceeds alert.
bool sphere_sphere(int i, int j, const Vec3& xi, const Vec3& xj, double ri, double rj,
                   double alert, SphereRow& row, ContactInfo3& info);
// Plane p (body 1, point xp, unit normal np) and sphere k (body 2).
bool plane_sphere(int p, int k, const Vec3& xp, const Vec3& np, const Vec3& xk, double rk,
                  double alert, SphereRow& row, ContactInfo3& info);

}  // namespace cd
