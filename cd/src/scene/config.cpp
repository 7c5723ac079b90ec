// Scene files. The parameter tables below bind every TOML key to its Scene
// member, unit, rule and meaning; reading, validation, error messages, the
// resolved scene.toml and the Markdown table are all generated from them.
// Defaults are never written here: they are the initialisers in scene.hpp.
#include "config.hpp"
#include "printable.hpp"
#include "protocol.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string_view>
#include <tuple>
#include <utility>
#include <variant>

#include <fmt/format.h>
#include <toml.hpp>

#include "shear_policy.hpp"
#include "suggest.hpp"

namespace cd {
namespace {

// ---- rules ----------------------------------------------------------------
// A rule sees the value as a number (integers included), a bool, a string or
// a list of numbers; `text` completes "must be ...".
using Val = std::variant<double, bool, std::string, std::vector<double>>;

struct Rule {
  std::string text;                       // empty: any value of the right type
  std::function<bool(const Val&)> ok;
};

double num(const Val& v) { return std::get<double>(v); }
Rule any() { return {}; }
Rule gt(double lo) { return {fmt::format("> {}", lo), [=](const Val& v) { return num(v) > lo; }}; }
Rule ge(double lo) { return {fmt::format(">= {}", lo), [=](const Val& v) { return num(v) >= lo; }}; }
Rule in(double lo, double hi) {
  return {fmt::format("in [{}, {}]", lo, hi),
          [=](const Val& v) { return num(v) >= lo && num(v) <= hi; }};
}
Rule in_open_closed(double lo, double hi) {
  return {fmt::format("in ({}, {}]", lo, hi),
          [=](const Val& v) { return num(v) > lo && num(v) <= hi; }};
}
Rule vector_of(std::size_t a, std::size_t b) {
  return {a == b ? fmt::format("a list of {} numbers", a) : fmt::format("a list of {} or {} numbers", a, b),
          [=](const Val& v) {
            const auto n = std::get<std::vector<double>>(v).size();
            return n == a || n == b;
          }};
}
// The run's name is its default folder outputs/<name>: one folder name, so
// that a name cannot write outside outputs/ ("../x", "/tmp/x").
Rule folder_name() {
  return {"a folder name: non-empty, no '/', not '.' or '..'", [](const Val& v) {
            const std::string& n = std::get<std::string>(v);
            return !n.empty() && n != "." && n != ".." && n.find('/') == std::string::npos &&
                   n.find('\0') == std::string::npos;
          }};
}
// An enum key (scene.hpp): one of its names. The value is checked when it is
// read (get below, with this text); the rule carries the text for the
// parameter table.
template <class E>
std::string names_text() {
  const auto& names = enum_names(E{});
  std::string t;
  for (std::size_t i = 0; i < names.size(); ++i)
    t += fmt::format("{}\"{}\"", i == 0 ? "" : i + 1 == names.size() ? " or " : ", ", names[i]);
  return t;
}
template <class E>
Rule one_of() {
  return {names_text<E>(), {}};
}
Rule region() {
  return {"[] or [xmin, ymin, xmax, ymax] with xmin < xmax, ymin < ymax", [](const Val& v) {
            const auto& r = std::get<std::vector<double>>(v);
            return r.empty() || (r.size() == 4 && r[0] < r[2] && r[1] < r[3]);
          }};
}
bool valid_sides(double n) { return n == 0 || (n >= 3 && n <= 60 && n == std::floor(n)); }
Rule sides() {
  return {"0 (disk) or an integer in [3, 60]", [](const Val& v) { return valid_sides(num(v)); }};
}
Rule side_list() {
  return {"a non-empty list of 0 (disk) or integers in [3, 60]", [](const Val& v) {
            const auto& r = std::get<std::vector<double>>(v);
            return !r.empty() && std::all_of(r.begin(), r.end(), valid_sides);
          }};
}
Rule positive_list() {
  return {"a list of numbers > 0", [](const Val& v) {
            const auto& r = std::get<std::vector<double>>(v);
            return std::all_of(r.begin(), r.end(), [](double x) { return x > 0; });
          }};
}
Rule disk_density() {
  return {"> 0, or -1 (particles.density)", [](const Val& v) { return num(v) > 0 || num(v) == -1; }};
}

// ---- the parameter table -----------------------------------------------------
template <class T>
using Field = std::variant<double T::*, int T::*, unsigned T::*, bool T::*, std::string T::*,
                           std::array<double, 2> T::*, std::vector<double> T::*, ShearMode T::*,
                           ShearControl T::*, SizeDist T::*, StopRows T::*, std::vector<Shape3d> T::*>;

template <class T>
struct Param {
  const char* section;  // "" : top-level key; "disk", "wall": [[disk]], [[wall]]
  const char* key;
  Field<T> field;
  const char* unit;
  Rule rule;
  const char* doc;
};

const std::vector<Param<Scene>>& scene_params() {
  static const std::vector<Param<Scene>> t = {
      {"", "name", &Scene::name, "", folder_name(), "run name (output folder outputs/<name> unless --out)"},
      {"", "dimension", &Scene::dimension, "", in(2, 3), "2: disks and polygons in the plane; 3: spheres in a box of plane walls (docs/3d.md: which keys apply)"},
      {"time", "dt", &Scene::dt, "s", gt(0), "time step"},
      {"time", "duration", &Scene::duration, "s", ge(0), "simulated time"},
      {"gravity", "g", &Scene::gravity, "m/s^2", vector_of(2, 3), "gravity vector: [gx, gy] in 2D, [gx, gy, gz] in 3D (z up)"},
      {"contact", "mu", &Scene::mu, "", ge(0), "particle-particle friction coefficient"},
      {"contact", "mu_wall", &Scene::mu_wall, "", any(), "particle-wall friction coefficient; < 0: same as mu; refused in a periodic cell (it has no walls)"},
      {"contact", "mu_b", &Scene::mu_b, "", any(), "3D only: orthotropic Coulomb friction, the elliptic cone |(r_a/mu, r_b/mu_b)| <= r_n: mu_b is the friction coefficient across contact.axis_a (mu along it); < 0: off (the round cone of mu)"},
      {"contact", "mu_wall_b", &Scene::mu_wall_b, "", any(), "3D only: the orthotropic cone on walls, across axis_a (mu_wall along it); < 0: mu_b when mu_wall < 0 (walls as spheres), else mu_wall (walls isotropic); refused in a periodic cell (it has no walls)"},
      {"contact", "axis_a", &Scene::axis_a, "", vector_of(3, 3), "3D only: the direction a of the orthotropic law, fixed in the world; each contact's t1 is its projection on the tangent plane (a contact whose normal is along axis_a keeps its default frame); any non-zero length; refused without mu_b or mu_wall_b (the round cone has no direction)"},
      {"contact", "e_n", &Scene::e_n, "", in(0, 1), "normal restitution coefficient"},
      {"contact", "e_t", &Scene::e_t, "", in(0, 1), "tangential restitution coefficient; refused without friction (contact.mu and mu_wall 0: no tangential impulse to act on)"},
      {"contact", "alert", &Scene::alert, "d_mean", ge(0), "alert distance of contact detection, in mean diameters"},
      {"contact", "rotation", &Scene::rotation, "", any(), "integrate particle rotations"},
      {"contact", "adhesion", &Scene::adhesion, "N", ge(0), "pull-off force f_a of the adhesion-shifted Signorini law, on contacts with gap <= debond; 0: no cohesion (no adhesion work at all)"},
      {"contact", "debond", &Scene::debond, "d_mean", ge(0), "debonding distance delta_a, in mean diameters: a bond breaks beyond it; refused without adhesion (contact.adhesion or cohesion_number)"},
      {"contact", "stiffness", &Scene::stiffness, "N/m", ge(0), "3D: compliant contacts, an implicit linear spring of this stiffness k on each contact's normal and tangential displacements over a step (the law acts on u + (r - r0)/(k dt^2), r0 the contact's impulse of the step before), Signorini and Coulomb kept (docs/accuracy.md, \"Compliant contacts\"); 0: rigid contacts (no cost)"},
      {"contact", "stiffness_number", &Scene::stiffness_number, "", ge(0), "3D: the stiffness number kappa = k / (p d) of compliant contacts at the imposed shear.pressure p (needs p > 0; instead of contact.stiffness), d = particles.d_mean as for contact.cohesion_number; 0: use contact.stiffness"},
      {"contact", "stiffness_ratio", &Scene::stiffness_ratio, "", gt(0), "3D, compliant contacts: the tangential stiffness k_t over the normal one k (linear DEM springs often take 2/7 to 1); 1: k_t = k"},
      {"contact", "cohesion_number", &Scene::cohesion_number, "", ge(0), "cohesion number eta, the pull-off force f_a in units of the imposed shear.pressure p (needs p > 0; instead of contact.adhesion): 2D f_a = eta p d (p in N/m), 3D f_a = eta p d^2 (p in N/m^2), d = particles.d_mean (with shear.start: the scene's particles.d_mean, within 10 % of the sample's; particles.diameters: their mean), the d of t_p and I; 0: use contact.adhesion"},
      {"contact", "overlap_correction", &Scene::overlap_correction, "", in(0, 1), "beta: an overlapping contact must separate at beta |gap|/dt; injects energy (bounded by the series column correction_work); 0: pure CD, overlaps never pushed apart"},
      {"contact", "overlap_projection", &Scene::overlap_projection, "", in(0, 1), "beta_p: on a step where some overlap reaches 1e-3 of its pair's smaller diameter, the positions (and the periodic cell's lengths) move by the smallest mass-weighted displacement that opens every overlap by beta_p times itself and closes no gap (a frictionless pseudo-velocity solve, at most 100 sweeps); velocities untouched, so no energy put in; the contact forces' work on those moves is the series column projection_work; 0: off; \"auto\": set by shear.inertial_number (docs/shear.md, Settings by I)"},
      {"solver", "tol", &Scene::tol, "", in_open_closed(0, 1), "NLGS convergence tolerance (relative); \"auto\": set by shear.inertial_number (docs/shear.md, Settings by I)"},
      {"solver", "max_iter", &Scene::max_iter, "", in(1, 1e8), "NLGS iteration cap per time step"},
      {"solver", "residual_tol", &Scene::residual_tol, "", ge(0), "> 0: a step's solve also stops when its largest law residual (relative to the mean impulse, the series' residual column) is below this, checked every 10 sweeps; 0: the rms |dp| test (solver.tol) alone; \"auto\": set by shear.inertial_number (docs/shear.md, Settings by I)"},
      {"solver", "anderson", &Scene::anderson, "", in(0, 50), "> 0: Anderson acceleration of the sweep with this memory (5 is the measured choice): after each forward-backward pair of sweeps the impulses are mixed over the last pairs, and the mixing is off for the rest of a step's solve once it stalls (docs/accuracy.md); an \"auto\" solver.tol then takes the shear policy's tolerance for it (docs/shear.md, Settings by I); 0: plain NLGS; \"auto\": the shear policy's choice by shear.inertial_number (measured on spheres), kept with a number for solver.tol (docs/accuracy.md)"},
      {"solver", "subspace", &Scene::subspace, "", in(0, 1000), "> 0: the subspace correction of the sweep (3D only; it acts on the round cone, with adhesion or not: an orthotropic scene refuses it): every two forward-backward pairs of sweeps, the linear problem of the contacts that stick (u = 0) and slide (u_n = 0) is solved by at most this many conjugate-gradient iterations and put into the impulses, until a stall stops them for the step (docs/accuracy.md); an \"auto\" solver.tol then takes the shear policy's tolerance for it; 0: off; \"auto\": the shear policy's choice by shear.inertial_number (docs/shear.md, Settings by I)"},
      {"solver", "stop_rows", &Scene::stop_rows, "", one_of<StopRows>(), "the rows the stop test (solver.tol) averages its rms |dp| and mean |p| over: all, every row, the open ones within the alert distance included (each counts as converged, so the test tightens with the share of open rows: with n rows of which n_f carry force it is sqrt(n/n_f) times the test over those); loaded, the rows loaded in the sweep (an impulse, or a change in it), whatever the alert distance keeps open, and the law-residual stop's scale (solver.residual_tol) the mean |p| of the rows with an impulse; an \"auto\" solver.tol or solver.residual_tol then takes the shear policy's stop expressed over the loaded rows (docs/shear.md, Settings by I)"},
      {"solver", "threads", &Scene::threads, "", in(0, 1024), "OpenMP threads; 0: OpenMP default"},
      {"particles", "n", &Scene::n, "", in(0, 1e8), "number of randomly generated disks; 0: none"},
      {"particles", "d_mean", &Scene::d_mean, "m", gt(0), "mean diameter of the generated disks"},
      {"particles", "size_ratio", &Scene::size_ratio, "", ge(1), "d_max / d_min"},
      {"particles", "size_dist", &Scene::size_dist, "", one_of<SizeDist>(), "diameter distribution: uniform in d, or uniform_area (equal area per size class)"},
      {"particles", "diameters", &Scene::diameters, "m", positive_list(), "explicit diameters of the generated particles, placed in an order shuffled by particles.seed; particles.n is then their count (0 or that count), and d_mean, size_ratio, size_dist are not used; []: draw them from the size law"},
      {"particles", "diameters_file", &Scene::diameters_file, "", any(), "a text file of diameters (m; whitespace-separated, # comments; relative to the scene file's folder) read into particles.diameters; \"\": none"},
      {"particles", "density", &Scene::density, "kg/m^2 (2D), kg/m^3 (3D)", gt(0), "2D: mass per unit area (2600 kg/m^3 x 1 mm = 2.6); 3D: mass per unit volume (2600 for glass)"},
      {"particles", "seed", &Scene::seed, "", any(), "random seed of sizes and positions"},
      {"particles", "nsides", &Scene::nsides, "", side_list(), "shapes of the generated particles, drawn uniformly from the list: 0 disk, n >= 3 regular n-gon (sizes are then circumscribed diameters)"},
      {"particles", "shape", &Scene::shape, "", {names_text<Shape3d>() + ", or a non-empty list of them", {}}, "3D only: the generated grains' shape: spheres, or a convex polyhedron of the engine (docs/3d.md) whose circumscribed diameter is the grain's size, placed at a random orientation: a Platonic solid, a cuboid (particles.aspect), or an irregular polyhedron, each grain its own (particles.vertices, particles.aspect); a list: a mixture, each grain's shape drawn from the list by particles.seed and its index, with the number fractions particles.shape_fractions"},
      {"particles", "shape_fractions", &Scene::shape_fractions, "", any(), "3D only: with a list particles.shape, the number fraction of each of its shapes, in its order: each >= 0, summing to 1; [] (the default): equal fractions"},
      {"particles", "aspect", &Scene::aspect, "", vector_of(3, 3), "3D only: with particles.shape = \"cuboid\", the ratios of its sides (along its own x, y, z); with \"irregular\", of the semi-axes of the ellipsoid its points are drawn on; each > 0, largest / smallest <= 100; refused with other shapes"},
      {"particles", "vertices", &Scene::vertices, "", in(4, 1000), "3D only: with particles.shape = \"irregular\", the number of random points (uniform on the ellipsoid) whose convex hull is each grain (those inside it dropped); refused with other shapes"},
      {"particles", "region", &Scene::region, "m", region(), "generation region [xmin, ymin, xmax, ymax]; []: inside the box"},
      {"box", "width", &Scene::box_width, "m", ge(0), "box of four static walls [0, width] x [0, height]; width and height both 0 (no box) or both > 0"},
      {"box", "height", &Scene::box_height, "m", ge(0), "box height; 3D: must be 0 (the box is open at the top)"},
      {"box", "depth", &Scene::box_depth, "m", ge(0), "3D only: the box is [0, width] x [0, depth] with a floor at z = 0 and four side walls; width and depth both 0: the square that holds the lattice of generated spheres (docs/3d.md)"},
      {"output", "series_interval", &Scene::series_interval, "s", gt(0), "time between rows of series.csv"},
      {"output", "snapshot_interval", &Scene::snapshot_interval, "s", ge(0), "time between VTK snapshots; 0: none"},
      {"output", "series_strain", &Scene::series_strain, "", ge(0), "> 0: a series row every this much shear strain (a shear run: shear.inertial_number or shear.rate > 0), instead of output.series_interval; 0: output.series_interval"},
      {"output", "snapshot_strain", &Scene::snapshot_strain, "", ge(0), "> 0: a VTK snapshot every this much shear strain (a shear run), instead of output.snapshot_interval; 0: output.snapshot_interval"},
      {"output", "checkpoint_interval", &Scene::checkpoint_interval, "s", ge(0), "simulated time between checkpoints (checkpoint.bin: rerunning the same command resumes), rounded up to whole series intervals; 0: none. Any of the three checkpoint keys writes one (and one at the end)"},
      {"output", "checkpoint_strain", &Scene::checkpoint_strain, "", ge(0), "shear strain between checkpoints (needs shear.inertial_number > 0), rounded up to whole series intervals; 0: none"},
      {"output", "checkpoint_wall", &Scene::checkpoint_wall, "s (wall clock)", ge(0), "a checkpoint at the first series row after this much wall-clock time since the last one (so at most this plus one series interval's wall time between checkpoints); changes no result; 0: none"},
      {"output", "quiet", &Scene::quiet, "", any(), "no progress output"},
      {"shear", "mode", &Scene::shear_mode, "", one_of<ShearMode>(), "boundary protocol: none; periodic (bi-periodic Lees-Edwards cell, height a dof at imposed pressure); walls (rough walls of glued grains, periodic in x, top wall at imposed velocity and pressure)"},
      {"shear", "width", &Scene::cell_width, "m", ge(0), "cell width (period in x); width and height both 0 with generated particles: sized for them (periodic: the square of their loose lattice; walls: a sample about as wide as tall once compacted; docs/shear.md)"},
      {"shear", "height", &Scene::cell_height, "m", ge(0), "initial cell height (periodic) or gap between the wall grains' centres (walls)"},
      {"shear", "depth", &Scene::cell_depth, "m", ge(0), "3D only: the periodic cell's length along z (vorticity direction; width along x is the shear direction, height along y the gradient); width, height and depth all 0: the cube that holds the generated spheres on a loose lattice"},
      {"shear", "control", &Scene::shear_control, "", one_of<ShearControl>(), "what the periodic cell imposes besides the shear: pressure (its height, with shear.isotropic every length, a degree of freedom at sigma = shear.pressure; shear rate from shear.inertial_number) or volume (its lengths fixed: the shear.start sample's, or shear.width and shear.height (3D: and shear.depth); shear rate shear.rate, or shear.rate_tp / t_p; the pressure and I are measured, and shear.pressure, if > 0, is only the scale p of t_p = d sqrt(rho/p) for shear.rate_tp, shear.dt_tp, the \"auto\" settings (at I = shear.rate t_p) and the cohesion and stiffness numbers)"},
      {"shear", "pressure", &Scene::pressure, "N/m", ge(0), "imposed normal stress sigma_yy (2D: force per length, N/m; 3D: force per area, N/m^2); shear.control = \"volume\": the pressure scale of t_p, not imposed"},
      {"shear", "volume_fraction", &Scene::volume_fraction, "", in(0, 1), "shear.control = \"volume\" from a sample (shear.start): its cell, positions and Lees-Edwards offset scaled about the cell's origin, the same factor on every axis, so that the grains fill this fraction of it (a compression is refused if it overlaps grains by more than the start check's 0.05 d); the grains keep their sizes, orientations and velocities; 0: the sample's cell as it is"},
      {"shear", "rate", &Scene::imposed_rate, "1/s", ge(0), "shear.control = \"volume\": the imposed shear rate gamma-dot (the inertial number is then measured: the series' inertial_number column); 0: no shear"},
      {"shear", "rate_tp", &Scene::rate_tp, "1/t_p", ge(0), "shear.control = \"volume\": the imposed shear rate in units of 1/t_p, t_p = d sqrt(rho/p) at the pressure scale shear.pressure: gamma-dot = rate_tp / t_p, the nominal inertial number of the \"auto\" settings (instead of shear.rate; a campaign at another p keeps its steps per unit strain and its settings); 0: shear.rate"},
      {"shear", "inertial_number", &Scene::inertial_number, "", ge(0), "imposed inertial number I: shear rate = I sqrt(p/rho)/d (walls: top wall speed = shear rate x current gap); 0: no shear"},
      {"shear", "cell_mass", &Scene::cell_mass, "total mass", gt(0), "mass of the cell height (and width; 3D: and depth) degree of freedom, in units of the particles' total mass; \"auto\": set by shear.inertial_number (docs/shear.md, Settings by I); refused under shear.control = \"volume\" (the lengths are held)"},
      {"shear", "isotropic", &Scene::isotropic, "", any(), "compaction: the width (3D: and the depth) is a degree of freedom too, at sigma_xx (= sigma_zz) = pressure (periodic, inertial_number = 0)"},
      {"shear", "compaction_rate", &Scene::compaction_rate, "1/t_p", in(0, 1), "periodic cell at imposed pressure: its height (and, isotropic, width) shrinks at most at this strain rate, -(dL/dt)/L <= compaction_rate / t_p (a brake on the pressure-driven collapse; the inertial number of the compaction); 0: no bound on the rate. Whatever it is, a length shrinks by at most a quarter of the alert distance a step (so that the contacts it closes are detected first)"},
      {"shear", "settle_stress", &Scene::settle_stress, "p", in(0, 1), "stop rule of a compaction (periodic, shear.pressure > 0, shear.inertial_number 0): the run ends, with its checkpoint, at the first series row where over the last shear.settle_time every row's mean contact stress sigma_aa, on each axis at imposed stress, was within this fraction of p, and the packing fraction moved by at most shear.settle_phi; time.duration is then a limit (summary.toml status \"settled\" or, if never met, \"done\" with a warning); 0: off"},
      {"shear", "settle_phi", &Scene::settle_phi, "", in(0, 1), "the stop rule's bound on the packing fraction's range (largest minus smallest) over the window, the rows of the last shear.settle_time and the row before them (needs shear.settle_stress)"},
      {"shear", "settle_time", &Scene::settle_time, "t_p", ge(0), "the stop rule's window, in t_p = d sqrt(rho/p): at least this much time between the row before the window and the row that ends it (needs shear.settle_stress)"},
      {"shear", "strain", &Scene::strain, "", ge(0), "run until this shear strain (overrides time.duration); 0: use time.duration"},
      {"shear", "dt_tp", &Scene::dt_tp, "t_p", ge(0), "time step in units of t_p = d sqrt(rho/p) (overrides time.dt); 0: use time.dt; \"auto\": set by shear.inertial_number (docs/shear.md, Settings by I)"},
      {"shear", "start", &Scene::start, "", any(), "checkpoint.bin to start from (same particles): of a preparation run (the cell it reached, from rest) or of a shear run (continued: its Lees-Edwards offset and cell rates kept, its mean flow replaced by this run's rate; strain counted from 0); \"\": generate particles"},
  };
  return t;
}

const std::vector<Param<DiskSpec>>& disk_params() {
  static const std::vector<Param<DiskSpec>> t = {
      {"disk", "pos", &DiskSpec::pos, "m", any(), "centre [x, y] (one [[disk]] table per explicit disk)"},
      {"disk", "vel", &DiskSpec::vel, "m/s", any(), "initial velocity"},
      {"disk", "radius", &DiskSpec::radius, "m", gt(0), "radius"},
      {"disk", "omega", &DiskSpec::omega, "rad/s", any(), "initial angular velocity"},
      {"disk", "density", &DiskSpec::density, "kg/m^2", disk_density(), "mass per unit area; -1: particles.density"},
      {"disk", "nsides", &DiskSpec::nsides, "", sides(), "0: a disk of this radius; n: a regular n-gon of this circumradius"},
      {"disk", "angle", &DiskSpec::angle, "rad", any(), "orientation of a polygon (vertex 0 at this angle)"},
      {"disk", "force", &DiskSpec::force, "N", any(), "constant applied force [fx, fy] (besides gravity)"},
  };
  return t;
}

const std::vector<Param<WallSpec>>& wall_params() {
  static const std::vector<Param<WallSpec>> t = {
      {"wall", "a", &WallSpec::a, "m", any(), "first end point at t = 0 (one [[wall]] table per rigid segment)"},
      {"wall", "b", &WallSpec::b, "m", any(), "second end point at t = 0 (must differ from a)"},
      {"wall", "vel", &WallSpec::vel, "m/s", any(), "imposed velocity"},
      {"wall", "omega", &WallSpec::omega, "rad/s", any(), "imposed angular velocity about the midpoint"},
  };
  return t;
}

// The keys that may be "auto": their value is the shear policy's for the
// scene's inertial number (shear_policy.hpp), put in once every key is read:
// the acceleration first (the integer keys, solver.anderson and
// solver.subspace), since the stop depends on it.
template <class T>
struct AutoField {
  T Scene::*member;
  T ShearSettings::*value;
};
struct AutoKey {
  std::string_view key;
  std::variant<AutoField<double>, AutoField<int>> field;
  bool acceleration() const { return std::holds_alternative<AutoField<int>>(field); }
};
const std::array<AutoKey, 7> kAutoKeys = {
    {{"solver.tol", AutoField<double>{&Scene::tol, &ShearSettings::tol}},
     {"solver.residual_tol", AutoField<double>{&Scene::residual_tol, &ShearSettings::residual_tol}},
     {"contact.overlap_projection",
      AutoField<double>{&Scene::overlap_projection, &ShearSettings::overlap_projection}},
     {"shear.dt_tp", AutoField<double>{&Scene::dt_tp, &ShearSettings::dt_tp}},
     {"shear.cell_mass", AutoField<double>{&Scene::cell_mass, &ShearSettings::cell_mass}},
     {"solver.anderson", AutoField<int>{&Scene::anderson, &ShearSettings::anderson}},
     {"solver.subspace", AutoField<int>{&Scene::subspace, &ShearSettings::subspace}}}};
const AutoKey* auto_key(std::string_view name) {
  for (const AutoKey& a : kAutoKeys)
    if (a.key == name) return &a;
  return nullptr;
}

// "contact.mu", "name", or "disk[3].radius" for an entry of an array of tables.
std::string label(std::string_view section, std::string_view key, const std::string& index = "") {
  if (!index.empty()) return fmt::format("{}[{}].{}", section, index, key);
  return section.empty() ? std::string(key) : fmt::format("{}.{}", section, key);
}

template <class T>
const Param<T>* find(const std::vector<Param<T>>& params, std::string_view section,
                     std::string_view key) {
  for (const Param<T>& p : params)
    if (p.section == section && p.key == key) return &p;
  return nullptr;
}

bool is_section(std::string_view name) {
  return name == "disk" || name == "wall" ||
         std::any_of(scene_params().begin(), scene_params().end(),
                     [&](const Param<Scene>& p) { return *p.section && p.section == name; });
}

// ---- values: TOML -> C++ (converters return "" or what is wrong) ------------
std::string type_name(const toml::value& v) {
  switch (v.type()) {
    case toml::value_t::boolean: return "a boolean";
    case toml::value_t::integer: return "an integer";
    case toml::value_t::floating: return "a float";
    case toml::value_t::string: return "a string";
    case toml::value_t::array: return fmt::format("an array of {}", v.as_array().size());
    case toml::value_t::table: return "a table";
    default: return "a date/time";
  }
}

// A number of any TOML kind; whether it is finite is checked by the callers
// (TOML spells inf and nan, and no scene value may be either).
std::string get_number(const toml::value& v, double& x) {
  if (v.is_floating()) x = v.as_floating();
  else if (v.is_integer()) x = static_cast<double>(v.as_integer());
  else return ": expected a number, got " + type_name(v);
  return "";
}

// The magnitudes a scene may give, in any units: 0, or between 1e-100 and
// 1e100. The engine multiplies a few scene values together (a mass is a
// density times a size squared or cubed, a kinetic energy a mass times a
// velocity squared, an impulse a force times a step): products of three
// such numbers stay within double precision's normal range (1e-308 to
// 1e308); a value like g = 1e308 or a density of 1e-300 would overflow or
// underflow there, into a divergence or a grain of zero mass, not physics.
constexpr double kMagnitudeMin = 1e-100, kMagnitudeMax = 1e100;
bool absurd(double x) { return x != 0 && !(std::abs(x) >= kMagnitudeMin && std::abs(x) <= kMagnitudeMax); }
std::string absurd_text() {
  return fmt::format("must be 0 or between {:g} and {:g} in magnitude (docs/errors.md: values out of double "
                     "precision's reach)", kMagnitudeMin, kMagnitudeMax);
}

std::string get(const toml::value& v, double& x) {
  if (std::string e = get_number(v, x); !e.empty()) return e;
  if (!std::isfinite(x)) return fmt::format(" = {}: must be a finite number", x);
  if (absurd(x)) return fmt::format(" = {:g}: {}", x, absurd_text());
  return "";
}

template <class I>
std::string get_integer(const toml::value& v, I& x) {
  if (!v.is_integer()) return ": expected an integer, got " + type_name(v);
  if (!std::in_range<I>(v.as_integer())) {
    // The TOML reader holds integers past 64 bits at the 64-bit bounds:
    // the value written is not the one it gives.
    const auto x64 = v.as_integer();
    const bool clamped = x64 == std::numeric_limits<decltype(x64)>::max() ||
                         x64 == std::numeric_limits<decltype(x64)>::min();
    return fmt::format(" = {}: must be an integer in [{}, {}]",
                       clamped ? fmt::format("{}{}", x64 < 0 ? "< " : "> ", x64 < 0 ? "-2^63" : "2^63 - 1")
                               : std::to_string(x64),
                       std::numeric_limits<I>::min(), std::numeric_limits<I>::max());
  }
  x = static_cast<I>(v.as_integer());
  return "";
}
std::string get(const toml::value& v, int& x) { return get_integer(v, x); }
std::string get(const toml::value& v, unsigned& x) { return get_integer(v, x); }

std::string get(const toml::value& v, bool& x) {
  if (!v.is_boolean()) return ": expected true or false, got " + type_name(v);
  x = v.as_boolean();
  return "";
}

std::string get(const toml::value& v, std::string& x) {
  if (!v.is_string()) return ": expected a string, got " + type_name(v);
  x = v.as_string().str;
  return "";
}

std::string text(const std::string& x, bool);

template <class E>
  requires std::is_enum_v<E>
std::string get(const toml::value& v, E& x) {
  std::string name;
  if (std::string e = get(v, name); !e.empty()) return e;
  const auto& names = enum_names(E{});
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return fmt::format(" = {}: must be {}", text(name, false), names_text<E>());
  x = static_cast<E>(it - names.begin());
  return "";
}

// particles.shape: a name, or a non-empty list of names.
std::string get(const toml::value& v, std::vector<Shape3d>& x) {
  std::vector<Shape3d> out;
  const auto one = [&](const toml::value& e) {
    Shape3d k{};
    std::string err = get(e, k);
    if (err.empty()) out.push_back(k);
    return err;
  };
  if (v.is_array()) {
    if (v.as_array().empty())
      return fmt::format(": expected a name or a non-empty list of names: {}", names_text<Shape3d>());
    for (const toml::value& e : v.as_array())
      if (std::string err = one(e); !err.empty()) return err;
  } else if (std::string err = one(v); !err.empty()) {
    return err;
  }
  x = std::move(out);
  return "";
}

std::string get(const toml::value& v, std::vector<double>& x) {
  if (!v.is_array()) return ": expected an array of numbers, got " + type_name(v);
  std::vector<double> out(v.as_array().size());
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!get_number(v.as_array()[i], out[i]).empty())
      return ": expected an array of numbers, got an array containing " + type_name(v.as_array()[i]);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!std::isfinite(out[i]))
      return fmt::format(": element {} is {}: must be finite numbers", i, out[i]);
    if (absurd(out[i])) return fmt::format(": element {} is {:g}: {}", i, out[i], absurd_text());
  }
  x = std::move(out);
  return "";
}

