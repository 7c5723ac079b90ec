// One exception type for every analysis failure that is the input's fault
// (missing file, missing column, empty run, too short a steady window). The
// message always names the file or quantity at fault; the command line prints
// it and exits non-zero.
#pragma once
#include <stdexcept>

namespace cda {

struct AnalysisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace cda
