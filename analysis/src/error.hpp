// One exception type for every analysis failure that is the input's fault
// (missing file, missing column, empty run, too short a steady window). The
// message always names the file or quantity at fault; the command line prints
// it and exits non-zero.
#pragma once
#include <fmt/core.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "cd/src/scene/printable.hpp"

namespace cda {

// Exit codes of cdanalysis (and of cdsim and cdproblem, where they apply):
// 0 done; 1 the analysis is refused (the input is readable but gives no
// honest answer: a degenerate fit, no steady window, a compare-fits FAIL);
// 2 bad input (usage, unreadable or malformed file, non-finite value);
// 3 a run diverged (cdsim).
// 5 done with reservations: everything that could be was written, but some
// runs were left out (no steady window, unreadable, other dimension) or
// some fitted parameters are undetermined; each is named on stderr and in
// the outputs. Scripts that only need "was anything produced" accept 0 and 5.
inline constexpr int kExitPartial = 5;

struct AnalysisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The input itself is at fault: a file missing, unreadable or malformed, a
// value not finite, an option out of range. Exit code 2.
struct InputError : AnalysisError {
  using AnalysisError::AnalysisError;
};

// A file the analysis reads is refused as what it is when a folder stands
// at its path (a reader would see it as an empty or truncated file).
inline void refuse_folder(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(fmt::format("'{}' is a folder, not a file", path));
}

// Text from a file or the command line, safe to print in a message
// (cd/src/scene/printable.hpp: the rule cdsim's scene errors follow too).
using cd::printable;

// The text of a TOML file the analysis reads, checked to be UTF-8 first
// (TOML's rule; toml11 3.7 reads outside its buffer when it reports a
// string that is not). Throws InputError naming the file, the line and the
// byte, or that it cannot be opened.
std::string toml_text(const std::string& path);

}  // namespace cda
