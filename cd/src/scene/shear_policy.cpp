#include "shear_policy.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace cd {

ShearSettings shear_settings(double I, Acceleration acc, SceneKind kind) {
  const ShearBand* b = &kShearBands.front();
  for (const ShearBand& x : kShearBands)
    if (I >= x.i_min) b = &x;
  // %.4g, then read back: the Makefile's awk printed dt_tp so.
  const double dt_tp = std::stod(fmt::format("{:.4g}", std::min(kSlidePerStep / I, kDtMaxTp)));
  const double tol = acc == Acceleration::Subspace ? b->tol_subspace
                     : acc == Acceleration::Anderson ? b->tol_anderson
                                                     : b->tol;
  if (kind.dimension == 2) return {tol, b->residual_tol, dt_tp, b->cell_mass, kind.polygons ? 0 : kAnderson, 0};
  if (kind.cohesive) return {tol, b->residual_tol, dt_tp, b->cell_mass, kAnderson, 0};
  return {tol, b->residual_tol, dt_tp, b->cell_mass, b->anderson, b->subspace};
}

}  // namespace cd
