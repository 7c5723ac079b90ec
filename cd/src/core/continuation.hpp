// shear.start, the part that does not depend on the dimension: a sample's
// grains checked against the scene that continues them (their density and
// mean diameter set the masses, t_p, the shear rate and f_a), and a sheared
// sample's mean flow replaced by the new run's profile. Each engine reads
// its own checkpoint and cell (2d/setup.cpp, 3d/setup3.cpp) and hands the
// grains here through accessors, so the two continue a sample alike.
#pragma once
#include <cmath>
#include <cstddef>
#include <string>

#include <fmt/format.h>

#include "derived.hpp"

namespace cd::continuation {

// The grains of a sample, as the engine sees them: n bodies, and for body i
// its height y(i), its velocity along the shear vx(i) (a reference, set
// here), its diameter d(i) and its density rho(i) (mass over area or volume).
// `what` names them in messages ("particles", "spheres") and `unit` the
// density's unit.
template <class Y, class Vx, class D, class Rho>
struct Grains {
  std::size_t n;
  Y y;
  Vx vx;
  D d;
  Rho rho;
  const char* what;
  const char* unit;
};
template <class Y, class Vx, class D, class Rho>
Grains(std::size_t, Y, Vx, D, Rho, const char*, const char*) -> Grains<Y, Vx, D, Rho>;

// Every grain has the scene's density (the masses come with the sample).
template <class G>
void check_density(const G& g, double density) {
  for (std::size_t i = 0; i < g.n; ++i)
    if (std::abs(g.rho(i) - density) > 1e-9 * density)
      throw SceneError(fmt::format("shear.start: the sample's {} have density {:.6g} {} (body {}), "
                                   "particles.density is {:.6g}; set particles.density to the preparation's",
                                   g.what, g.rho(i), g.unit, i, density));
}

// The grains' mean diameter is the scene's d (within 10 %): d sets the
// shear rate, t_p and f_a.
template <class G>
void check_mean_diameter(const G& g, double d_ref) {
  double dsum = 0;
  for (std::size_t i = 0; i < g.n; ++i) dsum += g.d(i);
  const double mean = g.n ? dsum / static_cast<double>(g.n) : 0.0;
  if (g.n == 0 || std::abs(mean - d_ref) > 0.1 * d_ref)
    throw SceneError(fmt::format("shear.start: the sample's mean diameter is {:.4g} m, particles.d_mean is "
                                 "{:.4g} m; set particles.d_mean to the preparation's",
                                 mean, d_ref));
}

// shear.volume_fraction: the factor on every length of the cell (and on
// the grains' positions about its origin, and the Lees-Edwards offset) that
// makes grains of total measure `grains` (area or volume) fill the fraction
// phi of a cell of measure `cell`, in `dim` dimensions. Refused when it is
// not finite and positive (an empty sample, a cell of no measure).
inline double volume_scale(double grains, double cell, double phi, int dim) {
  const double f = std::pow(grains / (phi * cell), 1.0 / dim);
  if (!(std::isfinite(f) && f > 0))
    throw SceneError(fmt::format("shear.volume_fraction = {}: the sample's grains ({:.4g}) in its cell ({:.4g}) "
                                 "give no finite scale",
                                 phi, grains, cell));
  return f;
}

// The flow: a sheared sample's mean flow a + g y (least squares over the
// grains) is taken out, and the new rate's profile gamma-dot (y - y_mid)
// put in, so that the run starts without a transient of momentum diffusing
// across the cell. A compacted sample (at rest) gets the profile alone.
template <class G>
void set_flow(G& g, bool sheared, double rate, double y_mid) {
  double a = 0, b = 0;  // the sample's mean flow vx = a + b y
  if (sheared) {
    double sy = 0, sv = 0, syy = 0, syv = 0, m = 0;
    for (std::size_t i = 0; i < g.n; ++i) {
      const double y = g.y(i), v = g.vx(i);
      sy += y, sv += v, syy += y * y, syv += y * v, m += 1;
    }
    const double den = m * syy - sy * sy;
    b = den > 0 ? (m * syv - sy * sv) / den : 0.0;
    a = m > 0 ? (sv - b * sy) / m : 0.0;
  }
  for (std::size_t i = 0; i < g.n; ++i) {
    const double y = g.y(i);
    if (sheared) g.vx(i) -= a + b * y;
    g.vx(i) += rate * (y - y_mid);
  }
}

}  // namespace cd::continuation
