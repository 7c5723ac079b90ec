#include "setup3.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "pile3d.hpp"

namespace cd {

void check_scene3(const Scene& s) {
  const auto fail = [](const std::string& m) { throw SceneError(m + " (dimension = 3; docs/3d.md)"); };
  if (s.dimension != 3) fail(fmt::format("dimension = {}: not a 3D scene", s.dimension));
  if (s.gravity.size() != 3) fail("gravity.g: a 3D scene needs [gx, gy, gz]");
  if (s.shear_mode != "none") fail("shear.mode: the shear protocols are 2D only; use \"none\"");
  if (s.pressure != 0 || s.inertial_number != 0 || s.isotropic || s.strain != 0 || s.dt_tp != 0 ||
      !s.start.empty() || s.cell_width != 0 || s.cell_height != 0 || s.cohesion_number != 0 ||
      s.checkpoint_strain != 0)
    fail("shear.* (pressure, inertial_number, isotropic, strain, dt_tp, start, cell_width, "
         "cell_height), contact.cohesion_number and output.checkpoint_strain belong to the 2D shear "
         "protocols: leave them at their defaults");
  if (!s.disks.empty()) fail("[[disk]]: explicit disks are 2D only");
  if (!s.walls.empty()) fail("[[wall]]: segment walls are 2D only; the 3D box is [box] width and depth");
  if (s.nsides.size() != 1 || s.nsides[0] != 0)
    fail("particles.nsides: 3D particles are spheres; use [0]");
  if (!s.region.empty()) fail("particles.region: 3D spheres are placed on the box's lattice; use []");
  if (!s.rotation) fail("contact.rotation = false: the 3D engine always integrates rotations");
  if (s.box_height != 0) fail(fmt::format("box.height = {}: the 3D box is open at the top; use 0", s.box_height));
  if ((s.box_width > 0) != (s.box_depth > 0))
    fail(fmt::format("box.width = {}, box.depth = {}: must be both 0 (fitted to the lattice) or both > 0",
                     s.box_width, s.box_depth));
  check_derived(s);
  if (s.n <= 0) fail("particles.n = 0: a 3D scene needs generated spheres (particles.n or particles.diameters)");
  const auto [d_min, d_max] = diameter_bounds(s);
  const double r_max = 0.5 * d_max;
  const int n = lattice_side3(s.n);
  const double side = n * 2.2 * r_max;
  for (const double d : {d_min, d_max}) {
    const double m = s.density * std::numbers::pi / 6.0 * d * d * d, I = 0.1 * m * d * d;
    if (!std::isfinite(side) || !std::isfinite(m) || !(m > 0) || !std::isfinite(I) || !(I > 0))
      fail(fmt::format("a sphere of diameter {} m and density {} kg/m^3 has mass {} kg and inertia {} "
                       "kg m^2, lattice side {} m: all must be finite and > 0 (particles.d_mean, "
                       "particles.diameters, particles.density)", d, s.density, m, I, side));
  }
  if (s.box_width > 0 && s.box_width < side)
    fail(fmt::format("box.width = {}: the {} x {} lattice of {} spheres (pitch 1.1 d_max = {} m) needs >= {} m",
                     s.box_width, n, n, s.n, 2.2 * r_max, side));
  if (s.box_depth > 0 && s.box_depth < side)
    fail(fmt::format("box.depth = {}: the {} x {} lattice of {} spheres (pitch 1.1 d_max = {} m) needs >= {} m",
                     s.box_depth, n, n, s.n, 2.2 * r_max, side));
}

WorldParams3 world_params3(const Scene& s) {
  check_scene3(s);
  WorldParams3 p;
  p.dt = s.dt;
  p.gravity = Vec3(s.gravity[0], s.gravity[1], s.gravity[2]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  p.d_ref = mean_diameter(s);
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.adhesion = s.adhesion;
  p.debond = s.debond * p.d_ref;
  p.e_n = s.e_n;  // restitution by mean velocities (method.md section 14)
  p.e_t = s.e_t;
  p.solver.tol = s.tol;
  p.solver.residual_tol = s.residual_tol;
  p.solver.max_iter = s.max_iter;
  return p;
}

World3 build_world3(const Scene& s) {
  const WorldParams3 p = world_params3(s);
  const std::vector<double> d = generated_diameters(s);
  const double r_max = 0.5 * diameter_bounds(s).second;
  return lattice_pile3d(p, static_cast<int>(d.size()), r_max, s.density, s.seed,
                        [&](std::mt19937_64&, int m) { return 0.5 * d[m]; }, s.box_width, s.box_depth);
}

}  // namespace cd
