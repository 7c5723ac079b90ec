// State hashes of World3 scenes that use none of the optional physics
// (restitution, orthotropic friction, periodic cells): their expected values
// in tests/test_world3_physics.cpp were recorded on the code before those
// options existed (commit cb1c628, same -O2 flags), so a change that alters
// the default path by a bit shows. Hashed: positions, orientations,
// velocities, and the last step's impulses in colour order.
#pragma once
#include <cstdint>

#include "pile3d.hpp"
#include "world3.hpp"

namespace cdtest {

inline std::uint64_t world3_hash(const cd::World3& w) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  };
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    mix(w.bodies.pos[i].data(), 3 * sizeof(double));
    mix(w.bodies.orient[i].coeffs().data(), 4 * sizeof(double));
    mix(w.bodies.vel[i].v.data(), 3 * sizeof(double));
    mix(w.bodies.vel[i].w.data(), 3 * sizeof(double));
  }
  for (const cd::SphereRow& r : w.rows()) mix(r.r.data(), 3 * sizeof(double));
  return h;
}

// Scene k: 0 frictionless pile, 1 Coulomb pile, 2 cohesive Coulomb pile, 3
// Coulomb pile with overlap correction; 200 spheres, 100 steps of 1 ms.
inline std::uint64_t world3_scene_hash(int k) {
  cd::Pile3dParams q;
  q.n_spheres = 200;
  q.mu = k == 0 ? 0.0 : 0.4;
  q.overlap_correction = k == 3 ? 0.05 : 0.0;
  q.solver.tol = 1e-6;
  q.solver.max_iter = 200;
  cd::World3 w = cd::make_pile3d(q);
  if (k == 2) {
    cd::WorldParams3 p = w.params();
    p.adhesion = 1e-4;
    p.debond = 0.2 * q.r_mean;
    w.set_params(p);
  }
  for (int s = 0; s < 100; ++s) w.step();
  return world3_hash(w);
}

}  // namespace cdtest