std::string get(const toml::value& v, std::array<double, 2>& x) {
  if (!v.is_array() || v.as_array().size() != 2)
    return ": expected an array of 2 numbers, got " + type_name(v);
  std::vector<double> a;
  if (std::string e = get(v, a); !e.empty()) return e;
  x = {a[0], a[1]};
  return "";
}

// ---- values: C++ -> TOML text (toml = false: for messages, 1 not 1.0) ---------
std::string text(double x, bool toml) {
  std::string s = fmt::format("{}", x);  // shortest text that reads back exactly
  if (toml && s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}
std::string text(int x, bool) { return fmt::format("{}", x); }
std::string text(unsigned x, bool) { return fmt::format("{}", x); }
std::string text(bool x, bool) { return x ? "true" : "false"; }
std::string text(const std::string& x, bool) {
  std::string out = "\"";
  for (const char c : x) {
    if (c == '"' || c == '\\') out += {'\\', c};
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) out += fmt::format("\\u{:04X}", int(c));
    else out += c;
  }
  return out + '"';
}
std::string text(const std::vector<double>& x, bool toml) {
  std::string out = "[";
  for (std::size_t i = 0; i < x.size(); ++i) out += (i ? ", " : "") + text(x[i], toml);
  return out + "]";
}
template <class E>
  requires std::is_enum_v<E>
