// Geometry of a regular polygon at a configuration (centre, circumradius,
// angle, sides). Vertex k is at angle th + 2 pi k / n; face k joins vertex k
// to vertex k + 1 and has its outward normal at angle th + pi (2k + 1) / n,
// at distance apothem = R cos(pi/n) from the centre. Regularity makes the
// support point and the face most opposed to a direction O(1) lookups.
#pragma once
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace cd {

struct PolyView {
  Eigen::Vector2d c;
  double R, th;
  int n;

  double step() const { return 2.0 * std::numbers::pi / n; }
  double apothem() const { return R * std::cos(std::numbers::pi / n); }
  int wrap(long k) const { return static_cast<int>(((k % n) + n) % n); }
  Eigen::Vector2d vertex(int k) const {
    const double a = th + step() * k;
    return c + R * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  Eigen::Vector2d normal(int k) const {
    const double a = th + step() * (k + 0.5);
    return {std::cos(a), std::sin(a)};
  }
  // Index of the vertex farthest along d.
  int support(const Eigen::Vector2d& d) const {
    return wrap(std::lround((std::atan2(d.y(), d.x()) - th) / step()));
  }
  // Index of the face whose outward normal is closest to direction d.
  int face_towards(const Eigen::Vector2d& d) const {
    return wrap(std::lround((std::atan2(d.y(), d.x()) - th) / step() - 0.5));
  }
};

}  // namespace cd
