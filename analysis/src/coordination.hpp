// Connectivity (method.md §10): coordination z over force-bearing contacts of
// non-rattler particles, fraction of non-floating particles, P_c.
//
// The definitions (force-bearing, physical contact, rattler, z, P_c) are
// cd/src/core/observables.hpp's, shared with cdsim's series columns z and
// non_rattler: this is that function on a snapshot. The particles are the
// particles snapshot's (the dynamic bodies); walls and other boundary
// bodies are never rattlers and a contact with one counts for the particle.
#pragma once
#include <vector>

#include "snapshot.hpp"

namespace cda {

struct Connectivity {
  std::size_t particles = 0;       // particles in the set
  std::size_t rattlers = 0;        // removed recursively
  std::size_t force_bearing = 0;   // force-bearing physical contacts (all bodies)
  double z = 0;                    // over non-rattlers; 0 if none is left
  double non_floating = 0;         // (particles - rattlers) / particles
  std::vector<double> P;           // P[c]: share of particles with exactly c contacts
  std::vector<bool> is_rattler;    // same order as the particle set
};

// f_eps < 0: cd::obs::force_threshold (1e-9 x mean |fn| of the set).
Connectivity connectivity(const ContactSet& cs, const ParticleSet& ps, double f_eps = -1,
                          int min_contacts = 2);
// 3D (spheres): the same definitions (docs/3d.md: a rattler has fewer than 2).
Connectivity connectivity(const ContactSet3& cs, const ParticleSet& ps, double f_eps = -1,
                          int min_contacts = 2);

}  // namespace cda
