#include "setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "continuation.hpp"
#include "observables.hpp"
#include "protocol.hpp"
#include "start_hint.hpp"

namespace cd {

namespace {

std::string body_name(const Scene& s, int i, int first_generated) {
  if (!s.start.empty()) return fmt::format("particle {} of the sample", i);
  if (i < static_cast<int>(s.disks.size())) return fmt::format("disk[{}]", i);
  return fmt::format("generated particle {}", i - first_generated);
}

// The protocol's rules are the scene layer's (scene/protocol.hpp); what is
// left is the cell's size, which the placement below needs.
void check_shear(const Scene& s) {
  check_protocol(s);
  if (s.shear_mode == ShearMode::None) return;
  // 0 x 0: a cell sized for the generated particles (with_auto_cell) or the
  // start sample's cell.
  const bool auto_cell = s.cell_width == 0 && s.cell_height == 0 &&
                         (s.n > 0 || (s.shear_mode == ShearMode::Periodic && !s.start.empty()));
  if (!auto_cell && (s.cell_width <= 0 || s.cell_height <= 0))
    throw SceneError(fmt::format("shear.mode = \"{}\" needs shear.width > 0 and shear.height > 0 (or both 0, "
                                 "for a cell sized for the generated particles)",
                                 name_of(s.shear_mode)));
}

}  // namespace

// A cell given as 0 x 0 for generated particles, computed from the actual
// size law, whatever the size ratio:
// - periodic: the smallest square that holds them on the generator's loose
//   lattice (pitch 1.02 d_max);
// - walls: a sample about as wide as tall once the top wall has compacted
//   it, the width that of a square of the grains' area at the packing
//   fraction kWallsPhi (sheared 2D packings lie within 0.75-0.85 of it, so
//   the sample is square to within 7 %, the walls' looser first layers
//   aside); the height holds the loose lattice's rows between the walls'
//   grains, and the top wall's first fall compacts it.
constexpr double kWallsPhi = 0.8;
Scene with_auto_cell(const Scene& s) {
  if (s.shear_mode == ShearMode::None || s.cell_width != 0 || s.cell_height != 0 || !s.start.empty() || s.n <= 0)
    return s;
  const std::vector<double> d = generated_diameters(s);
  const double pitch = 1.02 * *std::max_element(d.begin(), d.end());
  Scene c = s;
  if (s.shear_mode == ShearMode::Periodic) {
    const double k = std::ceil(std::sqrt(static_cast<double>(s.n)));
    c.cell_width = c.cell_height = pitch * k * (1 + 1e-9);  // floor(side / pitch) = k
    return c;
  }
  double area = 0.0;  // the grains', each the mean over the listed shapes it is drawn from
  for (const double di : d) {
    double a = 0.0;
    for (const double n : s.nsides) a += obs::particle_area(0.5 * di, static_cast<int>(n));
    area += a / static_cast<double>(s.nsides.size());
  }
  c.cell_width = std::max(std::sqrt(area / kWallsPhi), pitch * (1 + 1e-9));
  const double rows = std::ceil(static_cast<double>(s.n) / std::floor(c.cell_width / pitch));
  // place_generated's region: a wall grain's clearance (1.01 d_mean) from each wall.
  c.cell_height = pitch * rows * (1 + 1e-9) + 2 * 1.01 * s.d_mean;
  return c;
}

WorldParams world_params(const Scene& s0) {
  const Scene s = with_auto_cell(s0);
  check_shear(s);
  check_derived(s);
  WorldParams p;
  p.dt = time_step(s);
  p.gravity = Vec2(s.gravity[0], s.gravity[1]);
  p.mu = s.mu;
  p.mu_wall = s.mu_w();
  p.e_n = s.e_n;
  p.e_t = s.e_t;
  p.d_ref = mean_diameter(s);
  p.alert = s.alert * p.d_ref;
  p.overlap_correction = s.overlap_correction;
  p.overlap_projection = s.overlap_projection;
  p.adhesion = pull_off_force(s);  // eta p d, d = p.d_ref
  p.debond = s.debond * p.d_ref;
  if (s.shear_mode != ShearMode::None) {
    CellParams& c = p.cell;
    c.mode = s.shear_mode == ShearMode::Periodic ? CellParams::Mode::LeesEdwards : CellParams::Mode::Walls;
    c.width = s.cell_width;
    c.pressure = imposed_pressure(s);  // 0 under volume control: the lengths stay
    c.isotropic = s.isotropic;
    c.shear_rate = shear_rate(s);
    const double tp = pressure_time(s);
    c.max_strain_rate = s.compaction_rate > 0 && tp > 0 ? s.compaction_rate / tp : 0.0;
    // c.mass: set by build_world, which knows the particles' mass
  }
  p.solver.tol = s.tol;
  p.solver.residual_tol = s.residual_tol;
  p.solver.anderson = s.anderson;
  p.solver.max_iter = s.max_iter;
  p.rotation = s.rotation;
  return p;
}

namespace {

// shear.start: the particles and the cell of a sample (a preparation's or a
// shear run's checkpoint) into w, checked against the scene, its flow set
// for the new run (core/continuation.hpp).
void continue_sample(const Scene& s, const WorldParams& wp, World& w) {
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
  if (!s.disks.empty() || s.n > 0)
    throw SceneError("shear.start gives the particles: set particles.n = 0 and no [[disk]]");
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
  if (imposed_pressure(s) <= 0) w.cell.hdot = w.cell.wdot = 0.0;
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

// particles.n grains on a loose jittered lattice in the region, the cell
// (between the walls' grains) or the box.
void place_generated(const Scene& s, Bodies& B) {
  const bool shear = s.shear_mode != ShearMode::None, walls = s.shear_mode == ShearMode::Walls;
  // Loose placement on a jittered square lattice of pitch 1.02 d_max: no
  // overlap by construction, filled row by row from the bottom.
  std::vector<double> region = s.region;
  if (region.empty() && shear) {
    // The cell; between the walls' grains, a grain's clearance away.
    const double m = walls ? 1.0 * s.d_mean * 1.01 : 0.0;
    region = {0.0, m, s.cell_width, s.cell_height - m};
  }
  if (region.empty()) {
    if (s.box_width <= 0)
      throw SceneError("particles.n > 0 needs particles.region or a [box] to place them in");
    region = {0.0, 0.0, s.box_width, s.box_height};
  }
  const std::vector<double> d = generated_diameters(s);
  const double dmax = *std::max_element(d.begin(), d.end());
  const double pitch = 1.02 * dmax;
  // Counted in doubles (a region of 1e10 pitches overflows an int), and
  // no more columns than grains.
  const double cols = std::floor((region[2] - region[0]) / pitch), rows = std::floor((region[3] - region[1]) / pitch);
  if (!(cols * rows >= s.n))
    throw SceneError(fmt::format(
        "particles.n = {} does not fit in the region [{}, {}] x [{}, {}]: room for {:.0f} disks "
        "of the largest diameter {:.4g} on a loose lattice; enlarge the region or the box",
        s.n, region[0], region[2], region[1], region[3], std::max(0.0, cols * rows), dmax));
  const int nx = static_cast<int>(std::min<double>(cols, s.n));
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

World build_world(const Scene& s0) {
  if (s0.dimension != 2)
    throw SceneError(fmt::format("dimension = {}: build_world makes 2D worlds (3D: build_world3)", s0.dimension));
  const Scene s = with_auto_cell(s0);
  WorldParams wp = world_params(s);
  World w(wp);
  Bodies& B = w.bodies;
  const bool shear = s.shear_mode != ShearMode::None, walls = s.shear_mode == ShearMode::Walls;
  if (shear) {
    w.cell.width = s.cell_width;
    w.cell.height = s.cell_height;
  }
  if (!s.start.empty()) continue_sample(s, wp, w);

  // In a box, every body starts inside it: one outside would fall for ever
  // (one across a wall is refused as an overlap below).
  if (s.box_width > 0) {
    const double W = s.box_width, H = s.box_height;
    for (std::size_t i = 0; i < s.disks.size(); ++i) {
      const auto& x = s.disks[i].pos;
      if (!(x[0] > 0 && x[0] < W && x[1] > 0 && x[1] < H))
        throw SceneError(fmt::format("disk[{}].pos = [{}, {}] is outside the box [0, {}] x [0, {}]: it would "
                                     "never meet the walls", i, x[0], x[1], W, H));
    }
    const std::vector<double>& r = s.region;
    if (r.size() == 4 && !(r[0] >= 0 && r[1] >= 0 && r[2] <= W && r[3] <= H))
      throw SceneError(fmt::format("particles.region = [{}, {}, {}, {}] reaches outside the box [0, {}] x [0, {}]: "
                                   "grains placed there would never meet the walls", r[0], r[1], r[2], r[3], W, H));
  }
  for (const DiskSpec& d : s.disks) {
    const double rho = d.density > 0 ? d.density : s.density;
    const int i = d.nsides > 0 ? B.add_polygon({d.pos[0], d.pos[1]}, d.radius, d.nsides, d.angle,
                                               rho, {d.vel[0], d.vel[1]}, d.omega)
                               : B.add_disk({d.pos[0], d.pos[1]}, d.radius, rho,
                                            {d.vel[0], d.vel[1]}, d.omega);
    B.force[i] = Vec2(d.force[0], d.force[1]);
  }
  const int first_generated = static_cast<int>(B.size());

  if (s.n > 0) place_generated(s, B);

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
