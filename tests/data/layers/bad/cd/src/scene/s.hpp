// A scene header reaching up into core: refused.
#include "c.hpp"