std::string text(E x, bool toml) {
  return text(std::string(name_of(x)), toml);
}
std::string text(const std::vector<Shape3d>& x, bool) { return shape_text(x); }
template <std::size_t N>
std::string text(const std::array<double, N>& x, bool toml) {
  return text(std::vector<double>(x.begin(), x.end()), toml);
}

template <class X>
Val to_val(const X& x) {
  if constexpr (std::is_same_v<X, bool> || std::is_same_v<X, std::string>) return x;
  else if constexpr (std::is_enum_v<X>) return std::string(name_of(x));
  else if constexpr (std::is_same_v<X, std::vector<Shape3d>>) return shape_text(x);
  else if constexpr (std::is_arithmetic_v<X>) return static_cast<double>(x);
  else return std::vector<double>(x.begin(), x.end());
}

// ---- reading ------------------------------------------------------------------
// Problems found while reading, each prefixed with where it is: "file:line:col"
// (the column of the key when it is on the value's line), "--set k=v" for an
// override, or the bare path when the value has no position. All are reported
// at once, in file order.
struct Problems {
  const std::string& path;
  std::vector<std::tuple<int, unsigned, std::size_t, std::string>> list;  // rank, line, col, text
  std::vector<std::pair<const AutoKey*, toml::value>> autos;  // keys given as "auto", and where

