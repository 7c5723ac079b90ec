#include "world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace cd {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

void World::configure() {
  gravity_on_ = prm_.gravity.squaredNorm() > 0.0;
  restitution_on_ = prm_.e_n > 0.0 || prm_.e_t > 0.0;
  // With restitution the law acts at effective contacts only (gap <= 0), as in
  // Moreau's impact law: a predictive gap term would stop a body at the
  // contact with a small velocity and the impact speed would be lost.
  // Without restitution, contacts within the alert distance enter the solver
  // with the gap term u_n + g_m/dt >= 0, which closes gaps without overlap.
  alert_ = restitution_on_ ? 0.0 : prm_.alert;
  // Cohesive scenes only: contacts up to the debonding distance pull with
  // f_a (no bond history: a pair within debond of each other is bonded).
  adhesion_on_ = prm_.adhesion > 0.0;
  prob_.law = choose_law(prm_.mu > 0.0 || prm_.mu_wall > 0.0, adhesion_on_);
  prob_.rotation = prm_.rotation;
  if (adhesion_on_) alert_ = std::max(alert_, prm_.debond);
  periodic_ = prm_.cell.mode == CellParams::Mode::LeesEdwards;
  walls_ = prm_.cell.mode == CellParams::Mode::Walls;
  pc_.x = periodic_ || walls_;
  pc_.y = periodic_;
  if ((periodic_ || walls_) && cell.width <= 0.0) cell.width = prm_.cell.width;
  prepared_ = false;
}

void World::step() {
  if (!prepared_) {  // per-scene choices that depend on the bodies
    forces_on_ = std::any_of(bodies.force.begin(), bodies.force.end(),
                             [](const Vec2& f) { return f.squaredNorm() > 0.0; });
    on_top_.assign(walls_ ? bodies.size() : 0, 0);
    for (const std::int32_t i : top_wall) on_top_[i] = 1;
    prepared_ = true;
  }
  if (walls_) {  // the shear rate, not the wall speed, is imposed: V = gamma-dot x gap
    const double v = prm_.cell.shear_rate * cell.height;
    for (const std::int32_t i : top_wall) bodies.vel[i].vx = v;
  }
  auto t0 = Clock::now();
  predict();
  detect_stage();
  build();
  times.detect += since(t0);

  t0 = Clock::now();
  solve();
  times.solve += since(t0);

  t0 = Clock::now();
  integrate();
  times.integrate += since(t0);
  ++steps;
  time = static_cast<double>(steps) * prm_.dt;  // not a running sum: no drift
}

void World::predict() {
  const std::size_t n = bodies.size();
  const double h = 0.5 * prm_.dt;
  xm_.resize(n);
  thm_.resize(n);
  // Per-body and per-row loops with no reduction run in parallel above
  // the solver's threshold: each element is written once, so the result is
  // the same for any thread count.
  const bool par = static_cast<int>(n) >= prm_.solver.min_parallel / 2;
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t i = 0; i < n; ++i) {
    const BodyVel& v = bodies.vel[i];
    xm_[i] = bodies.pos[i] + h * Vec2(v.vx, v.vy);
    thm_[i] = bodies.angle[i] + h * v.w;
  }
  if (periodic_ || walls_) {
    cm_ = cell;
    cm_.height += h * cell.hdot;
    cm_.width += h * cell.wdot;
    if (periodic_) {
      cm_.offset = std::fmod(cell.offset + h * prm_.cell.shear_rate * cell.height, cm_.width);
      if (cm_.offset < 0) cm_.offset += cm_.width;
    }
    pc_.width = cm_.width;
    pc_.height = cm_.height;
    pc_.offset = cm_.offset;
  }
}

void World::detect_stage() {
  detect(bodies, xm_, thm_, alert_, grid_, prob_.rows, info_, (periodic_ || walls_) ? &pc_ : nullptr);
}

