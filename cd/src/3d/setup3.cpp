#include "setup3.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <cstdint>
#include <random>
#include <utility>

#include <fmt/format.h>

#include "checkpoint3.hpp"
#include "detect3.hpp"
#include "continuation.hpp"
#include "pile3d.hpp"
#include "poly_rows3.hpp"
#include "start_hint.hpp"

namespace cd {

namespace {

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

WorldParams3 world_params3(const CompleteScene& c) {
  const Scene& s = c.scene;
  WorldParams3 p;
  p.dt = c.dt;
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
  p.d_ref = c.d_mean;
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.overlap_projection = s.overlap_projection;
  p.adhesion = c.adhesion;  // contact.adhesion, or eta p d^2 with d = p.d_ref
  p.debond = s.debond * p.d_ref;
  p.stiffness = c.stiffness;
  p.stiffness_ratio = s.stiffness_ratio;
  p.e_n = s.e_n;  // restitution by mean velocities (method.md section 14)
  p.e_t = s.e_t;
  p.solver.tol = s.tol;
  p.solver.residual_tol = s.residual_tol;
  p.solver.anderson = s.anderson;
  p.solver.subspace = s.subspace;
  p.solver.stop_rows = s.stop_rows;
  p.solver.max_iter = s.max_iter;
  if (s.shear_mode == ShearMode::Periodic) {
    p.cell = Vec3(s.cell_width, s.cell_height, s.cell_depth);
    p.periodic = {true, true, true};
    // At imposed pressure: L_y a dof (sigma_yy = p); isotropic, all three.
    // cell_mass is set by build_cell3, which knows the spheres' mass.
    p.pressure = c.pressure;  // 0 under volume control: the lengths stay
    if (p.pressure > 0) p.cell_dof = {s.isotropic, true, s.isotropic};
    p.shear_rate = c.shear_rate;  // I sqrt(p/rho)/d
    p.max_strain_rate = s.compaction_rate > 0 && c.t_p > 0 ? s.compaction_rate / c.t_p : 0.0;
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
void load_start3(const CompleteScene& cs, World3& w) {
  const Scene& s = cs.scene;
  try {
    load_checkpoint3(s.start, w, nullptr, Shapes::File);
  } catch (const CheckpointError& e) {
    throw SceneError(fmt::format("shear.start: {}{}", e.what(), missing_start_hint(s)));
  }
  Bodies3& B = w.bodies;
  for (std::size_t i = 0; i < B.size(); ++i)
    if (B.shape[i] == Shape3::Plane || !B.is_dynamic(i))
      throw SceneError(fmt::format("shear.start: '{}' holds a plane or a driven grain (body {}); a periodic "
                                   "run starts from a periodic run's grains", s.start, i));
  // The grains (all dynamic: checked above) to core/continuation.hpp; a
  // polyhedron's diameter is its circumscribed one, as the scene's sizes.
  continuation::Grains grains{B.size(),
                              [&](std::size_t i) { return B.pos[i].y(); },
                              [&](std::size_t i) -> double& { return B.vel[i].v.x(); },
                              [&](std::size_t i) { return 2 * B.radius[i]; },
                              [&](std::size_t i) { return B.mass[i] / B.volume(i); },
                              B.has_polyhedra() ? "grains" : "spheres",
                              "kg/m^3"};
  continuation::check_density(grains, s.density);
  continuation::check_mean_diameter(grains, w.params().d_ref);
  CellState3 c = w.cell();
  const bool sheared = c.strain != 0.0;
  if (!sheared) {
    c.le_offset = 0.0;
    c.rate = Vec3::Zero();
  }
  if (cs.pressure <= 0) c.rate = Vec3::Zero();  // volume control: the lengths stay
  if (s.volume_fraction > 0) {
    double solids = 0;
    for (std::size_t i = 0; i < B.size(); ++i) solids += B.volume(i);
    const double f = continuation::volume_scale(solids, c.size.prod(), s.volume_fraction, 3);
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
  const PeriodicCell3 cell = periodic_cell3(w.params(), c.le_offset, c.size);
  Overlap3 o;
  try {
    o = deepest_overlap3(w.bodies, cell, w.params().solver.min_parallel);
  } catch (const std::exception& e) {
    throw SceneError(fmt::format("shear.start: '{}': {}", s.start, e.what()));
  }
  const double d = w.params().d_ref;
  if (o.depth > kStartOverlap * d)
    throw SceneError(fmt::format("shear.start: grains {} and {} of '{}' overlap by {:.3g} mean diameters{}; a "
                                 "started sample may overlap by at most {}",
                                 o.b1, o.b2, s.start, o.depth / d,
                                 s.volume_fraction > 0
                                     ? fmt::format(" once scaled to shear.volume_fraction = {}", s.volume_fraction)
                                     : std::string(),
                                 kStartOverlap));
}

}  // namespace

namespace {

// A polyhedra scene (particles.shape): each generated sphere becomes a
// convex polyhedron of the same circumscribed radius, centred where the
// sphere was (so the placement's no-overlap rules hold), at a uniformly
// random orientation (Shoemake's three uniforms, from a stream of its own
// seeded by particles.seed: the placement draws stay those of spheres).
// A Platonic solid or a cuboid (sides in the ratios particles.aspect): one
// shape per distinct size; an irregular grain: a shape of its own, the hull
// of particles.vertices points on the ellipsoid of semi-axes in those
// ratios, seeded by particles.seed and the grain's index. A mixture (a
// list particles.shape): grain i's shape is drawn from the list with the
// number fractions particles.shape_fractions by one uniform of its own,
// a hash of particles.seed and i; a sphere stays a sphere. Bodies keep
// their order and velocities.
ConvexPolyhedron grain_shape(const Scene& s, Shape3d k, double r, std::size_t grain) {
  const Vec3 a(s.aspect[0], s.aspect[1], s.aspect[2]);
  switch (k) {
    case Shape3d::Cuboid:
      return cuboid(a.x(), a.y(), a.z()).scaled_to_circumradius(r);
    case Shape3d::Irregular:
      return random_polyhedron(s.vertices, a, s.seed * 0x9e3779b97f4a7c15ull + grain).scaled_to_circumradius(r);
    default:
      return platonic(static_cast<Platonic>(static_cast<int>(k) - 1), r);
  }
}

// Grain i's shape in a mixture: splitmix64 of (seed, i) as a uniform in
// [0, 1), against the cumulative fractions (equal when none are given).
Shape3d mixture_shape(const Scene& s, std::size_t i) {
  std::uint64_t z = (static_cast<std::uint64_t>(s.seed) << 32 ^ i) + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  const double u = static_cast<double>(z >> 11) * 0x1.0p-53;
  const std::size_t n = s.shape.size();
  double c = 0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    c += s.shape_fractions.empty() ? 1.0 / static_cast<double>(n) : s.shape_fractions[k];
    if (u < c) return s.shape[k];
  }
  // the last shape with a nonzero fraction takes the rest
  for (std::size_t k = n; k-- > 0;)
    if (s.shape_fractions.empty() || s.shape_fractions[k] > 0) return s.shape[k];
  return s.shape.back();
}

Bodies3 polyhedra_of(const Scene& s, const Bodies3& B) {
  Bodies3 out;
  std::map<std::pair<int, double>, int> shapes;
  std::mt19937_64 g(s.seed ^ 0x9e3779b97f4a7c15ull);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (std::size_t i = 0; i < B.size(); ++i) {
    if (B.shape[i] == Shape3::Plane) {
      out.add_plane(B.pos[i], B.normal[i], B.vel[i].v);
      continue;
    }
    const double r = B.radius[i];
    const Shape3d k = s.shape.size() == 1 ? s.shape[0] : mixture_shape(s, i);
    const double u1 = U(g), u2 = U(g), u3 = U(g);
    if (k == Shape3d::Sphere) {
      out.add_sphere(B.pos[i], r, s.density, B.vel[i].v, B.vel[i].w);
      continue;
    }
    int id;
    if (k == Shape3d::Irregular) {
      id = out.add_shape(grain_shape(s, k, r, i));
    } else {
      auto it = shapes.find({static_cast<int>(k), r});
      if (it == shapes.end())
        it = shapes.emplace(std::pair{static_cast<int>(k), r}, out.add_shape(grain_shape(s, k, r, i))).first;
      id = it->second;
    }
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1), t2 = 2 * std::numbers::pi * u2,
                 t3 = 2 * std::numbers::pi * u3;
    const Quat q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
    out.add_polyhedron(B.pos[i], id, s.density, q, B.vel[i].v, B.vel[i].w);
  }
  return out;
}

void make_polyhedra3(const Scene& s, World3& w) {
  if (!all_spheres(s)) w.bodies = polyhedra_of(s, w.bodies);
}

}  // namespace

World3 build_cell3(const CompleteScene& c) {
  const Scene& s = c.scene;
  WorldParams3 p = world_params3(c);
  if (!s.start.empty()) {
    p.cell = Vec3::Ones();  // a placeholder: the sample's cell replaces it
    World3 w(p);
    load_start3(c, w);
    check_start_overlaps3(s, w);
    set_cell_mass3(s, w);
    return w;
  }
  World3 w(p);
  // Loose placement on a jittered cubic lattice of pitch 1.02 d_max (2D's
  // rule): sphere k at site (k mod nx, (k / nx) mod ny, k / (nx ny)), its
  // centre moved uniformly by up to the slack (pitch - d_k)/2 per axis, so
  // no two spheres touch, through the cell's faces either. At rest.
  const std::vector<double>& d = c.diameters;
  const double pitch = c.pitch;
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

World3 build_world3(const CompleteScene& c) {
  const Scene& s = c.scene;
  if (s.dimension != 3) throw SceneError(fmt::format("dimension = {}: not a 3D scene", s.dimension));
  if (s.shear_mode == ShearMode::Periodic) return build_cell3(c);
  const WorldParams3 p = world_params3(c);
  const std::vector<double>& d = c.diameters;
  World3 w = lattice_pile3d(p, static_cast<int>(d.size()), 0.5 * c.d_max, s.density, s.seed,
                            [&](std::mt19937_64&, int m) { return 0.5 * d[m]; }, s.box_width, s.box_depth);
  make_polyhedra3(s, w);
  return w;
}

}  // namespace cd
