// World: bodies, per-scene settings, and the time step as a table of named,
// timed stages (method.md section 6, midpoint scheme; the table is in
// world.cpp, World::step):
//   predict    r_m = r + dt/2 U-, and the cell at the midpoint
//   detect     contacts at the midpoint configuration
//   build      W blocks, law offsets (gap, restitution, images), adhesion,
//              warm start
//   colour     rows in colour order (the ContactProblem's colouring)
//   solve      external impulses, warm start into the velocities, boundary
//              dofs, NLGS on the ContactProblem, impulses kept for the next
//              warm start
//   integrate  r+ = r_m + dt/2 U+, and the cell
//   observe    the step's quality figures (contacts, overlaps, work)
// Work a scene does not need is not done; the law and the boundary
// protocol (boundary.hpp) are fixed once per scene. What World shares with
// World3 (bodies, clock, solver slot, warm start, colour stage) is
// core/world_shell.hpp.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "bodies.hpp"
#include "boundary.hpp"
#include "contact.hpp"
#include "contact_problem.hpp"
#include "detect.hpp"
#include "nlgs.hpp"
#include "observables.hpp"
#include "stages.hpp"
#include "world_shell.hpp"

namespace cd {

// Boundary protocols (method.md section 9), chosen once per scene.
//   LeesEdwards  bi-periodic cell [0, width) x [0, height); the images above
//                slide at shear_rate x height; with pressure > 0 the height
//                is a degree of freedom of mass `mass` loaded by -pressure x
//                width, solved with the contacts (BoundaryDof). isotropic:
//                the width too, at sigma_xx = pressure (compaction; no shear).
//   Walls        periodic in x over `width`; the bodies listed in
//                World::top_wall move together, at the horizontal velocity
//                shear_rate x (current gap) and a vertical velocity that is
//                a degree of freedom loaded by -pressure x width.
struct CellParams {
  enum class Mode { None, LeesEdwards, Walls };
  Mode mode = Mode::None;
  double width = 0.0;
  double shear_rate = 0.0;     // gamma-dot
  double pressure = 0.0;       // imposed normal stress (N/m); 0: height fixed
  double mass = 0.0;           // mass of the height (and width) dof (kg)
  bool isotropic = false;
  // > 0 (LeesEdwards with a pressure): a length dof L (height, width) may
  // shrink at most at this strain rate, -dL/dt <= max_strain_rate L (1/s).
  // The bound acts on the dof's free velocity v0 (the imposed stress's
  // impulse): a brake on the pressure-driven collapse, which the contacts,
  // pushing the cell apart, never undo. 0: no bound on the rate. Either
  // way a length shrinks by at most a quarter of the alert distance a step
  // (core/cell_dof.hpp, approach_floor).
  double max_strain_rate = 0.0;
};

struct WorldParams {
  double dt = defaults::dt;
  Vec2 gravity{0.0, 0.0};
  double mu = 0.0, mu_wall = 0.0;
  double e_n = 0.0, e_t = 0.0;
  double alert = 0.0;     // absolute alert distance
  // Overlap correction beta: an overlapping contact must separate at
  // beta |g|/dt (0: pure CD, overlaps are never pushed apart). The velocity
  // it gives persists, so it injects energy; its work p_n beta |g|/dt, an
  // upper bound of that energy, is reported in StepStats::correction_work.
  double overlap_correction = 0.0;
  // Overlap projection beta_p: after each solve, a frictionless solve of the
  // same contacts for pseudo-velocities (split impulse) that open every
  // overlapping contact by beta_p times its midpoint overlap and close no
  // open one, the cell's lengths free; the positions (and cell) move by dt
  // times them, the velocities not at all, so it puts no kinetic energy in
  // (World::project_overlaps). Only on steps where some overlap reaches
  // 1e-3 of its pair's smaller diameter. The contact forces' work on those
  // displacements, sum f_n dt u_n, is StepStats::projection_work. 0: off.
  double overlap_projection = 0.0;
  // Adhesion-shifted Signorini law (method.md section 2): pull-off force f_a
  // on every contact whose midpoint gap is <= debond (absolute); 0: none.
  double adhesion = 0.0, debond = 0.0;
  double d_ref = 1.0;     // length scale for overlaps (mean diameter)
  bool rotation = defaults::rotation;  // bodies rotate (false: translations only, every W block without 1/I)
  CellParams cell;
  SolverParams solver;
};

// State of the periodic cell or of the wall gap; part of the checkpoint.
struct CellState {
  double width = 0.0, height = 0.0;  // Walls: height = top wall's travel from its start + gap0
  double offset = 0.0;               // Lees-Edwards offset of the images above, in [0, width)
  double hdot = 0.0, wdot = 0.0;     // rates of height and width
  double strain = 0.0;               // integral of the shear rate
};

// The shell (bodies, clock, timers, the last step's problem and records,
// solver slot, warm-start memory of (p_n, p_t), colour stage) is
// core/world_shell.hpp's, shared with World3.
class World : public WorldShell<Bodies, ContactProblem, ContactInfo, std::pair<double, double>> {
 public:
  explicit World(const WorldParams& p) : prm_(p) { configure(); }

