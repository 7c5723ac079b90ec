// Observables of a contact network, in one place (method.md section 10):
// contact stress, coordination (force-bearing contacts, rattlers removed),
// packing fraction and fabric tensor. cdsim's series.csv and cdanalysis
// both call these functions, so a run's series and the analysis of one of
// its snapshots measure the same thing the same way.
//
// The functions take plain arrays, not the simulator's World or the
// analysis' snapshot types: a contact is its two body ids, its normal, its
// force on body 2 and its branch vector, in D dimensions (D = 2 today; the
// coordination itself needs no dimension at all).
//
// Definitions (the README's series columns and `cdanalysis fabric` use
// these; change them here and there together):
//
// - Frame (method.md section 1): n points from body 1 to body 2; the force
//   f = fn n + ft is the one body 1 exerts on body 2, fn > 0 repulsive and
//   fn < 0 a cohesive pull (adhesion-shifted Signorini: fn >= -f_a); l is
//   the branch vector from the centre of body 1 to the centre of body 2, or
//   of the periodic image of body 2 that is touched.
//
// - Stress: sigma_ij = (1/V) sum_c f_i l_j over the contacts given (every
//   point of a side-side contact: the sum is the same as over physical
//   contacts). With f on body 2 and l from 1 to 2, compression is positive.
//   Contact part only; the kinetic part needs the mean flow (World).
//
// - Force-bearing: a contact point bears force when |fn| + |ft| > f_eps,
//   f_eps = kForceEpsRel x mean |fn| over all the points given (open
//   candidates within the alert distance included: they are the rows
//   cdsim solved and the cells of its contacts_NNNNN.vtp alike). |fn| and
//   not fn > 0, so a cohesive contact held in tension (fn = -f_a) bears
//   force, and a closed cohesive contact at fn = 0, ft = 0 does not: what
//   counts is the force, not the state of the law. The solver's zero
//   forces are exact zeros or round-off, far below f_eps.
//   Rejected: "pn + f_a dt > 0" (cdsim's former rule, the law's active
//   set): it dropped contacts pulling at exactly -f_a and counted touching
//   cohesive contacts that carry nothing. Rejected: |sum over the points of
//   a pair| (cdanalysis' former rule): two points of a side-side contact
//   pulling and pushing equally cancel, yet the pair carries a moment.
//
// - Physical contact: the points of one body pair (the two points of a
//   side-side contact) are one contact; it bears force when any of its
//   points does.
//
// - Coordination: particles are the bodies listed (the dynamic bodies);
//   the others (walls, wall grains, pistons) are never rattlers, and a
//   contact with one counts for the particle. A rattler is a particle with
//   fewer than min_contacts (2) force-bearing physical contacts with
//   non-rattlers, removed recursively (removing one can make a neighbour a
//   rattler; the result, the 2-core of the network, does not depend on the
//   order). z = (sum over non-rattler particles of their force-bearing
//   contacts with non-rattler bodies) / (number of non-rattler particles),
//   0 if none is left; non_rattler = that number / number of particles;
//   P[c] the share of particles with exactly c force-bearing contacts,
//   before removal.
//
// - Packing fraction: (sum of the solid volumes given, with their weights)
//   / V; the caller weighs bodies cut by the cell's edge (wall grains: 1/2).
//
// - Fabric tensor: F_ij = (1/N) sum n_i n_j over the N force-bearing
//   physical contacts (the normal of a pair's first bearing point; the
//   points of a side-side contact share it); tr F = 1.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

namespace cd::obs {

template <int D>
using Vec = std::array<double, D>;
template <int D>
using Tensor = std::array<std::array<double, D>, D>;  // T[i][j]

// The relative threshold of "force-bearing" (see above).
inline constexpr double kForceEpsRel = 1e-9;

template <int D>
struct Contact {
  std::int32_t b1 = 0, b2 = 0;  // body ids (>= 0)
  Vec<D> n{};                   // unit normal, body 1 -> body 2
  double fn = 0;                // normal force on body 2 (> 0 repulsive)
  Vec<D> ft{};                  // tangential force on body 2 (orthogonal to n)
  Vec<D> l{};                   // branch vector, centre 1 -> centre of (the image of) 2

