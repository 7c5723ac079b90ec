#include "world3.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <variant>

#include <fmt/format.h>

#include "cell_dof.hpp"
#include "rigid_rotation.hpp"
#include "coupling3.hpp"

namespace cd {

namespace {


// exp(h w) q (rigid_rotation.hpp): the rotation by the angle h |w| about w
// (world frame), renormalised.
Quat rotate(const Quat& q, const Vec3& w, double h) { return rotate_orientation(q, w, h); }

}  // namespace

void World3::configure() {
  gravity_on_ = prm_.gravity.squaredNorm() > 0.0;
  adhesion_on_ = prm_.adhesion > 0.0;
  restitution_on_ = prm_.e_n > 0.0 || prm_.e_t > 0.0;
  const bool periodic = prm_.periodic[0] || prm_.periodic[1] || prm_.periodic[2];
  for (int a = 0; a < 3; ++a)
    if (prm_.periodic[a] && !(cell_.size[a] > 0.0))
      throw std::invalid_argument("WorldParams3: a periodic axis needs cell > 0");
  // Lees-Edwards: images that slide, or a cell whose images are offset (a
  // checkpoint's or a start sample's, the shear stopped).
  const bool le = cell_.le_offset != 0.0 || prm_.le_velocity != 0.0 || prm_.shear_rate != 0.0;
  if (le && !(prm_.periodic[0] && prm_.periodic[1]))
    throw std::invalid_argument("WorldParams3: Lees-Edwards needs periodic x and y");
  const bool tri = prm_.periodic[0] && prm_.periodic[1] && prm_.periodic[2];
  dofs_on_ = prm_.pressure > 0.0 && prm_.cell_mass > 0.0 &&
             (prm_.cell_dof[0] || prm_.cell_dof[1] || prm_.cell_dof[2]);
  if (dofs_on_ && !tri)
    throw std::invalid_argument("WorldParams3: cell lengths at imposed stress need a tri-periodic cell");
  // The protocol, chosen here once (boundary3.hpp).
  if (!periodic)
    boundary_ = NoBoundary3{};
  else if (le)
    boundary_ = LeesEdwardsCell3{};
  else
    boundary_ = Cell3{};
  // Images move relative to the bodies: Lees-Edwards, or lengths that move.
  const bool moving_images = (le && (prm_.le_velocity != 0.0 || prm_.shear_rate != 0.0)) || dofs_on_;
  le_velocity_ = prm_.le_velocity;
  cm_ = cell_.size;
  if (!dofs_on_) prob_.dofs.clear();
  // Contacts within the alert distance enter the solver with the gap term
  // u_n + g_m/dt >= 0, which closes gaps without overlap (as in 2D). With
  // restitution the law acts at effective contacts only (gap <= 0): a gap
  // term would stop a body short of the contact and lose the impact speed.
  alert_ = restitution_on_ ? 0.0 : prm_.alert;
  if (adhesion_on_) alert_ = std::max(alert_, prm_.debond);
  // Friction, decided here once: any coefficient of the cone (mu_b counts
  // on an orthotropic one); the law, the extras and the warm start follow.
  friction_on_ = prm_.mu > 0.0 || prm_.mu_wall > 0.0 ||
                 (prm_.orthotropic && (prm_.mu_b > 0.0 || prm_.mu_wall_b > 0.0));
  // Tangential offsets: tangential restitution or moving images; they and
  // the orthotropic mu_b are the rows' RowExtra3.
  const bool offsets = prm_.e_t > 0.0 || moving_images;
  extras_on_ = friction_on_ && (offsets || prm_.orthotropic);
  prob_.law = choose_law3({.friction = !friction_on_       ? Friction3::None
                                        : prm_.orthotropic ? Friction3::Orthotropic
                                                           : Friction3::Round,
                            .adhesion = adhesion_on_,
                            .offsets = friction_on_ && offsets});
  prob_.compliance = prm_.stiffness > 0.0 ? 1.0 / (prm_.stiffness * prm_.dt * prm_.dt) : 0.0;
  // k_t = k: 0, the tangential springs take the normal compliance.
  prob_.compliance_t =
      prm_.stiffness > 0.0 && prm_.stiffness_ratio != 1.0 ? prob_.compliance / prm_.stiffness_ratio : 0.0;
  std::visit([&](const auto& b) { b.configure(*this); }, boundary_);
}

PeriodicCell3 periodic_cell3(const WorldParams3& p, double offset, const Vec3& size) {
  PeriodicCell3 c;
  c.origin = p.cell_origin;
  c.size = size;
  c.periodic = p.periodic;
  c.le_offset = offset;
  return c;
}

PeriodicCell3 World3::cell_at(double offset, const Vec3& size) const { return periodic_cell3(prm_, offset, size); }

void World3::step() {
  static constexpr StageTable<World3> kTable = {{
      {Stage::Predict, &World3::predict},
      {Stage::Detect, &World3::detect_stage},
      {Stage::Build, &World3::build},
      {Stage::Colour, &World3::colour},
      {Stage::Solve, &World3::solve},
      {Stage::Integrate, &World3::integrate},
      {Stage::Observe, &World3::observe},
  }};
  std::visit([&](const auto& b) { b.begin_step(*this); }, boundary_);
  run_stages(*this, kTable, times);
  count_step(prm_.dt);
}

void World3::predict() {
  const std::size_t n = bodies.size();
  const double h = 0.5 * prm_.dt;
  xm_.resize(n);
  qm_.resize(n);
  const bool par = static_cast<int>(n) >= prm_.solver.min_parallel / 2;
  poly_ = bodies.has_polyhedra();
  if (poly_ && prm_.stiffness > 0.0)
    throw std::invalid_argument("WorldParams3: compliant contacts need bodies of scalar inertia (spheres)");
  std::visit([&](const auto& b) { b.predict(*this, h); }, boundary_);
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t i = 0; i < n; ++i) {
    const BodyVel3& v = bodies.vel[i];
    xm_[i] = bodies.pos[i] + h * v.v;
    qm_[i] = rotate(bodies.orient[i], v.w, h);
  }
}

