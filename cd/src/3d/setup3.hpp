// From a `dimension = 3` Scene to a World3: the scene keys that apply in 3D
// (docs/3d.md), checked, mapped onto WorldParams3, and the spheres placed by
// pile3d.hpp's lattice builder. The keys of 2D-only features (shear
// protocols, [[disk]], [[wall]], polygons, regions, restitution, rotation
// off) are refused by name rather than ignored.
#pragma once
#include "derived.hpp"
#include "scene.hpp"
#include "world3.hpp"

namespace cd {

// Throws SceneError naming the key if the scene asks for what the 3D engine
// does not have, or if its box cannot hold the lattice.
void check_scene3(const Scene& s);

WorldParams3 world_params3(const Scene& s);

// The world: a floor and four side walls, the generated spheres on the
// lattice (particles.n, the size law or the explicit diameters).
// shear.mode = periodic: build_cell3.
World3 build_world3(const Scene& s);

// A tri-periodic cell (shear.mode = "periodic"; docs/3d.md): L_x, L_y, L_z
// = shear.width, height, depth (all 0: the cube that holds the spheres),
// the generated spheres at rest on a jittered cubic lattice of pitch 1.02
// d_max, none touching. No walls, no gravity; the lengths are fixed (the
// imposed stress of the 2D protocols is refused by key).
World3 build_cell3(const Scene& s);

}  // namespace cd
