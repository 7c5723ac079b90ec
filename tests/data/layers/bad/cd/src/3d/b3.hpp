// The 3D engine on core: allowed.
#include "c.hpp"