void World::build() {
  const double dt = prm_.dt;
  const bool rot = prm_.rotation;
  const auto& V = bodies.vel;
  const std::size_t nr = prob_.rows.size();
  const bool par = static_cast<int>(nr) >= prm_.solver.min_parallel;
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t k = 0; k < nr; ++k) {
    ContactRow& r = prob_.rows[k];
    set_block(r, V[r.b1], V[r.b2], rot);
    r.mu = bodies.driven[r.b1] ? prm_.mu_wall : prm_.mu;
    const double gap = info_[k].gap;
    // Gap term u_n + g_m/dt >= 0 for an open candidate (g_m > 0): the next
    // midpoint gap is g_m + dt u+_n >= 0. (With 2 g_m/dt the end-of-step gap
    // would be >= 0 but the next midpoint, half a step on, could overlap by
    // g_m; measured: overlaps of 0.07 d in the default scene.)
    r.bn = gap > 0.0 ? gap / dt : prm_.overlap_correction * gap / dt;
    r.bt = 0.0;
  }
  if (periodic_) {
    // Lees-Edwards: the image of body 2 across the top moves at (gamma-dot
    // H, dH/dt) relative to body 2, across a side at (dW/dt, 0).
    for (std::size_t k = 0; k < nr; ++k) {
      if (info_[k].ix == 0 && info_[k].iy == 0) continue;
      ContactRow& r = prob_.rows[k];
      const Vec2 v = image_velocity(info_[k]);
      r.bn += r.nx * v.x() + r.ny * v.y();
      r.bt += -r.ny * v.x() + r.nx * v.y();
    }
  }
  if (adhesion_on_) {
    const double a = prm_.adhesion * dt;
    for (std::size_t k = 0; k < nr; ++k) prob_.rows[k].adh = info_[k].gap <= prm_.debond ? a : 0.0;
  }
  if (restitution_on_) {
    // Law on u+ + e u-, with u- the relative velocity at the start of the
    // step (before external forces) in the midpoint frame. Only approaching
    // normal velocities are restituted. (bn, bt so far hold only the gap
    // term and the periodic images' velocity: that velocity is part of u-.)
    for (std::size_t k = 0; k < nr; ++k) {
      ContactRow& r = prob_.rows[k];
      double un, ut;
      row_velocity(r, V, rot, un, ut);
      if (periodic_ && (info_[k].ix != 0 || info_[k].iy != 0)) {
        const Vec2 v = image_velocity(info_[k]);
        un += r.nx * v.x() + r.ny * v.y();
        ut += -r.ny * v.x() + r.nx * v.y();
      }
      r.bn += prm_.e_n * std::min(un, 0.0);
      r.bt += prm_.e_t * ut;
    }
  }
  // Warm start from the previous step's impulses, matched by contact key.
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t k = 0; k < nr; ++k) {
    const auto it = std::lower_bound(warm_.keys.begin(), warm_.keys.end(), info_[k].key);
    if (it != warm_.keys.end() && *it == info_[k].key) {
      const auto& p = warm_.p[it - warm_.keys.begin()];
      prob_.rows[k].pn = p.first;
      prob_.rows[k].pt = p.second;
    }
  }
}

void World::external() {
  const Vec2 dv = prm_.dt * prm_.gravity;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    Vec2 d = dv;
    if (forces_on_) d += prm_.dt * bodies.vel[i].inv_m * bodies.force[i];
    bodies.vel[i].vx += d.x();
    bodies.vel[i].vy += d.y();
  }
}

void World::solve() {
  // Colour and permute rows so that each colour is contiguous.
  prob_.colouring = colour_rows(prob_.rows, bodies);
  const Colouring& col = prob_.colouring;
  {
    std::vector<ContactRow> r(prob_.rows.size());
    std::vector<ContactInfo> f(info_.size());
#pragma omp parallel for schedule(static) if (static_cast<int>(prob_.rows.size()) >= prm_.solver.min_parallel)
    for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
      r[k] = prob_.rows[col.perm[k]];
      f[k] = info_[col.perm[k]];
    }
    prob_.rows.swap(r);
    info_.swap(f);
  }
  if (gravity_on_ || forces_on_) external();
  apply_impulses(prob_.rows, bodies.vel, prm_.rotation);
  if (periodic_ || walls_) set_cell_dofs();
  // The problem takes the velocities for the solve and gives them back.
  prob_.vel.swap(bodies.vel);
  if (hook_) hook_(prob_, prm_.solver);
  last_.solve = solver_ ? solver_(prob_, prm_.solver) : nlgs_solve(prob_, prm_.solver);
  prob_.vel.swap(bodies.vel);
  if (!prob_.dofs.empty()) {
    if (periodic_) {
      cell.hdot = prob_.dofs[0].v;
      if (prob_.dofs.size() > 1) cell.wdot = prob_.dofs[1].v;
    } else {
      cell.hdot = prob_.dofs[0].v;
      for (const std::int32_t i : top_wall) bodies.vel[i].vy = cell.hdot;
    }
  }

  // Keep the impulses for the next step's warm start.
  const std::size_t nr = prob_.rows.size();
  std::vector<std::size_t> idx(nr);
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(),
            [&](std::size_t a, std::size_t b) { return info_[a].key < info_[b].key; });
  warm_.keys.resize(nr);
  warm_.p.resize(nr);
  for (std::size_t k = 0; k < nr; ++k) {
    warm_.keys[k] = info_[idx[k]].key;
    warm_.p[k] = {prob_.rows[idx[k]].pn, prob_.rows[idx[k]].pt};
  }

  // Step quality: contacts, overlaps.
  last_.contacts = static_cast<int>(nr);
  int active = 0, nover = 0;
  double omax = 0, osum = 0;
  for (std::size_t k = 0; k < nr; ++k) {
    if (prob_.rows[k].pn + prob_.rows[k].adh > 0.0) ++active;
    const double ov = -info_[k].gap;
    if (ov > 0) {
      ++nover;
      osum += ov;
      omax = std::max(omax, ov);
    }
  }
  last_.active = active;
  // Work of the overlap correction: a row with bias b_n < 0 holds u_n >= -b_n,
  // and p_n (-b_n) bounds the energy that bias puts in.
  double work = 0.0;
  if (prm_.overlap_correction > 0.0)
    for (std::size_t k = 0; k < nr; ++k)
      if (info_[k].gap < 0.0 && prob_.rows[k].bn < 0.0) work += prob_.rows[k].pn * -prob_.rows[k].bn;
  last_.correction_work = work;
  last_.max_overlap = omax / prm_.d_ref;
  last_.mean_overlap = nover ? osum / nover / prm_.d_ref : 0.0;
}

