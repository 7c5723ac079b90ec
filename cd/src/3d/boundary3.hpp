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

#include "contact3.hpp"

namespace cd {

class World3;

// `cell`: the protocol has a cell (a volume, a kinetic stress). With
// `moving_images`, image_moves(f, dofs) tells whether the image of body 2
// that contact f touches moves relative to body 2 (`dofs`: the lengths are
// at imposed stress); its velocity enters the row (World3::build).
struct NoBoundary3 {
  static constexpr bool cell = false, moving_images = false;
  void predict(World3&, double /*h*/) const {}
  void detect(World3& w) const;
  static bool image_moves(const ContactInfo3&, bool) { return false; }
  void integrate(World3&, double /*h*/) const {}
  double shear_rate(const World3&) const { return 0.0; }
};

struct Cell3 {
  static constexpr bool cell = true, moving_images = true;
  // The midpoint lengths; spheres placed outside are brought in.
  void predict(World3& w, double h) const;
  void detect(World3& w) const;
  static bool image_moves(const ContactInfo3& f, bool dofs) {
    return dofs && (f.ix != 0 || f.iy != 0 || f.iz != 0);
  }
  // The lengths at the step's end; spheres back into the cell.
  void integrate(World3& w, double h) const;
  double shear_rate(const World3&) const { return 0.0; }
};

struct LeesEdwardsCell3 {
  static constexpr bool cell = true, moving_images = true;
  // As Cell3's, and the images' velocity V of the step (from the midpoint
  // L_y at an imposed shear rate).
  void predict(World3& w, double h) const;
  // Through the images at the midpoint offset.
  void detect(World3& w) const;
  static bool image_moves(const ContactInfo3& f, bool dofs) {
    return f.iy != 0 || (dofs && (f.ix != 0 || f.iz != 0));
  }
  // As Cell3's, and the offset and the strain advanced.
  void integrate(World3& w, double h) const;
  // WorldParams3::shear_rate if set, else V / L_y.
  double shear_rate(const World3& w) const;
};

using Boundary3 = std::variant<NoBoundary3, Cell3, LeesEdwardsCell3>;

}  // namespace cd
