// The 3D engine's vector and rotation types.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cd {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

}  // namespace cd
