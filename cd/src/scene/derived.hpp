// Quantities derived from several scene keys, the same in 2D and 3D: the
// size law and the mean diameter, the pressure time t_p and the shear rate
// of the shear protocols, the pull-off force of the cohesion number, the
// time step and the run's duration, and the checks that they are finite and
// give a run of a sensible number of steps. Both engines' setups and the
// run plan (core/run_plan.hpp) read them from here, so that a 2D and a 3D
// scene with the same keys mean the same thing.
#pragma once
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "scene.hpp"

namespace cd {

// A scene that cannot be run, for a reason that involves several keys or the
// bodies themselves (ConfigError, config.hpp, is for one key's value).
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Uniform in [0, 1) from the 53 high bits: the same on every platform,
// unlike std::uniform_real_distribution (the size law's draws, and 2D's
// placement).
inline double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

// Area of a disk (nsides = 0) or of a regular polygon of circumradius r
// (the grains' area the automatic walls cell is sized from, and
// obs::particle_area's).
inline double grain_area(double r, int nsides = 0) {
  return nsides > 0 ? 0.5 * nsides * r * r * std::sin(2 * std::numbers::pi / nsides) : std::numbers::pi * r * r;
}

// n = ceil(N^(1/3)): the side of the smallest cube of lattice sites holding
// N (3D's placements, in a periodic cell and in the pile's box).
inline int lattice_side3(int n_spheres) {
  return static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n_spheres)) - 1e-9));
}

// Mean diameter of the scene's particles (number mean), known before placement.
double mean_diameter(const Scene& s);

// The smallest and largest diameter the scene's generated particles may
// have: the size law's range, or the explicit list's extremes.
std::pair<double, double> diameter_bounds(const Scene& s);

// Diameters of the n generated particles (deterministic for a seed).
std::vector<double> generated_diameters(const Scene& s);

// Shear protocols: the imposed shear rate gamma-dot = I sqrt(p/rho)/d at
// imposed pressure, shear.rate (or shear.rate_tp / t_p) at imposed volume
// (scene/protocol.hpp); the
// pressure time t_p = d sqrt(rho/p) at shear.pressure (imposed, or the
// scale of a volume-controlled run); 0 without a pressure.
double shear_rate(const Scene& s);
double pressure_time(const Scene& s);
// The pull-off force f_a of the adhesion law: contact.adhesion, or from
// contact.cohesion_number eta at the imposed shear.pressure p, with d =
// mean_diameter (particles.d_mean for a shear.start sample, the number mean
// of the size law or of particles.diameters otherwise; the d of t_p and I):
// f_a = eta p d in 2D (p a force per length), eta p d^2 in 3D (p a force
// per area).
double pull_off_force(const Scene& s);
// The stiffness k of compliant contacts (3D): contact.stiffness, or
// contact.stiffness_number kappa at the imposed shear.pressure p, k = kappa
// p d with d = mean_diameter; 0: rigid contacts.
double contact_stiffness(const Scene& s);
// Time step and simulated time after the [shear] overrides (dt_tp, strain).
double time_step(const Scene& s);
double run_duration(const Scene& s);

// What the per-key rules cannot see, in both dimensions: a finite time step,
// pull-off force and shear time scales, and a run of at least one step and
// at most 1e9 steps. Throws SceneError naming the keys.
void check_derived(const Scene& s);

}  // namespace cd
