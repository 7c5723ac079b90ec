// Boundary protocols in 3D (method.md section 9; the sibling of 2D's
// boundary.hpp): what a periodic cell adds to a step, behind one object
// chosen once per scene (World3::configure, from the periodic axes, the
// Lees-Edwards keys and the cell's offset), so that the stages of
// world3.cpp hold no test of the protocol:
//   NoBoundary3       planes and gravity only (piles): no image, no cell.
//   Cell3             periodic along some axes, the images still; with the
//                     lengths at imposed stress (tri-periodic, CellDof3) the
//                     images across face a move at dL_a/dt (isotropic
//                     compaction).
//   LeesEdwardsCell3  periodic x and y: the images across y shifted along x
//                     by the offset and sliding at V (gamma-dot L_y, or
//                     WorldParams3::le_velocity); lengths at imposed stress
//                     as in Cell3 (shear at imposed pressure: L_y).
// The cell's evolving state (lengths, offset, rates, strain) is World3's
// (CellState3); these objects hold none. Each hook is called by the stage
// of World3::step named after it.
#pragma once
#include <variant>
#include <vector>

#include "contact3.hpp"
#include "contact_problem3.hpp"

namespace cd {

class World3;

// The hooks, the same as 2D's (2d/boundary.hpp), each called by the stage
// of World3::step named after it:
//   configure         once, when the world's parameters are set
//   begin_step        before the stages (a boundary's own imposed motion)
//   predict, detect   the midpoint cell; detection through its images
//   image_velocity    the velocity of the image of body 2 that contact f
//                     touches, relative to body 2 (build: into the row's
//                     offsets, with restitution into u-); asked only for a
//                     contact through an image, and only of a boundary
//                     with `moving_images`
//   set_dofs, take_dofs   the cell's lengths at imposed stress into the
//                     problem (solve), and their solved rates back
//   integrate         the cell at the step's end
//   pseudo_dofs, apply_pseudo_dofs   the lengths in the overlap projection
//                     (unloaded, from rest) and their pseudo-displacement
//   shear_rate        the cell's shear rate (0 without one)
// `cell`: the protocol has a cell (a volume, a kinetic stress);
// `moving_images`: its images may move relative to the bodies.
struct NoBoundary3 {
  static constexpr bool cell = false, moving_images = false;
  void configure(World3&) const {}
  void begin_step(World3&) const {}
  void predict(World3&, double /*h*/) const {}
  void detect(World3& w) const;
  Vec3 image_velocity(const World3&, const ContactInfo3&) const { return Vec3::Zero(); }
  void set_dofs(World3&) const {}
  void take_dofs(World3&) const {}
  void integrate(World3&, double /*h*/) const {}
  void pseudo_dofs(std::vector<CellDof3>& d) const { d.clear(); }
  void apply_pseudo_dofs(World3&, const std::vector<CellDof3>&, double) const {}
  double shear_rate(const World3&) const { return 0.0; }
};

// The lengths at imposed stress (both cells): their dofs, rates and
// pseudo-dofs, and the velocity of a moving image.
struct CellDofs3 {
  void set_dofs(World3& w) const;
  void take_dofs(World3& w) const;
  void pseudo_dofs(std::vector<CellDof3>& d) const;
  void apply_pseudo_dofs(World3& w, const std::vector<CellDof3>& d, double dt) const;

 protected:
  // The image across y moves at iy V e_x more than body 2, and across each
  // face a by i_a dL_a/dt e_a (the rates at the step's start).
  static Vec3 moving_image(const World3& w, const ContactInfo3& f);
};

struct Cell3 : CellDofs3 {
  static constexpr bool cell = true, moving_images = true;
  void configure(World3&) const {}
  void begin_step(World3&) const {}
  // The midpoint lengths; spheres placed outside are brought in.
  void predict(World3& w, double h) const;
  void detect(World3& w) const;
  // With the lengths at imposed stress, the image across face a moves at
  // i_a dL_a/dt e_a (the rates at the step's start); still otherwise.
  Vec3 image_velocity(const World3& w, const ContactInfo3& f) const;
  // The lengths at the step's end; spheres back into the cell.
  void integrate(World3& w, double h) const;
  double shear_rate(const World3&) const { return 0.0; }
};

struct LeesEdwardsCell3 : CellDofs3 {
  static constexpr bool cell = true, moving_images = true;
  void configure(World3&) const {}
  void begin_step(World3&) const {}
  // As Cell3's, and the images' velocity V of the step (from the midpoint
  // L_y at an imposed shear rate).
  void predict(World3& w, double h) const;
  // Through the images at the midpoint offset.
  void detect(World3& w) const;
  // Across y the image moves at iy V e_x more than body 2, and as Cell3's
  // with the lengths at imposed stress.
  Vec3 image_velocity(const World3& w, const ContactInfo3& f) const;
  // As Cell3's, and the offset and the strain advanced.
  void integrate(World3& w, double h) const;
  // WorldParams3::shear_rate if set, else V / L_y.
  double shear_rate(const World3& w) const;
};

using Boundary3 = std::variant<NoBoundary3, Cell3, LeesEdwardsCell3>;

}  // namespace cd
