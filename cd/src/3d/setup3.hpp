// From a `dimension = 3` scene to a World3: the complete scene
// (scene/complete.hpp: every 3D rule checked there, the keys of 2D-only
// features refused by name rather than ignored) mapped onto WorldParams3,
// and the grains placed: pile3d.hpp's lattice in a box, a loose lattice in
// the periodic cell, or a shear.start sample (checked here: it needs the
// bodies).
#pragma once
#include "complete.hpp"
#include "scene.hpp"
#include "world3.hpp"

namespace cd {

WorldParams3 world_params3(const CompleteScene& c);
World3 build_world3(const CompleteScene& c);
World3 build_cell3(const CompleteScene& c);

// The same from the scene's keys (complete_scene first).
inline WorldParams3 world_params3(const Scene& s) { return world_params3(complete_scene(s)); }
inline World3 build_world3(const Scene& s) { return build_world3(complete_scene(s)); }
inline World3 build_cell3(const Scene& s) { return build_cell3(complete_scene(s)); }

}  // namespace cd