  void add(const toml::value& at, std::string_view key, const std::string& msg) {
    const toml::source_location loc = at.location();
    if (loc.file_name().rfind("--set ", 0) == 0) {
      list.emplace_back(1, 0, 0, loc.file_name() + ": " + msg);
    } else if (loc.file_name() != path || loc.line_str() == "unknown line") {
      list.emplace_back(2, 0, 0, path + ": " + msg);
    } else {
      std::size_t col = loc.column();
      if (const auto k = loc.line_str().rfind(key, col - 1); !key.empty() && k != std::string::npos)
        col = k + 1;
      list.emplace_back(0, loc.line(), col, fmt::format("{}:{}:{}: {}", path, loc.line(), col, msg));
    }
  }
  void throw_if_any() {
    if (list.empty()) return;
    std::stable_sort(list.begin(), list.end(), [](const auto& a, const auto& b) {
      return std::tie(std::get<0>(a), std::get<1>(a), std::get<2>(a)) <
             std::tie(std::get<0>(b), std::get<1>(b), std::get<2>(b));
    });
    std::string msg;
    for (const auto& p : list) msg += (msg.empty() ? "" : "\n") + std::get<3>(p);
    throw ConfigError(msg);
  }
};

template <class T>
std::vector<std::string> labels(const std::vector<Param<T>>& params, const std::string& index = "") {
  std::vector<std::string> out;
  for (const Param<T>& p : params) out.push_back(label(p.section, p.key, index));
  return out;
}

