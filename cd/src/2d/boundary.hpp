// Boundary protocols (method.md section 9): what the periodic cell or the
// rough walls add to a step, behind one object chosen once per scene
// (World::configure, from CellParams::mode), so that the stages of
// world.cpp hold no test of the protocol:
//   NoBoundary       walls and gravity only (piles): every hook does nothing.
//   LeesEdwardsCell  bi-periodic cell [0, W) x [0, H); the images above slide
//                    at gamma-dot H; with a pressure the height (and, for
//                    isotropic compaction, the width) is a degree of
//                    freedom solved with the contacts (BoundaryDof).
//   WallShear        periodic in x; grains glued to the bottom wall (fixed)
//                    and to the top wall, which moves at gamma-dot x gap and
//                    whose height is a dof at the imposed pressure.
// The hooks, the same as 3D's (3d/boundary3.hpp), each called by the stage
// of World::step named after it:
//   configure         once, when the world's parameters are set
//   begin_step        before the stages (a boundary's own imposed motion)
//   predict, detect   the midpoint cell; detection through its images
//   image_velocity    the velocity of the image of body 2 that contact f
//                     touches, relative to body 2 (build: into the row's
//                     offsets, with restitution into u-); asked only for a
//                     contact through an image, and only of a boundary
//                     with `moving_images`
//   set_dofs, take_dofs   the boundary's dofs into the problem (solve), and
//                     their solved velocities back
//   integrate         the cell at the step's end
//   pseudo_dofs, apply_pseudo_dofs   the dofs in the overlap projection
//                     (unloaded, from rest) and their pseudo-displacement
//   shear_rate        the protocol's shear rate (0 without one)
#pragma once
#include <variant>
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"
#include "contact_problem.hpp"

namespace cd {

class World;

// The distance a pressure-driven boundary (the periodic cell's lengths, the
// top wall) may approach the grains by in four steps (cell_dof's
// approach_floor: a quarter of it a step): the alert distance `alert`, or
// less where the sample's smallest polygons would spin too fast for the
// midpoint's linearised gaps (boundary.cpp). Equal to `alert`, bit for bit,
// without polygons.
double boundary_approach(const Bodies& b, double alert);

// `cell`: the protocol has a cell (a volume, a kinetic stress).
// `moving_images`: periodic images move relative to the bodies (their
// velocity enters the rows that touch them).
struct NoBoundary {
  static constexpr bool cell = false, moving_images = false;
  void configure(World&) const {}
  void begin_step(World&) const {}
  void predict(World&, double /*h*/) const {}
  void detect(World& w) const;
  Vec2 image_velocity(const World&, const ContactInfo&) const { return Vec2::Zero(); }
  void set_dofs(World&) const {}
  void take_dofs(World&) const {}
  void integrate(World&, double /*h*/) const {}
  void pseudo_dofs(std::vector<BoundaryDof>& d) const { d.clear(); }
  void apply_pseudo_dofs(World&, const std::vector<BoundaryDof>&, double) const {}
  double shear_rate(const World&) const { return 0.0; }
};

struct LeesEdwardsCell {
  static constexpr bool cell = true, moving_images = true;
  void configure(World& w) const;
  void begin_step(World&) const {}
  void predict(World& w, double h) const;
  // Through the images at the midpoint offset.
  void detect(World& w) const;
  // Velocity of the image of body 2 that a contact touches, relative to
  // body 2 ((gamma-dot H, dH/dt) per cell up, (dW/dt, 0) per cell right), at
  // the step's start.
  Vec2 image_velocity(const World& w, const ContactInfo& f) const;
  void set_dofs(World& w) const;
  void take_dofs(World& w) const;
  void integrate(World& w, double h) const;
  // Overlap projection (World::project_overlaps): the cell's lengths take
  // part unloaded (free velocity 0), and their pseudo-velocities times dt
  // go into the midpoint cell.
  void pseudo_dofs(std::vector<BoundaryDof>& d) const;
  void apply_pseudo_dofs(World& w, const std::vector<BoundaryDof>& d, double dt) const;
  double shear_rate(const World& w) const;
};

struct WallShear {
  static constexpr bool cell = true, moving_images = false;
  void configure(World& w) const;
  // The shear rate, not the wall speed, is imposed: V = gamma-dot x gap.
  void begin_step(World& w) const;
  void predict(World& w, double h) const;
  // Through the images across x (the walls' grains are bodies).
  void detect(World& w) const;
  Vec2 image_velocity(const World&, const ContactInfo&) const { return Vec2::Zero(); }
  void set_dofs(World& w) const;
  void take_dofs(World& w) const;
  void integrate(World& w, double h) const;
  // Overlap projection: the top wall is held (no dof).
  void pseudo_dofs(std::vector<BoundaryDof>& d) const { d.clear(); }
  void apply_pseudo_dofs(World&, const std::vector<BoundaryDof>&, double) const {}
  double shear_rate(const World& w) const;
};

using Boundary = std::variant<NoBoundary, LeesEdwardsCell, WallShear>;

}  // namespace cd
