// Option checks the two commands share. CLI11's Range lets NaN through
// (every comparison with NaN is false), and a NaN option would then mean
// "not given"; these want a finite number. CLI11's PositiveNumber names the
// range of a double (0 to a 309-digit number) when an integer option is
// given a word: positive_count names what is wanted instead.
#pragma once
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

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

// A whole number >= 1 that fits a 64-bit integer (a step count).
inline CLI::Validator positive_count() {
  return CLI::Validator(
      [](std::string& v) {
        char* end = nullptr;
        errno = 0;
        const long long x = std::strtoll(v.c_str(), &end, 10);
        const bool ok = !v.empty() && *end == '\0' && errno == 0 && x >= 1;
        return ok ? std::string() : "'" + v + "' is not a whole number >= 1";
      },
      "a whole number >= 1");
}

}  // namespace cd
