// The 2D engine on core: allowed.
#include "c.hpp"
