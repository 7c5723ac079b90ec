// The analysis on the observables: allowed; on an engine: refused.
#include "cd/src/core/observables.hpp"
#include "cd/src/2d/w.hpp"
