#include "boundary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "cell_dof.hpp"
#include "world.hpp"

namespace cd {

namespace {

// The midpoint cell and its periodic view for detection.
void midpoint_cell(CellState& cm, PeriodicCell& pc, const CellState& cell, double h) {
  cm = cell;
  cm.height += h * cell.hdot;
  cm.width += h * cell.wdot;
  pc.width = cm.width;
  pc.height = cm.height;
  pc.offset = cm.offset;
}

}  // namespace

// A grain the boundary pushes moves at up to about its speed, s a step (a
// quarter of the approach distance), and a polygon of circumradius R hit
// near a corner spins by up to about s / R a step (measured: 0.10 rad at s
// / R = 0.096, a triangle of the ratio-5 mixture of make prep-overlap,
// N = 1000). A side turning by theta a step carries what rests on it into
// the side by l theta^2 / 2, l the distance from the polygon's centre to
// the contact along the side's normal: its apothem a, plus the radius of a
// disk lying on it. The gap the solve sees, linearised at the midpoint, does
// not: that triangle, at 2 / t_p, with a disk 3.6 times its size on a side
// (l = 1.07 mm), overlapped by 0.0103 of its size 2R a step (l theta^2 /
// 2 = 0.0054 mm), 0.0134 at most with the projection opening half of it a
// step. So s <= R sqrt(4 eps R / (a + r_disk)) keeps that closure below eps
// = 2.5e-3 of 2R a step, for the smallest polygon against the largest
// disk; the projection then holds the overlap below 2 eps, half of the 1 %
// of the smaller grain cdsim warns at. Disks do not need it (a turning
// disk presents the same surface): without polygons the approach distance
// is the alert distance. Polygons among themselves (l = a) need s <= 0.10
// to 0.14 R, a quarter of an alert distance of 0.1 d_mean once R >= 0.18 to
// 0.25 d_mean. Halving dt would not do: the approach floor is per step, so
// s / R, the spin a step, stays (measured: the N = 1000 mixture at dt / 2
// still reached 0.0095).
double boundary_approach(const Bodies& b, double alert) {
  constexpr double kEps = 2.5e-3;
  double r_disk = 0.0;
  for (std::size_t i = 0; i < b.size(); ++i)
    if (b.shape[i] == Shape::Disk) r_disk = std::max(r_disk, b.radius[i]);
  double s = 0.25 * alert;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.shape[i] != Shape::Polygon) continue;
    const double R = b.radius[i], a = R * std::cos(std::numbers::pi / b.nsides[i]);
    s = std::min(s, R * std::sqrt(4.0 * kEps * R / (a + r_disk)));
  }
  return 4.0 * s;
}

// ---- no cell ------------------------------------------------------------

void NoBoundary::detect(World& w) const { w.detect_through(nullptr); }

// ---- Lees-Edwards cell --------------------------------------------------

void LeesEdwardsCell::configure(World& w) const {
  w.pc_.x = true;
  w.pc_.y = true;
  if (w.cell.width <= 0.0) w.cell.width = w.prm_.cell.width;
}

void LeesEdwardsCell::predict(World& w, double h) const {
  midpoint_cell(w.cm_, w.pc_, w.cell, h);
  CellState& cm = w.cm_;
  cm.offset = std::fmod(w.cell.offset + h * w.prm_.cell.shear_rate * w.cell.height, cm.width);
  if (cm.offset < 0) cm.offset += cm.width;
  w.pc_.offset = cm.offset;
}

Vec2 LeesEdwardsCell::image_velocity(const World& w, const ContactInfo& f) const {
  return {f.iy * w.prm_.cell.shear_rate * w.cm_.height + f.ix * w.cell.wdot, f.iy * w.cell.hdot};
}

void LeesEdwardsCell::detect(World& w) const { w.detect_through(&w.pc_); }

double LeesEdwardsCell::shear_rate(const World& w) const { return w.prm_.cell.shear_rate; }

