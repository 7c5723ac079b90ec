// Bodies: particles and walls in one structure-of-arrays, so that a contact
// names its two bodies by index whatever they are. Hot solver data (velocity,
// inverse inertia: 40 bytes a body) lives apart from cold data (shape, id).
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace cd {

using Vec2 = Eigen::Vector2d;

enum class Shape : std::uint8_t { Disk, Segment, Polygon };

// What the NLGS sweep reads and writes per body. A wall or any body with
// imposed velocity has inv_m = inv_I = 0 and is never written by the solver.
struct BodyVel {
  double vx = 0, vy = 0, w = 0;
  double inv_m = 0, inv_I = 0;
};

struct Bodies {
  // hot
  std::vector<BodyVel> vel;
  // kinematics: position of the centre (segment: midpoint) and angle
  std::vector<Vec2> pos;
  std::vector<double> angle;
  // cold
  std::vector<Shape> shape;
  std::vector<double> radius;   // disk radius; polygon circumradius; segment half length
  std::vector<std::int32_t> nsides;  // polygon sides (3..60); 0 for disks and segments
  std::vector<double> mass, inertia;
  std::vector<std::uint8_t> driven;  // 1: imposed velocity (walls)
  std::vector<Vec2> force;           // constant applied force (besides gravity)

  std::size_t size() const { return pos.size(); }
  bool is_dynamic(std::size_t i) const { return driven[i] == 0; }

  // Adds a disk of the given areal density; returns its index.
  int add_disk(Vec2 x, double r, double density, Vec2 v = Vec2::Zero(), double omega = 0.0);
  // Adds a regular polygon of n sides, circumradius R, orientation angle
  // (vertex 0 at angle `angle`), with exact mass and moment of inertia.
  int add_polygon(Vec2 x, double R, int n, double angle, double density, Vec2 v = Vec2::Zero(),
                  double omega = 0.0);
  // Adds a segment wall from a to b moving with imposed (v, omega).
  int add_wall(Vec2 a, Vec2 b, Vec2 v = Vec2::Zero(), double omega = 0.0);

  // Segment end points of body i (i must be a segment).
  void segment_ends(std::size_t i, Vec2& a, Vec2& b) const;
};

}  // namespace cd
