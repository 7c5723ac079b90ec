// One exception type for every analysis failure that is the input's fault
// (missing file, missing column, empty run, too short a steady window). The
// message always names the file or quantity at fault; the command line prints
// it and exits non-zero.
#pragma once
#include <stdexcept>

namespace cda {

// Exit codes of cdanalysis (and of cdsim and cdproblem, where they apply):
// 0 done; 1 the analysis is refused (the input is readable but gives no
// honest answer: a degenerate fit, no steady window, a compare-fits FAIL);
// 2 bad input (usage, unreadable or malformed file, non-finite value);
// 3 a run diverged (cdsim).
struct AnalysisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The input itself is at fault: a file missing, unreadable or malformed, a
// value not finite, an option out of range. Exit code 2.
struct InputError : AnalysisError {
  using AnalysisError::AnalysisError;
};

}  // namespace cda