void LeesEdwardsCell::set_dofs(World& w) const {
  // One dof per controlled length: its velocity at the start of the step
  // (already in the rows' offsets), and v0 with the imposed stress's
  // impulse; the offsets get the difference.
  auto& dofs = w.prob_.dofs;
  dofs.clear();
  const CellParams& c = w.prm_.cell;
  if (c.pressure <= 0.0 || c.mass <= 0.0) return;
  // The imposed stress balances the whole normal stress: the height sees
  // only the contacts that cross the boundary, so the kinetic stress (the
  // momentum grains carry through it, relabelled by the periodicity) is
  // taken off the load, from the velocities at the start of the step.
  // Dense flows: K_yy << p, no change; collisional flows (I >~ 0.5): without
  // it the contact stress alone held p, and sigma_yy + K_yy overshot it.
  const Eigen::Matrix2d K = w.kinetic_stress();
  const CellState& cm = w.cm_;
  const CellState& cell = w.cell;
  // The free velocity of a length L is bounded below by a quarter of the
  // approach distance a step (the scene's alert distance, or less with
  // small polygons: boundary_approach), always: the images then approach the
  // grains across the boundary by well under the alert distance in a step,
  // so those contacts are detected before they close, and the grains they
  // hit move (and spin) no faster, whatever the cell's size. With
  // max_strain_rate, also by -max_strain_rate L (a controlled compaction
  // rate).
  const double rate = c.max_strain_rate;
  const auto floor = [&](double L) { return cell_dof::floor(rate, L, w.approach_, w.prm_.dt); };
  dofs.push_back(w.make_dof(cell.hdot, (c.pressure - K(1, 1)) * cm.width, cm.width, floor(cm.height)));
  if (c.isotropic)
    dofs.push_back(w.make_dof(cell.wdot, (c.pressure - K(0, 0)) * cm.height, cm.height, floor(cm.width)));
  for (std::size_t k = 0; k < w.prob_.rows.size(); ++k) {
    const ContactInfo& f = w.info_[k];
    const ContactRow& r = w.prob_.rows[k];
    if (f.iy != 0) w.couple_dof(dofs[0], k, f.iy * r.ny, f.iy * r.nx, cell.hdot);
    if (f.ix != 0 && c.isotropic) w.couple_dof(dofs[1], k, f.ix * r.nx, -f.ix * r.ny, cell.wdot);
  }
}

void LeesEdwardsCell::take_dofs(World& w) const {
  const auto& dofs = w.prob_.dofs;
  if (dofs.empty()) return;
  w.cell.hdot = dofs[0].v;
  if (dofs.size() > 1) w.cell.wdot = dofs[1].v;
}

void LeesEdwardsCell::integrate(World& w, double h) const {
  CellState& cell = w.cell;
  const CellState& cm = w.cm_;
  const double gd = w.shear_rate(), dt = w.prm_.dt;
  cell.height = cm.height + h * cell.hdot;
  cell.width = cm.width + h * cell.wdot;
  cell.strain += dt * gd;
  cell.offset = std::fmod(cell.offset + dt * w.prm_.cell.shear_rate * cm.height, cell.width);
  if (cell.offset < 0) cell.offset += cell.width;

  // Bodies back into the cell.
  Bodies& bodies = w.bodies;
  const double W = cell.width, H = cell.height;
  const double vs = w.prm_.cell.shear_rate * H;
  // Momentum the crossings' dH/dt and dW/dt parts give the sample, and its mass.
  double px = 0.0, py = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies.shape[i] == Shape::Segment) continue;
    Vec2& x = bodies.pos[i];
    // A body leaving through the top comes back through the bottom as its
    // own Lees-Edwards image: shifted back by the offset, and slower by the
    // images' velocity. Likewise through a side: the images there move at
    // dW/dt (build), so the body comes back slower by it.
    BodyVel& v = bodies.vel[i];
    const double m = bodies.mass[i];
    while (x.y() >= H) {
      x.y() -= H;
      x.x() -= cell.offset;
      v.vx -= vs;
      v.vy -= cell.hdot;
      py -= m * cell.hdot;
    }
    while (x.y() < 0.0) {
      x.y() += H;
      x.x() += cell.offset;
      v.vx += vs;
      v.vy += cell.hdot;
      py += m * cell.hdot;
    }
    const double k = std::floor(x.x() / W);
    x.x() -= W * k;
    v.vx -= k * cell.wdot;
    px -= k * m * cell.wdot;
    mass += m;
  }
  // The bottom and left edges are fixed, so a changing cell sweeps bodies
  // through the top and right only, and the rates' parts above would add
  // up to a drift of the whole sample (measured: 0.7 sqrt(p/rho) after an
  // isotropic compaction of 150 disks, all of the kinetic energy of the
  // jammed sample; the drift then streams the sample through the
  // Lees-Edwards boundary, and its mean vx falls at gamma-dot times that
  // drift). A uniform velocity is a symmetry of the periodic cell (no
  // walls, no gravity: relative velocities, the contacts and the cell's
  // dofs do not see it), so remove it: the contacts and the cell rates
  // conserve the sample's momentum. (The gamma-dot H part is the usual
  // Lees-Edwards one, kept.)
  if (mass > 0.0 && (px != 0.0 || py != 0.0)) {
    const double ux = px / mass, uy = py / mass;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!bodies.is_dynamic(i)) continue;
      bodies.vel[i].vx -= ux;
      bodies.vel[i].vy -= uy;
    }
  }
}

