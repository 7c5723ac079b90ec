// What to say when a scene's shear.start sample does not exist: which scene
// makes it. The shipped shear scenes start from outputs/<prep>/checkpoint.bin,
// the folder cdsim gives a scene named <prep> by default, so a newcomer who
// runs configs/shear-inertial.toml first is told to run the scene of that
// name (found beside the scene file) instead of only "cannot read checkpoint".
#pragma once
#include <string>

#include "scene.hpp"

namespace cd {

// "" when s.start exists; else "; no such file: ..." naming the scene in the
// scene file's folder whose default output folder holds s.start, or saying
// that a preparation run writes it.
std::string missing_start_hint(const Scene& s);

}  // namespace cd