void World::integrate() {
  const double h = 0.5 * prm_.dt;
  const bool rot = prm_.rotation;
  const std::size_t n = bodies.size();
#pragma omp parallel for schedule(static) if (static_cast<int>(n) >= prm_.solver.min_parallel / 2)
  for (std::size_t i = 0; i < n; ++i) {
    const BodyVel& v = bodies.vel[i];
    bodies.pos[i] = xm_[i] + h * Vec2(v.vx, v.vy);
    if (rot || !bodies.is_dynamic(i)) bodies.angle[i] = thm_[i] + h * v.w;
  }
  if (periodic_ || walls_) {
    const double gd = shear_rate();
    cell.height = cm_.height + h * cell.hdot;
    cell.width = cm_.width + h * cell.wdot;
    cell.strain += prm_.dt * gd;
    if (periodic_) {
      cell.offset = std::fmod(cell.offset + prm_.dt * prm_.cell.shear_rate * cm_.height, cell.width);
      if (cell.offset < 0) cell.offset += cell.width;
    }
    wrap_into_cell();
  }
}

Vec2 World::image_velocity(const ContactInfo& f) const {
  return {f.iy * prm_.cell.shear_rate * cm_.height + f.ix * cell.wdot, f.iy * cell.hdot};
}

void World::set_cell_dofs() {
  // One dof per controlled length: its velocity at the start of the step
  // (already in the rows' offsets, or in the top bodies' velocities), and
  // v0 with the imposed stress's impulse; the offsets get the difference.
  const double dt = prm_.dt, P = prm_.cell.pressure, M = prm_.cell.mass;
  prob_.dofs.clear();
  if (P <= 0.0 || M <= 0.0) return;
  // load: the external force on the dof (imposed stress x length); scale:
  // the imposed impulse p x length x dt, the unit of its convergence test.
  auto make = [&](double v_start, double load, double length) {
    BoundaryDof d;
    d.inv_mass = 1.0 / M;
    d.v0 = v_start - dt * load / M;
    d.v = d.v0;
    d.scale = dt * P * length;
    return d;
  };
  const std::size_t nr = prob_.rows.size();
  auto couple = [&](BoundaryDof& d, std::size_t k, double an, double at, double v_start) {
    d.rows.push_back(static_cast<std::int32_t>(k));
    d.an.push_back(an);
    d.at.push_back(at);
    prob_.rows[k].bn += an * (d.v0 - v_start);
    prob_.rows[k].bt += at * (d.v0 - v_start);
  };
  if (periodic_) {
    // The imposed stress balances the whole normal stress: the height sees
    // only the contacts that cross the boundary, so the kinetic stress (the
    // momentum grains carry through it, relabelled by the periodicity) is
    // taken off the load, from the velocities at the start of the step.
    // Dense flows: K_yy << p, no change; collisional flows (I >~ 0.5): without
    // it the contact stress alone held p, and sigma_yy + K_yy overshot it.
    const Eigen::Matrix2d K = kinetic_stress();
    prob_.dofs.push_back(make(cell.hdot, (P - K(1, 1)) * cm_.width, cm_.width));
    if (prm_.cell.isotropic)
      prob_.dofs.push_back(make(cell.wdot, (P - K(0, 0)) * cm_.height, cm_.height));
    for (std::size_t k = 0; k < nr; ++k) {
      const ContactInfo& f = info_[k];
      const ContactRow& r = prob_.rows[k];
      if (f.iy != 0) couple(prob_.dofs[0], k, f.iy * r.ny, f.iy * r.nx, cell.hdot);
      if (f.ix != 0 && prm_.cell.isotropic) couple(prob_.dofs[1], k, f.ix * r.nx, -f.ix * r.ny, cell.wdot);
    }
  } else {
    prob_.dofs.push_back(make(cell.hdot, P * cm_.width, cm_.width));
    for (std::size_t k = 0; k < nr; ++k) {
      const ContactRow& r = prob_.rows[k];
      const double s = on_top_[r.b2] ? 1.0 : on_top_[r.b1] ? -1.0 : 0.0;
      if (s != 0.0) couple(prob_.dofs[0], k, s * r.ny, s * r.nx, cell.hdot);
    }
  }
}

