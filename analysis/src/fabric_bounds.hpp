// Fabric bounds (method.md §11). Definition used here, as written in
// method.md: the contact density by orientation
//   E(theta) = (z/2pi)(1 + a_c cos 2(theta - theta_c))
// lies between the isotropic limit densities z_min/2pi and z_max/2pi.
// The maximum of E, (z/2pi)(1 + a_c), must not exceed z_max/2pi, and its
// minimum, (z/2pi)(1 - a_c), must not fall below z_min/2pi:
//   a_c <= z_max/z - 1   and   a_c <= 1 - z_min/z,
// so a_c <= a_max(z) = k min{1 - z_min/z, z_max/z - 1} with k = 1, peaking
// at z* = (z_min + z_max)/2 with a* = k (z_max - z_min)/(z_max + z_min).
// (k = 2 in the source talk is the same bound with limit densities defined
// as z_min/pi over [0, pi) against an E normalised over [0, 2 pi).) k is kept
// as a parameter so the other normalisation can be used; the definition
// above gives k = 1, the default.
//
// Envelope: each point (z, a) satisfies both bounds iff
//   z_min <= z (1 - a/k)   and   z_max >= z (1 + a/k),
// so the tightest envelope over a set of points is closed-form:
//   z_min = min_i z_i (1 - a_i/k),  z_max = max_i z_i (1 + a_i/k).
// Every point lies inside it and at least one point touches each branch;
// no iterative fit is needed. With error bars on (z, a), the uncertainty of
// z_min (z_max) is that of its extremal point, propagated to first order.
// A `quantile` below 1 replaces min/max by that quantile of the same
// per-point bounds (robust to a few outliers; the envelope then leaves
// those points out).
#pragma once
#include <span>

#include "error.hpp"

namespace cda {

struct FabricBounds {
  double z_min = 0, z_max = 0;
  double z_min_err = 0, z_max_err = 0;
  double k = 1;
  std::size_t i_min = 0, i_max = 0;  // the points that set each bound
  double a_max(double z) const;      // k min{1 - z_min/z, z_max/z - 1}
  double z_star() const;             // (z_min + z_max)/2
  double a_star() const;             // k (z_max - z_min)/(z_max + z_min)
};

FabricBounds fabric_bounds(std::span<const double> z, std::span<const double> a_c,
                           std::span<const double> z_err = {}, std::span<const double> a_err = {},
                           double k = 1.0, double quantile = 1.0);

}  // namespace cda
