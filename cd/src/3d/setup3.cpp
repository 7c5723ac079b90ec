#include "setup3.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <utility>

#include <fmt/format.h>

#include "checkpoint3.hpp"
#include "detect3.hpp"
#include "continuation.hpp"
#include "pile3d.hpp"
#include "protocol.hpp"
#include "start_hint.hpp"

namespace cd {

namespace {

[[noreturn]] void fail3(const std::string& m) { throw SceneError(m + " (dimension = 3; docs/3d.md)"); }

// Pitch of the loose lattice of a periodic cell: 1.02 d_max, as 2D's.
double cell_pitch3(const Scene& s) { return 1.02 * diameter_bounds(s).second; }

// The tri-periodic cell (shear.mode = "periodic"): the keys that apply,
// and the lattice fitting the cell.
void check_cell3(const Scene& s) {
  // The protocol's keys: the scene layer's rules (scene/protocol.hpp).
  check_protocol(s);
  if (!s.rotation) fail3("contact.rotation = false: the 3D engine always integrates rotations");
  if (!s.disks.empty()) fail3("[[disk]]: explicit disks are 2D only");
  if (!s.walls.empty()) fail3("[[wall]]: segment walls are 2D only");
  if (s.nsides.size() != 1 || s.nsides[0] != 0) fail3("particles.nsides: 3D particles are spheres; use [0]");
  if (!s.region.empty()) fail3("particles.region: the spheres fill the periodic cell; use []");
  check_derived(s);
  if (!s.start.empty()) {
    // The spheres and the cell come from the sample (build_cell3).
    if (s.n > 0 || !s.diameters.empty())
      fail3("shear.start gives the spheres: set particles.n = 0 and no particles.diameters");
    if (s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0)
      fail3(fmt::format("shear.width, shear.height, shear.depth = {}, {}, {}: shear.start gives the cell; "
                        "leave them at 0", s.cell_width, s.cell_height, s.cell_depth));
    return;
  }
  if (s.n <= 0) fail3("particles.n = 0: a 3D periodic cell needs generated spheres (particles.n or particles.diameters)");
  const bool given = s.cell_width > 0 || s.cell_height > 0 || s.cell_depth > 0;
  if (given && !(s.cell_width > 0 && s.cell_height > 0 && s.cell_depth > 0))
    fail3(fmt::format("shear.width = {}, shear.height = {}, shear.depth = {}: all three > 0, or all 0 (the "
                      "cube that holds the spheres)", s.cell_width, s.cell_height, s.cell_depth));
  // The spheres' masses: check_derived (above).
  const double d_max = diameter_bounds(s).second;
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
  if (s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0 || s.n <= 0 || !s.start.empty()) return s;
  Scene c = s;
  const double k = lattice_side3(s.n);
  c.cell_width = c.cell_height = c.cell_depth = cell_pitch3(s) * k * (1 + 1e-9);  // floor(side / pitch) = k
  return c;
}

// The cell's mass (the dofs' at imposed stress): shear.cell_mass times the
// spheres' total mass, as 2D's.
void set_cell_mass3(const Scene& s, World3& w) {
  double mass = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) mass += w.bodies.mass[i];
  WorldParams3 q = w.params();
  q.cell_mass = s.cell_mass * mass;
  w.set_params(q);
}

}  // namespace

namespace {

// What a polyhedra scene (particles.shape) cannot have yet, refused by key.
void check_polyhedra3(const Scene& s) {
  if (s.shape == Shape3d::Sphere) return;
  const std::string what = fmt::format("particles.shape = \"{}\"", name_of(s.shape));
  if (!s.start.empty())
    fail3(fmt::format("shear.start: a started sample holds spheres; {} grains start from their own placement "
                      "(shear.start = \"\")", what));
  if (contact_stiffness(s) > 0)
    fail3(fmt::format("contact.stiffness: compliant contacts need grains of scalar inertia (spheres); {} grains "
                      "take rigid contacts (no contact.stiffness)", what));
}

}  // namespace

