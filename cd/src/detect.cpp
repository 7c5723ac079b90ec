#include "detect.hpp"

#include <algorithm>
#include <cmath>

#include <omp.h>

namespace cd {

namespace {

constexpr int kMinParallelDetect = 2000;

// Lever arms of a contact point in the frame (n, t = n rotated +90 degrees).
inline void set_frame(ContactRow& row, const Vec2& n, const Vec2& c1, const Vec2& c2) {
  row.nx = n.x();
  row.ny = n.y();
  const Vec2 t(-n.y(), n.x());
  row.c1n = c1.dot(n);
  row.c1t = c1.dot(t);
  row.c2n = c2.dot(n);
  row.c2t = c2.dot(t);
  row.pn = row.pt = 0.0;
  row.bn = row.bt = 0.0;
  row.adh = 0.0;
}

}  // namespace

bool disk_disk(int i, int j, const Vec2& xi, const Vec2& xj, double ri, double rj, double alert,
               ContactRow& row, ContactInfo& info) {
  const Vec2 d = xj - xi;
  const double dist2 = d.squaredNorm();
  const double reach = ri + rj + alert;
  if (dist2 > reach * reach) return false;
  const double dist = std::sqrt(dist2);
  const Vec2 n = dist > 0 ? Vec2(d / dist) : Vec2(1.0, 0.0);
  const double gap = dist - ri - rj;
  // Contact point: middle of the gap (or of the overlap) along the line of centres.
  const Vec2 c1 = (ri + 0.5 * gap) * n;
  const Vec2 p = xi + c1;
  row.b1 = i;
  row.b2 = j;
  set_frame(row, n, c1, p - xj);
  info = {contact_key(i, j, 0), gap, p.x(), p.y(), ContactType::Disk};
  return true;
}

bool segment_disk(int w, int k, const Vec2& wa, const Vec2& wb, const Vec2& wc, const Vec2& xk,
                  double rk, double alert, ContactRow& row, ContactInfo& info) {
  const Vec2 e = wb - wa;
  const double L2 = e.squaredNorm();
  const double s = std::clamp((xk - wa).dot(e) / L2, 0.0, 1.0);
  const Vec2 q = wa + s * e;  // closest point of the segment
  const Vec2 d = xk - q;
  const double dist = d.norm();
  const double gap = dist - rk;
  if (gap > alert) return false;
  // A disk centre exactly on the segment has no defined side: take the left normal.
  const Vec2 n = dist > 0 ? Vec2(d / dist) : Vec2(Vec2(-e.y(), e.x()).normalized());
  const Vec2 p = q + 0.5 * gap * n;
  row.b1 = w;
  row.b2 = k;
  set_frame(row, n, p - wc, p - xk);
  info = {contact_key(w, k, 0), gap, p.x(), p.y(), ContactType::Disk};
  return true;
}

void detect(const Bodies& bodies, const std::vector<Vec2>& x, const std::vector<double>& th,
            double alert, CellGrid& grid, std::vector<ContactRow>& rows,
            std::vector<ContactInfo>& info) {
  rows.clear();
  info.clear();
  const int nb = static_cast<int>(bodies.size());

  // Dynamic disks go in the grid; walls are tested against every disk.
  std::vector<int> disks, walls;
  disks.reserve(nb);
  double rmax = 0;
  Vec2 lo(1e300, 1e300), hi(-1e300, -1e300);
  for (int i = 0; i < nb; ++i) {
    if (bodies.shape[i] == Shape::Segment) {
      walls.push_back(i);
    } else {
      disks.push_back(i);
      rmax = std::max(rmax, bodies.radius[i]);
      lo = lo.cwiseMin(x[i]);
      hi = hi.cwiseMax(x[i]);
    }
  }
  const int nd = static_cast<int>(disks.size());
  const int nthreads = omp_get_max_threads();
  grid.rows_t.resize(nthreads);
  grid.info_t.resize(nthreads);

  if (nd > 0) {
    double h = 2 * rmax + alert;
    const Vec2 ext = hi - lo;
    // Bound the cell count by ~4 cells a disk, so that a runaway particle
    // cannot blow up memory: the grid coarsens instead.
    while ((std::floor(ext.x() / h) + 1) * (std::floor(ext.y() / h) + 1) > 4.0 * nd + 16) h *= 1.5;
    const int ncx = static_cast<int>(ext.x() / h) + 1;
    const int ncy = static_cast<int>(ext.y() / h) + 1;
    auto cell_of = [&](int i) {
      const int cx = std::min(ncx - 1, static_cast<int>((x[i].x() - lo.x()) / h));
      const int cy = std::min(ncy - 1, static_cast<int>((x[i].y() - lo.y()) / h));
      return cy * ncx + cx;
    };
    grid.cell_start.assign(static_cast<std::size_t>(ncx) * ncy + 1, 0);
    for (int i : disks) ++grid.cell_start[cell_of(i) + 1];
    for (std::size_t c = 0; c + 1 < grid.cell_start.size(); ++c)
      grid.cell_start[c + 1] += grid.cell_start[c];
    grid.items.resize(nd);
    {
      std::vector<int> fill(grid.cell_start.begin(), grid.cell_start.end() - 1);
      for (int i : disks) grid.items[fill[cell_of(i)]++] = i;  // ascending index inside a cell
    }
    const std::vector<int>& cs = grid.cell_start;
    const std::vector<int>& it = grid.items;
    // Small systems detect on one thread: waking a team costs more than the
    // work, and much more on a loaded machine.
#pragma omp parallel if (nd >= kMinParallelDetect)
    {
      auto& R = grid.rows_t[omp_get_thread_num()];
      auto& I = grid.info_t[omp_get_thread_num()];
      R.clear();
      I.clear();
      ContactRow row;
      ContactInfo inf;
      // Half of the 3x3 stencil: the cell itself and E, NW, N, NE neighbours.
      static constexpr int off[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
#pragma omp for schedule(static)
      for (int cy = 0; cy < ncy; ++cy) {
        for (int cx = 0; cx < ncx; ++cx) {
          const int c = cy * ncx + cx;
          for (int a = cs[c]; a < cs[c + 1]; ++a) {
            const int i = it[a];
            for (int b = a + 1; b < cs[c + 1]; ++b) {
              const int j = it[b];
              if (disk_disk(i, j, x[i], x[j], bodies.radius[i], bodies.radius[j], alert, row, inf)) {
                R.push_back(row);
                I.push_back(inf);
              }
            }
            for (const auto& o : off) {
              const int nx = cx + o[0], ny = cy + o[1];
              if (nx < 0 || nx >= ncx || ny >= ncy) continue;
              const int cn = ny * ncx + nx;
              for (int b = cs[cn]; b < cs[cn + 1]; ++b) {
                int p = i, q = it[b];
                if (p > q) std::swap(p, q);  // frame always from lower to higher index
                if (disk_disk(p, q, x[p], x[q], bodies.radius[p], bodies.radius[q], alert, row,
                              inf)) {
                  R.push_back(row);
                  I.push_back(inf);
                }
              }
            }
          }
        }
      }
    }
    for (int t = 0; t < nthreads; ++t) {
      rows.insert(rows.end(), grid.rows_t[t].begin(), grid.rows_t[t].end());
      info.insert(info.end(), grid.info_t[t].begin(), grid.info_t[t].end());
    }
  }

  // Walls: few, each tested against every disk, wall as body 1.
  ContactRow row;
  ContactInfo inf;
  for (int w : walls) {
    Vec2 a, b;
    const double ang = th[w];
    const Vec2 e(std::cos(ang), std::sin(ang));
    a = x[w] - bodies.radius[w] * e;
    b = x[w] + bodies.radius[w] * e;
    for (int k : disks) {
      if (segment_disk(w, k, a, b, x[w], x[k], bodies.radius[k], alert, row, inf)) {
        rows.push_back(row);
        info.push_back(inf);
      }
    }
  }
}

}  // namespace cd