void World3::detect_stage() {
  std::visit([&](const auto& b) { b.detect(*this); }, boundary_);
  if (poly_)
    polyhedra_rows3(bodies, xm_, qm_, alert_, poly_memory_, prob_.rows, info_, poly_axes_,
                    prm_.solver.min_parallel);
}

void World3::build() {
  // Polyhedra: every body's world inverse inertia at the midpoint (a
  // sphere's is its scalar's, a driven body's zero), for the blocks.
  if (poly_) {
    const std::size_t n = bodies.size();
    prob_.inv_inertia.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const BodyVel3& v = bodies.vel[i];
      if (!bodies.is_dynamic(i)) prob_.inv_inertia[i].setZero();
      else if (bodies.shape[i] == Shape3::Polyhedron)
        prob_.inv_inertia[i] = world_inverse_inertia(bodies.moments[i], qm_[i]);
      else prob_.inv_inertia[i] = v.inv_I * Mat3::Identity();
    }
  } else {
    prob_.inv_inertia.clear();
  }
  std::visit([&](const auto& b) { build_rows(b); }, boundary_);
}

template <class B>
void World3::build_rows([[maybe_unused]] const B& b) {
  const double dt = prm_.dt;
  const auto& V = bodies.vel;
  const std::size_t nr = prob_.rows.size();
  const bool par = static_cast<int>(nr) >= prm_.solver.min_parallel;
  const double a = adhesion_on_ ? prm_.adhesion * dt : 0.0;
  prob_.extra.assign(extras_on_ ? nr : 0, RowExtra3{});
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t k = 0; k < nr; ++k) {
    SphereRow& r = prob_.rows[k];
    if (prm_.orthotropic) {
      // t1 along the friction axis projected on the tangent plane.
      const Vec3 ta = prm_.axis_a - prm_.axis_a.dot(r.n) * r.n;
      const double la = ta.norm();
      if (la > 1e-12 * prm_.axis_a.norm()) {
        r.t1 = ta / la;
        r.t2 = r.n.cross(r.t1);
      }
    }
    if (poly_) set_block(r, V[r.b1], V[r.b2], prob_.inv_inertia[r.b1], prob_.inv_inertia[r.b2]);
    else set_block(r, V[r.b1], V[r.b2]);
    const bool wall = bodies.driven[r.b1];
    r.mu = wall ? prm_.mu_wall : prm_.mu;
    RowExtra3* x = extras_on_ ? &prob_.extra[k] : nullptr;
    if (x) {
      *x = RowExtra3{};
      x->mu_b = prm_.orthotropic ? (wall ? prm_.mu_wall_b : prm_.mu_b) : r.mu;
    }
    // Warm start: the previous impulse by contact key, on the new frame.
    if (const Vec3* p = poly_ ? remembered_impulse(poly_memory_, info_[k]) : warm_.find(info_[k].key)) {
      r.r = r.to_frame(*p);
      if (!friction_on_) r.r[1] = r.r[2] = 0.0;
    }
    const double gap = info_[k].gap;
    r.adh = adhesion_on_ && gap <= prm_.debond ? a : 0.0;
    // Gap term u_n + g_m/dt >= 0 for an open candidate (g_m > 0): the next
    // midpoint gap is g_m + dt u+_n >= 0 (2D's choice, method.md section 6);
    // an overlap separates at beta |g|/dt (beta = 0: pure CD). A compliant
    // bond in tension (its previous impulse negative, the bond holding) has
    // no gap term: its gap is its spring's stretch, F/k, not a distance
    // still to close (method.md section 15).
    const bool stretched = prob_.compliance > 0.0 && r.r[0] < 0.0 && r.adh > 0.0;
    r.bn = gap > 0.0 ? (stretched ? 0.0 : gap / dt) : prm_.overlap_correction * gap / dt;
    // A contact with a moving image of body 2: across y (Lees-Edwards) the
    // image moves at iy le_velocity e_x more than body 2; with cell lengths
    // at imposed stress, across each face a by i_a dL_a/dt e_a (the rates at
    // the step's start). That velocity is part of the relative velocity the
    // law sees.
    Vec3 vimg = Vec3::Zero();
    if constexpr (B::moving_images) {
      const ContactInfo3& f = info_[k];
      if (f.ix != 0 || f.iy != 0 || f.iz != 0) {
        vimg = b.image_velocity(*this, f);
        r.bn += r.n.dot(vimg);
        if (x) {
          x->bt1 = r.t1.dot(vimg);
          x->bt2 = r.t2.dot(vimg);
        }
      }
    }
    // Restitution: the law on u+ + e u-, u- the relative velocity at the
    // start of the step (before gravity) in the midpoint frame, only
    // approaching normal velocities restituted.
    if (restitution_on_) {
      const Vec3 u = relative_velocity(r, V[r.b1], V[r.b2]) + vimg;
      r.bn += prm_.e_n * std::min(r.n.dot(u), 0.0);
      if (x) {
        x->bt1 += prm_.e_t * r.t1.dot(u);
        x->bt2 += prm_.e_t * r.t2.dot(u);
      }
    }
  }
}

