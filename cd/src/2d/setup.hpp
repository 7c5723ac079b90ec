// The 2D world a scene describes: built from the complete scene
// (scene/complete.hpp), which has checked every rule of the scene and
// resolved what the build needs; this adds the bodies (explicit disks,
// generated grains, a shear.start sample, walls) and checks what needs
// them (a sample's shapes and density, overlaps at t = 0).
#pragma once
#include "complete.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace cd {

WorldParams world_params(const CompleteScene& c);
World build_world(const CompleteScene& c);

// The same from the scene's keys (complete_scene first).
inline WorldParams world_params(const Scene& s) { return world_params(complete_scene(s)); }
inline World build_world(const Scene& s) { return build_world(complete_scene(s)); }

}  // namespace cd
