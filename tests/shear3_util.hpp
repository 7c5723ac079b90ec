// The small frictional 3D sample the tri-periodic tests compact and shear
// (test_shear3, test_cohesion3, test_cell_control): configs/shear3-prep.toml's
// units, d = 1 mm, rho = 2600 kg/m^3, p = 1e5 Pa, t_p = d sqrt(rho/p) =
// 1.61e-4 s; size ratio 1.5, mu 0.4, tol 1e-3, brake 0.1/t_p.
#pragma once

#include <string>

#include "scene.hpp"
#include "setup3.hpp"
#include "world3.hpp"

namespace cdtest {

// The scene's world with every loop parallel (min_parallel = 1): the
// tests that compare 1 and 2 threads.
inline cd::World3 parallel_world3(const cd::Scene& s) {
  cd::World3 w = cd::build_world3(s);
  cd::WorldParams3 p = w.params();
  p.solver.min_parallel = 1;
  w.set_params(p);
  return w;
}

inline cd::Scene shear3_prep_scene(int n) {
  cd::Scene s;
  s.dimension = 3;
  s.gravity = {0, 0, 0};
  s.shear_mode = cd::ShearMode::Periodic;
  s.n = n;
  s.d_mean = 1e-3;
  s.size_ratio = 1.5;
  s.density = 2600;
  s.mu = 0.4;
  s.alert = 0.1;
  s.tol = 1e-3;
  s.max_iter = 1000;
  s.pressure = 1e5;
  s.isotropic = true;
  s.dt_tp = 0.05;
  s.compaction_rate = 0.1;
  s.duration = 1.0;
  s.series_interval = 1.0;
  return s;
}

// The shear of that sample: the same scene with no particles of its own,
// started from the compacted checkpoint `start`, at inertial number I to
// strain 1 (callers change what they need).
inline cd::Scene shear3_shear_scene(const std::string& start, double I) {
  cd::Scene s = shear3_prep_scene(0);
  s.isotropic = false;
  s.compaction_rate = 0;
  s.inertial_number = I;
  s.start = start;
  s.strain = 1.0;
  return s;
}

}  // namespace cdtest