  const WorldParams& params() const { return prm_; }
  // Re-reads the parameters (call after changing them).
  void set_params(const WorldParams& p) {
    prm_ = p;
    configure();
  }

  void step();
  const LocalLaw& law() const { return prob_.law; }

  // Periodic cell (LeesEdwards) or gap between the walls (Walls).
  CellState cell;
  // Walls mode: the bodies glued to the top wall (driven, moved together).
  std::vector<std::int32_t> top_wall;

  // The last step's contacts as forces (impulses / dt) on body 2, with
  // their normals and branch vectors (midpoint configuration), in row
  // order: what observables.hpp measures, and what contacts_NNNNN.vtp holds.
  std::vector<obs::Contact<2>> contact_forces() const;
  // Contact stress of the last step, obs::contact_stress (method.md section
  // 10): sigma_ij = (1/V) sum_c f_i l_j, f the force on body 2, l the branch
  // vector from body 1; compression positive. V: `volume` if given, else the
  // cell area at the midpoint (LeesEdwards, Walls); neither: the sum itself
  // (stress times V).
  Eigen::Matrix2d contact_stress(double volume = 0.0) const;
  double cell_volume() const { return cm_.width * cm_.height; }  // midpoint cell area
  // Kinetic stress (1/V) sum m v' v'^T over dynamic bodies, v' the velocity
  // less the mean shear flow (gamma-dot y, 0) and the mean of the rest;
  // V the cell area. Zero without a cell.
  Eigen::Matrix2d kinetic_stress() const;
  // Imposed shear rate of the protocol (0 without one).
  double shear_rate() const;

  double kinetic_energy() const;
  double potential_energy() const;  // -m g.r summed over dynamic bodies

  // Status of a solved row: open, stick or slide.
  ContactStatus status(std::size_t k) const;

 private:
  friend struct NoBoundary;
  friend struct LeesEdwardsCell;
  friend struct WallShear;
  void configure();
  // The stages (world.cpp's table).
  void predict();
  void detect_stage();
  void build();
  void colour();
  void solve();
  void integrate();
  void observe();
  void external();
  // Detection at the midpoint, through the periodic cell c (null: none).
  void detect_through(const PeriodicCell* c);
  // The images' velocity into the offsets of the rows that touch them.
  template <class B>
  void image_offsets(const B& b);
  template <class B>
  void restitution_offsets(const B& b);
  // A boundary dof of mass cell.mass loaded by `load` (imposed stress x
  // length), at velocity v_start at the step's start; coupling row k to it.
  // v_floor: a lower bound of the dof's free velocity (max_strain_rate).
  // Sets last_.floor_held if the approach floor held the free velocity.
  BoundaryDof make_dof(double v_start, double load, double length,
                       double v_floor = -std::numeric_limits<double>::infinity());
  void project_overlaps();
  struct Projection;  // its adaptor (world.cpp)
  void couple_dof(BoundaryDof& d, std::size_t k, double an, double at, double v_start);

  WorldParams prm_;
  Boundary boundary_;
  bool gravity_on_ = false, restitution_on_ = false, adhesion_on_ = false;
  CellState cm_;           // cell at the midpoint configuration
  PeriodicCell pc_;        // its periodic view for detection (the boundary's detect)
  std::vector<std::uint8_t> on_top_;  // WallShear: body is glued to the top wall
  bool forces_on_ = false, prepared_ = false;  // forces_on_: some body has an applied force
  double alert_ = 0.0;
  // The boundaries' approach distance (boundary_approach, from the bodies at
  // the first step): a quarter of it a step at most.
  double approach_ = 0.0;
  std::vector<Vec2> xm_;
  std::vector<double> thm_;
  ContactProblem proj_;    // project_overlaps' pseudo-velocity problem
  CellGrid grid_;
};

}  // namespace cd
