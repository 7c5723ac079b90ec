#include "world.hpp"

#include <limits>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <type_traits>
#include <variant>

#include "cell_dof.hpp"
#include "projection_trigger.hpp"

namespace cd {

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
  switch (prm_.cell.mode) {
    case CellParams::Mode::None: boundary_ = NoBoundary{}; break;
    case CellParams::Mode::LeesEdwards: boundary_ = LeesEdwardsCell{}; break;
    case CellParams::Mode::Walls: boundary_ = WallShear{}; break;
  }
  std::visit([&](const auto& b) { b.configure(*this); }, boundary_);
  prepared_ = false;
}

// The step: its stages in order, each timed into its own slot (Box2D's
// stage list). A stage with nothing to do for a scene returns at once.
void World::step() {
  static constexpr StageTable<World> kTable = {{
      {Stage::Predict, &World::predict},
      {Stage::Detect, &World::detect_stage},
      {Stage::Build, &World::build},
      {Stage::Colour, &World::colour},
      {Stage::Solve, &World::solve},
      {Stage::Integrate, &World::integrate},
      {Stage::Observe, &World::observe},
  }};
  if (!prepared_) {  // per-scene choices that depend on the bodies
    forces_on_ = std::any_of(bodies.force.begin(), bodies.force.end(),
                             [](const Vec2& f) { return f.squaredNorm() > 0.0; });
    on_top_.assign(std::holds_alternative<WallShear>(boundary_) ? bodies.size() : 0, 0);
    for (const std::int32_t i : top_wall) on_top_[i] = 1;
    approach_ = boundary_approach(bodies, prm_.alert);
    prepared_ = true;
  }
  std::visit([&](const auto& b) { b.begin_step(*this); }, boundary_);
  run_stages(*this, kTable, times);
  count_step(prm_.dt);
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
  std::visit([&](const auto& b) { b.predict(*this, h); }, boundary_);
}

void World::detect_stage() {
  std::visit([&](const auto& b) { b.detect(*this); }, boundary_);
}

void World::detect_through(const PeriodicCell* c) {
  detect(bodies, xm_, thm_, alert_, grid_, prob_.rows, info_, c);
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
  std::visit([&](const auto& b) { image_offsets(b); }, boundary_);
  if (adhesion_on_) {
    const double a = prm_.adhesion * dt;
    for (std::size_t k = 0; k < nr; ++k) prob_.rows[k].adh = info_[k].gap <= prm_.debond ? a : 0.0;
  }
  if (restitution_on_) std::visit([&](const auto& b) { restitution_offsets(b); }, boundary_);
  // Warm start from the previous step's impulses, matched by contact key.
#pragma omp parallel for schedule(static) if (par)
  for (std::size_t k = 0; k < nr; ++k) {
    if (const auto* p = warm_.find(info_[k].key)) {
      prob_.rows[k].pn = p->first;
      prob_.rows[k].pt = p->second;
    }
  }
}

// The image of body 2 across the top moves at (gamma-dot H, dH/dt) relative
// to body 2, across a side at (dW/dt, 0) (the boundary's image_velocity).
template <class B>
void World::image_offsets([[maybe_unused]] const B& b) {
  if constexpr (B::moving_images) {
    for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
      const ContactInfo& f = info_[k];
      if (f.ix == 0 && f.iy == 0) continue;
      ContactRow& r = prob_.rows[k];
      const Vec2 v = b.image_velocity(*this, f);
      r.bn += r.nx * v.x() + r.ny * v.y();
      r.bt += -r.ny * v.x() + r.nx * v.y();
    }
  }
}

