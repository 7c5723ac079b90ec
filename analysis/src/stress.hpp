// Contact stress (method.md §10): sigma_ij = (1/V) sum_c f_i l_j, with f the
// force on body 2 and l the branch vector 1 -> 2, so compression is positive:
// cd/src/core/observables.hpp computes it, for cdsim's series too.
// The kinetic part is not included (it needs velocity fluctuations about the
// mean flow profile; add it where inertia matters).
#pragma once
#include "snapshot.hpp"

namespace cda {

struct Stress {
  double xx = 0, xy = 0, yx = 0, yy = 0;  // sigma_ij = (1/V) sum f_i l_j
  // Invariants of the symmetric part (2D): p = (s1 + s2)/2, q = (s1 - s2)/2.
  double p() const;
  double q() const;
  double q_over_p() const;  // sin(phi) = mu* ; NaN if p == 0
  // Direction of the major principal stress s1, in [0, pi).
  double theta() const;
  // Antisymmetric part (sigma_xy - sigma_yx)/2; ~0 at equilibrium.
  double skew() const;
};

// Sum over the given contacts divided by V (V > 0, else AnalysisError).
Stress contact_stress(const ContactSet& cs, double volume);

// Partial stresses by contact type: the sum of the three is the total.
struct PartialStress {
  Stress disk, sv, ss;
};
PartialStress partial_stress(const ContactSet& cs, double volume);

}  // namespace cda
