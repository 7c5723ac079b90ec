#include "detect3.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cell_grid.hpp"

namespace cd {

namespace {

void set_frame(SphereRow& row, int b1, int b2, const Vec3& n, const Vec3& c1, const Vec3& c2) {
  row.b1 = b1;
  row.b2 = b2;
  row.n = n;
  orthonormal_basis(n, row.t1, row.t2);
  row.c1 = c1;
  row.c2 = c2;
  row.wnn = row.wtt = 0.0;
  row.bn = 0.0;
  row.r = Vec3::Zero();
  row.mu = 0.0;
  row.adh = 0.0;
}

// Every plane against every (non-driven) sphere, planes in index order.
void plane_rows(const Bodies3& bodies, const std::vector<Vec3>& x, double alert,
                const std::vector<int>& planes, const std::vector<int>& spheres,
                std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info) {
  for (const int p : planes)
    for (const int k : spheres) {
      if (bodies.driven[k]) continue;
      SphereRow row;
      ContactInfo3 inf;
      if (plane_sphere(p, k, x[p], bodies.normal[p], x[k], bodies.radius[k], alert, row, inf)) {
        rows.push_back(row);
        info.push_back(inf);
      }
    }
}

int floor_div(int a, int n) { return a >= 0 ? a / n : -((-a + n - 1) / n); }
int wrap_index(int a, int n) { return a - n * floor_div(a, n); }

}  // namespace

Vec3 PeriodicCell3::nearest_image(const Vec3& x1, const Vec3& x2, std::array<int, 3>& k) const {
  Vec3 d = x2 - x1;
  k = {0, 0, 0};
  // y first: its images carry the Lees-Edwards shift along x.
  if (periodic[1]) {
    k[1] = static_cast<int>(-std::round(d.y() / size.y()));
    d.y() += k[1] * size.y();
    d.x() += k[1] * le_offset;
  }
  if (periodic[0]) {
    k[0] = static_cast<int>(-std::round(d.x() / size.x()));
    d.x() += k[0] * size.x();
  }
  if (periodic[2]) {
    k[2] = static_cast<int>(-std::round(d.z() / size.z()));
    d.z() += k[2] * size.z();
  }
  return x1 + d;
}

Vec3 PeriodicCell3::wrap(const Vec3& x, std::array<int, 3>& k) const {
  Vec3 y = x;
  k = {0, 0, 0};
  if (periodic[1]) {
    k[1] = -static_cast<int>(std::floor((y.y() - origin.y()) / size.y()));
    y.y() += k[1] * size.y();
    y.x() += k[1] * le_offset;
  }
  if (periodic[0]) {
    k[0] = -static_cast<int>(std::floor((y.x() - origin.x()) / size.x()));
    y.x() += k[0] * size.x();
  }
  if (periodic[2]) {
    k[2] = -static_cast<int>(std::floor((y.z() - origin.z()) / size.z()));
    y.z() += k[2] * size.z();
  }
  return y;
}

bool sphere_sphere(int i, int j, const Vec3& xi, const Vec3& xj, double ri, double rj,
                   double alert, SphereRow& row, ContactInfo3& info) {
  const Vec3 d = xj - xi;
  const double dist2 = d.squaredNorm();
  const double reach = ri + rj + alert;
  if (dist2 > reach * reach) return false;
  const double dist = std::sqrt(dist2);
  const Vec3 n = dist > 0 ? Vec3(d / dist) : Vec3(0.0, 0.0, 1.0);
  const double gap = dist - ri - rj;
  // Contact point: middle of the gap (or of the overlap) on the line of centres.
  const Vec3 c1 = (ri + 0.5 * gap) * n;
  const Vec3 p = xi + c1;
  set_frame(row, i, j, n, c1, p - xj);
  info = {contact_key3(i, j), gap, p, d};
  return true;
}

bool plane_sphere(int pl, int k, const Vec3& xp, const Vec3& np, const Vec3& xk, double rk,
                  double alert, SphereRow& row, ContactInfo3& info) {
  const double dist = (xk - xp).dot(np);
  const double gap = dist - rk;
  if (gap > alert) return false;
  const Vec3 foot = xk - dist * np;
  const Vec3 p = foot + 0.5 * gap * np;
  set_frame(row, pl, k, np, p - xp, p - xk);
  info = {contact_key3(pl, k), gap, p, xk - foot};
  return true;
}

namespace {

// The spheres go in the grid, the planes are tested against every sphere;
// pos(i) is where sphere i is binned.
template <class Pos>
GridMembers<Vec3> sphere_members(const Bodies3& bodies, Pos&& pos) {
  return grid_members<Vec3>(static_cast<int>(bodies.size()), bodies.radius,
                            [&](int i) { return bodies.shape[i] == Shape3::Plane; }, pos);
}

// The grid of both detections: along a periodic axis n = floor(L / h)
// cells of side L / n >= h over the cell, along the others cells of side h
// over the spheres' box. h starts at the reach 2 r_max + alert (a pair
// within reach is in the same or a neighbouring cell) and coarsens by 1.25
// until there are at most ~2 cells a sphere (a sphere far away coarsens the
// grid rather than blowing up memory).
struct Grid3 {
  std::array<int, 3> n{1, 1, 1};
  Vec3 side = Vec3::Ones(), org = Vec3::Zero();
  std::array<bool, 3> periodic{false, false, false};
  double h = 0.0;

