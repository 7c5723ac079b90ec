// Scene: every parameter of a run, as plain data, the same struct for 2D and
// 3D (the bottom layer: it includes nothing of the engines). The defaults
// written here are the only defaults (config.cpp binds each field to its
// TOML key, documents it and validates it; the resolved scene.toml written
// with every run is printed from the same table); the engines' parameter
// structs take the few they share from defaults.hpp.
#pragma once
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "defaults.hpp"

namespace cd {

// shear.mode: the boundary protocol (method.md section 9), chosen once per
// scene. The names are the scene file's, in enum order.
enum class ShearMode { None, Periodic, Walls };
inline constexpr std::array<std::string_view, 3> kShearModeNames = {"none", "periodic", "walls"};

// shear.control: what a shear protocol imposes besides the shear
// (scene/protocol.hpp): the normal stress (the cell's height a dof at
// shear.pressure, the rate from shear.inertial_number) or the volume (the
// cell's lengths fixed, the rate shear.rate).
enum class ShearControl { Pressure, Volume };
inline constexpr std::array<std::string_view, 2> kShearControlNames = {"pressure", "volume"};

// particles.size_dist: the size law of the generated particles.
enum class SizeDist { Uniform, UniformArea };
inline constexpr std::array<std::string_view, 2> kSizeDistNames = {"uniform", "uniform_area"};

// solver.stop_rows: the rows the solver's stop test averages over
// (core/solver.hpp, SolverParams::stop_rows).
inline constexpr std::array<std::string_view, 2> kStopRowsNames = {"all", "loaded"};

// particles.shape: the generated grains' shape in 3D: spheres, or a convex
// polyhedron whose circumscribed diameter is the grain's size (the
// engine's, docs/3d.md): a Platonic solid, a cuboid of sides in the ratios
// particles.aspect, or an irregular polyhedron, each grain its own: the
// hull of particles.vertices random points on the ellipsoid of semi-axes in
// those ratios.
enum class Shape3d { Sphere, Tetrahedron, Cube, Octahedron, Dodecahedron, Icosahedron, Cuboid, Irregular };
inline constexpr std::array<std::string_view, 8> kShape3dNames = {
    "sphere", "tetrahedron", "cube", "octahedron", "dodecahedron", "icosahedron", "cuboid", "irregular"};

// The names of an enum's values (config.cpp reads and writes every enum key
// through this overload; a new enum adds its names here and its member type
// to config.cpp's Field), and the name of one value, for messages.
constexpr const auto& enum_names(ShearMode) { return kShearModeNames; }
constexpr const auto& enum_names(ShearControl) { return kShearControlNames; }
constexpr const auto& enum_names(SizeDist) { return kSizeDistNames; }
constexpr const auto& enum_names(Shape3d) { return kShape3dNames; }
constexpr const auto& enum_names(StopRows) { return kStopRowsNames; }
template <class E>
constexpr std::string_view name_of(E e) { return enum_names(e)[static_cast<std::size_t>(e)]; }

struct DiskSpec {            // [[disk]]: one explicit disk
  std::array<double, 2> pos{0.0, 0.0};
  std::array<double, 2> vel{0.0, 0.0};
  double radius = 0.5e-3;
  double omega = 0.0;
  double density = -1.0;     // < 0: particles.density
  int nsides = 0;            // 0: disk; 3..60: regular polygon of circumradius `radius`
  double angle = 0.0;        // orientation (vertex 0 at this angle)
  std::array<double, 2> force{0.0, 0.0};  // constant applied force (N)
};

struct WallSpec {            // [[wall]]: a rigid segment with imposed velocity
  std::array<double, 2> a{0.0, 0.0};   // end points at t = 0
  std::array<double, 2> b{1.0, 0.0};
  std::array<double, 2> vel{0.0, 0.0};
  double omega = 0.0;        // imposed angular velocity about the midpoint
};

struct Scene {
  std::string name = "default";
  std::string source;        // file the scene came from (for messages)
  int dimension = 2;         // 2: disks and polygons (2d/setup.hpp); 3: spheres (3d/setup3.hpp)

