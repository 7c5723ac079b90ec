// 3D snapshots: one VTK point per dynamic sphere, for ParaView's Point
// Gaussian or Glyph (scale by `radius`).
#pragma once
#include <string>

#include "world3.hpp"

namespace cd {

// Writes path (.vtp): points at the sphere centres with point data id,
// radius, velocity (3), omega (3), orientation (unit quaternion w, x, y, z)
// and mass. Written to a temporary name and renamed into place; throws
// OutputError if it cannot be written.
void write_spheres_vtp(const World3& w, const std::string& path);

}  // namespace cd