void LeesEdwardsCell::pseudo_dofs(std::vector<BoundaryDof>& dofs) const {
  for (BoundaryDof& d : dofs) d.v0 = d.v = 0.0;
}

void LeesEdwardsCell::apply_pseudo_dofs(World& w, const std::vector<BoundaryDof>& dofs,
                                        double dt) const {
  if (dofs.empty()) return;
  w.cm_.height += dt * dofs[0].v;
  if (dofs.size() > 1) w.cm_.width += dt * dofs[1].v;
}

// ---- wall-driven shear --------------------------------------------------

void WallShear::configure(World& w) const {
  w.pc_.x = true;
  w.pc_.y = false;
  if (w.cell.width <= 0.0) w.cell.width = w.prm_.cell.width;
}

void WallShear::begin_step(World& w) const {
  const double v = w.prm_.cell.shear_rate * w.cell.height;
  for (const std::int32_t i : w.top_wall) w.bodies.vel[i].vx = v;
}

void WallShear::predict(World& w, double h) const {
  midpoint_cell(w.cm_, w.pc_, w.cell, h);
}

void WallShear::detect(World& w) const { w.detect_through(&w.pc_); }

double WallShear::shear_rate(const World& w) const { return w.prm_.cell.shear_rate; }

void WallShear::set_dofs(World& w) const {
  // The top wall's height: its velocity at the start of the step is in the
  // top bodies' velocities; v0 holds the imposed stress's impulse and the
  // offsets get the difference.
  auto& dofs = w.prob_.dofs;
  dofs.clear();
  const CellParams& c = w.prm_.cell;
  if (c.pressure <= 0.0 || c.mass <= 0.0) return;
  // The wall falls by at most a quarter of the alert distance a step (a
  // bound on the free velocity the pressure gives it): its grains come
  // within the alert distance of the sample's a step or more before they
  // touch, so those contacts are detected before they close. Unbounded, it
  // fell onto a loose sample at p W / M the whole gap: configs/shear-walls.toml's
  // wall landed at 0.13 d a step (the alert distance is 0.1 d), and from a
  // gap of 0.3 m at 1.2 d a step, a grain ending 0.82 d inside its row.
  // Dense shear moves the wall far slower; only the fall onto a loose
  // sample meets the bound. (The scene's alert distance: with restitution,
  // whose contacts are detected at touch, it bounds the overlap a landing
  // makes in a step; less with small polygons, boundary_approach.)
  dofs.push_back(w.make_dof(w.cell.hdot, c.pressure * w.cm_.width, w.cm_.width,
                            cell_dof::approach_floor(w.approach_, w.prm_.dt)));
  for (std::size_t k = 0; k < w.prob_.rows.size(); ++k) {
    const ContactRow& r = w.prob_.rows[k];
    const double s = w.on_top_[r.b2] ? 1.0 : w.on_top_[r.b1] ? -1.0 : 0.0;
    if (s != 0.0) w.couple_dof(dofs[0], k, s * r.ny, s * r.nx, w.cell.hdot);
  }
}

void WallShear::take_dofs(World& w) const {
  if (w.prob_.dofs.empty()) return;
  w.cell.hdot = w.prob_.dofs[0].v;
  for (const std::int32_t i : w.top_wall) w.bodies.vel[i].vy = w.cell.hdot;
}

void WallShear::integrate(World& w, double h) const {
  CellState& cell = w.cell;
  const CellState& cm = w.cm_;
  cell.height = cm.height + h * cell.hdot;
  cell.width = cm.width + h * cell.wdot;
  cell.strain += w.prm_.dt * w.shear_rate();
  // Periodic in x only.
  Bodies& bodies = w.bodies;
  const double W = cell.width;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies.shape[i] == Shape::Segment) continue;
    Vec2& x = bodies.pos[i];
    x.x() -= W * std::floor(x.x() / W);
  }
}

}  // namespace cd
