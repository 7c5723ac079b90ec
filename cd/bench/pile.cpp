#include "pile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include "setup.hpp"

namespace cdbench {

namespace {

using cd::Vec2;
constexpr double kEps = 1e-12;  // angular slack against round-off (rad)

// Disks on a grid of square cells of side h >= the largest diameter, so that
// any two touching disks are at most one cell apart, and a disk rolling on A
// can only meet disks within two cells of A.
struct Deposit {
  double W, h;
  int ncx;
  std::vector<std::vector<int>> cells;  // row-major, rows added as the pile grows
  Pile& p;

  Deposit(Pile& pile, double width, double dmax)
      : W(width), h(dmax), ncx(std::max(1, static_cast<int>(width / dmax))), p(pile) {
    h = std::max(h, W / ncx);
  }
  int cx(double x) const { return std::clamp(static_cast<int>(x / h), 0, ncx - 1); }
  int rows() const { return static_cast<int>(cells.size()) / ncx; }

  void insert(int i) {
    const int cy = static_cast<int>(p.x[i].y() / h);
    if (cy >= rows()) cells.resize(static_cast<std::size_t>(cy + 1) * ncx);
    cells[static_cast<std::size_t>(cy) * ncx + cx(p.x[i].x())].push_back(i);
  }

  // Falling from (px, from_y): the highest resting height (floor: r) and the
  // disk hit (-1: floor). Scans cell rows downwards; a disk in row cy gives a
  // contact height below (cy + 2) h, so the scan stops below the best found.
  double fall(double px, double from_y, double r, int& hit) const {
    double best = r;
    hit = -1;
    const int c0 = cx(px);
    const int top = from_y / h < rows() ? static_cast<int>(from_y / h) : rows() - 1;
    for (int cy = top; cy >= 0; --cy) {
      if ((cy + 2) * h < best) break;
      for (int c = std::max(0, c0 - 1); c <= std::min(ncx - 1, c0 + 1); ++c)
        for (int j : cells[static_cast<std::size_t>(cy) * ncx + c]) {
          const double R = r + p.r[j], dx = px - p.x[j].x();
          if (std::abs(dx) >= R) continue;
          const double y = p.x[j].y() + std::sqrt(R * R - dx * dx);
          if (y <= from_y + 1e-9 * h && y > best) {
            best = y;
            hit = j;
          }
        }
    }
    return best;
  }