  // [time]
  double dt = defaults::dt;  // time step (s)
  double duration = 0.5;     // simulated time (s)

  // [gravity]: [gx, gy] in 2D, [gx, gy, gz] in 3D
  std::vector<double> gravity{0.0, -9.81};

  // [contact]
  double mu = 0.4;           // particle-particle friction coefficient
  double mu_wall = -1.0;     // particle-wall friction (< 0: same as mu)
  // 3D orthotropic Coulomb (elliptic cone, method.md section 14): mu along
  // axis_a's projection on the tangent plane, mu_b across it; < 0: off.
  double mu_b = -1.0;
  double mu_wall_b = -1.0;   // on walls (< 0: mu_b if mu_wall < 0, else mu_wall)
  std::vector<double> axis_a = {1.0, 0.0, 0.0};
  double e_n = 0.0;          // normal restitution
  double e_t = 0.0;          // tangential restitution
  double alert = 0.1;        // alert distance, in mean diameters
  bool rotation = defaults::rotation;  // integrate rotations
  double overlap_correction = 0.0;  // beta: overlaps separate at beta |gap|/dt (0: none)
  double overlap_projection = 0.0;  // beta_p: centres moved apart by beta_p |gap| a step (0: none)
  double adhesion = 0.0;     // pull-off force f_a (N); 0: no cohesion
  double stiffness = 0.0;    // 3D: compliant contacts of stiffness k (N/m); 0: rigid
  double debond = 0.01;      // debonding distance delta_a, in mean diameters

  // [solver]
  // SolverParams (core/solver.hpp) takes the same defaults.hpp values: one source.
  double tol = defaults::tol;                // NLGS tolerance eps_f (relative)
  int max_iter = defaults::max_iter;         // iteration cap per step
  double residual_tol = defaults::residual_tol;  // > 0: also stop on the law residual
  int anderson = defaults::anderson;         // > 0: Anderson acceleration memory
  int subspace = defaults::subspace;         // > 0: subspace correction's CG iterations
  StopRows stop_rows = defaults::stop_rows;  // the stop test over every row, or the loaded ones
  int threads = 0;           // 0: OpenMP default

  // [particles]: random generation (n = 0 for none)
  int n = 0;
  double d_mean = 1e-3;      // mean diameter (m)
  double size_ratio = 2.0;   // d_max / d_min
  SizeDist size_dist = SizeDist::UniformArea;
  // explicit diameters of the generated particles (then n = their count, and
  // d_mean, size_ratio, size_dist are not used); read from diameters_file
  // (one per line or whitespace-separated, '#' comments) when that is given
  std::vector<double> diameters;
  std::string diameters_file;
  double density = 2.6;      // mass per unit area (kg/m^2): 2600 kg/m^3 x 1 mm
  unsigned seed = 1;
  // shapes drawn uniformly from this list: 0 disk, 3..60 regular polygon
  // (sizes then refer to the circumscribed diameter 2R)
  std::vector<double> nsides{0.0};
  // 3D: the generated grains' shape (sizes then circumscribed diameters);
  // several: a mixture, each grain's shape drawn from the list with the
  // number fractions shape_fractions (empty: equal fractions)
  std::vector<Shape3d> shape{Shape3d::Sphere};
  std::vector<double> shape_fractions;
  // cuboid: side ratios; irregular: the ellipsoid's semi-axis ratios
  std::vector<double> aspect{1.0, 1.0, 1.0};
  // irregular: the number of random points whose hull is a grain
  int vertices = 12;
  // generation region [xmin, ymin, xmax, ymax]; empty: inside the box
  std::vector<double> region;

  // [box]: four static walls (width = 0: no box)
  double box_width = 0.0;
  double box_height = 0.0;
  double box_depth = 0.0;    // 3D: y extent of the box (0 with width 0: fitted to the lattice)