void check_scene3(const Scene& s) {
  const auto fail = fail3;
  if (s.dimension != 3) fail(fmt::format("dimension = {}: not a 3D scene", s.dimension));
  check_polyhedra3(s);
  if (s.gravity.size() != 3) fail("gravity.g: a 3D scene needs [gx, gy, gz]");
  // A setting that cannot act under the scene's law is refused, not ignored.
  if (s.subspace > 0 && s.orthotropic())
    fail(fmt::format("solver.subspace = {}: the subspace correction acts on the round cone only, and "
                     "contact.{} = {} makes the cone orthotropic: give solver.subspace = 0 (solver.anderson "
                     "accelerates any cone)",
                     s.subspace, s.mu_b >= 0 ? "mu_b" : "mu_wall_b", s.mu_b >= 0 ? s.mu_b : s.mu_wall_b));
  if (s.shear_mode == ShearMode::Periodic) {
    check_derived(s);
    return check_cell3(with_auto_cell3(s));
  }
  check_protocol(s);  // no protocol (a 3D scene has no walls protocol): no protocol key
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
  const double r_max = 0.5 * diameter_bounds(s).second;
  const int n = lattice_side3(s.n);
  const double side = n * 2.2 * r_max;
  // The spheres' masses: check_derived (above).
  if (!std::isfinite(side))
    fail(fmt::format("the lattice of {} spheres of diameter up to {} m has side {} m: it must be finite "
                     "(particles.d_mean, particles.diameters)", s.n, 2 * r_max, side));
  if (s.box_width > 0 && s.box_width < side)
    fail(fmt::format("box.width = {}: the {} x {} lattice of {} spheres (pitch 1.1 d_max = {} m) needs >= {} m",
                     s.box_width, n, n, s.n, 2.2 * r_max, side));
  if (s.box_depth > 0 && s.box_depth < side)
    fail(fmt::format("box.depth = {}: the {} x {} lattice of {} spheres (pitch 1.1 d_max = {} m) needs >= {} m",
                     s.box_depth, n, n, s.n, 2.2 * r_max, side));
}

