// The polyhedra tests' world settings, and the pile of those that compare
// 1 and 2 threads: 48 grains
// on a 4 x 4 x 3 lattice dropped in a box of five planes (the floor z = 0,
// walls at x, y = +-0.05), each at a random orientation and velocity, the
// solver stopped after 30 sweeps a step (identity, not convergence, is
// what those tests check).
#pragma once
#include <random>
#include <vector>

#include "polyhedron.hpp"
#include "world3.hpp"

namespace cdtest {

// add(w, k, x, q, v, omega, shapes): puts grain k at x; shapes are the
// world's cube (side 0.01), tetrahedron and icosahedron. Returns the world
// before its first step.
template <class Add>
cd::World3 polyhedra_box(cd::WorldParams3 p, Add add) {
  using cd::Vec3;
  p.solver.tol = 1e-4;
  p.solver.max_iter = 30;
  p.solver.min_parallel = 8;
  p.alert = 2e-3;
  cd::World3 w(p);
  const double L = 0.1;
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  w.bodies.add_plane(Vec3(-L / 2, 0, 0), Vec3(1, 0, 0));
  w.bodies.add_plane(Vec3(L / 2, 0, 0), Vec3(-1, 0, 0));
  w.bodies.add_plane(Vec3(0, -L / 2, 0), Vec3(0, 1, 0));
  w.bodies.add_plane(Vec3(0, L / 2, 0), Vec3(0, -1, 0));
  const double r = 0.01;
  const int shapes[3] = {w.bodies.add_shape(cd::cuboid(r, r, r)),
                         w.bodies.add_shape(cd::platonic(cd::Platonic::Tetrahedron, r)),
                         w.bodies.add_shape(cd::platonic(cd::Platonic::Icosahedron, r * 0.7))};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  int k = 0;
  for (int iz = 0; iz < 3; ++iz)
    for (int iy = 0; iy < 4; ++iy)
      for (int ix = 0; ix < 4; ++ix, ++k) {
        const Vec3 x(-0.03 + 0.02 * ix, -0.03 + 0.02 * iy, 0.01 + 0.018 * iz);
        const cd::Quat q(Eigen::AngleAxisd(3 * U(rng), Vec3(U(rng), U(rng), U(rng)).normalized()));
        const Vec3 v = 0.2 * Vec3(U(rng), U(rng), U(rng)), om = 5.0 * Vec3(U(rng), U(rng), U(rng));
        add(w, k, x, q, v, om, shapes);
      }
  return w;
}

// Every body's position, velocity, angular velocity and orientation.
inline std::vector<double> body_state(const cd::World3& w) {
  std::vector<double> st;
  for (std::size_t i = 0; i < w.bodies.size(); ++i) {
    for (int c = 0; c < 3; ++c) st.push_back(w.bodies.pos[i][c]);
    for (int c = 0; c < 3; ++c) st.push_back(w.bodies.vel[i].v[c]);
    for (int c = 0; c < 3; ++c) st.push_back(w.bodies.vel[i].w[c]);
    for (const double q : w.bodies.orient[i].coeffs()) st.push_back(q);
  }
  return st;
}

// The closed-form tests' world: gravity g along -z, friction mu on grains
// and walls, an alert distance of 0.1 mm, the solver converged to round-off.
inline cd::WorldParams3 exact_params3(double mu, double dt = 1e-3) {
  cd::WorldParams3 p;
  p.dt = dt;
  p.gravity = cd::Vec3(0, 0, -9.81);
  p.mu = p.mu_wall = mu;
  p.alert = 1e-4;
  p.solver.tol = 1e-13;
  p.solver.max_iter = 10000;
  return p;
}

}  // namespace cdtest