  // Places disk i (radius r, abscissa x0). Each pass lowers the centre, so
  // the loop ends; the cap only guards against a geometric corner case.
  void place(int i, double x0) {
    const double r = p.r[i];
    Vec2 P(x0, std::numeric_limits<double>::infinity());
    int a;
    P.y() = fall(P.x(), P.y(), r, a);
    for (int pass = 0; pass < 10000 && a >= 0; ++pass) {
      // Roll on support a, away from its centre: the centre moves on the
      // circle of radius R about a, angle th from th0 towards 0 (s = +1) or
      // pi (s = -1).
      const Vec2 A = p.x[a];
      const double R = r + p.r[a];
      const double th0 = std::atan2(P.y() - A.y(), P.x() - A.x());
      if (th0 <= 0.0 || th0 >= std::numbers::pi) {  // below the support's centre: free fall
        P.y() = fall(P.x(), P.y(), r, a);
        continue;
      }
      const double s = P.x() >= A.x() ? 1.0 : -1.0;
      const double th_end = s > 0 ? 0.0 : std::numbers::pi;
      double th_hit = th_end;  // first event along the path
      int b_hit = -1;          // -1: none, -2: floor or wall
      auto consider = [&](double th, int who) {
        if (!std::isfinite(th)) return;
        if (s > 0 ? (th < th0 - kEps && th > th_hit) : (th > th0 + kEps && th < th_hit)) {
          th_hit = th;
          b_hit = who;
        }
      };
      // Floor y = r and side walls x = r, x = W - r.
      if (r > A.y()) consider(s > 0 ? std::asin((r - A.y()) / R)
                                    : std::numbers::pi - std::asin((r - A.y()) / R), -2);
      const double xw = s > 0 ? W - r : r;
      if (std::abs(xw - A.x()) <= R) consider(std::acos((xw - A.x()) / R), -2);
      // Other disks: the centre enters the excluded circle (radius RB about B)
      // at angle phi + alpha going down (s > 0) or phi - alpha (s < 0).
      const int ca = cx(A.x()), ra = static_cast<int>(A.y() / h);
      for (int cy = std::max(0, ra - 2); cy <= std::min(rows() - 1, ra + 2); ++cy)
        for (int c = std::max(0, ca - 2); c <= std::min(ncx - 1, ca + 2); ++c)
          for (int b : cells[static_cast<std::size_t>(cy) * ncx + c]) {
            if (b == a) continue;
            const Vec2 D = p.x[b] - A;
            const double d = D.norm(), RB = r + p.r[b];
            if (d >= R + RB || d <= std::abs(R - RB)) continue;
            const double phi = std::atan2(D.y(), D.x());
            const double cos_a = (R * R + d * d - RB * RB) / (2 * R * d);
            const double alpha = std::acos(std::clamp(cos_a, -1.0, 1.0));
            double th = s > 0 ? phi + alpha : phi - alpha;
            if (th > std::numbers::pi) th -= 2 * std::numbers::pi;
            if (th < -std::numbers::pi) th += 2 * std::numbers::pi;
            consider(th, b);
          }
      P = A + R * Vec2(std::cos(th_hit), std::sin(th_hit));
      if (b_hit == -2) break;  // resting on the floor or against a wall
      if (b_hit == -1) {  // rolled off a's side: fall from there, just clear of a
        P.x() = std::clamp(A.x() + s * R * (1 + 1e-9), r, W - r);
        P.y() = fall(P.x(), P.y(), r, a);
        continue;
      }
      const Vec2 B = p.x[b_hit];
      // Cradled between a and b (or wedged under b): at rest.
      if ((A.x() - P.x()) * (B.x() - P.x()) <= 0.0) break;
      // Both supports on one side: pivot on b, unless rolling on b would push
      // into a. That rare wedge is left as it is; settle() sorts it out.
      const Vec2 v = s * Vec2(P.y() - B.y(), -(P.x() - B.x()));  // motion about b, sense s
      const double sb = P.x() >= B.x() ? 1.0 : -1.0;
      if (sb * s < 0 || (P - A).dot(v) < 0) break;
      a = b_hit;
    }
    p.x[i] = P;
    insert(i);
  }
};

}  // namespace

Pile deposit(const std::vector<double>& diameters, double width, unsigned seed) {
  Pile p;
  p.width = width;
  const std::size_t n = diameters.size();
  p.r.resize(n);
  p.x.assign(n, Vec2::Zero());
  double dmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    p.r[i] = 0.5 * diameters[i];
    dmax = std::max(dmax, diameters[i]);
  }
  Deposit dep(p, width, dmax);
  std::mt19937_64 g(seed);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = static_cast<double>(g() >> 11) * 0x1.0p-53;  // platform-independent
    dep.place(static_cast<int>(i), p.r[i] + u * (width - 2 * p.r[i]));
    p.height = std::max(p.height, p.x[i].y() + p.r[i]);
  }
  return p;
}

cd::Scene pile_scene(int n, unsigned seed) {
  cd::Scene s;
  s.n = n;
  s.seed = seed;
  return s;
}

cd::World pile_world(const cd::Scene& s, double aspect) {
  const std::vector<double> d = cd::generated_diameters(s);
  double area = 0;
  for (double x : d) area += 0.25 * std::numbers::pi * x * x;
  // Deposits of this size distribution have a packing fraction ~0.72.
  const double width = std::sqrt(aspect * area / 0.72);
  const Pile p = deposit(d, width, s.seed);
  // Number the disks row by row (bands one largest diameter high), as
  // build_world's lattice does: deposition order is random in space, and
  // neighbours with distant indices make every sweep miss the cache.
  const double band = 2 * *std::max_element(p.r.begin(), p.r.end());
  std::vector<std::size_t> order(p.x.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto ka = std::floor(p.x[a].y() / band), kb = std::floor(p.x[b].y() / band);
    return ka != kb ? ka < kb : p.x[a].x() < p.x[b].x();
  });
  cd::World w(cd::world_params(s));
  for (std::size_t i : order) w.bodies.add_disk(p.x[i], p.r[i], s.density);
  const double H = 1.5 * p.height;
  w.bodies.add_wall({0, 0}, {width, 0});
  w.bodies.add_wall({0, H}, {0, 0});
  w.bodies.add_wall({width, 0}, {width, H});
  return w;
}

