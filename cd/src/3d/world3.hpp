// World3: spheres and planes, per-scene settings, and the time step as the
// stage table of core/stages.hpp (the 3D sibling of 2d/world.hpp; midpoint
// Moreau-Jean scheme, method.md sections 6 and 14):
//   predict    x_m = x + dt/2 v-, q_m = exp(dt/2 w-) q (unit quaternion)
//   detect     contacts at the midpoint configuration (detect3.hpp),
//              through periodic images in a periodic cell
//   build      frames (orthotropic axes), W blocks, gap terms, image
//              velocities, restitution, friction, adhesion, warm start
//   colour     rows in colour order (core/colour_rows.hpp)
//   solve      gravity, warm start into the velocities, NLGS
//              (core/sweep.hpp through BodyCoupling3), impulses kept for
//              the next warm start
//   integrate  x+ = x_m + dt/2 v+, q+ = exp(dt/2 w+) q_m; back into a
//              periodic cell, the Lees-Edwards offset advanced
//   observe    contacts, active contacts, overlaps
// The law (frictionless, Coulomb round or orthotropic, cohesive or not, with
// or without tangential offsets) is fixed once per scene into a template
// instance of the sweep; the boundary protocol (no cell, periodic cell,
// Lees-Edwards cell: boundary3.hpp) once per scene into a Boundary3, whose
// hooks the predict, detect, build and integrate stages call. WorldParams3
// is constant during a run; what the steps change is World3's state: the
// bodies, the cell (CellState3), the warm-start memory.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "bodies3.hpp"
#include "boundary3.hpp"
#include "contact3.hpp"
#include "contact_problem3.hpp"
#include "detect3.hpp"
#include "observables.hpp"
#include "poly_rows3.hpp"
#include "solver.hpp"
#include "stages.hpp"
#include "world_shell.hpp"

namespace cd {

struct WorldParams3 {
  double dt = 1e-3;
  Vec3 gravity = Vec3::Zero();
  double mu = 0.0, mu_wall = 0.0;  // sphere-sphere; rows with a driven body 1
  double alert = 0.0;              // absolute alert distance
  // Overlap correction beta, as 2D's: an overlapping contact must separate
  // at beta |g|/dt (0: pure CD, overlaps are never pushed apart). The
  // velocity it gives persists, so it injects energy.
  double overlap_correction = 0.0;
  // Overlap projection beta_p (2D's World::overlap_projection; projection3.cpp):
  // after the solve, on steps where some overlap reaches 1e-3 of its pair's
  // smaller diameter, the midpoint positions (and the solved cell lengths)
  // move by the smallest mass-weighted displacement that opens every
  // overlap by beta_p times itself and closes no gap; velocities untouched.
  // 0: off.
  double overlap_projection = 0.0;
  // Adhesion-shifted Signorini law: pull-off force f_a on every contact
  // whose midpoint gap is <= debond (absolute); 0: none.
  double adhesion = 0.0, debond = 0.0;
  // Compliant contacts (coupling3.hpp, BodyCouplingT3): the law on u +
  // (r - r0) / (k dt^2), an implicit spring of stiffness k (N/m) on each
  // contact's displacements over a step, r0 its previous impulse (the warm
  // start); the overlap projection stays rigid. 0: rigid contacts.
  double stiffness = 0.0;
  double stiffness_ratio = 1.0;  // k_t / k (compliant contacts)
  double d_ref = 1.0;  // length scale for overlaps (mean diameter)
  SolverParams solver;

  // Restitution by mean velocities (Moreau's impact law, method.md section
  // 14): the law acts on u+ + e u-, u- the relative velocity at the start of
  // the step, with b_n += e_n min(u-_n, 0), b_t += e_t u-_t. On (e_n > 0 or
  // e_t > 0) the alert distance is 0: the law acts at effective contacts
  // (gap <= 0) only, as in 2D. 0: off, at no cost.
  double e_n = 0.0, e_t = 0.0;

  // Orthotropic Coulomb (off unless `orthotropic`): every row's t1 is
  // axis_a projected on its tangent plane (t2 = n x t1), and the cone is
  // |(s_t1/mu_a, s_t2/mu_b)| <= s_n with (mu_a, mu_b) = (mu, mu_b) between
  // spheres and (mu_wall, mu_wall_b) on walls. A tangent plane normal to
  // axis_a keeps the default frame.
  bool orthotropic = false;
  Vec3 axis_a = Vec3::UnitX();
  double mu_b = 0.0, mu_wall_b = 0.0;