void World3::colour() {
  colour_and_permute(static_cast<int>(prob_.rows.size()) >= prm_.solver.min_parallel, prob_.extra);
}

void World3::solve() {
  auto& V = bodies.vel;
  // The kinetic stress the imposed one balances, from the velocities at
  // the step's start (before gravity and the warm start).
  last_.floor_held = false;
  std::visit([&](const auto& b) { b.set_dofs(*this); }, boundary_);
  if (gravity_on_) {
    const Vec3 dv = prm_.dt * prm_.gravity;
    for (std::size_t i = 0; i < bodies.size(); ++i)
      if (bodies.is_dynamic(i)) V[i].v += dv;
  }
  if (poly_) free_rotations();
  // Warm-start impulses into the velocities (sequential: bodies are shared).
  apply_impulses(prob_.rows, V, prob_.inv_inertia);
  solve_problem(prm_.solver, [](ContactProblem3& p, const SolverParams& s) { return nlgs_solve3(p, s); });
  std::visit([&](const auto& b) { b.take_dofs(*this); }, boundary_);
  if (prm_.overlap_projection > 0.0) project_overlaps();
  // The impulses, in the world frame, for the next step's warm start.
  if (poly_) keep_polyhedra_memory3(prob_.rows, info_, poly_axes_, poly_memory_);
  else keep_warm([&](std::size_t k) { return prob_.rows[k].to_world(prob_.rows[k].r); });
}

