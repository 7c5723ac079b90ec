#include "complete.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "protocol.hpp"

namespace cd {

namespace {

// ---- 2D ----

// The protocol's rules (protocol.hpp) and the cell's size, which the
// placement needs.
void check_shear2(const Scene& s) {
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

// A started sample gives the particles; in a box, every body starts inside
// it (one outside would fall for ever; one across a wall is refused as an
// overlap by the engine).
void check_bodies2(const Scene& s) {
  if (!s.start.empty() && (!s.disks.empty() || s.n > 0))
    throw SceneError("shear.start gives the particles: set particles.n = 0 and no [[disk]]");
  if (s.box_width <= 0) return;
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

// The loose lattice of the particles.n generated grains: a jittered square
// lattice of pitch 1.02 d_max (the largest drawn diameter) filled row by row
// from the bottom of the region (particles.region, else the cell between
// the walls' grains, else the box). No overlap by construction.
void place2(CompleteScene& c) {
  const Scene& s = c.scene;
  const bool shear = s.shear_mode != ShearMode::None, walls = s.shear_mode == ShearMode::Walls;
  std::vector<double> region = s.region;
  if (region.empty() && shear) {
    // The cell; between the walls' grains, a grain's clearance away.
    const double m = walls ? 1.0 * s.d_mean * 1.01 : 0.0;
    region = {0.0, m, s.cell_width, s.cell_height - m};
  }
  if (region.empty()) {
    if (s.box_width <= 0) throw SceneError("particles.n > 0 needs particles.region or a [box] to place them in");
    region = {0.0, 0.0, s.box_width, s.box_height};
  }
  const double dmax = *std::max_element(c.diameters.begin(), c.diameters.end());
  const double pitch = 1.02 * dmax;
  // Counted in doubles (a region of 1e10 pitches overflows an int), and
  // no more columns than grains.
  const double cols = std::floor((region[2] - region[0]) / pitch), rows = std::floor((region[3] - region[1]) / pitch);
  if (!(cols * rows >= s.n))
    throw SceneError(fmt::format(
        "particles.n = {} does not fit in the region [{}, {}] x [{}, {}]: room for {:.0f} disks "
        "of the largest diameter {:.4g} on a loose lattice; enlarge the region or the box",
        s.n, region[0], region[2], region[1], region[3], std::max(0.0, cols * rows), dmax));
  c.region = std::move(region);
  c.pitch = pitch;
  c.columns = static_cast<int>(std::min<double>(cols, s.n));
}

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
Scene with_auto_cell2(const Scene& s) {
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
    for (const double n : s.nsides) a += grain_area(0.5 * di, static_cast<int>(n));
    area += a / static_cast<double>(s.nsides.size());
  }
  c.cell_width = std::max(std::sqrt(area / kWallsPhi), pitch * (1 + 1e-9));
  const double rows = std::ceil(static_cast<double>(s.n) / std::floor(c.cell_width / pitch));
  // place2's region: a wall grain's clearance (1.01 d_mean) from each wall.
  c.cell_height = pitch * rows * (1 + 1e-9) + 2 * 1.01 * s.d_mean;
  return c;
}

// ---- 3D ----

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
      fail3("shear.start gives the grains: set particles.n = 0 and no particles.diameters");
    if (!all_spheres(s))
      fail3(fmt::format("particles.shape = {}: shear.start gives the grains, their shapes too (a sample "
                        "of polyhedra stores them); leave particles.shape out", shape_text(s.shape)));
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
  if (s.shear_mode != ShearMode::Periodic || s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0 ||
      s.n <= 0 || !s.start.empty())
    return s;
  Scene c = s;
  const double k = lattice_side3(s.n);
  c.cell_width = c.cell_height = c.cell_depth = cell_pitch3(s) * k * (1 + 1e-9);  // floor(side / pitch) = k
  return c;
}

// What a polyhedra scene (particles.shape) cannot have yet, refused by key.
void check_polyhedra3(const Scene& s) {
  if (!s.shape_fractions.empty() && s.shape_fractions.size() != s.shape.size())
    fail3(fmt::format("particles.shape_fractions: {} fractions for the {} shapes of particles.shape = {}: one per "
                      "shape, in its order", s.shape_fractions.size(), s.shape.size(), shape_text(s.shape)));
  if (all_spheres(s)) return;
  const std::string what = fmt::format("particles.shape = {}", shape_text(s.shape));
  if (contact_stiffness(s) > 0)
    fail3(fmt::format("contact.stiffness: compliant contacts need grains of scalar inertia (spheres); {} grains "
                      "take rigid contacts (no contact.stiffness)", what));
  const auto [lo, hi] = std::minmax_element(s.aspect.begin(), s.aspect.end());
  if (!(*lo > 0) || !(*hi <= 100 * *lo))
    fail3(fmt::format("particles.aspect = [{}]: each ratio > 0 and the largest at most 100 times the smallest "
                      "(a flatter grain is a plate the contact detection does not resolve)",
                      fmt::join(s.aspect, ", ")));
}

// Every quantity the engines build from, of a checked scene.
CompleteScene resolved(const Scene& s) {
  CompleteScene c;
  c.scene = s;
  c.diameters = generated_diameters(s);
  c.d_mean = mean_diameter(s);
  std::tie(c.d_min, c.d_max) = diameter_bounds(s);
  c.dt = time_step(s);
  c.pressure = imposed_pressure(s);
  c.shear_rate = shear_rate(s);
  c.t_p = pressure_time(s);
  c.adhesion = pull_off_force(s);
  c.stiffness = contact_stiffness(s);
  return c;
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

Scene with_auto_cell(const Scene& s) { return s.dimension == 3 ? with_auto_cell3(s) : with_auto_cell2(s); }

CompleteScene complete_scene(const Scene& s0) {
  if (s0.dimension == 3) {
    check_scene3(s0);
    CompleteScene c = resolved(with_auto_cell3(s0));
    if (c.scene.shear_mode == ShearMode::Periodic) c.pitch = cell_pitch3(c.scene);
    return c;
  }
  if (s0.dimension != 2) throw SceneError(fmt::format("dimension = {}: a scene is 2D or 3D", s0.dimension));
  const Scene s = with_auto_cell2(s0);
  check_shear2(s);
  check_derived(s);
  check_bodies2(s);
  CompleteScene c = resolved(s);
  if (s.n > 0) place2(c);
  return c;
}

}  // namespace cd