std::vector<std::string> section_names() {
  std::vector<std::string> out;
  for (const Param<Scene>& p : scene_params())
    if (*p.section && (out.empty() || out.back() != p.section)) out.push_back(p.section);
  out.insert(out.end(), {"disk", "wall"});
  return out;
}

// Reads `key = v` of `section` (entry `index` of an array of tables) into obj.
template <class T>
void read_key(const std::vector<Param<T>>& params, std::string_view section, const std::string& key,
              const toml::value& v, const std::string& index, T& obj, Problems& out) {
  const std::string name = label(section, key, index);
  const Param<T>* p = find(params, section, key);
  const bool table = v.is_table() || (v.is_array() && !v.as_array().empty() && v.as_array()[0].is_table());
  if (!p && section.empty() && table)
    return out.add(v, key, fmt::format("unknown section '{}'{}", key, did_you_mean(key, section_names())));
  if (!p) return out.add(v, key, fmt::format("unknown key '{}'{}", name, did_you_mean(name, labels(params, index))));
  if (const AutoKey* a = auto_key(name); a && v.is_string() && v.as_string().str == "auto")
  {
    out.autos.emplace_back(a, v);
    return;
  }
  std::visit([&](auto member) {
    auto x = obj.*member;
    if (const std::string e = get(v, x); !e.empty()) return out.add(v, key, name + e);
    if (p->rule.ok && !p->rule.ok(to_val(x)))
      return out.add(v, key, fmt::format("{} = {}: must be {}", name, text(x, false), p->rule.text));
    obj.*member = x;
  }, p->field);
}

