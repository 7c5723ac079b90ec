#include "fabric_bounds.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace cda {

double FabricBounds::a_max(double z) const {
  return k * std::min(1 - z_min / z, z_max / z - 1);
}
double FabricBounds::z_star() const { return 0.5 * (z_min + z_max); }
double FabricBounds::a_star() const { return k * (z_max - z_min) / (z_max + z_min); }

FabricBounds fabric_bounds(std::span<const double> z, std::span<const double> a,
                           std::span<const double> z_err, std::span<const double> a_err, double k,
                           double quantile) {
  const std::size_t n = z.size();
  if (n == 0) throw AnalysisError("fabric bounds: no (z, a_c) points");
  if (a.size() != n || (!z_err.empty() && z_err.size() != n) || (!a_err.empty() && a_err.size() != n))
    throw AnalysisError("fabric bounds: columns differ in length");
  if (!(k > 0)) throw AnalysisError(fmt::format("fabric bounds: k = {} is not positive", k));
  if (!(quantile > 0.5 && quantile <= 1))
    throw AnalysisError(fmt::format("fabric bounds: quantile {} outside (0.5, 1]", quantile));
  std::vector<double> lo(n), hi(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(z[i] > 0)) throw AnalysisError(fmt::format("fabric bounds: z = {} is not positive", z[i]));
    lo[i] = z[i] * (1 - a[i] / k);
    hi[i] = z[i] * (1 + a[i] / k);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  // Index of the point at the given quantile (1: the extreme).
  const auto skip = static_cast<std::size_t>(std::floor((1 - quantile) * static_cast<double>(n)));
  std::sort(order.begin(), order.end(), [&](auto i, auto j) { return lo[i] < lo[j]; });
  const std::size_t imin = order[std::min(skip, n - 1)];
  std::sort(order.begin(), order.end(), [&](auto i, auto j) { return hi[i] > hi[j]; });
  const std::size_t imax = order[std::min(skip, n - 1)];
  FabricBounds b;
  b.k = k;
  b.i_min = imin;
  b.i_max = imax;
  b.z_min = lo[imin];
  b.z_max = hi[imax];
  auto err = [&](std::size_t i, double sgn) {
    const double sz = z_err.empty() ? 0 : z_err[i], sa = a_err.empty() ? 0 : a_err[i];
    return std::hypot((1 + sgn * a[i] / k) * sz, z[i] / k * sa);
  };
  b.z_min_err = err(imin, -1);
  b.z_max_err = err(imax, +1);
  return b;
}

}  // namespace cda
