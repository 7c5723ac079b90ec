#include "shear_policy.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace cd {

ShearSettings shear_settings(double I, Acceleration acc, bool cohesive) {
  const ShearBand* b = &kShearBands.front();
  for (const ShearBand& x : kShearBands)
    if (I >= x.i_min) b = &x;
  // %.4g, then read back: the Makefile's awk printed dt_tp so.
  const double dt_tp = std::stod(fmt::format("{:.4g}", std::min(kSlidePerStep / I, kDtMaxTp)));
  const double tol = acc == Acceleration::Subspace ? b->tol_subspace
                     : acc == Acceleration::Anderson ? b->tol_anderson
                                                     : b->tol;
  if (cohesive) return {tol, b->residual_tol, dt_tp, b->cell_mass, kCohesiveAnderson, 0};
  return {tol, b->residual_tol, dt_tp, b->cell_mass, b->anderson, b->subspace};
}

}  // namespace cd