// Each dynamic polyhedron's angular velocity before the contacts: the
// implicit midpoint rule's, with the gyroscopic torque, at the midpoint
// inertia (rigid_rotation.hpp). A solve that does not converge (dt |w| of
// order 1: far beyond what contacts allow) stops the run.
void World3::free_rotations() {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies.shape[i] != Shape3::Polyhedron || !bodies.is_dynamic(i)) continue;
    BodyVel3& v = bodies.vel[i];
    const GyroscopicSolve g =
        solve_free_angular_velocity(bodies.moments[i], qm_[i], v.w, Vec3::Zero(), prm_.dt);
    if (!g.converged)
      throw std::runtime_error(fmt::format(
          "body {}: its rotation over one step did not converge (dt |w| = {:.3g} rad): the time step is too "
          "large for its spin",
          i, prm_.dt * v.w.norm()));
    v.w = g.w;
  }
}

// One dof per controlled length (as 2D's LeesEdwardsCell::set_dofs): its
// velocity at the start of the step is already in the rows' offsets (build),
// v0 holds the imposed stress's impulse, and the offsets get the difference.
// The imposed stress balances the whole normal stress: a length sees only
// the contacts across its face, so the kinetic stress K_aa (the momentum
// grains carry through the face) is taken off the load (2D's rule).
void World3::set_dofs(const Eigen::Matrix3d& K) {
  const double dt = prm_.dt, M = prm_.cell_mass;
  const double V = cm_.x() * cm_.y() * cm_.z();
  prob_.dofs.clear();
  for (int a = 0; a < 3; ++a) {
    if (!prm_.cell_dof[a]) continue;
    CellDof3 d;
    d.axis = a;
    d.inv_mass = 1.0 / M;
    const double area = V / cm_[a], v_start = cell_.rate[a];
    const double load = (prm_.pressure - K(a, a)) * area;
    const double v_floor = cell_dof::floor(prm_.max_strain_rate, cm_[a], prm_.alert, dt);
    d.v0 = cell_dof::free_velocity(v_start, load, M, dt, v_floor);
    if (cell_dof::load_past_floor(v_start, load, M, dt, v_floor, prm_.alert)) last_.floor_held = true;
    d.v = d.v0;
    d.scale = dt * prm_.pressure * area;
    d.extra = extras_on_ ? prob_.extra.data() : nullptr;
    const double dv = d.v0 - v_start;
    for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
      const ContactInfo3& f = info_[k];
      const int i = a == 0 ? f.ix : a == 1 ? f.iy : f.iz;
      if (i == 0) continue;
      SphereRow& r = prob_.rows[k];
      // The image of body 2 moves at i dL_a/dt e_a: u += i (n_a, t1_a, t2_a) v.
      const Vec3 c(i * r.n[a], d.extra ? i * r.t1[a] : 0.0, d.extra ? i * r.t2[a] : 0.0);
      d.rows.push_back(static_cast<std::int32_t>(k));
      d.a.push_back(c);
      r.bn += c[0] * dv;
      if (d.extra) {
        d.extra[k].bt1 += c[1] * dv;
        d.extra[k].bt2 += c[2] * dv;
      }
    }
    prob_.dofs.push_back(std::move(d));
  }
}

