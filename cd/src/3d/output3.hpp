// 3D snapshots for ParaView: spheres as points (Point Gaussian or Glyph,
// scaled by `radius`), polyhedra as their faces, contacts as lines, with
// .pvd collections.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "world3.hpp"

namespace cd {

// Writes path (.vtp): points at the sphere centres with point data id,
// radius, velocity (3), omega (3), orientation (unit quaternion w, x, y, z)
// and mass. Written to a temporary name and renamed into place; throws
// WriteError if it cannot be written.
void write_spheres_vtp(const World3& w, const std::string& path);

// Writes path (.vtp): the last step's contacts as lines, one cell each
// (each with its own points). A sphere's contact: from the centre of body 1
// to the centre of body 2 (a wall contact: from the contact point on the
// plane to the sphere's centre). A polyhedron's contact point (up to 4 rows
// a pair): the row's lever arms, a polyline of 3 points from the centroid
// of body 1 through the contact point to the centroid of body 2 (the
// touched image across a periodic side), at the step's midpoint
// configuration where the point was found (a wall contact: 2 points, from
// the contact point to the centroid). Cell data
//   fn      normal force (N; impulse / dt), > 0 compressive
//   ft      tangential force vector (world frame, N), on body 2
//   force   total force vector on body 2 (world frame, N)
//   normal  unit normal, body 1 to body 2
//   status  0 open, 1 stick, 2 slide (|f_t| >= mu (f_n + f_a))
//   gap     signed gap at the step's midpoint configuration (m)
//   b1, b2  body indices (planes are bodies 0.. of the box)
//   kind    ContactInfo3::kind: 0 a sphere's, 1 vertex-face, 2 edge-face,
//           3 face-face, 4 edge-edge (a polyhedron's)
//   branch  ContactInfo3::branch: centre of body 1 to the centre of body 2
//           (its touched image; a wall: from the centre's foot on the
//           plane), the lever of the contact stress
void write_contacts3_vtp(const World3& w, const std::string& path);

// Writes path (.vtp): every polyhedron (driven ones too) as its faces, one
// polygon cell per face with the body's own points (pos + orient * vertex,
// world frame, the loop counter-clockwise seen from outside), cell data
// repeated on each face of a body: id (body index), shape_id (index into
// bodies.polyhedra), radius (circumradius), velocity (3), omega (3).
// Written and refused as write_spheres_vtp (WriteError).
void write_polyhedra_vtp(const World3& w, const std::string& path);

// 0 open, 1 stick, 2 slide: row k of the last step (as 2D's ContactStatus).
int contact_status3(const SphereRow& r);

// spheres_NNNNN.vtp and contacts_NNNNN.vtp per snapshot, and spheres.pvd,
// contacts.pvd (rewritten atomically after each snapshot); a world with
// polyhedra (a shape library) also polyhedra_NNNNN.vtp and polyhedra.pvd.
class Snapshots3 {
 public:
  explicit Snapshots3(const std::string& dir = "",
                      std::vector<std::pair<double, std::string>> frames = {})
      : dir_(dir), n_(static_cast<int>(frames.size())), frames_(std::move(frames)) {}
  void write(const World3& w);

 private:
  std::string dir_;
  int n_ = 0;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace cd