template <class T>
void read_table(const toml::value& table, const std::vector<Param<T>>& params, std::string_view section,
                const std::string& index, T& obj, Problems& out) {
  for (const auto& [key, v] : table.as_table()) read_key(params, section, key, v, index, obj, out);
}

template <class T>
void read_array(const toml::value& v, const std::vector<Param<T>>& params, const std::string& name,
                std::vector<T>& list, Problems& out) {
  if (!v.is_array())
    return out.add(v, name, fmt::format("{}: expected [[{}]] tables, got {}", name, name, type_name(v)));
  for (std::size_t i = 0; i < v.as_array().size(); ++i) {
    const toml::value& e = v.as_array()[i];
    T obj;
    if (e.is_table()) read_table(e, params, name, std::to_string(i), obj, out);
    else out.add(e, "", fmt::format("{}[{}]: expected a table, got {}", name, i, type_name(e)));
    list.push_back(obj);
  }
}

const toml::value& child(const toml::value& t, const std::string& key) {
  static const toml::value none;
  return t.is_table() && t.contains(key) ? t.at(key) : none;
}

Scene read_scene(const toml::value& root, const std::string& path) {
  Problems out{path, {}, {}};
  Scene s;
  s.source = path;
  for (const auto& [name, v] : root.as_table()) {
    if (name == "disk") read_array(v, disk_params(), name, s.disks, out);
    else if (name == "wall") read_array(v, wall_params(), name, s.walls, out);
    else if (!is_section(name)) read_key(scene_params(), "", name, v, "", s, out);
    else if (v.is_table()) read_table(v, scene_params(), name, "", s, out);
    else out.add(v, name, fmt::format("{}: expected a [{}] table, got {}", name, name, type_name(v)));
  }
  out.throw_if_any();

  // "auto": the shear settings at the scene's I (after every key and
  // override is read, so that --set shear.inertial_number counts).
  const SceneKind kind{s.dimension, s.adhesion > 0 || s.cohesion_number > 0,
                       std::any_of(s.nsides.begin(), s.nsides.end(), [](double k) { return k >= 3; }),
                       s.orthotropic(), s.stop_rows == StopRows::Loaded};
  // Under volume control, the nominal I of shear.rate at the pressure scale
  // (scene/protocol.hpp); no "auto" key changes what it is made of.
  const double I = nominal_inertial_number(s);
  for (const bool acceleration : {true, false})
    for (const auto& [a, at] : out.autos) {
      if (a->acceleration() != acceleration) continue;
      // Held lengths have no mass: "auto" leaves a volume-controlled cell's
      // at its default (check_derived refuses another).
      if (a->key == "shear.cell_mass" && s.shear_control == ShearControl::Volume) continue;
      if (!(I > 0)) {
        out.add(at, a->key.substr(a->key.find('.') + 1),
                s.shear_control == ShearControl::Volume
                    ? fmt::format("{} = \"auto\" is set by the nominal inertial number shear.rate x t_p "
                                  "(docs/shear.md, \"Settings by I\"), which is {}: give shear.rate > 0 (or "
                                  "shear.rate_tp) and shear.pressure > 0 (the pressure scale of t_p), or a number",
                                  a->key, text(I, false))
                    : fmt::format("{} = \"auto\" is set by shear.inertial_number (docs/shear.md, \"Settings "
                                  "by I\"), which is {}: give shear.inertial_number > 0 or a number",
                                  a->key, text(s.inertial_number, false)));
        continue;
      }
      if (kind.loaded_stop && s.dimension == 2 && (a->key == "solver.tol" || a->key == "solver.residual_tol")) {
        out.add(at, a->key.substr(a->key.find('.') + 1),
                fmt::format("{} = \"auto\" with solver.stop_rows = \"loaded\": the shear policy's stops over "
                            "the loaded rows are measured in 3D only (shear_policy.hpp); give a number, or "
                            "solver.stop_rows = \"all\"",
                            a->key));
        continue;
      }
      const Acceleration acc = s.subspace > 0  ? Acceleration::Subspace
                               : s.anderson > 0 ? Acceleration::Anderson
                                                : Acceleration::None;
      const ShearSettings set = shear_settings(I, acc, kind);
      std::visit([&](const auto& f) { s.*f.member = set.*f.value; }, a->field);
    }
  out.throw_if_any();

  // Explicit diameters: from the file (it wins over a list, so that a
  // resolved scene.toml, which holds both, reads back the same), then n.
  if (!s.diameters_file.empty()) {
    namespace fs = std::filesystem;
    fs::path f(s.diameters_file);
    if (f.is_relative()) f = fs::absolute(fs::path(path).parent_path() / f).lexically_normal();
    // Kept absolute, so that the resolved scene.toml (in the output folder)
    // names the same file.
    s.diameters_file = f.string();
    std::ifstream in(f);
    if (!in) {
      out.add(child(child(root, "particles"), "diameters_file"), "diameters_file",
              fmt::format("particles.diameters_file: cannot read '{}'", f.string()));
      out.throw_if_any();
    }
    std::vector<double> d;
    std::string line;
    for (int ln = 1; std::getline(in, line); ++ln) {
      std::istringstream ls(line.substr(0, line.find('#')));
      for (std::string tok; ls >> tok;) {
        char* end = nullptr;
        const double x = std::strtod(tok.c_str(), &end);
        if (*end != '\0' || !std::isfinite(x) || !(x > 0) || absurd(x))
          throw ConfigError(fmt::format("{}:{}: '{}' is not a diameter (a finite number between {:g} and {:g})",
                                        f.string(), ln, tok, kMagnitudeMin, kMagnitudeMax));
        d.push_back(x);
      }
    }
    if (d.empty()) throw ConfigError(fmt::format("{}: no diameter in the file", f.string()));
    s.diameters = std::move(d);
  }
  if (!s.diameters.empty()) {
    const auto count = static_cast<int>(s.diameters.size());
    if (s.n == 0) s.n = count;
    else if (s.n != count)
      out.add(child(root, "particles"), "particles",
              fmt::format("particles.n = {} but particles.diameters holds {} diameters: give n = 0 "
                          "or n = {}", s.n, count, count));
  }

  // Rules that involve two keys.
  if (s.gravity.size() != static_cast<std::size_t>(s.dimension))
    out.add(child(child(root, "gravity"), "g"), "g",
            fmt::format("gravity.g = {}: a dimension = {} scene needs {} components ({})",
                        text(s.gravity, false), s.dimension, s.dimension,
                        s.dimension == 3 ? "[gx, gy, gz], z up" : "[gx, gy]"));
  if (s.dimension == 2 && s.box_depth > 0)
    out.add(child(child(root, "box"), "depth"), "depth",
            fmt::format("box.depth = {}: only a dimension = 3 scene has a depth",
                        text(s.box_depth, false)));
  if (s.dimension == 2 && !all_spheres(s))
    out.add(child(child(root, "particles"), "shape"), "shape",
            fmt::format("particles.shape = {}: a dimension = 3 key; 2D shapes are particles.nsides",
                        shape_text(s.shape)));
  if (!s.shape_fractions.empty()) {
    const toml::value& at = child(child(root, "particles"), "shape_fractions");
    const std::string f = "particles.shape_fractions = " + text(s.shape_fractions, false);
    double sum = 0;
    for (const double x : s.shape_fractions) sum += x;
    const auto neg = std::find_if(s.shape_fractions.begin(), s.shape_fractions.end(), [](double x) { return x < 0; });
    if (s.dimension == 2)
      out.add(at, "shape_fractions", f + ": a dimension = 3 key; 2D shapes are particles.nsides");
    else if (s.shape_fractions.size() != s.shape.size())
      out.add(at, "shape_fractions",
              fmt::format("{}: {} fractions for the {} shapes of particles.shape = {}: one per shape, in its order",
                          f, s.shape_fractions.size(), s.shape.size(), shape_text(s.shape)));
    else if (neg != s.shape_fractions.end())
      out.add(at, "shape_fractions",
              fmt::format("{}: element {} is {}: must be >= 0", f, neg - s.shape_fractions.begin(), text(*neg, false)));
    else if (!(std::abs(sum - 1) <= 1e-9))
      out.add(at, "shape_fractions", fmt::format("{}: the fractions sum to {}: must sum to 1 (within 1e-9)", f, sum));
  }
  if (s.dimension == 2 && s.subspace > 0)
    out.add(child(child(root, "solver"), "subspace"), "subspace",
            fmt::format("solver.subspace = {}: the subspace correction serves 3D spheres only (dimension = 3); "
                        "2D scenes take solver.anderson", s.subspace));
  if (s.dimension == 2 && (s.mu_b >= 0 || s.mu_wall_b >= 0))
    out.add(child(child(root, "contact"), s.mu_b >= 0 ? "mu_b" : "mu_wall_b"), s.mu_b >= 0 ? "mu_b" : "mu_wall_b",
            fmt::format("contact.{} = {}: an orthotropic (elliptic) cone needs a 2D tangent plane, "
                        "only a dimension = 3 scene has one", s.mu_b >= 0 ? "mu_b" : "mu_wall_b",
                        text(s.mu_b >= 0 ? s.mu_b : s.mu_wall_b, false)));
  if (s.axis_a.size() == 3 && s.dimension == 3 && s.axis_a[0] == 0 && s.axis_a[1] == 0 && s.axis_a[2] == 0)
    out.add(child(child(root, "contact"), "axis_a"), "axis_a",
            "contact.axis_a = [0, 0, 0]: the orthotropic direction needs a non-zero length");
  if (s.dimension == 2 && s.axis_a != std::vector<double>{1.0, 0.0, 0.0})
    out.add(child(child(root, "contact"), "axis_a"), "axis_a",
            fmt::format("contact.axis_a = {}: only a dimension = 3 scene has an orthotropic cone",
                        text(s.axis_a, false)));
  if (s.dimension == 2 && s.cell_depth > 0)
    out.add(child(child(root, "shear"), "depth"), "depth",
            fmt::format("shear.depth = {}: only a dimension = 3 scene has a depth",
                        text(s.cell_depth, false)));
  if (s.dimension == 2 && (s.box_width > 0) != (s.box_height > 0))
    out.add(child(root, "box"), "box",
            fmt::format("box.width = {}, box.height = {}: must be both 0 (no box) or both > 0",
                        text(s.box_width, false), text(s.box_height, false)));
  // The stop rule: its three keys together (the protocol it needs:
  // check_derived, derived.cpp).
  if (s.settle_stress > 0 || s.settle_phi > 0 || s.settle_time > 0) {
    const auto at = [&](const char* k) { return child(child(root, "shear"), k); };
    const char* key = s.settle_stress > 0 ? "settle_stress" : s.settle_phi > 0 ? "settle_phi" : "settle_time";
    if (!(s.settle_stress > 0 && s.settle_phi > 0 && s.settle_time > 0))
      out.add(at(key), key,
              fmt::format("shear.settle_stress = {}, settle_phi = {}, settle_time = {}: the stop rule needs all "
                          "three > 0 (or all 0: off)", text(s.settle_stress, false), text(s.settle_phi, false),
                          text(s.settle_time, false)));
  }
  for (std::size_t i = 0; i < s.walls.size(); ++i)
    if (s.walls[i].a == s.walls[i].b)
      out.add(child(root, "wall").as_array().at(i), "wall",
              fmt::format("wall[{}]: a = b = {}: the end points must differ", i, text(s.walls[i].a, false)));
  out.throw_if_any();
  return s;
}

