// World3::project_overlaps: the split-impulse overlap projection of 2D's
// World::project_overlaps (2d/world.cpp), for spheres and planes. After the
// velocity solve, a frictionless solve of the same rows for pseudo-velocities
// that open every overlapping contact by beta_p times its midpoint overlap
// and close no open one (bn = beta_p g / dt if g < 0, else g / dt), the
// periodic cell's solved lengths free; the midpoint positions (and lengths)
// move by dt times them. Velocities are untouched, so no kinetic energy is
// put in; the contact forces' work on the displacements is reported
// (StepStats::projection_work). Rotations: a sphere's gap does not depend on
// its orientation and frictionless rows carry no tangential impulse, so the
// pseudo-problem never turns a sphere; a polyhedron's normal impulses off
// its centroid do turn it (the rows' inverse inertia tensors), and its
// midpoint orientation turns by dt times its pseudo angular velocity.
#include "projection_trigger.hpp"
#include "rigid_rotation.hpp"
#include "world3.hpp"

namespace cd {

// The projection's adaptor (core/projection_trigger.hpp's project()): the
// step's sphere rows (a plane's sphere's diameter is its pair's smaller
// one), the periodic cell's lengths as dofs from rest.
struct World3::Projection {
  World3& w;
  ContactProblem3& q = w.proj_;
  double smaller(std::size_t k) const {
    const SphereRow& r = w.prob_.rows[k];
    const double r1 = w.bodies.radius[r.b1], r2 = w.bodies.radius[r.b2];
    return 2.0 * (r1 <= 0.0 ? r2 : r2 <= 0.0 ? r1 : std::min(r1, r2));
  }
  void start() {
    q.rows = w.prob_.rows;
    q.extra = w.prob_.extra;
    q.colouring = w.prob_.colouring;
    q.law = choose_law3(LawSpec3{});  // frictionless, no adhesion
    q.vel = w.bodies.vel;
    q.inv_inertia = w.prob_.inv_inertia;
    for (BodyVel3& v : q.vel) v.v = v.w = Vec3::Zero();
    q.dofs = w.prob_.dofs;
    std::visit([&](const auto& b) { b.pseudo_dofs(q.dofs); }, w.boundary_);
  }
  void set_offset(std::size_t k, double bn) {
    SphereRow& r = q.rows[k];
    r.bn = bn;
    r.r = Vec3::Zero();
    r.mu = r.adh = 0.0;
  }
  void solve() { nlgs_solve3(q, projection::solver_params(w.prm_.solver)); }
  double impulse(std::size_t k) const { return w.prob_.rows[k].r[0]; }
  double normal_velocity(std::size_t k) const {
    const SphereRow& r = w.prob_.rows[k];
    return r.n.dot(relative_velocity(q.rows[k], q.vel[r.b1], q.vel[r.b2]));
  }
  double add_dof_work(double work) const {
    for (const CellDof3& d : q.dofs)
      for (std::size_t i = 0; i < d.rows.size(); ++i)
        if (w.prob_.rows[d.rows[i]].r[0] > 0.0) work += w.prob_.rows[d.rows[i]].r[0] * d.a[i][0] * d.v;
    return work;
  }
  void move(double dt) {
    for (std::size_t i = 0; i < w.bodies.size(); ++i) w.xm_[i] += dt * q.vel[i].v;
    if (w.poly_)
      for (std::size_t i = 0; i < w.bodies.size(); ++i)
        if (w.bodies.shape[i] == Shape3::Polyhedron) w.qm_[i] = rotate_orientation(w.qm_[i], q.vel[i].w, dt);
    std::visit([&](const auto& b) { b.apply_pseudo_dofs(w, q.dofs, dt); }, w.boundary_);
  }
};

void World3::project_overlaps() {
  Projection e{*this};
  const auto gap = [&](std::size_t k) { return info_[k].gap; };
  last_.projection_work = projection::project(e, prob_.rows.size(), gap, prm_.overlap_projection, prm_.dt);
}

}  // namespace cd