  std::vector<DiskSpec> disks;
  std::vector<WallSpec> walls;

  // [output]
  double series_interval = 0.005;    // time between series rows (s)
  double snapshot_interval = 0.025;  // time between VTK snapshots (s); 0: none
  double series_strain = 0.0;        // > 0: shear strain between series rows (instead of the interval)
  double snapshot_strain = 0.0;      // > 0: shear strain between snapshots (instead of the interval)
  double checkpoint_interval = 0.0;  // time between checkpoints (s); 0: none
  double checkpoint_strain = 0.0;    // shear strain between checkpoints; 0: none
  double checkpoint_wall = 0.0;      // most wall-clock seconds between checkpoints; 0: none
  bool quiet = false;

  // [shear]: boundary protocols (method.md section 9)
  ShearMode shear_mode = ShearMode::None;  // periodic: Lees-Edwards cell; walls: rough walls
  double cell_width = 0.0;          // cell width (m)
  double cell_height = 0.0;         // initial cell height / wall gap (m)
  double cell_depth = 0.0;          // 3D periodic cell: its length along z (m)
  ShearControl shear_control = ShearControl::Pressure;
  double pressure = 0.0;            // imposed normal stress (N/m); volume control: the scale of t_p
  double imposed_rate = 0.0;        // shear.rate: the shear rate under volume control (1/s)
  double rate_tp = 0.0;             // shear.rate_tp: the same in units of 1/t_p (t_p at shear.pressure)
  double volume_fraction = 0.0;     // volume control from a sample: scaled to this packing fraction; 0: as is
  double inertial_number = 0.0;     // imposed I: gamma-dot = I sqrt(p/rho) / d
  double cell_mass = 0.1;           // mass of the height (width) dof, in total particle mass
  bool isotropic = false;           // compaction: the width is a dof too (periodic, I = 0)
  double compaction_rate = 0.0;     // > 0: cell lengths shrink at most at this rate x 1/t_p
  // The stop rule of a compaction (core/settle.hpp): the run ends at the first
  // series row where, over the last settle_time t_p, every controlled axis's
  // contact stress was within settle_stress p of p and the packing fraction
  // moved by at most settle_phi. settle_stress 0: off (run time.duration).
  double settle_stress = 0.0;
  double settle_phi = 0.0;
  double settle_time = 0.0;         // t_p
  double strain = 0.0;              // > 0: run until this shear strain (overrides duration)
  double dt_tp = 0.0;               // > 0: dt = dt_tp x t_p, t_p = d sqrt(rho/p)
  std::string start;                // checkpoint.bin of a preparation run to start from
  // [contact] cohesion_number: eta > 0 gives f_a = eta p d
  double cohesion_number = 0.0;
  // [contact] stiffness_number: kappa > 0 gives k = kappa p d (3D)
  double stiffness_number = 0.0;
  // [contact] stiffness_ratio: k_t / k of compliant contacts (3D)
  double stiffness_ratio = 1.0;

  double mu_w() const { return mu_wall < 0 ? mu : mu_wall; }
  // The orthotropic (elliptic) cone: 3D, with mu_b or mu_wall_b given (>= 0).
  bool orthotropic() const { return dimension == 3 && (mu_b >= 0 || mu_wall_b >= 0); }
};

// particles.shape: whether any generated grain may be `k`, whether all are
// spheres, and the value as written ("cube", or ["sphere", "cube"]).
inline bool has_shape(const Scene& s, Shape3d k) {
  for (const Shape3d x : s.shape)
    if (x == k) return true;
  return false;
}
inline bool all_spheres(const Scene& s) {
  for (const Shape3d x : s.shape)
    if (x != Shape3d::Sphere) return false;
  return true;
}
inline std::string shape_text(const std::vector<Shape3d>& v) {
  std::string out;
  for (const Shape3d x : v) out += (out.empty() ? "\"" : ", \"") + std::string(name_of(x)) + "\"";
  return v.size() == 1 ? out : "[" + out + "]";
}

}  // namespace cd
