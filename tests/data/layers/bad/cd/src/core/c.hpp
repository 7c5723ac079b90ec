// Core on the scene: allowed.
#include "s.hpp"
