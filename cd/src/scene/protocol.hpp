// The boundary protocol of a scene, and its rules, in one place for both
// engines: the boundary (shear.mode: none, the periodic cell, rough walls),
// what the cell imposes besides the shear (shear.control: the normal stress,
// or the volume), the shear rate, and what each protocol key needs of the
// others. The engines take the imposed pressure and the shear rate from
// here (and from derived.hpp) and do not check a protocol key again.
//
// A new protocol is a value of ShearMode or ShearControl (scene.hpp, with
// its name), its rules in check_protocol, what it imposes in
// imposed_pressure / shear_rate, and the engines' boundary for it
// (2d/boundary.hpp, 3d/boundary3.hpp).
#pragma once
#include "scene.hpp"

namespace cd {

// The normal stress the cell's lengths are held at: shear.pressure under
// pressure control, 0 (lengths fixed) under volume control or without a
// protocol.
double imposed_pressure(const Scene& s);

// The inertial number the "auto" settings are chosen for (shear_policy.hpp):
// shear.inertial_number under pressure control; under volume control the
// nominal I = shear.rate x t_p at the pressure scale shear.pressure (0
// without one, and "auto" is then refused), which is shear.rate_tp when the
// rate is given in units of 1/t_p.
double nominal_inertial_number(const Scene& s);

// Every rule of the protocol keys, in both dimensions (3D's messages end
// with "(dimension = 3; docs/3d.md)"): throws SceneError naming the keys.
// The rules of the cell's size against the grains stay with the engines'
// placement (setup.cpp, setup3.cpp).
void check_protocol(const Scene& s);

}  // namespace cd
