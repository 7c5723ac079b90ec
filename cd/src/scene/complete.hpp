// The scene as an engine takes it: complete and valid, made in one pass.
//
// complete_scene checks every rule the scene alone decides (the keys of its
// dimension, the protocol's rules, the derived quantities', the room the
// generated grains need) and resolves what the engines build from: the
// automatic cell (shear.width = height (= depth) = 0), the generated
// diameters, the mean diameter and its range, the time step, the protocol's
// pressure, shear rate and t_p, the pull-off force and the contact
// stiffness, and in 2D the lattice the generated grains are placed on. The
// engines' setups (2d/setup.cpp, 3d/setup3.cpp) build from these fields and
// call nothing back; what they still check needs bodies: a shear.start
// sample (its shapes, density, overlaps) and the overlaps of explicit disks
// and walls at t = 0.
//
// A new rule of a scene goes here (or in protocol.cpp for a protocol key,
// derived.cpp for a derived quantity); a new resolved quantity is a field
// below, set in complete_scene.
#pragma once
#include <vector>

#include "derived.hpp"
#include "scene.hpp"

namespace cd {

struct CompleteScene {
  Scene scene;  // the keys, the automatic cell's lengths filled in
  std::vector<double> diameters;  // the particles.n generated grains', in placement order
  double d_mean = 0, d_min = 0, d_max = 0;  // mean_diameter, diameter_bounds
  double dt = 0;
  double pressure = 0;    // imposed_pressure: 0 under volume control or without a protocol
  double shear_rate = 0;  // 1/s
  double t_p = 0;         // d sqrt(rho/p); 0 without shear.pressure
  double adhesion = 0;    // the pull-off force f_a (0: no adhesion)
  double stiffness = 0;   // of compliant contacts (0: rigid)
  // 2D generated grains (particles.n > 0, no shear.start): the region
  // [x0, y0, x1, y1] their loose lattice fills, its pitch (1.02 d_max) and
  // its number of columns.
  std::vector<double> region;
  double pitch = 0;
  int columns = 0;
};

// Throws SceneError (or ConfigError) naming the keys of the first rule the
// scene breaks.
CompleteScene complete_scene(const Scene& s);

// The 3D rules alone (complete_scene's for dimension = 3).
void check_scene3(const Scene& s);

// The scene with its automatic cell sized: 2D (both shear modes) and 3D
// (the periodic cell); unchanged when no automatic cell is asked for.
Scene with_auto_cell(const Scene& s);

}  // namespace cd