  Grid3(const GridMembers<Vec3>& g, double reach, const PeriodicCell3& cell) : periodic(cell.periodic) {
    const int ns = static_cast<int>(g.members.size());
    std::array<double, 3> count;
    auto layout = [&](double hh) {
      double cells = 1;
      for (int a = 0; a < 3; ++a) {
        count[a] = periodic[a] ? std::max(1.0, std::floor(cell.size[a] / hh)) : std::floor((g.hi[a] - g.lo[a]) / hh) + 1;
        cells *= count[a];
      }
      return cells;
    };
    h = reach;
    const double cap = 2.0 * ns + 64;
    while (layout(h) > cap) h *= 1.25;
    for (int a = 0; a < 3; ++a) {
      n[a] = static_cast<int>(count[a]);
      side[a] = periodic[a] ? cell.size[a] / n[a] : h;
      org[a] = periodic[a] ? cell.origin[a] : g.lo[a];
    }
  }
  std::size_t cells() const { return static_cast<std::size_t>(n[0]) * n[1] * n[2]; }
  int axis(double v, int a) const {
    const int c = static_cast<int>(std::floor((v - org[a]) / side[a]));
    return periodic[a] ? wrap_index(c, n[a]) : std::clamp(c, 0, n[a] - 1);
  }
  // Cells in (z, y, x) order.
  int cell(const Vec3& p) const { return (axis(p.z(), 2) * n[1] + axis(p.y(), 1)) * n[0] + axis(p.x(), 0); }
};

// The sphere pair (i, j), i < j, if within reach: a driven body is body 1
// (the colouring's split and the wall friction look at body 1 only); with
// Periodic, through body j's image nearest to body i. row, inf: scratch.
template <bool Periodic>
inline void sphere_pair(const Bodies3& bodies, const std::vector<Vec3>& x, double alert,
                        const PeriodicCell3& cell, int i, int j, SphereRow& row, ContactInfo3& inf,
                        std::vector<SphereRow>& R, std::vector<ContactInfo3>& I) {
  if (bodies.driven[i] && bodies.driven[j]) return;
  if (bodies.driven[j] && !bodies.driven[i]) std::swap(i, j);
  if constexpr (Periodic) {
    std::array<int, 3> k;
    const Vec3 xj = cell.nearest_image(x[i], x[j], k);
    if (!sphere_sphere(i, j, x[i], xj, bodies.radius[i], bodies.radius[j], alert, row, inf)) return;
    inf.ix = static_cast<std::int8_t>(k[0]);
    inf.iy = static_cast<std::int8_t>(k[1]);
    inf.iz = static_cast<std::int8_t>(k[2]);
  } else {
    if (!sphere_sphere(i, j, x[i], x[j], bodies.radius[i], bodies.radius[j], alert, row, inf)) return;
  }
  R.push_back(row);
  I.push_back(inf);
}

}  // namespace

void detect3(const Bodies3& bodies, const std::vector<Vec3>& x, double alert, CellGrid3& grid,
             std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info, int min_parallel) {
  rows.clear();
  info.clear();
  const GridMembers<Vec3> g = sphere_members(bodies, [&](int i) { return x[i]; });
  const int ns = static_cast<int>(g.members.size());
  if (ns > 1) {
    const PeriodicCell3 none;
    const Grid3 gr(g, 2 * g.rmax + alert, none);
    const int nx = gr.n[0], ny = gr.n[1], nz = gr.n[2];
    grid.bins.bin(gr.cells(), g.members, [&](int i) { return gr.cell(x[i]); });
    const std::vector<int>& cs = grid.bins.cell_start;
    const std::vector<int>& it = grid.bins.items;
    // Half of the 27-cell stencil: the cell itself (pairs a < b) and the 13
    // neighbours after it in (z, y, x) order.
    static constexpr int off[13][3] = {{1, 0, 0},  {-1, 1, 0}, {0, 1, 0},  {1, 1, 0},  {-1, -1, 1},
                                       {0, -1, 1}, {1, -1, 1}, {-1, 0, 1}, {0, 0, 1},  {1, 0, 1},
                                       {-1, 1, 1}, {0, 1, 1},  {1, 1, 1}};
    grid.threads.run(
        ns >= min_parallel / 2,
        [&](std::vector<SphereRow>& R, std::vector<ContactInfo3>& I) {
          SphereRow row;
          ContactInfo3 inf;
          auto pair = [&](int i, int j) {
            if (i > j) std::swap(i, j);
            sphere_pair<false>(bodies, x, alert, none, i, j, row, inf, R, I);
          };
#pragma omp for schedule(static)
          for (int cz = 0; cz < nz; ++cz)
            for (int cy = 0; cy < ny; ++cy)
              for (int cx = 0; cx < nx; ++cx) {
                const int c = (cz * ny + cy) * nx + cx;
                for (int a = cs[c]; a < cs[c + 1]; ++a) {
                  const int i = it[a];
                  for (int b = a + 1; b < cs[c + 1]; ++b) pair(i, it[b]);
                  for (const auto& o : off) {
                    const int qx = cx + o[0], qy = cy + o[1], qz = cz + o[2];
                    if (qx < 0 || qx >= nx || qy < 0 || qy >= ny || qz >= nz) continue;
                    const int d = (qz * ny + qy) * nx + qx;
                    for (int b = cs[d]; b < cs[d + 1]; ++b) pair(i, it[b]);
                  }
                }
              }
        },
        rows, info);
  }
  plane_rows(bodies, x, alert, g.others, g.members, rows, info);
}

void detect3(const Bodies3& bodies, const std::vector<Vec3>& x, double alert, const PeriodicCell3& cell,
             CellGrid3& grid, std::vector<SphereRow>& rows, std::vector<ContactInfo3>& info,
             int min_parallel) {
  if (!cell.any()) {
    detect3(bodies, x, alert, grid, rows, info, min_parallel);
    return;
  }
  rows.clear();
  info.clear();
  // Spheres are binned at an image inside the cell (xw); the narrow phase
  // takes the nearest image from the positions themselves.
  std::vector<Vec3> xw(bodies.size(), Vec3::Zero());
  const GridMembers<Vec3> g = sphere_members(bodies, [&](int i) {
    std::array<int, 3> k;
    return xw[i] = cell.wrap(x[i], k);
  });
  const int ns = static_cast<int>(g.members.size());
  const double reach = 2 * g.rmax + alert;
  for (int a = 0; a < 3; ++a)
    if (cell.periodic[a] && !(cell.size[a] >= 2 * reach))
      throw std::invalid_argument("detect3: a periodic length is below 2 (2 r_max + alert)");
  if (ns > 1) {
    const Grid3 gr(g, reach, cell);
    const int nx = gr.n[0], ny = gr.n[1], nz = gr.n[2];
    const double h = gr.h;
    const Vec3& side = gr.side;
    grid.bins.bin(gr.cells(), g.members, [&](int i) { return gr.cell(xw[i]); });
    const std::vector<int>& cs = grid.bins.cell_start;
    const std::vector<int>& it = grid.bins.items;
    const bool le = cell.periodic[0] && cell.periodic[1] && cell.le_offset != 0.0;
    grid.threads.run(
        ns >= min_parallel / 2,
        [&](std::vector<SphereRow>& R, std::vector<ContactInfo3>& I) {
          std::vector<int> nbr;
          SphereRow row;
          ContactInfo3 inf;
          // The whole 27-cell stencil, wrapped along periodic axes and
          // without repeats (a periodic axis of 1 or 2 cells maps several
          // offsets onto one cell); a pair is taken from the cell of its
          // lower-index sphere. Across the y boundary of a Lees-Edwards cell
          // the neighbours' images are shifted by +-le_offset along x: the x
          // cells are those within h of this cell's x range once shifted
          // back (up to 4).
#pragma omp for schedule(static)
          for (int cz = 0; cz < nz; ++cz)
            for (int cy = 0; cy < ny; ++cy)
              for (int cx = 0; cx < nx; ++cx) {
                const int c = (cz * ny + cy) * nx + cx;
                if (cs[c] == cs[c + 1]) continue;
                nbr.clear();
                for (int oz = -1; oz <= 1; ++oz) {
                  int qz = cz + oz;
                  if (cell.periodic[2]) qz = wrap_index(qz, nz);
                  else if (qz < 0 || qz >= nz) continue;
                  for (int oy = -1; oy <= 1; ++oy) {
                    int qy = cy + oy;
                    int cross = 0;
                    if (cell.periodic[1]) {
                      cross = floor_div(qy, ny);
                      qy -= cross * ny;
                    } else if (qy < 0 || qy >= ny) {
                      continue;
                    }
                    int x0 = cx - 1, x1 = cx + 1;
                    if (le && cross != 0) {
                      const double s = cross * cell.le_offset;
                      x0 = static_cast<int>(std::floor((cx * side[0] - h - s) / side[0]));
                      x1 = static_cast<int>(std::floor(((cx + 1) * side[0] + h - s) / side[0]));
                    }
                    for (int qx = x0; qx <= x1; ++qx) {
                      int px = qx;
                      if (cell.periodic[0]) px = wrap_index(qx, nx);
                      else if (qx < 0 || qx >= nx) continue;
                      nbr.push_back((qz * ny + qy) * nx + px);
                    }
                  }
                }
                std::sort(nbr.begin(), nbr.end());
                nbr.erase(std::unique(nbr.begin(), nbr.end()), nbr.end());
                for (int a = cs[c]; a < cs[c + 1]; ++a) {
                  const int i = it[a];
                  for (const int d : nbr)
                    for (int b = cs[d]; b < cs[d + 1]; ++b)
                      if (i < it[b]) sphere_pair<true>(bodies, x, alert, cell, i, it[b], row, inf, R, I);
                }
              }
        },
        rows, info);
  }
  plane_rows(bodies, x, alert, g.others, g.members, rows, info);
}

Overlap3 largest_overlap3(const Bodies3& bodies, const PeriodicCell3& cell, int min_parallel) {
  CellGrid3 grid;
  std::vector<SphereRow> rows;
  std::vector<ContactInfo3> info;
  if (cell.any()) detect3(bodies, bodies.pos, 0.0, cell, grid, rows, info, min_parallel);
  else detect3(bodies, bodies.pos, 0.0, grid, rows, info, min_parallel);
  Overlap3 o;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (-info[k].gap > o.depth) o = {-info[k].gap, rows[k].b1, rows[k].b2};
  return o;
}

}  // namespace cd
