// 3D snapshots for ParaView: spheres as points (Point Gaussian or Glyph,
// scaled by `radius`) and contacts as lines, with .pvd collections.
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

// Writes path (.vtp): the last step's contacts as lines, one cell each,
// from the centre of body 1 to the centre of body 2 (a wall contact: from
// the contact point on the plane to the sphere's centre), with cell data
//   fn      normal force (N; impulse / dt), > 0 compressive
//   ft      tangential force vector (world frame, N), on body 2
//   force   total force vector on body 2 (world frame, N)
//   normal  unit normal, body 1 to body 2
//   status  0 open, 1 stick, 2 slide (|f_t| >= mu (f_n + f_a))
//   gap     signed gap at the step's midpoint configuration (m)
//   b1, b2  body indices (planes are bodies 0.. of the box)
void write_contacts3_vtp(const World3& w, const std::string& path);

// 0 open, 1 stick, 2 slide: row k of the last step (as 2D's ContactStatus).
int contact_status3(const SphereRow& r);

// spheres_NNNNN.vtp and contacts_NNNNN.vtp per snapshot, and spheres.pvd,
// contacts.pvd (rewritten atomically after each snapshot).
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
