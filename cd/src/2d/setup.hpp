// From a Scene to a World: generated and explicit disks, walls, and the
// per-scene settings. Checks what the parser cannot: that particles fit in
// their region and that no two bodies overlap at t = 0.
#pragma once
#include <stdexcept>
#include <utility>

#include "scene.hpp"
#include "world.hpp"

namespace cd {

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Mean diameter of the scene's disks (number mean), known before placement.
double mean_diameter(const Scene& s);

WorldParams world_params(const Scene& s);

// What the per-key rules cannot see, in both dimensions: a finite time step,
// pull-off force and shear time scales, and a run of at least one step and
// at most 1e9 steps. Throws SceneError naming the keys.
void check_derived(const Scene& s);

// Shear protocols: the imposed shear rate gamma-dot = I sqrt(p/rho)/d, the
// pressure time t_p = d sqrt(rho/p); 0 when the scene imposes no pressure.
double shear_rate(const Scene& s);
double pressure_time(const Scene& s);
// The pull-off force f_a of the adhesion law: contact.adhesion, or from
// contact.cohesion_number eta at the imposed shear.pressure p, with d =
// mean_diameter (particles.d_mean for a shear.start sample, the number mean
// of the size law or of particles.diameters otherwise; the d of t_p and I):
// f_a = eta p d in 2D (p a force per length), eta p d^2 in 3D (p a force
// per area).
double pull_off_force(const Scene& s);
// Time step and simulated time after the [shear] overrides (dt_tp, strain).
double time_step(const Scene& s);
double run_duration(const Scene& s);

// The scene with a periodic cell given as 0 x 0 (for generated particles)
// replaced by the smallest square that holds them on the generator's loose
// lattice, from the actual size law; any other scene unchanged.
Scene with_auto_cell(const Scene& s);

// Builds the world; throws SceneError naming the bodies at fault.
World build_world(const Scene& s);

// The smallest and largest diameter the scene's generated particles may
// have: the size law's range, or the explicit list's extremes.
std::pair<double, double> diameter_bounds(const Scene& s);

// Diameters of the n generated disks (deterministic for a seed).
std::vector<double> generated_diameters(const Scene& s);

}  // namespace cd
