// One run folder as the analysis sees it: series.csv plus snapshots. Joins
// the reader to the steady-state and fabric measurements, so the command
// line and the report share one path.
#pragma once
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "anisotropy.hpp"
#include "coordination.hpp"
#include "fabric3.hpp"
#include "steady.hpp"
#include "stress.hpp"
#include "table.hpp"
#include "trends.hpp"

namespace cda {

// series.csv of a run folder. Throws AnalysisError naming the folder if it
// is missing, or the file if it is empty or malformed.
Table read_series(const std::string& run_dir);

// The abscissa of a run: `strain` when the series has it (shear runs), else
// `time`.
std::string default_x_column(const Table& series);

struct RunSteady {
  std::string run, column, x_column;
  bool detected = false;  // false: the window was given
  SteadyStats stats;
};

// Steady statistics of `column`: over [a, b] of the x column when `range` is
// given, else over the detected steady window (steady.hpp).
RunSteady run_steady(const std::string& run_dir, const Table& series, const std::string& column,
                     const std::string& x_column,
                     const std::optional<std::pair<double, double>>& range,
                     const SteadyOptions& opt = {});

// Statistics of `column` over a window already found (e.g. for q_over_p).
SteadyStats stats_over(const Table& series, const std::string& column, const std::string& x_column,
                       const Window& w);

// The measured inertial number over a steady window, I = gamma-dot d
// sqrt(rho / <sigma_yy>), sigma_yy = syy + kyy (contact and kinetic, when
// the series has kyy): from the mean normal stress, not the mean of the
// per-row inertial_number column, which is biased upwards by sigma_yy's
// fluctuations (Jensen: <sigma^-1/2> > <sigma>^-1/2; +40 % at I = 0.3 with
// rows every 2 steps). Falls back to the column's mean when the series has
// no syy column. Error: from sigma_yy's correlated error, dI = I dsigma / 2 sigma.
struct Estimate {
  double mean = 0, err = 0;
};
Estimate measured_inertial_number(const Table& series, const std::string& x_column, const Window& w);

// Fabric of one contact snapshot (physical contacts: ss points merged).
struct RunFabric {
  std::string file;
  std::size_t contacts = 0, physical_contacts = 0;
  Anisotropy fft, tensor;
  AngularProfile profile;
  Stress stress;               // with the given volume (1 if none: stress times V)
  bool has_volume = false;
  double sliding = 0;           // status flag 2 (the solver's own test, see sliding_share)
  // |f_t| >= mu f_n (1 - tol) with the mu and tol given to run_fabric (nan
  // when mu <= 0), and the share of side-side contacts, both over the
  // force-bearing physical contacts.
  double sliding_coulomb = std::nan("");
  double ss_share = 0;
  cd::obs::Tensor<2> fabric{};  // fabric tensor <n n> over the force-bearing physical contacts
  std::optional<Connectivity> connectivity;  // when the particles snapshot exists
  // Per-type partial results (sv, ss), when the set has such contacts.
  std::optional<Anisotropy> sv, ss;
  std::optional<Stress> sv_stress, ss_stress;
};

// snapshot k of contacts_NNNNN.vtp (k < 0 from the end). volume <= 0: none.
// mu > 0: also the Coulomb test of sliding with that friction and tolerance.
// force_rel: a contact bears force when |fn| + |ft| > force_rel x mean |fn|
// of the snapshot (cd::obs::force_threshold); the default is the series' z.
RunFabric run_fabric(const std::string& run_dir, int k, int bins, double volume, double mu = 0,
                     double sliding_tol = 1e-4, double force_rel = cd::obs::kForceEpsRel);

// Fabric of one 3D contact snapshot (spheres; fabric3.hpp). The fabric and
// anisotropies are over the force-bearing contacts (cd::obs::bears_force),
// the stress over all contacts; z from the spheres snapshot with the same
// number, when it exists.
struct RunFabric3 {
  std::string file;
  std::size_t contacts = 0, physical_contacts = 0;
  // The anisotropies; empty when the harmonic forms do not fit the contacts
  // (too few, or anisotropies of order 1), with the reason in aniso_problem.
  std::optional<Anisotropy3> aniso;
  std::optional<BranchAnisotropy3> branch;  // of the same contacts, with aniso
  std::string aniso_problem;
  Stress3 stress;  // with the given volume (1 if none: stress times V)
  bool has_volume = false;
  double sliding = 0;                          // status flag 2
  double sliding_coulomb = std::nan("");       // |f_t| >= mu f_n (1 - tol), when mu > 0
  Mat3 fabric{};                               // <n n>, cd::obs::fabric_tensor<3>
  std::optional<Connectivity> connectivity;
  // Polyhedra (rows of kind > 0): the force-bearing physical contacts by
  // kind (Kind3), the anisotropies of the face-face ones and of the others
  // (empty when there are none or the forms do not fit them), and the
  // stress their rows carry (stress = stress_face_face + stress_other).
  bool polyhedra = false;
  std::array<std::size_t, kKinds3> by_kind{};
  std::optional<Anisotropy3> aniso_face_face, aniso_other;
  Stress3 stress_face_face, stress_other;
  double kind_share(Kind3 k) const;  // of physical_contacts; NaN without polyhedra
  // q carried by the face-face rows over p: (e1.s_ff e1 - e3.s_ff e3)/3 / p
  // on the whole stress's principal axes e1, e3, so that the parts add up to q/p.
  double q_over_p_face_face() const;
};
RunFabric3 run_fabric3(const std::string& run_dir, int k, double volume, double mu = 0,
                       double sliding_tol = 1e-4, double force_rel = cd::obs::kForceEpsRel);

// The simulated time of each snapshot `prefix`_NNNNN.vtp of a run, in the
// order of list_snapshots, read from the run's `prefix`.pvd collection
// (cdsim writes <DataSet timestep="t" file="contacts_00003.vtp"/> per
// frame, t the world's time, the clock of series.csv's time column):
// nullopt for a file the collection does not list. Throws AnalysisError
// when the collection is missing or lists no frame.
std::vector<std::optional<double>> snapshot_times(const std::string& run_dir, const std::string& prefix);

// The series' x column at time t: t itself when x is `time`, else linear
// interpolation between the two rows whose times bracket t (a row at t
// exactly: its x). NaN when t is outside the rows' times by more than
// their rounding in series.csv (1e-9 relative; e.g. the snapshot at t = 0,
// before the first row) or the time column decreases.
double x_at_time(const Table& series, const std::string& x_column, double t);

// The contact snapshots whose x (x_at_time of their .pvd time) lies in the
// window [w.x_begin, w.x_end]: their indices (list_snapshots order) and x.
// `problem` says why none could be placed (no contacts.pvd); snapshots the
// collection does not list are left out.
struct WindowSnapshots {
  std::vector<int> index;
  std::vector<double> x;
  std::vector<double> time;  // each one's .pvd time
  std::size_t total = 0;     // snapshots of the run
  std::string problem;
};
// prefix: the snapshots' (contacts; particles_prefix for the bodies).
WindowSnapshots snapshots_in_window(const std::string& run_dir, const Table& series,
                                    const std::string& x_column, const Window& w,
                                    const std::string& prefix = "contacts");

// Is the shear homogeneous? The profile of the local shear rate across the
// gradient direction y of a shear run, from the particle snapshots
// (particles_/spheres_NNNNN.vtp) in the window w, L_y and gd the series'
// cell_height and shear_rate at the snapshot's time (interpolated).
// Periodic (Lees-Edwards) cell: each snapshot's particles are brought into
// one period [0, L_y) of the images (y - k L_y with velocity v_x - k gd L_y,
// k = floor(y/L_y): the Lees-Edwards image of the particle, so nothing
// depends on where the cell's origin is), sorted into `layers` equal
// layers, whose mean v_x give the rate of each gap between neighbouring
// layer centres, the last across the periodic boundary (+ gd L_y):
//   s_i = (v_{i+1} - v_i) / (gd L_y / layers),   sum_i s_i = layers exactly.
// Walls protocol (shear mode walls): [0, L_y] is the gap between the wall
// grains' centres, the bottom row at rest, the top row at v_x = gd L_y.
// The profile is that of the mean velocity over each interval between
// consecutive snapshots of the window (the particles' displacements,
// periodic along x, over the interval's imposed strain: far less noisy than
// one instant's velocities; the top wall may move at most half the period
// between them), so its samples are the intervals, not the snapshots; the
// `layers` equal layers of the gap give layers + 1 gaps: from the bottom
// wall (at rest, y = 0) to the first layer's centre and from the last
// layer's centre to the top wall (y = L_y), each half a layer wide, and the
// layers - 1 between centres, so that
//   s_0/2 + s_1 + ... + s_{layers-1} + s_layers/2 = layers exactly
// (grains slipping on a wall show as a rate above 1 in its gap). Either
// way s = 1 in every gap for a homogeneous shear, and a layer moving as a
// rigid plug gives s near 0 on both sides of it. rate: each gap's s, mean
// +- sem over the snapshots; rate_min: the smallest of those means (with
// its sem), the plug indicator; max_rate: the per-snapshot max of s, mean
// +- sem (a band that wanders between snapshots still shows there);
// bulk_rate (walls only, else nan): the rate of the central half of the
// gap, [L_y/4, 3L_y/4) (the walls protocol's bulk, docs/shear.md): the
// least-squares slope of the displacement against y over the particles
// whose centre is in it, / the imposed strain, mean +- sem over the
// intervals (1: the bulk shears at the imposed rate; it does not depend on
// `layers`); bulk_phi (walls only): the central half's packing fraction,
// each particle's area in it (area_in_band) over W L_y / 2, mean +- sem
// over the snapshots, and bulk_phi_centres the same counting whole
// particles by their centre (cdsim's series column
// bulk_packing_fraction), whose error bar the grains cut by the band's
// edges widen. The
// per-snapshot noise of s is about sqrt(layers/n) times the particles'
// velocity fluctuation in units of gd L_y / layers. Throws AnalysisError
// when the scene's [shear] mode is neither periodic nor walls, the series
// lacks cell_height, shear_rate or time (walls: cell_width), no particle
// snapshot of the window can be placed (2 needed), or layers < 2 or a layer
// is empty.
struct ShearProfile {
  int layers = 0;
  bool walls = false;
  std::vector<Val> rate;  // per gap (periodic: i between layers i and i+1, the last across the boundary;
                          // walls: bottom wall-0, i-1 to i, last layer-top wall)
  Val rate_min, max_rate;
  Val bulk_rate;          // walls: the central half's rate / gd; periodic: nan
  Val bulk_phi, bulk_phi_centres;  // walls: the central half's packing fraction; periodic: nan
  std::size_t snapshots = 0;
  std::vector<double> x;  // each snapshot's x (the window's column)
};
ShearProfile shear_profile(const std::string& run_dir, const Table& series, const std::string& x_column,
                           const Window& w, int layers);
// Below this rate_min a run is flagged as banded (not a homogeneous shear):
// half the mean rate in a gap between layers, averaged over the window.
// Measured with 5 layers on 1000 spheres (docs/3d.md): homogeneous runs,
// cohesive or not, have rate_min 0.71-0.98; the eta = 10 runs at I = 0.03
// and 0.1, 0.08 and 0.41 (a plug of one to two fifths of the cell).
inline constexpr double kBandedRateMin = 0.5;
inline bool is_banded(double rate_min) { return rate_min < kBandedRateMin; }  // false for nan
// ", rate_min = v +- err" (+ " BANDED" below kBandedRateMin), or ",
// rate_min n/a (...)" for nan: the note the fits print after each run.
std::string rate_min_note(double v, double err);
// The rate_min of a run's window (shear_profile, 5 layers) or nan, nan
// when it cannot be measured (no particle snapshots, not a periodic shear).
Val window_rate_min(const std::string& run_dir, const Table& series, const std::string& x_column, const Window& w);

// The per-snapshot quantities of a 3D run's fabric, in the order of the
// report's fabric.csv (each followed by its _err there): the
// spherical-harmonic anisotropies a_c, a_n, a_t and (2/5) sum a (from the
// harmonics and from the tensors; fabric3.hpp), q/p with q = (s1 - s3)/3,
// von Mises' q/p, mu = -sxy/syy, the sliding share, z and the share of
// non-floating particles.
extern const std::vector<std::string> kFabric3Columns;

// A 3D run's fabric over its steady window w: each kFabric3Columns
// quantity's mean +- sem over the contact snapshots inside w
// (snapshots_in_window), or the last snapshot's value alone (err nan) when
// w is null or holds fewer than 2 snapshots (`alone` says why).
// check_rel = ((2/5) sum a - q/p)/(q/p) of the means, its error the sem of
// the per-snapshot differences over |q/p| (paired: their common fluctuation
// cancels). In a window, a snapshot that cannot be read is left out and
// named in `problems`, as is a failed anisotropy fit (its a columns nan,
// skipped by the means). Throws AnalysisError when no snapshot can be read.
struct WindowFabric3 {
  std::vector<Val> mean;  // per kFabric3Columns
  // ((2/5) sum a - q/p)/(q/p) per snapshot, averaged, with its sem: the
  // force and fabric terms (a_c + a_n + a_t), and with the branch terms too
  // (+ a_ln + a_lt).
  double check_rel = std::nan(""), check_rel_err = std::nan("");
  double check_rel_branch = std::nan(""), check_rel_branch_err = std::nan("");
  std::vector<std::string> files;  // the snapshots used, in order
  double bearing = 0;              // force-bearing contacts per snapshot, mean
  bool averaged = false;           // false: the last snapshot alone
  std::string alone;               // why, when not averaged
  std::vector<std::string> problems;
  const Val& of(const std::string& column) const;  // throws for an unknown column
};
WindowFabric3 window_fabric3(const std::string& run_dir, const Table& series, const std::string& x_column,
                             const Window* w);

// The column that is mu in the rheology of a run of this dimension: 2D
// q_over_p (sin phi of the Mohr circle, method.md §11), 3D
// shear_stress_ratio (-sigma_xy/sigma_yy; the 3D q_over_p is von Mises').
inline const char* mu_column(int dimension) { return dimension == 3 ? "shear_stress_ratio" : "q_over_p"; }

// "a:b" -> (a, b); throws AnalysisError on bad syntax or a >= b.
std::pair<double, double> parse_range(const std::string& s);
// A run's steady window from the --window option: "a:b" in the abscissa x
// (parse_range), or "a%:b%" as percentages of the run's own span of x, from
// its first row to its last (0 <= a < b <= 100): "50%:100%" is the second
// half of every run whatever its length, for campaigns whose runs differ in
// strain. Throws AnalysisError naming the spec when it is neither, or when
// x is empty.
std::pair<double, double> resolve_window(const std::string& spec, std::span<const double> x);
// The same for an optional --window: nullopt when spec is empty (the
// steady window is then detected).
std::optional<std::pair<double, double>> window_range(const std::string& spec, std::span<const double> x);

}  // namespace cda
