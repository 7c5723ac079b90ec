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
  const bool spheres = kind.dimension == 3 && !kind.cohesive;
  const int anderson = kind.dimension == 2 ? (kind.polygons ? 0 : kAnderson) : kind.cohesive ? kAnderson : b->auto_anderson;
  const int subspace = spheres && !kind.orthotropic ? b->auto_subspace : 0;
  const bool polygons = kind.dimension == 2 && kind.polygons && !kind.cohesive;
  const Stop& stop = acc == Acceleration::Subspace   ? b->subspace
                     : acc == Acceleration::Anderson ? (kind.cohesive ? b->cohesive : b->anderson)
                     : polygons                      ? b->polygons
                                                     : b->plain;
  const double over = kind.loaded_stop ? kRowsPerLoadedRow : 1.0;
  return {stop.tol / std::sqrt(over), stop.residual_tol / over, stop.overlap_projection, dt_tp, b->cell_mass,
          anderson, subspace};
}

}  // namespace cd