  Vec<D> force() const {
    Vec<D> f;
    for (int i = 0; i < D; ++i) f[i] = fn * n[i] + ft[i];
    return f;
  }
  double ft_norm() const {
    if constexpr (D == 1) return std::abs(ft[0]);
    double s = 0;
    for (int i = 0; i < D; ++i) s += ft[i] * ft[i];
    return std::sqrt(s);
  }
};

// 2D: t = n turned by +90 degrees, the tangential force ft t.
inline Contact<2> contact_2d(std::int32_t b1, std::int32_t b2, double nx, double ny, double fn,
                             double ft, double lx, double ly) {
  return {b1, b2, {nx, ny}, fn, {-ft * ny, ft * nx}, {lx, ly}};
}

// ---- stress ----

// sigma_ij = (1/V) sum_c f_i l_j; V > 0 (else std::invalid_argument).
template <int D>
Tensor<D> contact_stress(std::span<const Contact<D>> cs, double volume);

// ---- force-bearing ----

// f_eps = rel x mean |fn| over cs (0 when cs is empty); rel defaults to
// kForceEpsRel, the series' z. A larger rel (cdanalysis fabric
// --force-threshold) leaves the weak contacts out of z and the fabric.
template <int D>
double force_threshold(std::span<const Contact<D>> cs, double rel = kForceEpsRel);

template <int D>
bool bears_force(const Contact<D>& c, double f_eps) {
  return std::abs(c.fn) + c.ft_norm() > f_eps;
}

// A body pair, b1 < b2.
struct Link {
  std::int32_t b1 = 0, b2 = 0;
  friend bool operator==(const Link&, const Link&) = default;
  friend auto operator<=>(const Link&, const Link&) = default;
};

// The force-bearing physical contacts: the pairs of which some point bears
// force, each once, sorted. f_eps < 0: force_threshold(cs).
template <int D>
std::vector<Link> force_bearing_links(std::span<const Contact<D>> cs, double f_eps = -1);

// Indices into cs of one bearing point per force-bearing pair (the first),
// in the order of cs.
template <int D>
std::vector<std::size_t> force_bearing_points(std::span<const Contact<D>> cs, double f_eps = -1);

// ---- coordination ----

struct Coordination {
  std::size_t particles = 0;      // particles given
  std::size_t rattlers = 0;       // removed recursively
  std::size_t force_bearing = 0;  // force-bearing physical contacts (any bodies)
  double z = 0;                   // over non-rattlers; 0 if none is left
  double non_rattler = 0;         // (particles - rattlers) / particles; 0 without particles
  std::vector<double> P;          // P[c]: share of particles with exactly c contacts
  std::vector<bool> is_rattler;   // in the order of `particles`
};

// links: the force-bearing physical contacts (force_bearing_links), each
// pair once; particles: the ids of the bodies that may be rattlers.
Coordination coordination(std::span<const Link> links, std::span<const std::int32_t> particles,
                          int min_contacts = 2);

template <int D>
Coordination coordination(std::span<const Contact<D>> cs, std::span<const std::int32_t> particles,
                          double f_eps = -1, int min_contacts = 2) {
  return coordination(force_bearing_links(cs, f_eps), particles, min_contacts);
}

// ---- packing fraction ----

// Area of a disk (nsides = 0) or of a regular polygon of circumradius r.
double particle_area(double r, int nsides = 0);
// Volume of a sphere of radius r.
double sphere_volume(double r);
// (sum_i w_i v_i) / V, V > 0 (else std::invalid_argument); w empty: all 1.
double packing_fraction(std::span<const double> volumes, std::span<const double> weights,
                        double volume);

// ---- fabric ----

// F_ij = (1/N) sum n_i n_j over the force-bearing physical contacts (zero
// tensor when there is none). f_eps < 0: force_threshold(cs).
template <int D>
Tensor<D> fabric_tensor(std::span<const Contact<D>> cs, double f_eps = -1);

// 2D invariants of a tensor's symmetric part: (s1 + s2)/2 and (s1 - s2)/2.
double mean_2d(const Tensor<2>& t);
double deviator_2d(const Tensor<2>& t);
// 3D invariants of a tensor's symmetric part: p = tr/3 and the von Mises
// q = sqrt(3/2 s:s), s the deviator of the symmetric part (q = s1 - s3
// when s2 = s3, a triaxial test's deviator).
double mean_3d(const Tensor<3>& t);
double deviator_3d(const Tensor<3>& t);

}  // namespace cd::obs
