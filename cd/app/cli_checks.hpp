// Option checks the two commands share. CLI11's Range lets NaN through
// (every comparison with NaN is false), and a NaN option would then mean
// "not given"; these want a finite number. CLI11's PositiveNumber names the
// range of a double (0 to a 309-digit number) when an integer option is
// given a word: positive_count names what is wanted instead.
#pragma once
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace cd {

// A finite number in [lo, hi] (in (lo, hi] with `open_lo`).
inline CLI::Validator finite_range(double lo, double hi, bool open_lo = false) {
  const std::string range = fmt::format("{}{}, {}]", open_lo ? "(" : "[", lo, hi);
  return CLI::Validator(
      [=](std::string& v) {
        char* end = nullptr;
        const double x = std::strtod(v.c_str(), &end);
        const bool ok = !v.empty() && *end == '\0' && std::isfinite(x) && (open_lo ? x > lo : x >= lo) && x <= hi;
        return ok ? std::string() : "must be a finite number in " + range;
      },
      "in " + range);
}

// A whole number >= 1 that fits a 64-bit integer (a step count); nullopt
// for anything else.
inline std::optional<long long> count_of(const std::string& v) {
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno != 0 || x < 1) return std::nullopt;
  return x;
}

// A whole number >= 1 that fits a 64-bit integer (a step count).
inline CLI::Validator positive_count() {
  return CLI::Validator(
      [](std::string& v) { return count_of(v) ? std::string() : "'" + v + "' is not a whole number >= 1"; },
      "a whole number >= 1");
}

// A --dump-problem step: a whole number >= 1 (the step), or "last", or
// "last-K" (K >= 1 steps before the run's last), which a campaign gives
// without computing the run's step count. Returned as the step itself, or
// <= 0 for the last (0) and last-K (-K); nullopt for any other word.
inline std::optional<long long> dump_step(const std::string& v) {
  if (v == "last") return 0;
  if (v.rfind("last-", 0) == 0) {
    const auto k = count_of(v.substr(5));
    return k ? std::optional<long long>(-*k) : std::nullopt;
  }
  return count_of(v);
}
inline CLI::Validator dump_step_word() {
  return CLI::Validator(
      [](std::string& v) {
        return dump_step(v) ? std::string()
                            : "'" + v + "' is not a whole number >= 1, \"last\" or \"last-K\" (K >= 1)";
      },
      "STEP, last or last-K");
}

// The steps of the --dump-problem words (dump_step_word() checked them) in
// a run of nsteps steps; throws std::invalid_argument for a last-K before
// the run's first step. (One past the last is the run session's check.)
inline std::vector<std::int64_t> dump_steps(const std::vector<std::string>& words, std::int64_t nsteps) {
  std::vector<std::int64_t> steps;
  for (const std::string& w : words) {
    const long long k = *dump_step(w);
    if (k <= 0 && nsteps + k < 1)
      throw std::invalid_argument(fmt::format(
          "--dump-problem {}: the run has {} steps, so it has no step {} before its last", w, nsteps, -k));
    steps.push_back(k <= 0 ? nsteps + k : k);
  }
  return steps;
}

}  // namespace cd
