// From a Scene to a World: generated and explicit disks, walls, and the
// per-scene settings. Checks what the parser cannot: that particles fit in
// their region and that no two bodies overlap at t = 0. The quantities both
// dimensions derive from a scene (mean diameter, size law, t_p, shear rate,
// time step, ...) are the scene layer's (scene/derived.hpp).
#pragma once
#include "derived.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace cd {

WorldParams world_params(const Scene& s);

// The scene with a shear cell given as 0 x 0 (for generated particles)
// sized for them, from the actual size law: periodic, the smallest square
// that holds them on the generator's loose lattice; walls, a sample about
// as wide as tall once the top wall has compacted it (setup.cpp). Any other
// scene unchanged.
Scene with_auto_cell(const Scene& s);

// Builds the world; throws SceneError naming the bodies at fault.
World build_world(const Scene& s);

}  // namespace cd
