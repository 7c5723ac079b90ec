// The pile3d deposition scene, the benchmark scene LIGGGHTS and YADE were
// measured on: N spheres, r ~ U[0.5, 1] r_mean, density 2600 kg/m^3, on a
// cubic lattice n x n x ceil(N/n^2), n = ceil(N^(1/3)), pitch 2.2 r_max,
// uniform jitter +-0.05 r_mean, bottom layer at 1.1 r_max, in a square box
// of side n pitch (floor and four walls); g = 9.81, mu = 0.4, no restitution.
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

#include "derived.hpp"  // lattice_side3
#include "world3.hpp"

namespace cd {


struct Pile3dParams {
  int n_spheres = 1000;
  double r_mean = 0.005;
  double density = 2600.0;
  double mu = 0.4;
  double dt = 1e-3;
  // Alert distance / r_mean. It must exceed the relative travel in a step:
  // at N = 4000 spheres fall ~0.18 m and hit at ~2 m/s, 2 mm a 1 ms step;
  // measured: 0.2 lost contacts (largest overlap 0.042 r_mean during the
  // impact), 0.5 kept it at 0.0039 r_mean for 10% more time.
  double alert_rel = 0.5;
  double overlap_correction = 0.0;  // beta (WorldParams3)
  std::uint64_t seed = 1;
  SolverParams solver;
};

// Spheres on the pile3d lattice in a box of plane walls, the one builder of
// make_pile3d and of `dimension = 3` scenes (setup3.cpp). n_spheres on the
// cubic lattice n x n x ceil(N/n^2), n = ceil(N^(1/3)), pitch 2.2 r_max,
// sphere m at cell (m mod n, (m / n) mod n, m / n^2), bottom layer at
// 1.1 r_max, each centre jittered uniformly by +-0.05 r_max per axis; a
// floor at z = 0 and four side walls bounding [0, Lx] x [0, Ly] (0: the
// lattice's side n pitch). radius(rng, m) gives sphere m's radius, after
// its jitter is drawn from the same generator (seeded with `seed`).
template <class Radius>
World3 lattice_pile3d(const WorldParams3& p, int n_spheres, double r_max, double density,
                      std::uint64_t seed, Radius&& radius, double Lx = 0, double Ly = 0) {
  const double pitch = 2.2 * r_max;
  const int n = lattice_side3(n_spheres);
  World3 w(p);
  if (Lx <= 0) Lx = n * pitch;
  if (Ly <= 0) Ly = n * pitch;
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 0, 1));
  w.bodies.add_plane(Vec3::Zero(), Vec3(1, 0, 0));
  w.bodies.add_plane(Vec3(Lx, 0, 0), Vec3(-1, 0, 0));
  w.bodies.add_plane(Vec3::Zero(), Vec3(0, 1, 0));
  w.bodies.add_plane(Vec3(0, Ly, 0), Vec3(0, -1, 0));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> J(-0.05 * r_max, 0.05 * r_max);
  for (int m = 0; m < n_spheres; ++m) {
    const int i = m % n, j = (m / n) % n, k = m / (n * n);
    // One draw per statement: the order of a call's arguments is unspecified.
    const double jx = J(rng), jy = J(rng), jz = J(rng);
    const double r = radius(rng, m);
    w.bodies.add_sphere(Vec3((i + 0.5) * pitch + jx, (j + 0.5) * pitch + jy, 1.1 * r_max + k * pitch + jz), r,
                        density);
  }
  return w;
}

inline World3 make_pile3d(const Pile3dParams& q) {
  WorldParams3 p;
  p.dt = q.dt;
  p.gravity = Vec3(0, 0, -9.81);
  p.mu = p.mu_wall = q.mu;
  p.alert = q.alert_rel * q.r_mean;
  p.overlap_correction = q.overlap_correction;
  p.d_ref = 1.5 * q.r_mean;  // mean diameter of U[0.5, 1] r_mean radii
  p.solver = q.solver;
  std::uniform_real_distribution<double> R(0.5 * q.r_mean, q.r_mean);
  return lattice_pile3d(p, q.n_spheres, q.r_mean, q.density, q.seed,
                        [&](std::mt19937_64& g, int) { return R(g); });
}

}  // namespace cd
