// The library of convex polyhedra (polyhedron.hpp): Platonic solids,
// cuboids, random hulls of points on an ellipsoid.
#include <cmath>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "polyhedron.hpp"

namespace cd {

namespace {

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument(what); }

void check_length(const char* what, double x) {
  if (!(x > 0.0) || !std::isfinite(x)) refuse(fmt::format("{} = {} is not a positive finite length", what, x));
}

// The points (+-x, +-y, +-z) over the signs of the non-zero components.
void add_signs(std::vector<Vec3>& out, double x, double y, double z) {
  for (double sx : {1.0, -1.0})
    for (double sy : {1.0, -1.0})
      for (double sz : {1.0, -1.0}) {
        if ((sx < 0 && x == 0) || (sy < 0 && y == 0) || (sz < 0 && z == 0)) continue;
        out.emplace_back(sx * x, sy * y, sz * z);
      }
}

// (x, y, z) and its cyclic permutations, over the signs.
void add_cyclic(std::vector<Vec3>& out, double x, double y, double z) {
  add_signs(out, x, y, z);
  add_signs(out, z, x, y);
  add_signs(out, y, z, x);
}

// A uniform double in [0, 1) from the 53 high bits of one draw.
double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

}  // namespace

ConvexPolyhedron platonic(Platonic kind, double r) {
  check_length("circumradius", r);
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v;
  double radius = 0.0;  // of the points as listed
  switch (kind) {
    case Platonic::Tetrahedron:
      v = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
      radius = std::sqrt(3.0);
      break;
    case Platonic::Cube:
      add_signs(v, 1, 1, 1);
      radius = std::sqrt(3.0);
      break;
    case Platonic::Octahedron:
      add_cyclic(v, 1, 0, 0);
      radius = 1.0;
      break;
    case Platonic::Dodecahedron:
      add_signs(v, 1, 1, 1);
      add_cyclic(v, 0, 1 / phi, phi);
      radius = std::sqrt(3.0);
      break;
    case Platonic::Icosahedron:
      add_cyclic(v, 0, 1, phi);
      radius = std::sqrt(1 + phi * phi);
      break;
  }
  for (Vec3& p : v) p *= r / radius;
  return ConvexPolyhedron(v);
}

ConvexPolyhedron cuboid(double a, double b, double c) {
  check_length("cuboid side a", a);
  check_length("cuboid side b", b);
  check_length("cuboid side c", c);
  std::vector<Vec3> v;
  add_signs(v, a / 2, b / 2, c / 2);
  return ConvexPolyhedron(v);
}

std::vector<Vec3> random_points_on_ellipsoid(int n, const Vec3& semi_axes, std::uint64_t seed) {
  if (n < 0) refuse(fmt::format("random points: n = {} is negative", n));
  check_length("semi-axis a", semi_axes.x());
  check_length("semi-axis b", semi_axes.y());
  check_length("semi-axis c", semi_axes.z());
  std::mt19937_64 g(seed);
  std::vector<Vec3> out;
  out.reserve(n);
  // A uniform point of the ball, away from its centre, normalised: a
  // uniform direction (rejection keeps 52 % of the draws).
  while (static_cast<int>(out.size()) < n) {
    const double x = 2.0 * uniform01(g) - 1.0, y = 2.0 * uniform01(g) - 1.0, z = 2.0 * uniform01(g) - 1.0;
    const double r2 = x * x + y * y + z * z;
    if (r2 > 1.0 || r2 <= 1e-6) continue;
    const double r = std::sqrt(r2);
    out.emplace_back(semi_axes.x() * (x / r), semi_axes.y() * (y / r), semi_axes.z() * (z / r));
  }
  return out;
}

ConvexPolyhedron random_polyhedron(int n, const Vec3& semi_axes, std::uint64_t seed) {
  return ConvexPolyhedron(random_points_on_ellipsoid(n, semi_axes, seed), RedundantPoints::Drop);
}

}  // namespace cd