void World::wrap_into_cell() {
  const double W = cell.width, H = cell.height;
  const double vs = prm_.cell.shear_rate * H;
  // Momentum the crossings' dH/dt and dW/dt parts give the sample, and its mass.
  double px = 0.0, py = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies.shape[i] == Shape::Segment) continue;
    Vec2& x = bodies.pos[i];
    if (periodic_) {
      // A body leaving through the top comes back through the bottom as
      // its own Lees-Edwards image: shifted back by the offset, and slower
      // by the images' velocity. Likewise through a side: the images there
      // move at dW/dt (World::build), so the body comes back slower by it.
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
    } else {
      x.x() -= W * std::floor(x.x() / W);
    }
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
  if (periodic_ && mass > 0.0 && (px != 0.0 || py != 0.0)) {
    const double ux = px / mass, uy = py / mass;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!bodies.is_dynamic(i)) continue;
      bodies.vel[i].vx -= ux;
      bodies.vel[i].vy -= uy;
    }
  }
}

double World::shear_rate() const { return (periodic_ || walls_) ? prm_.cell.shear_rate : 0.0; }

Eigen::Matrix2d World::kinetic_stress() const {
  Eigen::Matrix2d k = Eigen::Matrix2d::Zero();
  const double V = cell.width * cell.height;
  if (!(periodic_ || walls_) || V <= 0.0) return k;
  const double gd = shear_rate();
  double m = 0.0;
  Vec2 mv = Vec2::Zero();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    const Vec2 u(bodies.vel[i].vx - gd * bodies.pos[i].y(), bodies.vel[i].vy);
    m += bodies.mass[i];
    mv += bodies.mass[i] * u;
    k += bodies.mass[i] * u * u.transpose();
  }
  if (m > 0.0) k -= mv * mv.transpose() / m;  // about the mean: sum m (u - <u>)(u - <u>)^T
  return k / V;
}

Eigen::Matrix2d World::contact_stress(double volume) const {
  Eigen::Matrix2d s = Eigen::Matrix2d::Zero();
  for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
    const ContactRow& r = prob_.rows[k];
    const Vec2 p(r.nx * r.pn - r.ny * r.pt, r.ny * r.pn + r.nx * r.pt);
    s += p * Vec2(info_[k].lx, info_[k].ly).transpose();
  }
  const double V = volume > 0.0 ? volume : cell_volume();
  return s / ((V > 0.0 ? V : 1.0) * prm_.dt);  // no volume: stress times V
}

double World::kinetic_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    const BodyVel& v = bodies.vel[i];
    e += 0.5 * bodies.mass[i] * (v.vx * v.vx + v.vy * v.vy) + 0.5 * bodies.inertia[i] * v.w * v.w;
  }
  return e;
}

double World::potential_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies.is_dynamic(i)) e -= bodies.mass[i] * prm_.gravity.dot(bodies.pos[i]);
  return e;
}

ContactStatus World::status(std::size_t k) const {
  const ContactRow& r = prob_.rows[k];
  const double s = r.pn + r.adh;
  if (s <= 0.0) return ContactStatus::Open;
  if (r.mu > 0.0 && std::abs(r.pt) >= r.mu * s * (1.0 - 1e-9)) return ContactStatus::Slide;
  return ContactStatus::Stick;
}

}  // namespace cd
