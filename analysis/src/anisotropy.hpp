// Fabric and force anisotropies by orientation of the contact normal
// (method.md §10), 2D, pi-periodic in the angle theta of n. Both orientations
// of a contact are the same contact, and fn, ft, l.n, l.t are unchanged when
// the roles of the two bodies swap, so every profile is pi-periodic.
//
// Harmonic forms (P normalised over [0, 2 pi), as in method.md):
//   P(theta)     = (1/2pi)(1 + a_c  cos 2(theta - theta_c))
//   <l_n>(theta) = <l_n>(1 + a_ln cos 2(theta - theta_ln))
//   <l_t>(theta) = -<l_n> a_lt sin 2(theta - theta_lt)
//   <f_n>(theta) = <f_n>(1 + a_fn cos 2(theta - theta_fn))
//   <f_t>(theta) = -<f_n> a_ft sin 2(theta - theta_ft)
// Sign of the tangential forms: method.md writes +sin. With our frame
// (t = n rotated by +90 degrees, f on body 2), friction mobilised by a shear
// whose major compression is along theta_s is f_t = -|.| sin 2(theta -
// theta_s) (a contact at +45 degrees from the compression slides with u_t > 0,
// so f_t < 0). With the minus sign a_ft >= 0 and theta_ft = theta_s, so all
// five directions coincide for a coaxial state and q/p ~ sum(a)/2 holds with
// plain magnitudes. It is method.md's form with the tangent taken clockwise.
//
// Every a is >= 0 with its direction theta in [0, pi). The complex form
// A = a exp(2 i theta) is kept too: the stress check sums the A's, which is
// right also when the directions differ.
#pragma once
#include <complex>
#include <vector>

#include "snapshot.hpp"
#include "stress.hpp"

namespace cda {

struct Harmonic {
  std::complex<double> A;  // a exp(2 i theta)
  double a() const { return std::abs(A); }
  double theta() const;    // in [0, pi)
};

struct Anisotropy {
  Harmonic c, ln, lt, fn, ft;
  double mean_fn = 0, mean_ln = 0;  // the <f_n>, <l_n> of the harmonic forms
  std::size_t contacts = 0;
  // (a_c + a_ln + a_lt + a_fn + a_ft)/2: method.md's estimate of q/p.
  double sum_half() const;
  // |A_c + A_ln + A_lt + A_fn + A_ft|/2: the same, with directions.
  double sum_half_vector() const;
};

// Binned profiles over [0, pi): bin k covers [k d, (k+1) d), d = pi/bins.
// P is normalised over [0, 2 pi) (so P = count / (2 N d)); the other profiles
// are bin means; an empty bin gets the periodic linear interpolation of its
// nearest non-empty neighbours (its count stays 0).
struct AngularProfile {
  std::vector<double> theta;  // bin centres
  std::vector<std::size_t> count;
  std::vector<double> P, ln, lt, fn, ft;
  std::size_t empty_bins = 0;
};
AngularProfile angular_profile(const ContactSet& cs, int bins);

// (a) Second harmonic of the binned profiles by an FFTW r2c transform. The
// transform of a histogram sees the bin average of cos 2 theta, which is the
// value at the bin centre times sinc(d) = sin(d)/d; this factor is divided
// out (it is 0.9987 for 36 bins). <f_n> and <l_n> are the bin-mean averages
// (the zeroth harmonic of the profile, not the contact mean: the harmonic
// form's mean is an orientation average).
Anisotropy anisotropy_fft(const ContactSet& cs, int bins = 36);

// (b) Tensor definitions. With D(T) = 2((T11 - T22) + i(T12 + T21))/tr T,
// which is a exp(2 i theta) of 2(T1 - T2)/(T1 + T2) for a symmetric T:
//   chi_c  = sum n n      A_c = D(chi_c)
//   chi_ln = sum l_n n n  A_c + A_ln = r_l D(chi_ln)
//   chi_l  = sum l n      A_lt       = r_l (D(chi_l) - D(chi_ln))
//   chi_fn = sum f_n n n  A_c + A_fn = r_f D(chi_fn)
//   chi_f  = sum f n      A_ft       = r_f (D(chi_f) - D(chi_fn))
// The usual first-order definitions take r = 1. For profiles that are pure
// second harmonics the exact relation has r = (contact mean)/(harmonic
// mean) = 1 + Re(A_c conj(A_x))/2 (the cross term of P(theta) <x>(theta)
// adds to the trace only); it is solved by fixed-point iteration (a
// contraction, |D| |A_c|/2 < 1), so that (a) and (b) agree to sampling error
// and not only to first order.
// Limit: the tensors weight <x>(theta) by P(theta), so a 4th harmonic of P
// (strong in ordered packings) times the 2nd harmonic of <x> feeds D. On a
// square lattice (contacts at 0 and 90 degrees only, fn 2 and 1) the tensor
// gives a_fn = 2/3 where the harmonic form has 1/3. Compare (a) and (b):
// when they differ, the packing is far from the harmonic forms.
// The FFT method also needs most bins occupied (empty ones are interpolated).
Anisotropy anisotropy_tensor(const ContactSet& cs);

// Contacts that bear force and are sliding: status 2 among the contacts
// that bear force (cd::obs::bears_force; f_eps < 0: cd::obs::force_threshold
// of cs). With mu > 0 the test is |ft| >= mu fn (1 - tol) instead of the
// status flag.
double sliding_share(const ContactSet& cs, double mu = 0, double tol = 1e-6, double f_eps = -1);

}  // namespace cda
