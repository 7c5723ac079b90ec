// The 3D engine including a 2D header: refused.
#include "b3.hpp"
#include "w.hpp"
