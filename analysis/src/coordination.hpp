// Connectivity (method.md §10): coordination z over force-bearing contacts of
// non-rattler particles, fraction of non-floating particles, P_c.
//
// Choices:
// - Contacts are counted per body pair: the two points of a side-side contact
//   are one contact.
// - A pair is force-bearing when |sum fn| + |sum ft| > f_eps. f_eps defaults
//   to 1e-9 times the mean |fn| of the set: the solver's zero forces are
//   exact zeros or round-off, far below that. |fn| rather than fn > 0, so a
//   cohesive contact held in tension (fn = -f_a) bears force.
// - Bodies that are not in the particle set (walls, pistons) are never
//   rattlers; a contact with one counts for the particle.
// - Rattlers: particles with fewer than `min_contacts` (2) force-bearing
//   contacts, removed iteratively (removing one can make a neighbour a
//   rattler). z = sum of the remaining particles' contacts with remaining
//   bodies / number of remaining particles.
// - The non-floating fraction is the share of particles that are not rattlers.
// - P_c is over all particles, with the raw (before removal) count c.
#pragma once
#include <vector>

#include "snapshot.hpp"

namespace cda {

struct Connectivity {
  std::size_t particles = 0;       // particles in the set
  std::size_t rattlers = 0;        // removed iteratively
  std::size_t force_bearing = 0;   // force-bearing pairs (all bodies)
  double z = 0;                    // over non-rattlers; 0 if none is left
  double non_floating = 0;         // (particles - rattlers) / particles
  std::vector<double> P;           // P[c]: share of particles with exactly c contacts
  std::vector<bool> is_rattler;    // same order as the particle set
};

Connectivity connectivity(const ContactSet& cs, const ParticleSet& ps, double f_eps = -1,
                          int min_contacts = 2);

}  // namespace cda
