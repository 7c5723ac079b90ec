// 3D bodies: spheres and plane walls in one structure of arrays, so that a
// contact names its two bodies by index whatever they are (as 2D's Bodies).
// Hot solver data (velocity, angular velocity, inverse mass and inertia)
// lives apart from the kinematics and the cold data. Spheres have a scalar
// moment of inertia (2/5 m r^2), so inv_I is a scalar; the orientation is a
// unit quaternion, integrated for output and for later non-spherical shapes.
// A plane is the half space (x - pos).normal >= 0 seen from its side: a
// driven body (inv_m = inv_I = 0) moving at an imposed velocity.
#pragma once
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cd {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

enum class Shape3 : std::uint8_t { Sphere, Plane };

// What the NLGS sweep reads and writes per body: velocity v, angular
// velocity w (world frame), inverse mass and inverse (scalar) inertia. A
// driven body has inv_m = inv_I = 0 and is never written by the solver.
struct BodyVel3 {
  Vec3 v = Vec3::Zero(), w = Vec3::Zero();
  double inv_m = 0, inv_I = 0;
};

struct Bodies3 {
  // hot
  std::vector<BodyVel3> vel;
  // kinematics: centre (plane: a point of it) and orientation
  std::vector<Vec3> pos;
  std::vector<Quat> orient;
  // cold
  std::vector<Shape3> shape;
  std::vector<double> radius;   // sphere radius; 0 for planes
  std::vector<Vec3> normal;     // plane: unit normal into the free side; spheres: 0
  std::vector<double> mass, inertia;
  std::vector<std::uint8_t> driven;  // 1: imposed velocity (walls, driven spheres)

  std::size_t size() const { return pos.size(); }
  bool is_dynamic(std::size_t i) const { return driven[i] == 0; }

  // A sphere of radius r and density rho (kg/m^3); returns its index.
  int add_sphere(const Vec3& x, double r, double rho, const Vec3& v = Vec3::Zero(),
                 const Vec3& w = Vec3::Zero()) {
    const double m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    return add(Shape3::Sphere, x, r, Vec3::Zero(), m, 0.4 * m * r * r, false, v, w);
  }
  // A plane through point p with normal n (normalised here), moving at v.
  int add_plane(const Vec3& p, const Vec3& n, const Vec3& v = Vec3::Zero()) {
    return add(Shape3::Plane, p, 0.0, n.normalized(), 0.0, 0.0, true, v, Vec3::Zero());
  }
  // Imposes the current velocity of body i from now on (driven sphere).
  void drive(int i) {
    driven[i] = 1;
    vel[i].inv_m = vel[i].inv_I = 0.0;
  }

 private:
  int add(Shape3 s, const Vec3& x, double r, const Vec3& n, double m, double I, bool drv,
          const Vec3& v, const Vec3& w) {
    BodyVel3 b;
    b.v = v;
    b.w = w;
    b.inv_m = drv || m <= 0 ? 0.0 : 1.0 / m;
    b.inv_I = drv || I <= 0 ? 0.0 : 1.0 / I;
    vel.push_back(b);
    pos.push_back(x);
    orient.push_back(Quat::Identity());
    shape.push_back(s);
    radius.push_back(r);
    normal.push_back(n);
    mass.push_back(m);
    inertia.push_back(I);
    driven.push_back(drv ? 1 : 0);
    return static_cast<int>(pos.size()) - 1;
  }
};

}  // namespace cd