// ---- overrides -----------------------------------------------------------------
// Throws ConfigError "WHAT: invalid UTF-8 byte 0xNN at line L, byte B" for
// the first byte of `text` that does not start a UTF-8 sequence.
// (TOML text is UTF-8; printable.hpp says why nothing else reaches toml11.)
void check_utf8(std::string_view text, const std::string& what) {
  if (const auto f = utf8_fault(text))
    throw ConfigError(fmt::format("{}: invalid UTF-8 byte 0x{:02x} at line {}, byte {}", what, f->value, f->line,
                                  f->byte));
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string_view::npos ? "" : std::string(s.substr(b, e - b + 1));
}

// `section.key=value`: the value is read as TOML and put into the tree. For a
// string key, a value that is not TOML is taken as is (the shell turns
// name="x" into name=x).
void apply_override(toml::value& root, const std::string& set) {
  const std::string src = "--set " + set;
  const auto eq = set.find('=');
  if (eq == std::string::npos) throw ConfigError(src + ": expected section.key=value");
  const std::string key = trim(std::string_view(set).substr(0, eq)), value = trim(set.substr(eq + 1));
  const auto dot = key.find('.');
  const Param<Scene>* p = dot == std::string::npos ? find(scene_params(), "", key)
                                                   : find(scene_params(), key.substr(0, dot), key.substr(dot + 1));
  if (!p)
    throw ConfigError(fmt::format("{}: unknown key '{}'{}", src, key, did_you_mean(key, labels(scene_params()))));

  check_utf8(value, fmt::format("--set {}: the value", key));  // not echoed: it is not text
  const auto parse = [&](const std::string& v) {
    std::istringstream in("v = " + v);
    return toml::value(toml::parse(in, src).at("v"));
  };
  toml::value v;
  try {
    v = parse(value);
  } catch (const std::exception&) {
    // A string key, or an enum key (a name), takes a bare word; so does an
    // "auto" key, the word auto.
    const bool word = std::holds_alternative<std::string Scene::*>(p->field) ||
                      std::holds_alternative<ShearMode Scene::*>(p->field) ||
                      std::holds_alternative<ShearControl Scene::*>(p->field) ||
                      std::holds_alternative<SizeDist Scene::*>(p->field) ||
                      std::holds_alternative<StopRows Scene::*>(p->field) ||
                      std::holds_alternative<std::vector<Shape3d> Scene::*>(p->field) ||
                      (value == "auto" && auto_key(key));
    if (!word)
      throw ConfigError(fmt::format("{}: '{}' is not a TOML value (a number, true, false, "
                                    "\"string\" or [array])", src, value));
    v = parse(text(value, true));
  }
  toml::value* table = &root;
  if (*p->section) {
    table = &root.as_table()[p->section];
    if (table->is_uninitialized()) *table = toml::table{};
    if (!table->is_table()) return;  // reported as a bad section when read
  }
  table->as_table()[p->key] = v;
}

}  // namespace