WorldParams3 world_params3(const Scene& s0) {
  check_scene3(s0);
  const Scene s = s0.shear_mode == ShearMode::Periodic ? with_auto_cell3(s0) : s0;
  WorldParams3 p;
  p.dt = time_step(s);
  p.gravity = Vec3(s.gravity[0], s.gravity[1], s.gravity[2]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  // Orthotropic Coulomb: on when mu_b or mu_wall_b is set (>= 0).
  if (s.orthotropic()) {
    p.orthotropic = true;
    // Scaled first: a direction given as [1e-300, 0, 0] or [1e308, 1e308, 0]
    // is a direction (a plain norm under- or overflows and drops it).
    p.axis_a = Vec3(s.axis_a[0], s.axis_a[1], s.axis_a[2]).stableNormalized();
    p.mu_b = s.mu_b >= 0 ? s.mu_b : s.mu;
    p.mu_wall_b = s.mu_wall_b >= 0 ? s.mu_wall_b : (s.mu_wall < 0 ? p.mu_b : s.mu_wall);
  }
  p.d_ref = mean_diameter(s);
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.overlap_projection = s.overlap_projection;
  p.adhesion = pull_off_force(s);  // contact.adhesion, or eta p d^2 with d = p.d_ref
  p.debond = s.debond * p.d_ref;
  p.stiffness = contact_stiffness(s);
  p.stiffness_ratio = s.stiffness_ratio;
  p.e_n = s.e_n;  // restitution by mean velocities (method.md section 14)
  p.e_t = s.e_t;
  p.solver.tol = s.tol;
  p.solver.residual_tol = s.residual_tol;
  p.solver.anderson = s.anderson;
  p.solver.subspace = s.subspace;
  p.solver.max_iter = s.max_iter;
  if (s.shear_mode == ShearMode::Periodic) {
    p.cell = Vec3(s.cell_width, s.cell_height, s.cell_depth);
    p.periodic = {true, true, true};
    // At imposed pressure: L_y a dof (sigma_yy = p); isotropic, all three.
    // cell_mass is set by build_cell3, which knows the spheres' mass.
    p.pressure = imposed_pressure(s);  // 0 under volume control: the lengths stay
    if (p.pressure > 0) p.cell_dof = {s.isotropic, true, s.isotropic};
    p.shear_rate = shear_rate(s);  // I sqrt(p/rho)/d
    const double tp = pressure_time(s);
    p.max_strain_rate = s.compaction_rate > 0 && tp > 0 ? s.compaction_rate / tp : 0.0;
  }
  return p;
}

namespace {

// shear.start: the spheres and the cell of a 3D periodic run's checkpoint (a
// preparation's or a shear run's), as 2D's. Time and strain start from 0; a
// compacted sample (strain 0) starts from rest, its offset and rates 0; a
// sheared one keeps its Lees-Edwards offset and cell rates (the images stay
// where the spheres see them) and has its mean flow a + g y (least squares)
// replaced. Either way the shear starts from the linear profile
// gamma-dot (y - L_y/2) e_x, without a start-up transient.
void load_start3(const Scene& s, World3& w) {
  try {
    load_checkpoint3(s.start, w);
  } catch (const CheckpointError& e) {
    throw SceneError(fmt::format("shear.start: {}{}", e.what(), missing_start_hint(s)));
  }
  Bodies3& B = w.bodies;
  for (std::size_t i = 0; i < B.size(); ++i)
    if (B.shape[i] != Shape3::Sphere || !B.is_dynamic(i))
      throw SceneError(fmt::format("shear.start: '{}' holds a plane or a driven sphere (body {}); a periodic "
                                   "run starts from a periodic run's spheres", s.start, i));
  // The spheres (all dynamic: checked above) to core/continuation.hpp.
  continuation::Grains grains{B.size(),
                              [&](std::size_t i) { return B.pos[i].y(); },
                              [&](std::size_t i) -> double& { return B.vel[i].v.x(); },
                              [&](std::size_t i) { return 2 * B.radius[i]; },
                              [&](std::size_t i) { return B.mass[i] / obs::sphere_volume(B.radius[i]); },
                              "spheres",
                              "kg/m^3"};
  continuation::check_density(grains, s.density);
  continuation::check_mean_diameter(grains, w.params().d_ref);
  CellState3 c = w.cell();
  const bool sheared = c.strain != 0.0;
  if (!sheared) {
    c.le_offset = 0.0;
    c.rate = Vec3::Zero();
  }
  if (imposed_pressure(s) <= 0) c.rate = Vec3::Zero();  // volume control: the lengths stay
  if (s.volume_fraction > 0) {
    double volume = 0;
    for (std::size_t i = 0; i < B.size(); ++i) volume += obs::sphere_volume(B.radius[i]);
    const double f = continuation::volume_scale(volume, c.size.prod(), s.volume_fraction, 3);
    const Vec3 o = w.params().cell_origin;
    for (Vec3& x : B.pos) x = o + f * (x - o);
    c.size *= f;
    c.le_offset *= f;
  }
  c.strain = 0.0;
  w.set_cell(c);
  w.steps = 0;
  w.time = 0.0;
  w.times = StageTimes{};
  const WorldParams3& q = w.params();
  continuation::set_flow(grains, sheared, q.shear_rate, q.cell_origin.y() + 0.5 * c.size.y());
}

// A started sample comes from a simulation, with its solver-sized
// overlaps (2D's rule): up to kStartOverlap d of any pair, through the
// cell's images too; more means another cell than the grains' (a damaged
// sample, or shear.volume_fraction compressing it too far).
void check_start_overlaps3(const Scene& s, const World3& w) {
  constexpr double kStartOverlap = 0.05;
  const CellState3& c = w.cell();
  PeriodicCell3 cell;
  cell.origin = w.params().cell_origin;
  cell.size = c.size;
  cell.periodic = {true, true, true};
  cell.le_offset = c.le_offset;
  CellGrid3 grid;
  std::vector<SphereRow> rows;
  std::vector<ContactInfo3> info;
  try {
    detect3(w.bodies, w.bodies.pos, 0.0, cell, grid, rows, info, w.params().solver.min_parallel);
  } catch (const std::exception& e) {
    throw SceneError(fmt::format("shear.start: '{}': {}", s.start, e.what()));
  }
  const double d = w.params().d_ref;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (info[k].gap < -kStartOverlap * d)
      throw SceneError(fmt::format("shear.start: spheres {} and {} of '{}' overlap by {:.3g} mean diameters{}; a "
                                   "started sample may overlap by at most {}",
                                   rows[k].b1, rows[k].b2, s.start, -info[k].gap / d,
                                   s.volume_fraction > 0
                                       ? fmt::format(" once scaled to shear.volume_fraction = {}", s.volume_fraction)
                                       : std::string(),
                                   kStartOverlap));
}

}  // namespace

namespace {

// A polyhedra scene (particles.shape): each generated sphere becomes the
// scene's Platonic solid of the same circumscribed radius, centred where
// the sphere was (so the placement's no-overlap rules hold), at a uniformly
// random orientation (Shoemake's three uniforms, from a stream of its own
// seeded by particles.seed: the placement draws stay those of spheres).
// One shape per distinct size. Bodies keep their order and velocities.
void make_polyhedra3(const Scene& s, World3& w) {
  if (s.shape == Shape3d::Sphere) return;
  const Platonic kind = static_cast<Platonic>(static_cast<int>(s.shape) - 1);
  const Bodies3& B = w.bodies;
  Bodies3 out;
  std::map<double, int> shapes;
  std::mt19937_64 g(s.seed ^ 0x9e3779b97f4a7c15ull);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (std::size_t i = 0; i < B.size(); ++i) {
    if (B.shape[i] == Shape3::Plane) {
      out.add_plane(B.pos[i], B.normal[i], B.vel[i].v);
      continue;
    }
    const double r = B.radius[i];
    auto it = shapes.find(r);
    if (it == shapes.end()) it = shapes.emplace(r, out.add_shape(platonic(kind, r))).first;
    const double u1 = U(g), u2 = U(g), u3 = U(g);
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1), t2 = 2 * std::numbers::pi * u2,
                 t3 = 2 * std::numbers::pi * u3;
    const Quat q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
    out.add_polyhedron(B.pos[i], it->second, s.density, q, B.vel[i].v, B.vel[i].w);
  }
  w.bodies = std::move(out);
}

}  // namespace

World3 build_cell3(const Scene& s0) {
  WorldParams3 p = world_params3(s0);
  const Scene s = with_auto_cell3(s0);
  if (!s.start.empty()) {
    p.cell = Vec3::Ones();  // a placeholder: the sample's cell replaces it
    World3 w(p);
    load_start3(s, w);
    check_start_overlaps3(s, w);
    set_cell_mass3(s, w);
    return w;
  }
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
  make_polyhedra3(s, w);
  set_cell_mass3(s, w);
  return w;
}

World3 build_world3(const Scene& s0) {
  if (s0.shear_mode == ShearMode::Periodic) return build_cell3(s0);
  const Scene& s = s0;
  const WorldParams3 p = world_params3(s);
  const std::vector<double> d = generated_diameters(s);
  const double r_max = 0.5 * diameter_bounds(s).second;
  World3 w = lattice_pile3d(p, static_cast<int>(d.size()), r_max, s.density, s.seed,
                            [&](std::mt19937_64&, int m) { return 0.5 * d[m]; }, s.box_width, s.box_depth);
  make_polyhedra3(s, w);
  return w;
}

}  // namespace cd