// Law on u+ + e u-, with u- the relative velocity at the start of the step
// (before external forces) in the midpoint frame. Only approaching normal
// velocities are restituted. (bn, bt so far hold only the gap term and the
// periodic images' velocity: that velocity is part of u-.)
template <class B>
void World::restitution_offsets(const B& b) {
  const auto& V = bodies.vel;
  const bool rot = prm_.rotation;
  for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
    ContactRow& r = prob_.rows[k];
    double un, ut;
    row_velocity(r, V, rot, un, ut);
    if constexpr (B::moving_images) {
      if (info_[k].ix != 0 || info_[k].iy != 0) {
        const Vec2 v = b.image_velocity(*this, info_[k]);
        un += r.nx * v.x() + r.ny * v.y();
        ut += -r.ny * v.x() + r.nx * v.y();
      }
    }
    r.bn += prm_.e_n * std::min(un, 0.0);
    r.bt += prm_.e_t * ut;
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

void World::colour() {
  colour_and_permute(static_cast<int>(prob_.rows.size()) >= prm_.solver.min_parallel);
}

void World::solve() {
  if (gravity_on_ || forces_on_) external();
  apply_impulses(prob_.rows, bodies.vel, prm_.rotation);
  last_.floor_held = false;  // make_dof sets it
  std::visit([&](const auto& b) { b.set_dofs(*this); }, boundary_);
  solve_problem(prm_.solver, [](ContactProblem& p, const SolverParams& s) { return nlgs_solve(p, s); });
  std::visit([&](const auto& b) { b.take_dofs(*this); }, boundary_);
  keep_warm([&](std::size_t k) { return std::pair{prob_.rows[k].pn, prob_.rows[k].pt}; });
}

void World::observe() {
  // Step quality: contacts, overlaps.
  const std::size_t nr = prob_.rows.size();
  last_.contacts = static_cast<int>(nr);
  int active = 0, nover = 0;
  double omax = 0, osum = 0, omax_small = 0;
  // The diameter a user compares an overlap with: the smaller grain's of the
  // pair (a wall segment has none: the grain's).
  const auto diameter = [&](std::int32_t i) {
    return bodies.shape[i] == Shape::Segment ? std::numeric_limits<double>::infinity()
                                             : 2.0 * bodies.radius[i];
  };
  for (std::size_t k = 0; k < nr; ++k) {
    if (prob_.rows[k].pn + prob_.rows[k].adh > 0.0) ++active;
    const double ov = -info_[k].gap;
    if (ov > 0) {
      ++nover;
      osum += ov;
      omax = std::max(omax, ov);
      const double d = std::min(diameter(prob_.rows[k].b1), diameter(prob_.rows[k].b2));
      if (std::isfinite(d)) omax_small = std::max(omax_small, ov / d);
    }
  }
  last_.max_overlap_small = omax_small;
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
  if (prm_.overlap_projection > 0.0) project_overlaps();
  const double h = 0.5 * prm_.dt;
  const bool rot = prm_.rotation;
  const std::size_t n = bodies.size();
#pragma omp parallel for schedule(static) if (static_cast<int>(n) >= prm_.solver.min_parallel / 2)
  for (std::size_t i = 0; i < n; ++i) {
    const BodyVel& v = bodies.vel[i];
    bodies.pos[i] = xm_[i] + h * Vec2(v.vx, v.vy);
    if (rot || !bodies.is_dynamic(i)) bodies.angle[i] = thm_[i] + h * v.w;
  }
  std::visit([&](const auto& b) { b.integrate(*this, h); }, boundary_);
}

// Overlap projection (WorldParams::overlap_projection): a second,
// frictionless solve of the step's contacts for pseudo-velocities (Catto's
// split impulse) that require u_n >= beta_p |g_m|/dt at an overlapping
// contact and u_n >= -g_m/dt at an open one (the gap term: it closes no
// gap), from rest, with the cell's lengths as unloaded dofs (a jammed
// sample's overlaps go only if the cell may dilate). Its solution is the
// smallest mass-weighted displacement that removes the fraction beta_p of
// every overlap; dt times it goes into the midpoint positions (and the
// cell), never into the velocities: no kinetic energy is put in. Run only
// on steps where some overlap reaches projection::kTrigger of its pair's
// smaller diameter (the solve costs sweeps, and on every step it would keep
// a jammed sample's main solve from settling: measured, 313 instead of 210
// main-solve sweeps a step at ratio 4, N = 300, beta_p = 0.2); at most
// projection::kSweeps sweeps, which are not in StepStats (their time is in
// the integrate stage's).
// The projection's adaptor (core/projection_trigger.hpp's project()): the
// step's rows, disks' and polygons' (a wall's grain's diameter is its pair's
// smaller one), the boundary's dofs as it frees them.
struct World::Projection {
  World& w;
  ContactProblem& q = w.proj_;
  double smaller(std::size_t k) const {
    const ContactRow& r = w.prob_.rows[k];
    const Bodies& b = w.bodies;
    const bool s1 = b.shape[r.b1] == Shape::Segment, s2 = b.shape[r.b2] == Shape::Segment;
    return 2.0 * (s1 ? b.radius[r.b2] : s2 ? b.radius[r.b1] : std::min(b.radius[r.b1], b.radius[r.b2]));
  }
  void start() {
    q.rows = w.prob_.rows;
    q.colouring = w.prob_.colouring;
    q.rotation = w.prob_.rotation;
    q.law = Frictionless{};
    q.vel = w.bodies.vel;
    for (BodyVel& v : q.vel) v.vx = v.vy = v.w = 0.0;
    q.dofs = w.prob_.dofs;
    std::visit([&](const auto& b) { b.pseudo_dofs(q.dofs); }, w.boundary_);
  }
  void set_offset(std::size_t k, double bn) {
    ContactRow& r = q.rows[k];
    r.bn = bn;
    r.bt = r.pn = r.pt = r.mu = r.adh = 0.0;
  }
  void solve() { nlgs_solve(q, projection::solver_params(w.prm_.solver)); }
  double impulse(std::size_t k) const { return w.prob_.rows[k].pn; }
  double normal_velocity(std::size_t k) const {
    double un, ut;
    row_velocity(q.rows[k], q.vel, q.rotation, un, ut);
    return un;
  }
  double add_dof_work(double work) const {
    for (const BoundaryDof& d : q.dofs)
      for (std::size_t i = 0; i < d.rows.size(); ++i)
        if (w.prob_.rows[d.rows[i]].pn > 0.0) work += w.prob_.rows[d.rows[i]].pn * d.an[i] * d.v;
    return work;
  }
  void move(double dt) {
    for (std::size_t i = 0; i < w.bodies.size(); ++i) {
      w.xm_[i] += dt * Vec2(q.vel[i].vx, q.vel[i].vy);
      if (w.prm_.rotation) w.thm_[i] += dt * q.vel[i].w;
    }
    std::visit([&](const auto& b) { b.apply_pseudo_dofs(w, q.dofs, dt); }, w.boundary_);
  }
};

void World::project_overlaps() {
  Projection e{*this};
  const auto gap = [&](std::size_t k) { return info_[k].gap; };
  last_.projection_work = projection::project(e, prob_.rows.size(), gap, prm_.overlap_projection, prm_.dt);
}

BoundaryDof World::make_dof(double v_start, double load, double length, double v_floor) {
  const double dt = prm_.dt, M = prm_.cell.mass;
  BoundaryDof d;
  d.inv_mass = 1.0 / M;
  d.v0 = cell_dof::free_velocity(v_start, load, M, dt, v_floor);
  if (cell_dof::load_past_floor(v_start, load, M, dt, v_floor, approach_)) last_.floor_held = true;
  d.v = d.v0;
  d.scale = dt * prm_.cell.pressure * length;  // the imposed impulse, unit of its convergence test
  return d;
}

void World::couple_dof(BoundaryDof& d, std::size_t k, double an, double at, double v_start) {
  d.rows.push_back(static_cast<std::int32_t>(k));
  d.an.push_back(an);
  d.at.push_back(at);
  prob_.rows[k].bn += an * (d.v0 - v_start);
  prob_.rows[k].bt += at * (d.v0 - v_start);
}

double World::shear_rate() const {
  return std::visit([&](const auto& b) { return b.shear_rate(*this); }, boundary_);
}

Eigen::Matrix2d World::kinetic_stress() const {
  Eigen::Matrix2d k = Eigen::Matrix2d::Zero();
  const double V = cell.width * cell.height;
  const bool has_cell =
      std::visit([](const auto& b) { return std::decay_t<decltype(b)>::cell; }, boundary_);
  if (!has_cell || V <= 0.0) return k;
  const double gd = shear_rate();
  // A length at imposed stress: the velocities along it are taken about
  // the grains' own linear profile along it (core/cell_dof.hpp, Profile).
  const bool le = std::holds_alternative<LeesEdwardsCell>(boundary_) &&
                  prm_.cell.pressure > 0.0 && prm_.cell.mass > 0.0;
  const bool fx = le && prm_.cell.isotropic;
  double bx = 0.0, by = 0.0;
  if (le) {
    cell_dof::Profile px, py;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!bodies.is_dynamic(i)) continue;
      py.add(bodies.mass[i], bodies.pos[i].y(), bodies.vel[i].vy);
      if (fx) px.add(bodies.mass[i], bodies.pos[i].x(), bodies.vel[i].vx - gd * bodies.pos[i].y());
    }
    by = py.slope();
    bx = px.slope();
  }
  double m = 0.0;
  Vec2 mv = Vec2::Zero();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.is_dynamic(i)) continue;
    Vec2 u(bodies.vel[i].vx - gd * bodies.pos[i].y(), bodies.vel[i].vy);
    if (le) {
      u.y() -= by * bodies.pos[i].y();
      if (fx) u.x() -= bx * bodies.pos[i].x();
    }
    m += bodies.mass[i];
    mv += bodies.mass[i] * u;
    k += bodies.mass[i] * u * u.transpose();
  }
  if (m > 0.0) k -= mv * mv.transpose() / m;  // about the mean: sum m (u - <u>)(u - <u>)^T
  return k / V;
}

std::vector<obs::Contact<2>> World::contact_forces() const {
  std::vector<obs::Contact<2>> cs;
  cs.reserve(prob_.rows.size());
  const double dt = prm_.dt;
  for (std::size_t k = 0; k < prob_.rows.size(); ++k) {
    const ContactRow& r = prob_.rows[k];
    cs.push_back(obs::contact_2d(r.b1, r.b2, r.nx, r.ny, r.pn / dt, r.pt / dt, info_[k].lx,
                                 info_[k].ly));
  }
  return cs;
}

Eigen::Matrix2d World::contact_stress(double volume) const {
  const double V = volume > 0.0 ? volume : cell_volume();
  const auto s = obs::contact_stress<2>(contact_forces(), V > 0.0 ? V : 1.0);  // no volume: stress times V
  Eigen::Matrix2d m;
  m << s[0][0], s[0][1], s[1][0], s[1][1];
  return m;
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