// ---- public API -------------------------------------------------------------------
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides) {
  check_utf8(text, fmt::format("'{}' is not a scene file (TOML text)", path));
  toml::value root;
  try {
    std::istringstream in(text);
    root = toml::parse(in, path);
  } catch (const toml::syntax_error& e) {
    std::string what = e.what();
    if (what.rfind("[error] ", 0) == 0) what.erase(0, 8);
    // The reader quotes the line: bytes that are not text shown as \xNN.
    throw ConfigError(fmt::format("{}:{}: TOML syntax error: {}", path, e.location().line(), printable(what)));
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: {}", path, e.what()));
  }
  for (const std::string& o : overrides) apply_override(root, o);
  return read_scene(root, path);
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(fmt::format("'{}' is a folder, not a scene file", path));
  if (!in) throw ConfigError(fmt::format("cannot open scene file '{}'", path));
  std::ostringstream text;
  text << in.rdbuf();
  // A binary file is named as such, not echoed to the terminal by the TOML
  // parser's message: TOML text has no control bytes but tab and newlines.
  const std::string t = std::move(text).str();
  for (std::size_t i = 0, line = 1; i < t.size(); ++i) {
    const auto c = static_cast<unsigned char>(t[i]);
    if (c == '\n') ++line;
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f)
      throw ConfigError(fmt::format("'{}' is not a scene file (TOML text): control byte 0x{:02x} at line {}, "
                                    "byte {}", path, c, line, i + 1));
  }
  return parse_scene(t, path, overrides);
}

namespace {

// The resolved scene as TOML; docs = false: the values alone (no comments).
std::string resolved_text(const Scene& s, bool docs) {
  std::string out;
  if (docs) {
    out = "# Resolved scene: every parameter with the value used";
    out += s.source.empty() ? ".\n" : fmt::format(" (read from {}).\n", s.source);
  }
  std::string section;
  const auto line = [&](const auto& p, const auto& obj) {
    const std::string kv =
        fmt::format("{} = {}", p.key, std::visit([&](auto m) { return text(obj.*m, true); }, p.field));
    if (docs) out += fmt::format("{:<32} # {}{}\n", kv, *p.unit ? fmt::format("[{}] ", p.unit) : "", p.doc);
    else out += kv + '\n';
  };
  for (const Param<Scene>& p : scene_params()) {
    if (p.section != section) out += fmt::format("\n[{}]\n", section = p.section);
    line(p, s);
  }
  const auto array = [&](const auto& list, const auto& params) {
    for (const auto& obj : list) {
      out += fmt::format("\n[[{}]]\n", params.front().section);
      for (const auto& p : params) line(p, obj);
    }
  };
  array(s.disks, disk_params());
  array(s.walls, wall_params());
  return out;
}

}  // namespace

std::string resolved_toml(const Scene& s) { return resolved_text(s, true); }

std::string resolved_values(const Scene& s) { return resolved_text(s, false); }

namespace {
// One row of the parameter table: what --help-scene shows of a key.
struct DocRow {
  std::string key, value, unit, rule, doc;
};

// Every key with its default, from the tables. A list's default is shown as
// it may be written (nsides = [0], not [0.0]: the lists take integers).
std::vector<DocRow> doc_rows() {
  std::vector<DocRow> out;
  const auto rows = [&](const auto& params, const auto& defaults, const std::string& index) {
    for (const auto& p : params) {
      const auto [value, rule] = std::visit([&](auto m) {
        using F = std::remove_cvref_t<decltype(defaults.*m)>;
        const bool integer = std::is_integral_v<F> && !std::is_same_v<F, bool>;
        const bool list = std::is_same_v<F, std::vector<double>> || std::is_same_v<F, std::array<double, 2>>;
        return std::pair(text(defaults.*m, !list), integer ? trim("integer " + p.rule.text) : p.rule.text);
      }, p.field);
      out.push_back({label(p.section, p.key, index), value, p.unit, rule, p.doc});
    }
  };
  rows(scene_params(), Scene{}, "");
  rows(disk_params(), DiskSpec{}, "i");
  rows(wall_params(), WallSpec{}, "i");
  return out;
}

// `words` cut into lines of at most `width` characters (a longer word alone).
std::vector<std::string> wrap(const std::string& words, std::size_t width) {
  std::vector<std::string> lines(1);
  std::istringstream in(words);
  for (std::string w; in >> w;) {
    if (!lines.back().empty() && lines.back().size() + 1 + w.size() > width) lines.emplace_back();
    lines.back() += (lines.back().empty() ? "" : " ") + w;
  }
  return lines;
}
}  // namespace

std::string parameter_table_markdown() {
  std::string md = "| key | default | unit | rule | meaning |\n|---|---|---|---|---|\n";
  const auto cell = [](std::string s) {
    for (std::size_t k = 0; (k = s.find('|', k)) != std::string::npos; k += 2) s.insert(k, "\\");
    return s;
  };
  for (const DocRow& r : doc_rows())
    md += fmt::format("| `{}` | `{}` | {} | {} | {} |\n", r.key, cell(r.value), r.unit, cell(r.rule),
                      cell(r.doc));
  return md;
}

std::string parameter_table_text() {
  const std::vector<DocRow> rows = doc_rows();
  std::size_t kw = 0, vw = 0;
  for (const DocRow& r : rows) {
    kw = std::max(kw, r.key.size());
    vw = std::max(vw, r.value.size() + (r.unit.empty() ? 0 : r.unit.size() + 1));
  }
  std::string out, section;
  for (const DocRow& r : rows) {
    const std::string sec = r.key.find('.') == std::string::npos ? "" : r.key.substr(0, r.key.find('.'));
    if (sec != section && !out.empty()) out += "\n";
    section = sec;
    const std::string value = r.unit.empty() ? r.value : r.value + " " + r.unit;
    out += trim(fmt::format("{:<{}}  {:<{}}  {}", r.key, kw, value, vw, r.rule)) + "\n";
    for (const std::string& l : wrap(r.doc, 74)) out += "      " + l + "\n";
  }
  return out;
}

}  // namespace cd
