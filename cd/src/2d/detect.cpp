#include "detect.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include "cell_grid.hpp"
#include "parallel.hpp"

namespace cd {

namespace {


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

namespace {

// Clips the incident face [w1, w2] to the extent of the reference face
// [v1, v2] (outward normal n) and appends the points within the alert
// distance. Returns the number appended.
int clip_and_emit(int ref, int inc, const Vec2& v1, const Vec2& v2, const Vec2& n,
                  const Vec2& cref, const Vec2& w1, const Vec2& w2, const Vec2& cinc, double alert,
                  std::vector<ContactRow>& rows, std::vector<ContactInfo>& info) {
  const Vec2 e = v2 - v1;
  const double L = e.norm();
  const Vec2 t = e / L;
  const double s1 = (w1 - v1).dot(t), s2 = (w2 - v1).dot(t);
  double u0 = 0.0, u1 = 1.0;
  if (s1 != s2) {
    const double ua = -s1 / (s2 - s1), ub = (L - s1) / (s2 - s1);
    u0 = std::max(0.0, std::min(ua, ub));
    u1 = std::min(1.0, std::max(ua, ub));
    if (u0 > u1) return 0;
  } else if (s1 < 0.0 || s1 > L) {
    return 0;
  }
  Vec2 q[2] = {w1 + u0 * (w2 - w1), w1 + u1 * (w2 - w1)};
  double sep[2] = {(q[0] - v1).dot(n), (q[1] - v1).dot(n)};
  const int nq = (u1 - u0) * (w2 - w1).norm() > 1e-12 * L ? 2 : 1;
  bool keep[2] = {sep[0] <= alert, nq == 2 && sep[1] <= alert};
  const bool ss = keep[0] && keep[1] && std::abs(sep[0] - sep[1]) <= 0.02 * L;
  int emitted = 0;
  for (int k = 0; k < nq; ++k) {
    if (!keep[k]) continue;
    const Vec2 p = q[k] - 0.5 * sep[k] * n;
    ContactRow row;
    row.b1 = ref;
    row.b2 = inc;
    set_frame(row, n, p - cref, p - cinc);
    rows.push_back(row);
    info.push_back({contact_key(ref, inc, k), sep[k], p.x(), p.y(),
                    ss ? ContactType::SideSide : ContactType::SideVertex});
    ++emitted;
  }
  return emitted;
}

// Largest separation of B from the faces of A: only faces within a quarter
// turn (plus one) of the direction to B can separate convex bodies.
double max_face_separation(const PolyView& A, const PolyView& B, int& face) {
  const int f0 = A.face_towards(B.c - A.c);
  const int span = std::min(A.n / 4 + 1, A.n / 2);
  double best = -1e300;
  const double ap = A.apothem();
  for (int k = -span; k <= span && k < A.n - span; ++k) {
    const int f = A.wrap(f0 + k);
    const Vec2 nf = A.normal(f);
    const double s = (B.vertex(B.support(-nf)) - A.c).dot(nf) - ap;
    if (s > best) {
      best = s;
      face = f;
    }
  }
  return best;
}

}  // namespace

int polygon_polygon(int i, int j, const PolyView& A, const PolyView& B, double alert,
                    std::vector<ContactRow>& rows, std::vector<ContactInfo>& info) {
  int fa = 0, fb = 0;
  const double sa = max_face_separation(A, B, fa);
  if (sa > alert) return 0;
  const double sb = max_face_separation(B, A, fb);
  if (sb > alert) return 0;
  // Reference face: A's unless B's separates clearly more. The bias keeps
  // vertex-vertex configurations, where both are nearly equal, from flipping
  // frame every step on round-off (which would let motion deepen overlaps).
  const bool flip = sb > sa + 1e-3 * std::min(A.R, B.R);
  const PolyView& R = flip ? B : A;
  const PolyView& I = flip ? A : B;
  const int fr = flip ? fb : fa;
  const Vec2 n = R.normal(fr);
  const int fi = I.face_towards(-n);
  const int ref = flip ? j : i, inc = flip ? i : j;
  const Vec2 v1 = R.vertex(fr);
  const int m = clip_and_emit(ref, inc, v1, R.vertex(fr + 1), n, R.c, I.vertex(fi),
                              I.vertex(fi + 1), I.c, alert, rows, info);
  if (m > 0) return m;
  // Many-sided polygons have faces shorter than the lateral offset of the
  // centres from a face normal (a 60-gon: face 0.05 d, offset up to
  // d sin 3 deg), so the incident face can fall beside the reference face
  // and clipping keeps nothing. The pair still overlaps on this axis: take
  // the incident polygon's deepest vertex as one side-vertex point.
  // (Without this, 60-gon piles lost contacts until 0.08 d deep.)
  const Vec2 q = I.vertex(I.support(-n));
  const double sep = (q - v1).dot(n);
  if (sep > alert) return 0;
  const Vec2 pt = q - 0.5 * sep * n;
  ContactRow row;
  row.b1 = ref;
  row.b2 = inc;
  set_frame(row, n, pt - R.c, pt - I.c);
  rows.push_back(row);
  info.push_back({contact_key(ref, inc, 2), sep, pt.x(), pt.y(), ContactType::SideVertex});
  return 1;
}

bool polygon_disk(int p, int k, const PolyView& P, const Vec2& xk, double rk, double alert,
                  ContactRow& row, ContactInfo& info) {
  const int f = P.face_towards(xk - P.c);
  const Vec2 nf = P.normal(f);
  const double s = (xk - P.c).dot(nf) - P.apothem();
  if (s - rk > alert) return false;
  Vec2 q, n;
  double dist;
  if (s <= 0.0) {  // centre inside: push out through the nearest face
    n = nf;
    dist = s;
    q = xk - s * nf;
  } else {
    const Vec2 v1 = P.vertex(f), v2 = P.vertex(f + 1);
    const Vec2 e = v2 - v1;
    const double u = std::clamp((xk - v1).dot(e) / e.squaredNorm(), 0.0, 1.0);
    q = v1 + u * e;
    const Vec2 d = xk - q;
    dist = d.norm();
    n = dist > 0 ? Vec2(d / dist) : nf;
  }
  const double gap = dist - rk;
  if (gap > alert) return false;
  const Vec2 pt = q + 0.5 * gap * n;
  row.b1 = p;
  row.b2 = k;
  set_frame(row, n, pt - P.c, pt - xk);
  info = {contact_key(p, k, 0), gap, pt.x(), pt.y(), ContactType::SideVertex};
  return true;
}

int segment_polygon(int w, int p, const Vec2& wa, const Vec2& wb, const Vec2& wc, const PolyView& P,
                    double alert, std::vector<ContactRow>& rows, std::vector<ContactInfo>& info) {
  const Vec2 e = (wb - wa).normalized();
  Vec2 n(-e.y(), e.x());
  if ((P.c - wa).dot(n) < 0) n = -n;  // the wall's face towards the polygon
  const double s = (P.vertex(P.support(-n)) - wa).dot(n);
  if (s > alert) return 0;
  const int fi = P.face_towards(-n);
  return clip_and_emit(w, p, wa, wb, n, wc, P.vertex(fi), P.vertex(fi + 1), P.c, alert, rows,
                       info);
}

namespace {

// The image of body j a pair is computed with: j seen at x[j] + s.
struct Image {
  Vec2 s = Vec2::Zero();
  std::int8_t ix = 0, iy = 0;
  Image operator-() const { return {-s, static_cast<std::int8_t>(-ix), static_cast<std::int8_t>(-iy)}; }
};

PolyView poly_view(const Bodies& b, const Vec2& c, const std::vector<double>& th, int i) {
  return {c, b.radius[i], th[i], b.nsides[i]};
}

// All contacts of the pair (i < j), with j seen through image im. Poly =
// false: the scene has only disks, and the shape dispatch is compiled out.
template <bool Poly>
void pair_contacts(const Bodies& b, const std::vector<Vec2>& x, const std::vector<double>& th,
                   int i, int j, const Image& im, double alert, std::vector<ContactRow>& R,
                   std::vector<ContactInfo>& I) {
  if (b.driven[i] && b.driven[j]) return;  // bodies glued to one wall, or to two
  const std::size_t n0 = R.size();
  const Vec2 xj = x[j] + im.s;
  ContactRow row;
  ContactInfo inf;
  if (!Poly || (b.nsides[i] == 0 && b.nsides[j] == 0)) {
    if (disk_disk(i, j, x[i], xj, b.radius[i], b.radius[j], alert, row, inf)) {
      R.push_back(row);
      I.push_back(inf);
    }
  } else if constexpr (Poly) {
    // Bounding circles first: cheap rejection before the polygon geometry.
    const double reach = b.radius[i] + b.radius[j] + alert;
    if ((xj - x[i]).squaredNorm() > reach * reach) return;
    if (b.nsides[i] > 0 && b.nsides[j] > 0) {
      polygon_polygon(i, j, poly_view(b, x[i], th, i), poly_view(b, xj, th, j), alert, R, I);
    } else {
      const bool pi = b.nsides[i] > 0;
      const int p = pi ? i : j, k = pi ? j : i;
      if (polygon_disk(p, k, poly_view(b, pi ? x[i] : xj, th, p), pi ? xj : x[i], b.radius[k],
                       alert, row, inf)) {
        R.push_back(row);
        I.push_back(inf);
      }
    }
  }
  // A driven body (wall, glued grain) is always body 1: the wall friction
  // (World::build) and the colouring's split of wall rows (nlgs.cpp) look at
  // body 1 only. (It was not so for glued grains, which have higher indices
  // than the free grains and came out as body 2: mu_wall was ignored.)
  for (std::size_t k = n0; k < R.size(); ++k)
    if (b.driven[R[k].b2]) reverse_contact(R[k], I[k]);
  // Branch vectors and images, whichever body the narrow phase made body 1.
  for (std::size_t k = n0; k < R.size(); ++k) {
    const bool fwd = R[k].b1 == i;
    const Image m = fwd ? im : -im;
    const Vec2 l = x[R[k].b2] + m.s - x[R[k].b1];
    I[k].lx = l.x();
    I[k].ly = l.y();
    I[k].ix = m.ix;
    I[k].iy = m.iy;
  }
}

// One axis of the grid: origin, cell size and count, periodic or not.
struct Axis {
  double lo = 0, h = 1;
  int n = 1;
  bool periodic = false;
  double length = 0;  // period
  int cell(double v) const { return std::clamp(static_cast<int>(std::floor((v - lo) / h)), 0, n - 1); }
};

template <bool Poly, bool Periodic>
void grid_pairs(const Bodies& bodies, const std::vector<Vec2>& x, const std::vector<double>& th,
                double alert, const Axis& ax, const Axis& ay, double offset,
                const std::vector<int>& cs, const std::vector<int>& it,
                std::vector<ContactRow>& R, std::vector<ContactInfo>& I) {
  const int ncx = ax.n, ncy = ay.n;
  // The pair (i, j) is computed from the lower index, with j's image.
  auto visit_cell = [&](int i, int cn, const Image& im) {
    for (int b = cs[cn]; b < cs[cn + 1]; ++b) {
      const int j = it[b];
      if (i < j)
        pair_contacts<Poly>(bodies, x, th, i, j, im, alert, R, I);
      else
        pair_contacts<Poly>(bodies, x, th, j, i, -im, alert, R, I);
    }
  };
  // Half of the 3x3 stencil: the cell itself and E, NW, N, NE neighbours.
  static constexpr int off[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
#pragma omp for schedule(static)
  for (int cy = 0; cy < ncy; ++cy) {
    for (int cx = 0; cx < ncx; ++cx) {
      const int c = cy * ncx + cx;
      for (int a = cs[c]; a < cs[c + 1]; ++a) {
        const int i = it[a];
        for (int b = a + 1; b < cs[c + 1]; ++b)
          pair_contacts<Poly>(bodies, x, th, i, it[b], Image{}, alert, R, I);
        for (const auto& o : off) {
          int nx = cx + o[0], ny = cy + o[1];
          Image im;
          if constexpr (Periodic) {
            if (ny == ncy) {
              if (!ay.periodic) continue;
              if (o[0] != 0) continue;  // the top row's neighbours above, all at once below
              // Lees-Edwards: the bottom row seen above the top shifted by
              // (offset, height). Images within reach of cell cx lie over
              // [(cx - 1) h, (cx + 2) h): up to 4 cells of the bottom row.
              const double xlo = (cx - 1) * ax.h - offset, xhi = (cx + 2) * ax.h - offset;
              const int k0 = static_cast<int>(std::floor(xlo / ax.h));
              const int k1 = static_cast<int>(std::ceil(xhi / ax.h)) - 1;
              for (int kr = k0; kr <= k1; ++kr) {
                const int k = ((kr % ncx) + ncx) % ncx;
                const int m = (kr - k) / ncx;
                visit_cell(i, k, {Vec2(m * ax.length + offset, ay.length),
                                  static_cast<std::int8_t>(m), 1});
              }
              continue;
            }
            if (nx < 0 || nx >= ncx) {
              if (!ax.periodic) continue;
              const int m = nx < 0 ? -1 : 1;
              nx -= m * ncx;
              im = {Vec2(m * ax.length, 0.0), static_cast<std::int8_t>(m), 0};
            }
          } else {
            if (nx < 0 || nx >= ncx || ny >= ncy) continue;
          }
          visit_cell(i, ny * ncx + nx, im);
        }
      }
    }
  }
}

// Grid axis over [lo, hi] (open) or over the period [0, length).
Axis make_axis(double lo, double hi, double h, bool periodic, double length) {
  Axis a;
  a.periodic = periodic;
  if (periodic) {
    a.length = length;
    a.lo = 0.0;
    a.n = std::max(1, static_cast<int>(std::floor(length / h)));
    a.h = length / a.n;
  } else {
    a.lo = lo;
    a.h = h;
    a.n = static_cast<int>((hi - lo) / h) + 1;
  }
  return a;
}

}  // namespace

void detect(const Bodies& bodies, const std::vector<Vec2>& x, const std::vector<double>& th,
            double alert, CellGrid& grid, std::vector<ContactRow>& rows,
            std::vector<ContactInfo>& info, const PeriodicCell* cell) {
  rows.clear();
  info.clear();
  // Particles go in the grid (bounding circles); walls are tested against
  // every particle.
  const GridMembers<Vec2> g = grid_members<Vec2>(
      static_cast<int>(bodies.size()), bodies.radius,
      [&](int i) { return bodies.shape[i] == Shape::Segment; }, [&](int i) { return x[i]; });
  const std::vector<int>& parts = g.members;
  const std::vector<int>& walls = g.others;
  const bool poly = std::any_of(parts.begin(), parts.end(),
                                [&](int i) { return bodies.shape[i] == Shape::Polygon; });
  const int nd = static_cast<int>(parts.size());
  const Vec2 &lo = g.lo, &hi = g.hi;

  if (nd > 0) {
    const double h = 2 * g.rmax + alert;
    const bool px = cell && cell->x, py = cell && cell->y;
    const double wx = cell ? cell->width : 0, wy = cell ? cell->height : 0;
    if (!std::isfinite(wx) || !std::isfinite(wy) || !std::isfinite(h))
      throw std::runtime_error(fmt::format("the periodic cell ({} x {}) or the largest grain plus the alert "
                                           "distance ({}) is not finite", wx, wy, h));
    // Bound the cell count by ~4 cells a particle, so that a runaway particle
    // cannot blow up memory: the grid coarsens instead. A periodic axis has
    // its own bounded length and never coarsens below the 4 x 3 cells its
    // images need (a dilute sample in a large cell is no runaway): the other
    // axis coarsens alone.
    double hx = h, hy = h;
    auto count = [](double e, bool p, double len, double hh) { return std::floor((p ? len : e) / hh) + 1; };
    while (count(hi.x() - lo.x(), px, wx, hx) * count(hi.y() - lo.y(), py, wy, hy) > 4.0 * nd + 16) {
      const bool cx = !px || std::floor(wx / (1.5 * hx)) >= 4;
      const bool cy = !py || std::floor(wy / (1.5 * hy)) >= 3;
      if (!cx && !cy) break;
      if (cx) hx *= 1.5;
      if (cy) hy *= 1.5;
    }
    const Axis ax = make_axis(lo.x(), hi.x(), hx, px, wx);
    const Axis ay = make_axis(lo.y(), hi.y(), hy, py, wy);
    if ((px && ax.n < 4) || (py && ay.n < 3))
      throw std::runtime_error(
          "periodic cell too small: it must span at least 4 (x) and 3 (y) times 2 r_max + alert");
    const int ncx = ax.n;
    grid.bins.bin(static_cast<std::size_t>(ncx) * ay.n, parts,
                  [&](int i) { return ay.cell(x[i].y()) * ncx + ax.cell(x[i].x()); });
    const double offset = cell ? cell->offset : 0.0;
    const auto& cs = grid.bins.cell_start;
    const auto& it = grid.bins.items;
    // Small systems detect on one thread (parallel.hpp).
    grid.threads.run(
        nd >= kMinParallelBodies,
        [&](std::vector<ContactRow>& R, std::vector<ContactInfo>& I) {
          if (cell) {
            if (poly)
              grid_pairs<true, true>(bodies, x, th, alert, ax, ay, offset, cs, it, R, I);
            else
              grid_pairs<false, true>(bodies, x, th, alert, ax, ay, offset, cs, it, R, I);
          } else {
            if (poly)
              grid_pairs<true, false>(bodies, x, th, alert, ax, ay, offset, cs, it, R, I);
            else
              grid_pairs<false, false>(bodies, x, th, alert, ax, ay, offset, cs, it, R, I);
          }
        },
        rows, info);
  }

  // Walls: few, each tested against every particle, wall as body 1.
  ContactRow row;
  ContactInfo inf;
  for (int w : walls) {
    const Vec2 e(std::cos(th[w]), std::sin(th[w]));
    const Vec2 a = x[w] - bodies.radius[w] * e, b = x[w] + bodies.radius[w] * e;
    const std::size_t n0 = rows.size();
    for (int k : parts) {
      if (bodies.driven[k]) continue;
      if (bodies.nsides[k] > 0) {
        segment_polygon(w, k, a, b, x[w], poly_view(bodies, x[k], th, k), alert, rows, info);
      } else if (segment_disk(w, k, a, b, x[w], x[k], bodies.radius[k], alert, row, inf)) {
        rows.push_back(row);
        info.push_back(inf);
      }
    }
    for (std::size_t k = n0; k < rows.size(); ++k) {
      info[k].lx = x[rows[k].b2].x() - x[w].x();
      info[k].ly = x[rows[k].b2].y() - x[w].y();
    }
  }
}

Overlap largest_overlap(const Bodies& bodies, const PeriodicCell* cell) {
  CellGrid grid;
  std::vector<ContactRow> rows;
  std::vector<ContactInfo> info;
  detect(bodies, bodies.pos, bodies.angle, 0.0, grid, rows, info, cell);
  Overlap o;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (-info[k].gap > o.depth) o = {-info[k].gap, rows[k].b1, rows[k].b2};
  return o;
}

}  // namespace cd