void settle(cd::World& w) {
  const cd::WorldParams p0 = w.params();
  cd::WorldParams q = p0;
  q.dt = 5e-4;
  q.solver.tol = 1e-3;
  q.solver.max_iter = 500;
  w.set_params(q);
  for (int k = 0; k < 600; ++k) w.step();
  w.set_params(p0);
  for (int k = 0; k < 50; ++k) w.step();
}

cd::World polygon_pile(int n, int sides, int coarse_steps, unsigned seed) {
  cd::Scene s = pile_scene(n, seed);
  s.nsides = {static_cast<double>(sides)};
  const std::vector<double> d = cd::generated_diameters(s);
  const double pitch = 1.02 * *std::max_element(d.begin(), d.end());
  const int nx = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(n)))));
  const int ny = (n + nx - 1) / nx;
  s.box_width = (nx + 0.5) * pitch;   // build_world fits floor(W / pitch) = nx columns
  s.box_height = (ny + 0.5) * pitch;
  cd::World w = cd::build_world(s);
  const cd::WorldParams p0 = w.params();
  cd::WorldParams q = p0;
  q.dt = 5e-4;
  q.solver.tol = 1e-3;
  q.solver.max_iter = 500;
  // The bodies fall about 1 cm and hit the pile at ~0.5 m/s, i.e. 25 % d a
  // coarse step: without a correction that depth of overlap stays (measured:
  // max overlap 27 % d for squares). beta = 0.2 pushes it out (0.3 % d).
  q.overlap_correction = 0.2;
  w.set_params(q);
  for (int k = 0; k < coarse_steps; ++k) w.step();
  w.set_params(p0);
  for (int k = 0; k < 50; ++k) w.step();
  return w;
}

double box_width(const cd::World& w) {
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.shape[i] == cd::Shape::Segment) return 2 * w.bodies.pos[i].x();  // the floor
  return 0;
}

cd::World tile(const cd::World& base, int copies) {
  const cd::Bodies& B = base.bodies;
  double lo = 1e300, hi = -1e300, top = 0;
  for (std::size_t i = 0; i < B.size(); ++i)
    if (B.is_dynamic(i)) {
      lo = std::min(lo, B.pos[i].x() - B.radius[i]);
      hi = std::max(hi, B.pos[i].x() + B.radius[i]);
      top = std::max(top, B.pos[i].y() + B.radius[i]);
    }
  const double W = hi - lo;
  cd::World w(base.params());
  for (int c = 0; c < copies; ++c)
    for (std::size_t i = 0; i < B.size(); ++i) {
      if (!B.is_dynamic(i)) continue;
      const double x = B.pos[i].x();
      const cd::Vec2 at(c * W + (c % 2 ? hi - x : x - lo), B.pos[i].y());
      if (B.shape[i] == cd::Shape::Polygon) {
        const int ns = B.nsides[i];
        const double R = B.radius[i];
        const double area = 0.5 * ns * R * R * std::sin(2 * std::numbers::pi / ns);
        w.bodies.add_polygon(at, R, ns, c % 2 ? std::numbers::pi - B.angle[i] : B.angle[i],
                             B.mass[i] / area);
      } else {
        w.bodies.add_disk(at, B.radius[i],
                          B.mass[i] / (std::numbers::pi * B.radius[i] * B.radius[i]));
      }
    }
  const double L = copies * W, H = 1.5 * top;
  w.bodies.add_wall({0, 0}, {L, 0});
  w.bodies.add_wall({0, H}, {0, 0});
  w.bodies.add_wall({L, 0}, {L, H});
  return w;
}

double wall_force_y(const cd::World& w) {
  double py = 0;
  for (const cd::ContactRow& r : w.rows())
    if (w.bodies.driven[r.b1]) py += r.ny * r.pn + r.nx * r.pt;  // impulse on body 2
  return py / w.params().dt;
}

double total_weight(const cd::World& w) {
  double m = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) m += w.bodies.mass[i];
  return m * w.params().gravity.norm();
}

}  // namespace cdbench
