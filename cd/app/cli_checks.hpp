// Option checks the two commands share. CLI11's Range lets NaN through
// (every comparison with NaN is false), and a NaN option would then mean
// "not given"; these want a finite number.
#pragma once
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

}  // namespace cd
