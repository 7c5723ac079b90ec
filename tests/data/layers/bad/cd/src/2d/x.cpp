// The 2D engine reaching into 3D by path: refused.
#include "cd/src/3d/b3.hpp"
#include "w.hpp"
