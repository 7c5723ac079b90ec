#include "setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "continuation.hpp"
#include "observables.hpp"
#include "start_hint.hpp"

namespace cd {

namespace {

std::string body_name(const Scene& s, int i, int first_generated) {
  if (!s.start.empty()) return fmt::format("particle {} of the sample", i);
  if (i < static_cast<int>(s.disks.size())) return fmt::format("disk[{}]", i);
  return fmt::format("generated particle {}", i - first_generated);
}

}  // namespace

WorldParams world_params(const CompleteScene& c) {
  const Scene& s = c.scene;
  WorldParams p;
  p.dt = c.dt;
  p.gravity = Vec2(s.gravity[0], s.gravity[1]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  p.e_n = s.e_n;
  p.e_t = s.e_t;
  p.d_ref = c.d_mean;
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.overlap_projection = s.overlap_projection;
  p.adhesion = c.adhesion;  // eta p d, d = p.d_ref
  p.debond = s.debond * p.d_ref;
  if (s.shear_mode != ShearMode::None) {
    CellParams& q = p.cell;
    q.mode = s.shear_mode == ShearMode::Periodic ? CellParams::Mode::LeesEdwards : CellParams::Mode::Walls;
    q.width = s.cell_width;
    q.pressure = c.pressure;  // 0 under volume control: the lengths stay
    q.isotropic = s.isotropic;
    q.shear_rate = c.shear_rate;
    q.max_strain_rate = s.compaction_rate > 0 && c.t_p > 0 ? s.compaction_rate / c.t_p : 0.0;
    // q.mass: set by build_world, which knows the particles' mass
  }
  p.solver.tol = s.tol;
  p.solver.residual_tol = s.residual_tol;
  p.solver.anderson = s.anderson;
  p.solver.stop_rows = s.stop_rows;
  p.solver.max_iter = s.max_iter;
  p.rotation = s.rotation;
  return p;
}

namespace {

// shear.start: the particles and the cell of a sample (a preparation's or a
// shear run's checkpoint) into w, checked against the scene, its flow set
// for the new run (core/continuation.hpp).
void continue_sample(const CompleteScene& c, const WorldParams& wp, World& w) {
  const Scene& s = c.scene;
  Bodies& B = w.bodies;
  // The particles and the cell a preparation run reached; time, strain
  // and the cell's rates start from zero, and the shear starts from the
  // linear velocity profile (so that there is no start-up transient of
  // momentum diffusion across the cell).
  World prep(wp);
  try {
    load_checkpoint(s.start, prep);
  } catch (const CheckpointError& e) {
    throw SceneError(fmt::format("shear.start: {}{}", e.what(), missing_start_hint(s)));
  }
  B = prep.bodies;
  w.cell = prep.cell;
  if (w.cell.width <= 0 || w.cell.height <= 0)
    throw SceneError(fmt::format("shear.start: '{}' holds no periodic cell (not a periodic "
                                 "preparation run)", s.start));
  // The particles come from the sample alone (complete_scene).
  // The shapes come with the sample, but the scene's "auto" settings were
  // chosen (config.cpp, before the sample is read) for the shapes
  // particles.nsides names: polygons take no Anderson mixing and their own
  // stop (docs/shear.md, "Settings by I"), so the two must agree.
  const bool scene_polygons = std::any_of(s.nsides.begin(), s.nsides.end(), [](double k) { return k >= 3; });
  std::size_t poly = B.size();  // the sample's first polygon
  for (std::size_t i = 0; i < B.size() && poly == B.size(); ++i)
    if (B.nsides[i] >= 3) poly = i;
  if ((poly < B.size()) != scene_polygons)
    throw SceneError(fmt::format(
        "shear.start: the sample's particles are {}, but particles.nsides = [{}] names {}; the \"auto\" "
        "shear settings depend on it (docs/shear.md, \"Settings by I\"): set particles.nsides to the "
        "preparation's",
        scene_polygons ? std::string("disks only")
                       : fmt::format("polygons ({}-gon: body {})", B.nsides[poly], poly),
        fmt::join(s.nsides, ", "), scene_polygons ? "polygons" : "disks only"));
  for (std::size_t i = 0; i < B.size(); ++i)
    if (!B.is_dynamic(i))
      throw SceneError(fmt::format("shear.start: '{}' holds walls or wall grains (body {}); a "
                                   "periodic run starts from a periodic preparation", s.start, i));
  // The grains (all dynamic: checked above) to core/continuation.hpp.
  continuation::Grains grains{
      B.size(),
      [&](std::size_t i) { return B.pos[i].y(); },
      [&](std::size_t i) -> double& { return B.vel[i].vx; },
      [&](std::size_t i) { return 2 * B.radius[i]; },
      [&](std::size_t i) { return B.mass[i] / obs::particle_area(B.radius[i], B.nsides[i]); },
      "particles",
      "kg/m^2"};
  continuation::check_density(grains, s.density);
  // A sheared sample (strain > 0) is continued: its Lees-Edwards offset
  // and cell rates are kept (the images stay where the grains see them:
  // resetting the offset would overlap grains across the sheared
  // boundary), and its mean flow replaced by the new run's profile. A
  // compacted sample starts from rest. Either way the strain counts from
  // 0. Under volume control the lengths stay: their rates are 0.
  const bool sheared = w.cell.strain != 0.0;
  if (!sheared) w.cell.offset = w.cell.hdot = w.cell.wdot = 0.0;
  if (c.pressure <= 0) w.cell.hdot = w.cell.wdot = 0.0;
  if (s.volume_fraction > 0) {
    double area = 0;
    for (std::size_t i = 0; i < B.size(); ++i) area += obs::particle_area(B.radius[i], B.nsides[i]);
    const double f = continuation::volume_scale(area, w.cell.width * w.cell.height, s.volume_fraction, 2);
    for (Vec2& x : B.pos) x *= f;
    w.cell.width *= f;
    w.cell.height *= f;
    w.cell.offset *= f;
  }
  w.cell.strain = 0.0;
  w.set_warm_start(prep.warm_start());
  continuation::set_flow(grains, sheared, wp.cell.shear_rate, 0.5 * w.cell.height);
  continuation::check_mean_diameter(grains, wp.d_ref);
}

// particles.n grains on the loose jittered lattice complete_scene laid out
// (region, pitch, columns), filled row by row from the bottom: no overlap
// by construction.
void place_generated(const CompleteScene& c, Bodies& B) {
  const Scene& s = c.scene;
  const std::vector<double>& d = c.diameters;
  const std::vector<double>& region = c.region;
  const double pitch = c.pitch;
  const int nx = c.columns;
  std::mt19937_64 g(s.seed + 1);
  std::mt19937_64 gs(s.seed + 2);  // shapes and orientations: their own stream, so a
                                   // disk-only scene places exactly as before
  for (int k = 0; k < s.n; ++k) {
    const int ix = k % nx, iy = k / nx;
    const double slack = 0.5 * (pitch - d[k]);
    const double x = region[0] + (ix + 0.5) * pitch + slack * (2 * uniform01(g) - 1);
    const double y = region[1] + (iy + 0.5) * pitch + slack * (2 * uniform01(g) - 1);
    const int sides =
        s.nsides.size() == 1
            ? static_cast<int>(s.nsides[0])
            : static_cast<int>(s.nsides[std::min<std::size_t>(
                  s.nsides.size() - 1, static_cast<std::size_t>(uniform01(gs) * s.nsides.size()))]);
    if (sides > 0)
      B.add_polygon({x, y}, 0.5 * d[k], sides, 2 * std::numbers::pi * uniform01(gs), s.density);
    else
      B.add_disk({x, y}, 0.5 * d[k], s.density);
  }
}

// No overlap at t = 0 (a started sample: at most kStartOverlap d).
void check_initial_overlaps(const Scene& s, const World& w, int first_generated) {
  const Bodies& B = w.bodies;
  const bool shear = s.shear_mode != ShearMode::None, walls = s.shear_mode == ShearMode::Walls;
  // No overlap at t = 0: run the detector with zero alert on the initial
  // configuration. Round-off sized overlaps (1e-9 d) are tolerated so that
  // disks placed exactly touching are accepted. A started state comes from a
  // simulation, with its solver-sized overlaps: up to kStartOverlap d.
  std::vector<ContactRow> rows;
  std::vector<ContactInfo> info;
  CellGrid grid;
  PeriodicCell cell{shear, shear && !walls, w.cell.width, w.cell.height, w.cell.offset};
  try {
    detect(B, B.pos, B.angle, 0.0, grid, rows, info, shear ? &cell : nullptr);
  } catch (const std::runtime_error& e) {
    throw SceneError(fmt::format("shear.width, shear.height: {}", e.what()));
  }
  constexpr double kStartOverlap = 0.05;
  const double tol = (s.start.empty() ? 1e-9 : kStartOverlap) * w.params().d_ref;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (info[k].gap >= -tol) continue;
    const int i = rows[k].b1, j = rows[k].b2;
    const std::string a = B.driven[i] ? fmt::format("a wall (body {})", i)
                                      : body_name(s, i, first_generated);
    throw SceneError(fmt::format(
        "initial overlap: {} at ({:.6g}, {:.6g}) and {} at ({:.6g}, {:.6g}) overlap by {:.3g} "
        "(= {:.3g} mean diameters); {}",
        a, B.pos[i].x(), B.pos[i].y(), body_name(s, j, first_generated), B.pos[j].x(),
        B.pos[j].y(), -info[k].gap, -info[k].gap / w.params().d_ref,
        s.start.empty() ? std::string("particles must not overlap at t = 0")
                        : fmt::format("a started sample may overlap by at most {} mean diameters "
                                      "(shear.start = '{}')", kStartOverlap, s.start)));
  }
}

}  // namespace

World build_world(const CompleteScene& c) {
  const Scene& s = c.scene;
  if (s.dimension != 2)
    throw SceneError(fmt::format("dimension = {}: build_world makes 2D worlds (3D: build_world3)", s.dimension));
  WorldParams wp = world_params(c);
  World w(wp);
  Bodies& B = w.bodies;
  const bool shear = s.shear_mode != ShearMode::None, walls = s.shear_mode == ShearMode::Walls;
  if (shear) {
    w.cell.width = s.cell_width;
    w.cell.height = s.cell_height;
  }
  if (!s.start.empty()) continue_sample(c, wp, w);

  for (const DiskSpec& d : s.disks) {
    const double rho = d.density > 0 ? d.density : s.density;
    const int i = d.nsides > 0 ? B.add_polygon({d.pos[0], d.pos[1]}, d.radius, d.nsides, d.angle,
                                               rho, {d.vel[0], d.vel[1]}, d.omega)
                               : B.add_disk({d.pos[0], d.pos[1]}, d.radius, rho,
                                            {d.vel[0], d.vel[1]}, d.omega);
    B.force[i] = Vec2(d.force[0], d.force[1]);
  }
  const int first_generated = static_cast<int>(B.size());

  if (s.n > 0) place_generated(c, B);

  if (walls) {
    // Rough walls: a row of touching grains of the mean diameter glued to
    // each wall (driven bodies); the top row moves together (World::top_wall).
    const int m = std::max(1, static_cast<int>(std::floor(s.cell_width / s.d_mean)));
    const double pitch = s.cell_width / m, r = 0.5 * std::min(pitch, s.d_mean);
    const Vec2 vtop(wp.cell.shear_rate * s.cell_height, 0.0);
    for (int k = 0; k < m; ++k) {
      const int b = B.add_disk({(k + 0.5) * pitch, 0.0}, r, s.density);
      B.driven[b] = 1;
      B.vel[b] = {0, 0, 0, 0, 0};
    }
    for (int k = 0; k < m; ++k) {
      const int t = B.add_disk({(k + 0.5) * pitch, s.cell_height}, r, s.density, vtop);
      B.driven[t] = 1;
      B.vel[t] = {vtop.x(), 0, 0, 0, 0};
      w.top_wall.push_back(t);
    }
  }
  if (shear) {
    double mass = 0;
    for (std::size_t i = 0; i < B.size(); ++i)
      if (B.is_dynamic(i)) mass += B.mass[i];
    wp.cell.mass = s.cell_mass * mass;
    w.set_params(wp);
  }

  if (s.box_width > 0) {
    const double W = s.box_width, H = s.box_height;
    B.add_wall({0, 0}, {W, 0});
    B.add_wall({0, H}, {0, 0});
    B.add_wall({W, 0}, {W, H});
    B.add_wall({W, H}, {0, H});
  }
  for (const WallSpec& ws : s.walls)
    B.add_wall({ws.a[0], ws.a[1]}, {ws.b[0], ws.b[1]}, {ws.vel[0], ws.vel[1]}, ws.omega);

  check_initial_overlaps(s, w, first_generated);
  return w;
}

}  // namespace cd