void World3::integrate() {
  const double h = 0.5 * prm_.dt;
  const std::size_t n = bodies.size();
#pragma omp parallel for schedule(static) if (static_cast<int>(n) >= prm_.solver.min_parallel / 2)
  for (std::size_t i = 0; i < n; ++i) {
    const BodyVel3& v = bodies.vel[i];
    bodies.pos[i] = xm_[i] + h * v.v;
    bodies.orient[i] = rotate(qm_[i], v.w, h);
  }
  std::visit([&](const auto& b) { b.integrate(*this, h); }, boundary_);
}

// Spheres back into the periodic cell at Lees-Edwards offset `off`: a
// sphere moved by ky images across y takes the images' shift and velocity.
void World3::wrap_into_cell(double off) {
  const std::size_t n = bodies.size();
  const PeriodicCell3 c = cell_at(off, cell_.size);
  if (dofs_on_) {
    // Lengths that move: a sphere brought back across face a takes the
    // images' velocity there, k_a dL_a/dt e_a, too. The origin is fixed, so
    // a changing cell sweeps spheres through the far faces only, and those
    // parts would add up to a drift of the whole sample (2D measured 0.7
    // sqrt(p/rho) after an isotropic compaction); a uniform velocity is a
    // symmetry of the periodic cell, so it is removed (2D's rule; the
    // gamma-dot L_y part is the usual Lees-Edwards one, kept). In body
    // order, one thread: the sum must not depend on the thread count.
    const Vec3& R = cell_.rate;
    Vec3 P = Vec3::Zero();
    double mass = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (bodies.shape[i] == Shape3::Plane) continue;
      std::array<int, 3> k;
      bodies.pos[i] = c.wrap(bodies.pos[i], k);
      const Vec3 dv(k[0] * R.x(), k[1] * R.y(), k[2] * R.z());
      bodies.vel[i].v += dv;
      bodies.vel[i].v.x() += k[1] * le_velocity_;
      P += bodies.mass[i] * dv;
      mass += bodies.mass[i];
    }
    if (mass > 0.0 && P != Vec3::Zero()) {
      const Vec3 u = P / mass;
      for (std::size_t i = 0; i < n; ++i)
        if (bodies.is_dynamic(i)) bodies.vel[i].v -= u;
    }
    return;
  }
#pragma omp parallel for schedule(static) if (static_cast<int>(n) >= prm_.solver.min_parallel / 2)
  for (std::size_t i = 0; i < n; ++i) {
    if (bodies.shape[i] == Shape3::Plane) continue;
    std::array<int, 3> k;
    bodies.pos[i] = c.wrap(bodies.pos[i], k);
    if (k[1] != 0) bodies.vel[i].v.x() += k[1] * le_velocity_;
  }
}

void World3::observe() {
  const std::size_t nr = prob_.rows.size();
  last_.contacts = static_cast<int>(nr);
  int active = 0, nover = 0;
  double omax = 0, osum = 0;
  for (std::size_t k = 0; k < nr; ++k) {
    if (prob_.rows[k].r[0] + prob_.rows[k].adh > 0.0) ++active;
    const double ov = -info_[k].gap;
    if (ov > 0) {
      ++nover;
      osum += ov;
      omax = std::max(omax, ov);
    }
  }
  last_.active = active;
  // Work of the overlap correction: a row with bias b_n < 0 holds u_n >=
  // -b_n, and r_n (-b_n) bounds the energy that bias puts in.
  double work = 0.0;
  if (prm_.overlap_correction > 0.0)
    for (std::size_t k = 0; k < nr; ++k)
      if (info_[k].gap < 0.0 && prob_.rows[k].bn < 0.0) work += prob_.rows[k].r[0] * -prob_.rows[k].bn;
  last_.correction_work = work;
  last_.max_overlap = omax / prm_.d_ref;
  last_.mean_overlap = nover ? osum / nover / prm_.d_ref : 0.0;
}