  // Periodic cell (off unless some periodic[a]): along a periodic axis the
  // spheres meet the images of the others and are brought back into
  // [cell_origin, cell_origin + L) at the end of each step. Lees-Edwards
  // (periodic x and y): the images across y, at +-L_y, are shifted along x
  // by +-offset and move at +-V along x (shear along x, gradient along y);
  // a sphere brought back across y has its x and v_x shifted with them.
  // Each step advances the offset by V dt (kept in [0, L_x)). Each periodic
  // length must be >= 2 (2 r_max + alert). `cell` and `le_offset` are the
  // lengths L and the offset at construction: from there on they are the
  // world's state (World3::cell(), CellState3), which the step changes.
  // le_velocity: V, the images' velocity, unless shear_rate is set.
  Vec3 cell_origin = Vec3::Zero(), cell = Vec3::Zero();
  std::array<bool, 3> periodic{false, false, false};
  double le_offset = 0.0, le_velocity = 0.0;

  // Imposed shear rate gamma-dot (> 0): the images across y move at
  // V = gamma-dot L_y, L_y at each step's midpoint (a height that follows a
  // pressure changes it); 0: V = le_velocity.
  double shear_rate = 0.0;
  // Cell lengths at imposed stress (tri-periodic cell; method.md section 9,
  // docs/3d.md; 2D's LeesEdwardsCell in 3D): with pressure > 0 and
  // cell_mass > 0, each length L_a with cell_dof[a] is a degree of freedom
  // of mass cell_mass, solved with the contacts, driven by the imposed
  // stress: M dL_a/dt changes by (sum of the contact impulses across the
  // face normal to a) - dt (pressure - K_aa) A_a, A_a = V / L_a the face,
  // K the kinetic stress (pressure: force per area, N/m^2). Isotropic
  // compaction: all three; shear: L_y. max_strain_rate > 0: the lengths
  // shrink at most at that strain rate (the brake); whatever it is, by at
  // most a quarter of the alert distance a step (core/cell_dof.hpp).
  double pressure = 0.0, cell_mass = 0.0, max_strain_rate = 0.0;
  std::array<bool, 3> cell_dof{false, false, false};
};

// The periodic cell's state, what the steps change (checkpointed, "3d.cell";
// 2D's CellState): the lengths L, the Lees-Edwards offset (in [0, L_x)),
// the rates dL/dt of the lengths at imposed stress, and the shear strain
// sum dt gamma-dot. All 0 without a cell.
struct CellState3 {
  Vec3 size = Vec3::Zero();
  double le_offset = 0.0;
  Vec3 rate = Vec3::Zero();
  double strain = 0.0;
};

// Polyhedra (bodies of Shape3::Polyhedron, alone or with spheres, and
// planes): detect adds the narrow phase of poly_rows3.hpp
// (the candidates' points), build takes every body's world inverse inertia
// at the midpoint orientation (ContactProblem3::inv_inertia; the solver
// then sweeps block rows, block_coupling3.hpp), and solve gives each
// polyhedron its free angular velocity with the gyroscopic torque by the
// implicit midpoint rule before the contacts (rigid_rotation.hpp). The
// warm start is then the pair memory of poly_rows3.hpp in place of the
// shell's. Checkpoints and problem dumps hold them (checkpoint3.hpp,
// dump3.hpp); the compliant law refuses them.
//
// The shell (bodies, clock, timers, the last step's problem and records,
// solver slot, warm-start memory, colour stage) is core/world_shell.hpp's,
// shared with the 2D World. The warm-start memory holds the impulses in the
// world frame, on body 2: re-projected on the new frame when reused, so
// that a turning frame does not rotate the remembered friction.
// The periodic cell of parameters p (origin, periodic axes) with lengths
// `size` at the Lees-Edwards offset `offset`.
PeriodicCell3 periodic_cell3(const WorldParams3& p, double offset, const Vec3& size);

class World3 : public WorldShell<Bodies3, ContactProblem3, ContactInfo3, Vec3> {
 public:
  // The cell starts from the parameters' lengths and offset, at rest.
  explicit World3(const WorldParams3& p) : prm_(p), cell_{p.cell, p.le_offset} { configure(); }

