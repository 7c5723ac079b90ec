#include "setup3.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>

#include <fmt/format.h>

#include "pile3d.hpp"

namespace cd {

namespace {

[[noreturn]] void fail3(const std::string& m) { throw SceneError(m + " (dimension = 3; docs/3d.md)"); }

// Pitch of the loose lattice of a periodic cell: 1.02 d_max, as 2D's.
double cell_pitch3(const Scene& s) { return 1.02 * diameter_bounds(s).second; }

// The tri-periodic cell (shear.mode = "periodic"): the keys that apply,
// and the lattice fitting the cell.
void check_cell3(const Scene& s) {
  // What needs the cell lengths as boundary dofs at imposed stress (issue 13
  // item 3), or a cell carried by a 3D checkpoint: refused by name.
  const std::pair<const char*, bool> later[] = {
      {"shear.pressure", s.pressure != 0},
      {"shear.inertial_number", s.inertial_number != 0},
      {"shear.isotropic", s.isotropic},
      {"shear.compaction_rate", s.compaction_rate != 0},
      {"shear.strain", s.strain != 0},
      {"shear.dt_tp", s.dt_tp != 0},
      {"shear.start", !s.start.empty()},
      {"contact.cohesion_number", s.cohesion_number != 0},
      {"output.checkpoint_strain", s.checkpoint_strain != 0},
  };
  for (const auto& [key, set] : later)
    if (set)
      fail3(fmt::format("{}: a 3D periodic cell has fixed lengths and no imposed stress yet (issue 13 "
                        "item 3); leave it at its default",
                        key));
  if (s.gravity[0] != 0 || s.gravity[1] != 0 || s.gravity[2] != 0)
    fail3("gravity.g: a tri-periodic cell has no floor; use [0, 0, 0]");
  if (s.box_width != 0 || s.box_depth != 0 || s.box_height != 0)
    fail3("box.width, box.depth, box.height: a periodic cell has no box; its lengths are shear.width, "
          "shear.height and shear.depth");
  if (!s.rotation) fail3("contact.rotation = false: the 3D engine always integrates rotations");
  if (!s.disks.empty()) fail3("[[disk]]: explicit disks are 2D only");
  if (!s.walls.empty()) fail3("[[wall]]: segment walls are 2D only");
  if (s.nsides.size() != 1 || s.nsides[0] != 0) fail3("particles.nsides: 3D particles are spheres; use [0]");
  if (!s.region.empty()) fail3("particles.region: the spheres fill the periodic cell; use []");
  check_derived(s);
  if (s.n <= 0) fail3("particles.n = 0: a 3D periodic cell needs generated spheres (particles.n or particles.diameters)");
  const bool given = s.cell_width > 0 || s.cell_height > 0 || s.cell_depth > 0;
  if (given && !(s.cell_width > 0 && s.cell_height > 0 && s.cell_depth > 0))
    fail3(fmt::format("shear.width = {}, shear.height = {}, shear.depth = {}: all three > 0, or all 0 (the "
                      "cube that holds the spheres)", s.cell_width, s.cell_height, s.cell_depth));
  const auto [d_min, d_max] = diameter_bounds(s);
  for (const double d : {d_min, d_max}) {
    const double m = s.density * std::numbers::pi / 6.0 * d * d * d, I = 0.1 * m * d * d;
    if (!std::isfinite(m) || !(m > 0) || !std::isfinite(I) || !(I > 0))
      fail3(fmt::format("a sphere of diameter {} m and density {} kg/m^3 has mass {} kg and inertia {} "
                        "kg m^2: both must be finite and > 0 (particles.d_mean, particles.diameters, "
                        "particles.density)", d, s.density, m, I));
  }
  if (!given) return;
  // World3's bound: each periodic length >= 2 (2 r_max + alert), so that a
  // pair meets through one image at most.
  const double lmin = 2.0 * (d_max + s.alert * mean_diameter(s));
  const std::pair<const char*, double> lengths[] = {
      {"shear.width", s.cell_width}, {"shear.height", s.cell_height}, {"shear.depth", s.cell_depth}};
  for (const auto& [key, L] : lengths)
    if (!std::isfinite(L) || L < lmin)
      fail3(fmt::format("{} = {}: a periodic length must be >= 2 (d_max + alert) = {:.4g} m", key, L, lmin));
  const double pitch = cell_pitch3(s);
  const long room = static_cast<long>(s.cell_width / pitch) * static_cast<long>(s.cell_height / pitch) *
                    static_cast<long>(s.cell_depth / pitch);
  if (room < s.n)
    fail3(fmt::format("particles.n = {} does not fit in the cell {} x {} x {}: room for {} spheres of the "
                      "largest diameter {:.4g} on a loose lattice (pitch 1.02 d_max); enlarge shear.width, "
                      "shear.height or shear.depth", s.n, s.cell_width, s.cell_height, s.cell_depth, room, d_max));
}

// 0 x 0 x 0: the smallest cube that holds the spheres on the loose lattice.
Scene with_auto_cell3(const Scene& s) {
  if (s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0 || s.n <= 0) return s;
  Scene c = s;
  const double k = lattice_side3(s.n);
  c.cell_width = c.cell_height = c.cell_depth = cell_pitch3(s) * k * (1 + 1e-9);  // floor(side / pitch) = k
  return c;
}

}  // namespace

void check_scene3(const Scene& s) {
  const auto fail = fail3;
  if (s.dimension != 3) fail(fmt::format("dimension = {}: not a 3D scene", s.dimension));
  if (s.gravity.size() != 3) fail("gravity.g: a 3D scene needs [gx, gy, gz]");
  if (s.shear_mode == "periodic") {
    check_derived(s);
    return check_cell3(with_auto_cell3(s));
  }
  if (s.shear_mode != "none")
    fail(fmt::format("shear.mode = \"{}\": a 3D scene is \"none\" (the box) or \"periodic\" (a "
                     "tri-periodic cell)", s.shear_mode));
  if (s.pressure != 0 || s.inertial_number != 0 || s.isotropic || s.strain != 0 || s.dt_tp != 0 ||
      !s.start.empty() || s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0 ||
      s.cohesion_number != 0 || s.checkpoint_strain != 0)
    fail("shear.* (pressure, inertial_number, isotropic, strain, dt_tp, start, width, height, depth), "
         "contact.cohesion_number and output.checkpoint_strain need shear.mode = \"periodic\": leave them "
         "at their defaults");
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

WorldParams3 world_params3(const Scene& s0) {
  check_scene3(s0);
  const Scene s = s0.shear_mode == "periodic" ? with_auto_cell3(s0) : s0;
  WorldParams3 p;
  p.dt = s.dt;
  p.gravity = Vec3(s.gravity[0], s.gravity[1], s.gravity[2]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  // Orthotropic Coulomb: on when mu_b or mu_wall_b is set (>= 0).
  if (s.mu_b >= 0 || s.mu_wall_b >= 0) {
    p.orthotropic = true;
    p.axis_a = Vec3(s.axis_a[0], s.axis_a[1], s.axis_a[2]).normalized();
    p.mu_b = s.mu_b >= 0 ? s.mu_b : s.mu;
    p.mu_wall_b = s.mu_wall_b >= 0 ? s.mu_wall_b : (s.mu_wall < 0 ? p.mu_b : s.mu_wall);
  }
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
  if (s.shear_mode == "periodic") {
    p.cell = Vec3(s.cell_width, s.cell_height, s.cell_depth);
    p.periodic = {true, true, true};
  }
  return p;
}

World3 build_cell3(const Scene& s0) {
  const WorldParams3 p = world_params3(s0);
  const Scene s = with_auto_cell3(s0);
  World3 w(p);
  // Loose placement on a jittered cubic lattice of pitch 1.02 d_max (2D's
  // rule): sphere k at site (k mod nx, (k / nx) mod ny, k / (nx ny)), its
  // centre moved uniformly by up to the slack (pitch - d_k)/2 per axis, so
  // no two spheres touch, through the cell's faces either. At rest.
  const std::vector<double> d = generated_diameters(s);
  const double pitch = cell_pitch3(s);
  const int nx = static_cast<int>(s.cell_width / pitch), ny = static_cast<int>(s.cell_height / pitch);
  std::mt19937_64 g(s.seed + 1);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < static_cast<int>(d.size()); ++k) {
    const int i = k % nx, j = (k / nx) % ny, l = k / (nx * ny);
    const double slack = 0.5 * (pitch - d[k]);
    // One draw per statement: the order of a call's arguments is unspecified.
    const double jx = slack * U(g), jy = slack * U(g), jz = slack * U(g);
    w.bodies.add_sphere(Vec3((i + 0.5) * pitch + jx, (j + 0.5) * pitch + jy, (l + 0.5) * pitch + jz),
                        0.5 * d[k], s.density);
  }
  return w;
}

World3 build_world3(const Scene& s0) {
  if (s0.shear_mode == "periodic") return build_cell3(s0);
  const Scene& s = s0;
  const WorldParams3 p = world_params3(s);
  const std::vector<double> d = generated_diameters(s);
  const double r_max = 0.5 * diameter_bounds(s).second;
  return lattice_pile3d(p, static_cast<int>(d.size()), r_max, s.density, s.seed,
                        [&](std::mt19937_64&, int m) { return 0.5 * d[m]; }, s.box_width, s.box_depth);
}

}  // namespace cd