double World3::kinetic_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    const BodyVel3& v = bodies.vel[i];
    const double rot = bodies.shape[i] == Shape3::Polyhedron
                           ? v.w.dot(world_inertia(bodies.moments[i], bodies.orient[i]) * v.w)
                           : bodies.inertia[i] * v.w.squaredNorm();
    e += 0.5 * bodies.mass[i] * v.v.squaredNorm() + 0.5 * rot;
  }
  return e;
}

Vec3 World3::angular_momentum() const {
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    const BodyVel3& v = bodies.vel[i];
    const Vec3 spin = bodies.shape[i] == Shape3::Polyhedron
                          ? Vec3(world_inertia(bodies.moments[i], bodies.orient[i]) * v.w)
                          : Vec3(bodies.inertia[i] * v.w);
    L += bodies.mass[i] * bodies.pos[i].cross(v.v) + spin;
  }
  return L;
}

std::vector<obs::Contact<3>> World3::contact_forces() const {
  std::vector<obs::Contact<3>> cs;
  cs.reserve(prob_.rows.size());
  const double inv_dt = 1.0 / prm_.dt;
  for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
    const SphereRow& r = prob_.rows[k];
    const Vec3 ft = (r.r[1] * r.t1 + r.r[2] * r.t2) * inv_dt;
    const Vec3& l = info_[k].branch;
    cs.push_back({r.b1, r.b2, {r.n.x(), r.n.y(), r.n.z()}, r.r[0] * inv_dt, {ft.x(), ft.y(), ft.z()},
                  {l.x(), l.y(), l.z()}});
  }
  return cs;
}

double World3::cell_volume() const {
  const bool tri = prm_.periodic[0] && prm_.periodic[1] && prm_.periodic[2];
  return tri ? cell_.size.x() * cell_.size.y() * cell_.size.z() : 0.0;
}

double World3::shear_rate() const {
  return std::visit([&](const auto& b) { return b.shear_rate(*this); }, boundary_);
}

Eigen::Matrix3d World3::contact_stress(double volume) const {
  const double V = volume > 0.0 ? volume : cell_volume();
  const auto s = obs::contact_stress<3>(contact_forces(), V > 0.0 ? V : 1.0);
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = s[i][j];
  return m;
}

Eigen::Matrix3d World3::kinetic_stress() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  const double V = cell_volume();
  if (V <= 0.0) return k;
  const double gd = shear_rate();
  // A length at imposed stress: the velocities along it are taken about
  // the spheres' own linear profile along it (core/cell_dof.hpp, Profile).
  Vec3 b = Vec3::Zero();
  if (dofs_on_) {
    std::array<cell_dof::Profile, 3> pr;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!bodies.is_dynamic(i)) continue;
      for (int a = 0; a < 3; ++a) {
        if (!prm_.cell_dof[a]) continue;
        double v = bodies.vel[i].v[a];
        if (a == 0) v -= gd * (bodies.pos[i].y() - prm_.cell_origin.y());
        pr[a].add(bodies.mass[i], bodies.pos[i][a] - prm_.cell_origin[a], v);
      }
    }
    for (int a = 0; a < 3; ++a) b[a] = prm_.cell_dof[a] ? pr[a].slope() : 0.0;
  }
  double m = 0.0;
  Vec3 mv = Vec3::Zero();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    Vec3 u = bodies.vel[i].v;
    u.x() -= gd * (bodies.pos[i].y() - prm_.cell_origin.y());
    if (dofs_on_)
      for (int a = 0; a < 3; ++a)
        if (prm_.cell_dof[a]) u[a] -= b[a] * (bodies.pos[i][a] - prm_.cell_origin[a]);
    m += bodies.mass[i];
    mv += bodies.mass[i] * u;
    k += bodies.mass[i] * u * u.transpose();
  }
  if (m > 0.0) k -= mv * mv.transpose() / m;  // about the mean: sum m (u - <u>)(u - <u>)^T
  return k / V;
}

double World3::potential_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies.is_dynamic(i)) e -= bodies.mass[i] * prm_.gravity.dot(bodies.pos[i]);
  return e;
}

}  // namespace cd
