#include "setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

namespace cd {

namespace {

// Uniform in [0, 1) from the 53 high bits: the same on every platform,
// unlike std::uniform_real_distribution.
double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

// Diameter range [a, b] with b = ratio a whose number mean is d_mean.
//   uniform:       d uniform,           mean = a (1 + r) / 2
//   uniform_area:  pdf(d) ~ 1/d^2, i.e. each size class holds the same area
//                  fraction (2D), mean = a r ln r / (r - 1)
void diameter_range(const Scene& s, double& a, double& b) {
  const double r = s.size_ratio;
  if (r == 1.0) {
    a = b = s.d_mean;
  } else if (s.size_dist == "uniform") {
    a = 2.0 * s.d_mean / (1.0 + r);
  } else {
    a = s.d_mean * (r - 1.0) / (r * std::log(r));
  }
  b = a * r;
}

std::string body_name(const Scene& s, int i, int first_generated) {
  if (i < static_cast<int>(s.disks.size())) return fmt::format("disk[{}]", i);
  return fmt::format("generated particle {}", i - first_generated);
}

}  // namespace

std::vector<double> generated_diameters(const Scene& s) {
  double a, b;
  diameter_range(s, a, b);
  std::mt19937_64 g(s.seed);
  std::vector<double> d(s.n);
  for (double& x : d) {
    const double u = uniform01(g);
    x = s.size_dist == "uniform" ? a + u * (b - a) : 1.0 / (1.0 / a - u * (1.0 / a - 1.0 / b));
  }
  return d;
}

double mean_diameter(const Scene& s) {
  double sum = 0;
  int n = 0;
  for (const DiskSpec& d : s.disks) {
    sum += 2 * d.radius;
    ++n;
  }
  if (s.n > 0) {
    sum += s.n * s.d_mean;
    n += s.n;
  }
  return n > 0 ? sum / n : s.d_mean;
}

WorldParams world_params(const Scene& s) {
  WorldParams p;
  p.dt = s.dt;
  p.gravity = Vec2(s.gravity[0], s.gravity[1]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  p.e_n = s.e_n;
  p.e_t = s.e_t;
  p.d_ref = mean_diameter(s);
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.adhesion = s.adhesion;
  p.debond = s.debond * p.d_ref;
  p.solver.tol = s.tol;
  p.solver.max_iter = s.max_iter;
  p.solver.rotation = s.rotation;
  return p;
}

World build_world(const Scene& s) {
  World w(world_params(s));
  Bodies& B = w.bodies;

  for (const DiskSpec& d : s.disks) {
    const double rho = d.density > 0 ? d.density : s.density;
    const int i = d.nsides > 0 ? B.add_polygon({d.pos[0], d.pos[1]}, d.radius, d.nsides, d.angle,
                                               rho, {d.vel[0], d.vel[1]}, d.omega)
                               : B.add_disk({d.pos[0], d.pos[1]}, d.radius, rho,
                                            {d.vel[0], d.vel[1]}, d.omega);
    B.force[i] = Vec2(d.force[0], d.force[1]);
  }
  const int first_generated = static_cast<int>(B.size());

  if (s.n > 0) {
    // Loose placement on a jittered square lattice of pitch 1.02 d_max: no
    // overlap by construction, filled row by row from the bottom.
    std::vector<double> region = s.region;
    if (region.empty()) {
      if (s.box_width <= 0)
        throw SceneError("particles.n > 0 needs particles.region or a [box] to place them in");
      region = {0.0, 0.0, s.box_width, s.box_height};
    }
    const std::vector<double> d = generated_diameters(s);
    const double dmax = *std::max_element(d.begin(), d.end());
    const double pitch = 1.02 * dmax;
    const int nx = static_cast<int>((region[2] - region[0]) / pitch);
    const int ny = static_cast<int>((region[3] - region[1]) / pitch);
    if (static_cast<long>(nx) * ny < s.n)
      throw SceneError(fmt::format(
          "particles.n = {} does not fit in the region [{}, {}] x [{}, {}]: room for {} disks "
          "of the largest diameter {:.4g} on a loose lattice; enlarge the region or the box",
          s.n, region[0], region[2], region[1], region[3], static_cast<long>(nx) * ny, dmax));
    std::mt19937_64 g(s.seed + 1);
    std::mt19937_64 gs(s.seed + 2);  // shapes and orientations: their own stream, so a
                                     // disk-only scene places exactly as before
    for (int k = 0; k < s.n; ++k) {
      const int ix = k % nx, iy = k / nx;
      const double slack = 0.5 * (pitch - d[k]);
      const double x = region[0] + (ix + 0.5) * pitch + slack * (2 * uniform01(g) - 1);
      const double y = region[1] + (iy + 0.5) * pitch + slack * (2 * uniform01(g) - 1);
      const int sides =
          s.nsides.size() == 1
              ? static_cast<int>(s.nsides[0])
              : static_cast<int>(s.nsides[std::min<std::size_t>(
                    s.nsides.size() - 1, static_cast<std::size_t>(uniform01(gs) * s.nsides.size()))]);
      if (sides > 0)
        B.add_polygon({x, y}, 0.5 * d[k], sides, 2 * std::numbers::pi * uniform01(gs), s.density);
      else
        B.add_disk({x, y}, 0.5 * d[k], s.density);
    }
  }

  if (s.box_width > 0) {
    const double W = s.box_width, H = s.box_height;
    B.add_wall({0, 0}, {W, 0});
    B.add_wall({0, H}, {0, 0});
    B.add_wall({W, 0}, {W, H});
    B.add_wall({W, H}, {0, H});
  }
  for (const WallSpec& ws : s.walls)
    B.add_wall({ws.a[0], ws.a[1]}, {ws.b[0], ws.b[1]}, {ws.vel[0], ws.vel[1]}, ws.omega);

  // No overlap at t = 0: run the detector with zero alert on the initial
  // configuration. Round-off sized overlaps (1e-9 d) are tolerated so that
  // disks placed exactly touching are accepted.
  std::vector<ContactRow> rows;
  std::vector<ContactInfo> info;
  CellGrid grid;
  detect(B, B.pos, B.angle, 0.0, grid, rows, info);
  const double tol = 1e-9 * w.params().d_ref;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (info[k].gap >= -tol) continue;
    const int i = rows[k].b1, j = rows[k].b2;
    const std::string a = B.driven[i] ? fmt::format("a wall (body {})", i)
                                      : body_name(s, i, first_generated);
    throw SceneError(fmt::format(
        "initial overlap: {} at ({:.6g}, {:.6g}) and {} at ({:.6g}, {:.6g}) overlap by {:.3g} "
        "(= {:.3g} mean diameters); particles must not overlap at t = 0",
        a, B.pos[i].x(), B.pos[i].y(), body_name(s, j, first_generated), B.pos[j].x(),
        B.pos[j].y(), -info[k].gap, -info[k].gap / w.params().d_ref));
  }
  return w;
}

}  // namespace cd
