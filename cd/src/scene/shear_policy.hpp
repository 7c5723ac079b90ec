// The shear settings that depend on the inertial number I, decided in one
// place for a single run and a campaign alike: a scene gives "auto" for
// solver.tol, solver.residual_tol, contact.overlap_projection, shear.dt_tp or
// shear.cell_mass (and, in 3D, solver.anderson and
// solver.subspace: the band's acceleration), and the
// scene reader (config.cpp) puts in the value for its shear.inertial_number,
// so the run's resolved scene.toml holds the number it ran with. The
// Makefile's campaigns only name I (configs/shear-inertial.toml and
// shear3-inertial.toml say "auto"). The measurements behind each number:
// docs/shear.md, "Settings by I".
#pragma once
#include <array>

namespace cd {

// The policy, all its numbers in this table: a band applies from its I_min
// up to the next band's. A stop is the solver's stopping rule (solver.tol,
// solver.residual_tol) with the overlap projection that holds the overlaps
// a looser stop lets grow (contact.overlap_projection). A scene with
// Anderson's mixing on (solver.anderson > 0: configs/shear-inertial.toml
// with disks, the 3D scene below I = 0.01) gets the band's `anderson` stop,
// a cohesive one its `cohesive` stop, one with the subspace correction on
// (solver.subspace > 0) its `subspace` stop, and a 2D scene of polygons
// without cohesion and without acceleration its `polygons` stop (the
// others' plain solve: `plain`). The 3D scene
// (configs/shear3-inertial.toml) lets the band choose between the two
// accelerations: "auto" for solver.anderson and solver.subspace gives
// auto_anderson and auto_subspace (measured on spheres; 2D scenes refuse
// the subspace correction).
struct Stop {
  double tol;                       // solver.tol
  double residual_tol;              // solver.residual_tol (0: the rms |dp| test alone)
  double overlap_projection = 0.0;  // contact.overlap_projection (0: off)
};
struct ShearBand {
  double i_min;       // the band starts at this I
  Stop plain;         // plain NLGS
  Stop anderson;      // solver.anderson > 0, cohesionless
  Stop subspace;      // solver.subspace > 0
  Stop cohesive;      // solver.anderson > 0, cohesive (contact.adhesion or cohesion_number > 0)
  Stop polygons;      // plain NLGS, 2D polygons (particles.nsides), cohesionless
  int auto_anderson;  // solver.anderson = "auto" (3D)
  int auto_subspace;  // solver.subspace = "auto" (3D)
  double cell_mass;   // shear.cell_mass, in the particles' total mass
};
inline constexpr std::array<ShearBand, 3> kShearBands = {{
    // Below I = 0.01, tol 1e-3 stops too early (mu* 5 % high, overlaps
    // 0.012 d at I = 1e-3) and tol 1e-4 alone hits the sweep cap on 43 % of
    // the steps; 1e-4 with the law-residual stop 3e-3 agrees with it within
    // 0.7 sigma at a third of its cost. With Anderson (and its stall rule)
    // the same stop keeps mu, phi and z within 0.5 sigma of plain NLGS's
    // over three samples at I = 1e-3, at 0.68x (1000 spheres) and 0.60x
    // (1000 disks) the CPU.
    // The subspace correction at the same stop costs what Anderson does
    // (1000 spheres, I = 1e-3, 1.00x) and leaves z 0.017 low (1.5 sigma,
    // three samples): the band's acceleration is Anderson's. Anderson at
    // tol 3e-4 without the residual stop, the overlap projection holding
    // the overlaps, keeps mu, phi and z within 0.6 sigma (spheres) and 1.2
    // sigma (disks) of plain NLGS at the residual stop, at 0.81x and 0.79x
    // the CPU of Anderson at that stop (five samples each; spheres at tol
    // 5e-4: z 5 sigma high). Cohesive scenes keep the residual stop (not
    // measured at the looser one). Polygons (plain NLGS: Anderson's mixing
    // biases their mu) take the same looser stop with the projection: 1000
    // hexagons at I = 1e-3, five samples, mu, phi and z within 0.8 sigma of
    // the residual stop at 0.50x its CPU (tol 5e-4: 0.29x, z 1.2 sigma high).
    {0.0, {1e-4, 3e-3}, {3e-4, 0.0, 0.5}, {1e-4, 3e-3}, {1e-4, 3e-3}, {3e-4, 0.0, 0.5}, 5, 0, 0.1},
    // From I = 0.01, tol 1e-3 keeps mu*, phi and z within ~2 sigma of tol
    // 1e-5 at 11-35 % of its cost; 1e-4 costs 2-4x more, not measurably
    // closer (disks). On 1000 spheres at I = 0.01 (three samples against tol
    // 1e-4 + residual_tol 3e-3), plain tol 1e-3 leaves z 0.016 high (3.7
    // sigma); Anderson at tol 5e-4 holds mu, phi and z within 1 sigma at
    // 1.4x plain tol 1e-3's CPU (7e-4: the same CPU, z 0.008 high). 1000
    // disks: within 1.2 sigma at 0.93x plain tol 1e-3's CPU. The subspace
    // correction at tol 7e-4 holds all three within 0.5 sigma at 0.57x
    // Anderson's CPU at 5e-4 (spheres, three samples, side by side).
    // Polygons (1000 hexagons at I = 0.01, five samples against plain tol
    // 1e-4 + residual_tol 3e-3): plain tol 1e-3 puts mu 2.0 sigma high with
    // overlaps of 4.5e-3 d; tol 2e-3 with the overlap projection holds mu,
    // phi and z within 1.1 sigma at 0.58x its CPU, overlaps 1.4e-3 d (tol
    // 1.5e-3: 0.72x, within 1.4 sigma). The band above 0.5 (collisional,
    // light cell) keeps plain tol 1e-3 (not measured).
    {0.01, {1e-3, 0.0}, {5e-4, 0.0}, {7e-4, 0.0}, {5e-4, 0.0}, {2e-3, 0.0, 0.5}, 0, 10, 0.1},
    // From I = 0.5 the cell height of mass 0.1 oscillates for several units
    // of strain; a light cell (0.01) holds sigma_yy + K_yy = p.
    {0.5, {1e-3, 0.0}, {5e-4, 0.0}, {7e-4, 0.0}, {5e-4, 0.0}, {1e-3, 0.0}, 0, 10, 0.01},
}};
// The time step, in t_p = d sqrt(rho/p): at most kDtMaxTp, and at most
// kSlidePerStep d of relative sliding per step, dt <= kSlidePerStep t_p / I;
// rounded to 4 significant digits, as the campaigns have always run it.
inline constexpr double kDtMaxTp = 0.05;
inline constexpr double kSlidePerStep = 0.005;

// The settings at inertial number I > 0, for a plain solve, one with
// Anderson's mixing, or one with the subspace correction (which decides the
// stop when a scene asks for both).
enum class Acceleration { None, Anderson, Subspace };
struct ShearSettings {
  double tol, residual_tol, overlap_projection;  // the stop
  double dt_tp, cell_mass;
  int anderson, subspace;  // the band's acceleration (the "auto" of those keys)
};
// The bands' acceleration is the 3D one. A cohesive 3D scene
// (contact.adhesion or contact.cohesion_number > 0) gets Anderson's mixing
// (memory kAnderson) for an "auto" acceleration in every band: the subspace
// correction cost 2.4x its CPU on a 1000-sphere sample at eta = 10,
// I = 0.01, tol 1e-3 (one run, docs/accuracy.md). A 2D scene gets Anderson's
// mixing with disks (1000 disks, three samples: 0.93x and 0.60x plain NLGS's
// CPU at I = 0.01 and 1e-3, results within 1.2 sigma) and none with polygons
// (particles.nsides with a polygon; 1000 hexagons at I = 0.01, three
// samples: 1.05x plain tol 1e-3's CPU with mu 3.3 sigma high), and never the
// subspace correction.
inline constexpr int kAnderson = 5;
struct SceneKind {
  int dimension = 3;
  bool cohesive = false;
  bool polygons = false;  // 2D: some particle is a polygon
  // 3D: the orthotropic cone (contact.mu_b or mu_wall_b >= 0), on which the
  // subspace correction does not act: "auto" gives it none (and the band's
  // Anderson choice), so its stop is the plain or Anderson column's.
  bool orthotropic = false;
  // 3D: solver.stop_rows = "loaded": the stop over the loaded rows (below).
  bool loaded_stop = false;
};
// The stops above were measured with the test over every row (solver.stop_rows
// = "all"), on sphere packings where the open rows within the alert distance
// (0.1 d) are a fixed share: 2.13 rows per loaded row at I = 1e-3 and 2.15
// at I = 0.01 (1000 spheres, averages over the runs' series). Over the loaded
// rows the same stop is tol / sqrt(2.13) (the test over n rows, rms |dp| /
// mean |p|, is sqrt(n/n_f) times the test over the n_f loaded ones: the
// open rows add nothing to either sum) and, the residual stop's scale being
// the mean |p| of the rows with an impulse (n/n_f times the mean over every
// row), residual_tol / 2.13. A scene of polyhedra, 4.6 (cubes) to 5.2
// (icosahedra) rows per loaded row at the same alert, then meets the
// spheres' accuracy over its forces (docs/3d.md, "At equal accuracy"),
// where the test over every row would hold it 1.5 times tighter. 2D scenes
// refuse it (their share is the shape's: 2.9 rows per loaded row for
// heptagons).
inline constexpr double kRowsPerLoadedRow = 2.13;
ShearSettings shear_settings(double inertial_number, Acceleration acc = Acceleration::None, SceneKind kind = {});

}  // namespace cd
