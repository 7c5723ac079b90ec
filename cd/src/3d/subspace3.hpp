// What the sweep's subspace correction (core/sweep.hpp, Subspace) asks of a
// 3D row, the same for sphere rows (coupling3.hpp) and polyhedra's block
// rows (block_coupling3.hpp): which of its components are free in the
// linear problem, and the trial impulse a correction gives it.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "vec3.hpp"

namespace cd::subspace3 {

// A closed row (shifted normal impulse s_n = r_n + a > 0, a the adhesion)
// is free in its normal component, and in its tangential ones too when it
// sticks (|r_t| below mu s_n by more than round-off: the local solve puts a
// sliding impulse on the cone itself). |r_t| as law3's project_sphere3
// takes it (sqrt, not the libm hypot: 3.6 % of a dense shear run's time
// went there).
template <class L>
inline void free_components(const Vec3& r, double mu, double adh, double* free) {
  const double sn = r[0] + (L::cohesive ? adh : 0.0);
  const bool closed = sn > 0;
  const bool sticks = L::tangential && closed && std::sqrt(r[1] * r[1] + r[2] * r[2]) < (1.0 - 1e-9) * mu * sn;
  free[0] = closed ? 1.0 : 0.0;
  free[1] = free[2] = sticks ? 1.0 : 0.0;
}

// r + d, for the law's projection to take: a sliding row's tangential
// impulse held in direction and scaled with the shifted normal one (so that
// it stays on the cone's edge).
template <class L>
inline Vec3 trial(const Vec3& r, double adh, const double* d, bool sticking) {
  Vec3 y(r[0] + d[0], r[1], r[2]);
  if (sticking) {
    y[1] += d[1];
    y[2] += d[2];
  } else if (L::tangential) {
    const double a = L::cohesive ? adh : 0.0;
    y.tail<2>() *= std::max(y[0] + a, 0.0) / (r[0] + a);
  }
  return y;
}

// The scatter of a product W p: the bodies' copy s zeroed, then every
// listed row's p pushed into it (the row kind's push_impulse, both bodies).
template <class Row, class Bodies>
inline void scatter(const Row* R, const std::vector<int>& live, const double* p, Bodies& s) {
  for (auto& b : s) {
    b.v.setZero();
    b.w.setZero();
  }
  for (const int i : live) push_impulse<true>(R[i], Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), s.data());
}

}  // namespace cd::subspace3
