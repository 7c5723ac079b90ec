#include "bodies.hpp"

#include <cmath>
#include <numbers>

namespace cd {

int Bodies::add_disk(Vec2 x, double r, double density, Vec2 v, double omega) {
  const double m = density * std::numbers::pi * r * r;
  const double I = 0.5 * m * r * r;
  vel.push_back({v.x(), v.y(), omega, 1.0 / m, 1.0 / I});
  pos.push_back(x);
  angle.push_back(0.0);
  shape.push_back(Shape::Disk);
  radius.push_back(r);
  nsides.push_back(0);
  mass.push_back(m);
  inertia.push_back(I);
  driven.push_back(0);
  force.push_back(Vec2::Zero());
  return static_cast<int>(pos.size()) - 1;
}

int Bodies::add_polygon(Vec2 x, double R, int n, double ang, double density, Vec2 v,
                        double omega) {
  // Area (n/2) R^2 sin(2 pi/n); polar moment per unit mass (R^2/6)(2 + cos(2 pi/n)),
  // which gives s^2/6 for the square, s^2/12 for the triangle, R^2/2 as n -> inf.
  const double a = 2.0 * std::numbers::pi / n;
  const double m = density * 0.5 * n * R * R * std::sin(a);
  const double I = m * R * R * (2.0 + std::cos(a)) / 6.0;
  vel.push_back({v.x(), v.y(), omega, 1.0 / m, 1.0 / I});
  pos.push_back(x);
  angle.push_back(ang);
  shape.push_back(Shape::Polygon);
  radius.push_back(R);
  nsides.push_back(n);
  mass.push_back(m);
  inertia.push_back(I);
  driven.push_back(0);
  force.push_back(Vec2::Zero());
  return static_cast<int>(pos.size()) - 1;
}

int Bodies::add_wall(Vec2 a, Vec2 b, Vec2 v, double omega) {
  const Vec2 mid = 0.5 * (a + b);
  const Vec2 d = b - a;
  vel.push_back({v.x(), v.y(), omega, 0.0, 0.0});
  pos.push_back(mid);
  angle.push_back(std::atan2(d.y(), d.x()));
  shape.push_back(Shape::Segment);
  radius.push_back(0.5 * d.norm());
  nsides.push_back(0);
  mass.push_back(0.0);
  inertia.push_back(0.0);
  driven.push_back(1);
  force.push_back(Vec2::Zero());
  return static_cast<int>(pos.size()) - 1;
}

void Bodies::segment_ends(std::size_t i, Vec2& a, Vec2& b) const {
  const Vec2 e(std::cos(angle[i]), std::sin(angle[i]));
  a = pos[i] - radius[i] * e;
  b = pos[i] + radius[i] * e;
}

}  // namespace cd
