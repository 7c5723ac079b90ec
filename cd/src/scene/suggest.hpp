// "Did you mean": the closest known name to one that is not known, for the
// messages that refuse a scene key (config.cpp) or a command-line option
// (cd/app/cli_errors.hpp).
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace cd {

// The candidate closest to `name`, or "" when none is close enough to be a
// likely slip. Names are compared whole and by their last dot-separated part
// (so 'solver.mu' finds 'contact.mu'), by edit distance (insertions,
// deletions, substitutions, adjacent swaps; at most 1 + length / 5), and a
// name that lengthens or shortens a candidate in the same section
// ('solver.tolerance' for 'solver.tol', '--thread' for '--threads') counts as
// one edit away.
std::string closest(std::string_view name, const std::vector<std::string>& candidates);

// " (did you mean 'x'?)" for closest(name, candidates), or "".
std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates);

}  // namespace cd