  // The parameters are constant during the run; set_params replaces them
  // (a study's or a test's change), the cell's state kept.
  const WorldParams3& params() const { return prm_; }
  void set_params(const WorldParams3& p) {
    prm_ = p;
    configure();
  }
  // The periodic cell's state; set_cell replaces it (a checkpoint, a start
  // sample), checked against the parameters as at construction (throws
  // std::invalid_argument).
  const CellState3& cell() const { return cell_; }
  void set_cell(const CellState3& c) {
    cell_ = c;
    configure();
  }

  void step();
  // The last step's row extras, in colour order (empty unless the scene
  // has tangential offsets or an orthotropic cone).
  const std::vector<RowExtra3>& row_extras() const { return prob_.extra; }

  // The polyhedra's warm-start memory (empty in scenes of spheres).
  const PolyMemory3& polyhedra_memory() const { return poly_memory_; }
  void set_polyhedra_memory(PolyMemory3 m) { poly_memory_ = std::move(m); }

  double kinetic_energy() const;    // translational + rotational, dynamic bodies
  // Sum of m x v + I_w w over the dynamic bodies, about the origin.
  Vec3 angular_momentum() const;
  double potential_energy() const;  // -m g.x summed over dynamic bodies

  // Observables of the last step (method.md section 10, core/observables.hpp).
  // The rows as obs::Contact<3>: force r/dt on body 2 (world frame), branch
  // vector from the centre of body 1 to the centre of the image of body 2
  // that is touched (a plane's: to the sphere's foot).
  std::vector<obs::Contact<3>> contact_forces() const;
  // L_x L_y L_z of a tri-periodic cell; 0 unless x, y and z are all periodic.
  double cell_volume() const;
  // Shear rate of the Lees-Edwards cell: WorldParams3::shear_rate if set,
  // else le_velocity / L_y (0 without).
  double shear_rate() const;
  // The Lees-Edwards images' velocity V along x of the last step
  // (gamma-dot L_y at its midpoint, or WorldParams3::le_velocity).
  double le_velocity() const { return le_velocity_; }
  // The cell lengths solved at imposed stress (pressure, cell_mass and some
  // cell_dof set).
  bool cell_dofs() const { return dofs_on_; }
  // Contact stress sigma_ij = (1/V) sum_c f_i l_j, compression positive;
  // V = cell_volume() unless volume > 0 (no volume at all: stress times V).
  Eigen::Matrix3d contact_stress(double volume = 0.0) const;
  // Kinetic stress (1/V) sum m u u^T over dynamic bodies, u = v - gd y e_x
  // minus its mass mean (gd = shear_rate(): the mean shear flow removed);
  // zero without a tri-periodic cell.
  Eigen::Matrix3d kinetic_stress() const;

 private:
  friend struct NoBoundary3;
  friend struct CellDofs3;
  friend struct Cell3;
  friend struct LeesEdwardsCell3;
  void configure();
  void predict();
  void detect_stage();
  void build();
  void colour();
  void solve();
  void integrate();
  void observe();
  void project_overlaps();
  void free_rotations();
  struct Projection;  // its adaptor (projection3.cpp)

  template <class B>
  void build_rows(const B& b);
  PeriodicCell3 cell_at(double offset, const Vec3& size) const;
  void wrap_into_cell(double offset);
  void set_dofs(const Eigen::Matrix3d& K);

  WorldParams3 prm_;
  CellState3 cell_;
  Boundary3 boundary_;
  // dofs_on_: the cell's lengths at imposed stress (a Cell3's or a
  // LeesEdwardsCell3's).
  bool gravity_on_ = false, adhesion_on_ = false, restitution_on_ = false, extras_on_ = false,
       dofs_on_ = false, friction_on_ = false;
  double alert_ = 0.0;
  double le_velocity_ = 0.0;  // V of the step (LeesEdwardsCell3)
  bool poly_ = false;  // the bodies hold polyhedra (set at each step's predict)
  PolyMemory3 poly_memory_;
  std::vector<PolyPairAxis3> poly_axes_;
  std::vector<Vec3> xm_;
  std::vector<Quat> qm_;
  ContactProblem3 proj_;  // project_overlaps' pseudo-velocity problem
  CellGrid3 grid_;
  Vec3 cm_ = Vec3::Zero();  // the cell's lengths at the step's midpoint
};

}  // namespace cd
