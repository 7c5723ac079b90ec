#include "boundary3.hpp"

#include <cmath>

#include "world3.hpp"

namespace cd {

// ---- no cell ------------------------------------------------------------

void NoBoundary3::detect(World3& w) const {
  detect3(w.bodies, w.xm_, w.alert_, w.grid_, w.prob_.rows, w.info_, w.prm_.solver.min_parallel);
}

// ---- the lengths at imposed stress (both cells) ------------------------

Vec3 CellDofs3::moving_image(const World3& w, const ContactInfo3& f) {
  const Vec3& L = w.cell_.rate;
  return Vec3(f.iy * w.le_velocity_ + f.ix * L.x(), f.iy * L.y(), f.iz * L.z());
}

void CellDofs3::set_dofs(World3& w) const {
  if (w.dofs_on_) w.set_dofs(w.kinetic_stress());
}

void CellDofs3::take_dofs(World3& w) const {
  for (const CellDof3& d : w.prob_.dofs) w.cell_.rate[d.axis] = d.v;
}

void CellDofs3::pseudo_dofs(std::vector<CellDof3>& d) const {
  for (CellDof3& x : d) x.v0 = x.v = 0.0;
}

void CellDofs3::apply_pseudo_dofs(World3& w, const std::vector<CellDof3>& d, double dt) const {
  for (const CellDof3& x : d) w.cm_[x.axis] += dt * x.v;
}

// ---- periodic cell ----------------------------------------

void Cell3::predict(World3& w, double h) const {
  // The midpoint cell: lengths at imposed stress move at their rates.
  if (w.dofs_on_) w.cm_ = w.cell_.size + h * w.cell_.rate;
  // Spheres placed outside the cell are brought in first (the end of each
  // step keeps them in), so that image counts stay small.
  w.wrap_into_cell(0.0);
}

void Cell3::detect(World3& w) const {
  detect3(w.bodies, w.xm_, w.alert_, w.cell_at(0.0, w.cm_), w.grid_, w.prob_.rows, w.info_,
          w.prm_.solver.min_parallel);
}

Vec3 Cell3::image_velocity(const World3& w, const ContactInfo3& f) const {
  return w.dofs_on_ ? moving_image(w, f) : Vec3::Zero();
}

void Cell3::integrate(World3& w, double h) const {
  if (w.dofs_on_) w.cell_.size = w.cm_ + h * w.cell_.rate;
  w.wrap_into_cell(0.0);
}

// ---- Lees-Edwards cell --------------------------------------------------

void LeesEdwardsCell3::predict(World3& w, double h) const {
  if (w.dofs_on_) w.cm_ = w.cell_.size + h * w.cell_.rate;
  // An imposed shear rate sets the images' velocity from the midpoint height.
  if (w.prm_.shear_rate != 0.0) w.le_velocity_ = w.prm_.shear_rate * w.cm_.y();
  w.wrap_into_cell(w.cell_.le_offset);
}

void LeesEdwardsCell3::detect(World3& w) const {
  detect3(w.bodies, w.xm_, w.alert_, w.cell_at(w.cell_.le_offset + 0.5 * w.prm_.dt * w.le_velocity_, w.cm_),
          w.grid_, w.prob_.rows, w.info_, w.prm_.solver.min_parallel);
}

Vec3 LeesEdwardsCell3::image_velocity(const World3& w, const ContactInfo3& f) const {
  return f.iy != 0 || w.dofs_on_ ? moving_image(w, f) : Vec3::Zero();
}

void LeesEdwardsCell3::integrate(World3& w, double h) const {
  CellState3& c = w.cell_;
  if (w.dofs_on_) c.size = w.cm_ + h * c.rate;
  c.strain += w.prm_.dt * shear_rate(w);
  double off = c.le_offset + w.prm_.dt * w.le_velocity_;
  off -= c.size.x() * std::floor(off / c.size.x());
  w.wrap_into_cell(off);
  c.le_offset = off;
}

double LeesEdwardsCell3::shear_rate(const World3& w) const {
  return w.prm_.shear_rate != 0.0 ? w.prm_.shear_rate : w.le_velocity_ / w.cell_.size.y();
}

}  // namespace cd
