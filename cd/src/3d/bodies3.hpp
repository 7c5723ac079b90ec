// 3D bodies: spheres, convex polyhedra and plane walls in one structure of
// arrays, so that a contact names its two bodies by index whatever they are
// (as 2D's Bodies). Hot solver data (velocity, angular velocity, inverse
// mass and inertia) lives apart from the kinematics and the cold data.
// Spheres have a scalar moment of inertia (2/5 m r^2), so inv_I is a scalar
// and their orientation is integrated for output only. A polyhedron refers
// to a shape of the `polyhedra` library, expressed in its principal frame:
// its orientation maps that frame to the world, its inertia is its three
// principal moments (`moments`; the world tensor R diag(moments) R^T is
// rigid_rotation.hpp's), and its inv_I is 0 (the solver takes the tensor
// from ContactProblem3::inv_inertia instead; nothing may read inv_I as a
// polyhedron's). A plane is the half space (x - pos).normal >= 0 seen from
// its side: a driven body (inv_m = inv_I = 0) moving at an imposed velocity.
#pragma once
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <stdexcept>

#include "polyhedron.hpp"
#include "vec3.hpp"

namespace cd {

enum class Shape3 : std::uint8_t { Sphere, Plane, Polyhedron };

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
  std::vector<double> radius;   // sphere radius; polyhedron: circumradius; 0 for planes
  std::vector<Vec3> normal;     // plane: unit normal into the free side; others: 0
  std::vector<double> mass, inertia;  // inertia: a sphere's scalar moment; 0 for the others
  std::vector<std::uint8_t> driven;  // 1: imposed velocity (walls, driven spheres)
  // Polyhedra: the shape (index into `polyhedra`; -1 for the others) and
  // the principal moments of inertia (0 for the others).
  std::vector<std::int32_t> shape_id;
  std::vector<Vec3> moments;
  std::vector<ConvexPolyhedron> polyhedra;  // principal frame: unit_inertia() diagonal

  bool has_polyhedra() const { return !polyhedra.empty(); }
  const ConvexPolyhedron& polyhedron(std::size_t i) const { return polyhedra[static_cast<std::size_t>(shape_id[i])]; }

  std::size_t size() const { return pos.size(); }
  bool is_dynamic(std::size_t i) const { return driven[i] == 0; }
  // A grain's volume: its polyhedron's, or the sphere's (obs::sphere_volume's
  // expression); 0 for a plane.
  double volume(std::size_t i) const {
    if (shape[i] == Shape3::Polyhedron) return polyhedron(i).volume();
    return shape[i] == Shape3::Sphere ? 4.0 / 3.0 * std::numbers::pi * radius[i] * radius[i] * radius[i] : 0.0;
  }

  // A sphere of radius r and density rho (kg/m^3); returns its index.
  int add_sphere(const Vec3& x, double r, double rho, const Vec3& v = Vec3::Zero(),
                 const Vec3& w = Vec3::Zero()) {
    const double m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    const int i = add(Shape3::Sphere, x, r, Vec3::Zero(), m, 0.4 * m * r * r, false, v, w);
    moments[i] = Vec3::Constant(inertia[i]);
    return i;
  }
  // A shape for add_polyhedron, expressed in its principal frame (the hull
  // of its vertices turned by principal_axes()^T unless its inertia is
  // already diagonal, as the library's solids and cuboids are); returns its
  // index. The frame is the body's: a body's orientation maps it to the world.
  int add_shape(const ConvexPolyhedron& s) {
    const Eigen::Matrix3d& J = s.unit_inertia();
    const double off = std::abs(J(0, 1)) + std::abs(J(0, 2)) + std::abs(J(1, 2));
    if (off <= 1e-12 * J.trace()) {
      polyhedra.push_back(s);
    } else {
      std::vector<Vec3> v;
      for (const Vec3& p : s.vertices()) v.push_back(s.principal_axes().transpose() * p);
      polyhedra.emplace_back(v);
    }
    return static_cast<int>(polyhedra.size()) - 1;
  }
  // A polyhedron of shape `id` (add_shape) and density rho, centroid at x,
  // principal frame turned to the world by q; returns its index.
  int add_polyhedron(const Vec3& x, int id, double rho, const Quat& q = Quat::Identity(),
                     const Vec3& v = Vec3::Zero(), const Vec3& w = Vec3::Zero()) {
    if (id < 0 || id >= static_cast<int>(polyhedra.size()))
      throw std::invalid_argument("Bodies3::add_polyhedron: no shape of that index");
    const ConvexPolyhedron& s = polyhedra[static_cast<std::size_t>(id)];
    const int i = add(Shape3::Polyhedron, x, s.circumradius(), Vec3::Zero(), s.mass(rho), 0.0, false, v, w);
    orient[i] = q.normalized();
    shape_id[i] = id;
    moments[i] = rho * s.unit_inertia().diagonal();
    return i;
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
    shape_id.push_back(-1);
    moments.push_back(Vec3::Zero());
    return static_cast<int>(pos.size()) - 1;
  }
};

}  // namespace cd
