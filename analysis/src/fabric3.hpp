// 3D stress and fabric of spheres (docs/analysis.md, "3D runs"): the contact
// stress, its invariants, the fabric tensor and the contact-orientation,
// normal-force and tangential-force anisotropies of the second-order
// spherical-harmonic expansion (Ouadfel & Rothenburg, Mech. Mater. 33, 201
// (2001); Azema, Radjai & Dubois, PRE 87, 062203 (2013)).
//
// Harmonic forms over the unit sphere (n the contact normal; A_c, A_n, A_t
// traceless symmetric tensors):
//   P(n)       = (1/4pi) (1 + A_c : n n)
//   <f_n>(n)   = <f> (1 + A_n : n n)
//   <f_t>(n)   = <f> (2/3) (A_t n - (n . A_t n) n)       (a vector, _|_ n)
// For a state axisymmetric about the unit vector e, A = a (3 e e - 1), the
// classical forms with cos(theta) = n . e:
//   P = (1/4pi)(1 + a_c (3 cos^2 theta - 1)),
//   <f_n> = <f>(1 + a_n (3 cos^2 theta - 1)),
//   <f_t> = <f> a_t sin 2 theta, along -e_theta (towards e),
// so each scalar anisotropy is a = (A_1 - A_3)/3 of its tensor's principal
// values (A_1 >= A_2 >= A_3). With the contact stress
// sigma = (N/V) <f (x) l> and l = <l> n this gives, to first order in the
// anisotropies and for coaxial tensors,
//   q/p = (2/5)(a_c + a_n + a_t),  p = tr sigma / 3,  q = (sigma_1 - sigma_3)/3.
// (The fabric: F = <n n> = 1/3 + (2/15) A_c, so a_c = (5/2)(F_1 - F_3).)
//
// Estimators: F = (1/N) sum n n over the N force-bearing contacts gives A_c
// = (15/2) dev F exactly. chi_n = (1/N) sum f_n n n and the symmetric part
// of chi_t = (1/N) sum f_t (x) n are, for the forms above,
//   dev chi_n = <f> [(2/15)(A_c + A_n) + (4/105) dev(A_c A_n + A_n A_c)],
//   tr chi_n  = <f> [1 + (2/15) A_c : A_n],
//   dev sym chi_t = <f> [(2/15) A_t + (2/105) dev(A_c A_t + A_t A_c)]
// (the 4th and 6th isotropic moments of n), solved for A_n, <f>, A_t by
// fixed-point iteration: exact for the pure second-order forms, so that a
// sample drawn from them is recovered to sampling error, not only to first
// order. With A_c = 0 they reduce to the usual first-order definitions
// A_n = (15/2) dev chi_n / tr chi_n - A_c, A_t = (15/2) dev sym chi_t / tr chi_n.
#pragma once
#include <array>

#include "snapshot.hpp"

namespace cda {

using Mat3 = cd::obs::Tensor<3>;

// Principal values of the symmetric part of t, descending, and the unit
// principal directions (dir[k] goes with value[k]).
struct Principal {
  std::array<double, 3> value{};
  std::array<std::array<double, 3>, 3> dir{};
};
Principal principal(const Mat3& t);

// (A_1 - A_3)/3 of a tensor's symmetric part: the scalar anisotropy.
double spread3(const Mat3& t);

struct Stress3 {
  Mat3 s{};  // sigma_ij = (1/V) sum f_i l_j
  double p() const;          // tr sigma / 3
  double q() const;          // (sigma_1 - sigma_3)/3 (the stress-fabric relation's q)
  double q_over_p() const;   // NaN if p == 0
  double q_vm() const;       // sqrt(3/2 s:s): cdsim's series q (von Mises)
  double mu() const;         // -(sigma_xy + sigma_yx)/2 / sigma_yy: the series' shear_stress_ratio
  double skew() const;       // largest |sigma_ij - sigma_ji|/2
};

// Sum over the given contacts divided by V (V > 0, else AnalysisError).
Stress3 contact_stress3(const ContactSet3& cs, double volume);

struct Anisotropy3 {
  Mat3 Ac{}, An{}, At{};
  double mean_f = 0;  // <f> of the harmonic forms
  std::size_t contacts = 0;
  int iterations = 0;  // of the fixed point
  double a_c() const { return spread3(Ac); }
  double a_n() const { return spread3(An); }
  double a_t() const { return spread3(At); }
  // (2/5)(a_c + a_n + a_t): the first-order estimate of q/p.
  double sum_2_5() const;
  // (2/5) spread3(A_c + A_n + A_t): the same with the tensors' directions.
  double sum_2_5_tensor() const;
  // (2/5)(e1.A e1 - e3.A e3)/3 of A = A_c + A_n + A_t on sigma's principal
  // axes e1 (major), e3 (minor): the prediction of q/p in sigma's own frame.
  double sum_2_5_on(const Stress3& s) const;
};

// The branch anisotropies (Azema, Radjai & Dubois 2013): the same harmonic
// forms for the branch vector l (centre of body 1 to centre of body 2) as
// for the force, its normal part l_n = l.n and tangential part
// l_t = l - l_n n in place of f_n and f_t,
//   <l_n>(n) = <l> (1 + A_ln : n n),
//   <l_t>(n) = <l> (2/3) (A_lt n - (n . A_lt n) n),
// estimated as the force's (anisotropy3 with f := l). With them the
// stress-fabric relation for grains whose branch is not along the normal is
//   q/p = (2/5)(a_c + a_n + a_t + a_ln + a_lt)
// to first order. Spheres: l = |l| n, so A_lt = 0 and A_ln says only how the
// pairs' sizes correlate with their direction.
//
// And the fabric of the branch directions, A_c^l = (15/2) dev <l^ l^> (l^ =
// l/|l|): the fabric A_c with the branch direction in place of the normal.
// Azema, Radjai & Saussine (Mech. Mater. 41, 729 (2009)) build their
// harmonic approximation of the fabric on the branch vectors; for grains
// whose contacts lie on faces the two fabrics differ (a face contact's
// normal is the face's, its branch points at the other grain's centre).
// Spheres: l^ = n, A_c^l = A_c.
struct BranchAnisotropy3 {
  Mat3 Aln{}, Alt{};
  Mat3 Acl{};         // the branch directions' fabric A_c^l
  double mean_l = 0;  // <l> of the forms
  double a_ln() const { return spread3(Aln); }
  double a_lt() const { return spread3(Alt); }
  double a_c_branch() const { return spread3(Acl); }
};

// The anisotropies of the given contacts (each one force-bearing physical
// contact; the caller selects them). Throws AnalysisError when there are
// none, or when the fixed point does not converge (anisotropies of order 1,
// far outside the harmonic forms).
Anisotropy3 anisotropy3(const ContactSet3& cs);
// The branch anisotropies of the same contacts (thrown as anisotropy3).
BranchAnisotropy3 branch_anisotropy3(const ContactSet3& cs);
// (15/2) dev <l^ l^> over the given contacts: exact, no harmonic fit (so
// defined for any sample of branches). Throws AnalysisError when there are
// no contacts or a branch is not a finite nonzero vector.
Mat3 branch_fabric3(const ContactSet3& cs);

}  // namespace cda
