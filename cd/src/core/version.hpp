// The cdlab version: `git describe --always --dirty --tags` of the source
// tree when it was built (cd/version.cmake, rerun at every build), or
// "unknown" when the source is not a git clone.
#pragma once

namespace cd {
const char* version();
}
