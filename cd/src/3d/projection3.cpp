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
// pseudo-problem never turns a sphere.
#include "projection_trigger.hpp"
#include "world3.hpp"

namespace cd {

void World3::project_overlaps() {
  last_.projection_work = 0.0;
  const std::size_t nr = prob_.rows.size();
  // The pair's smaller diameter (a plane's sphere's).
  const auto smaller = [&](std::size_t k) {
    const SphereRow& r = prob_.rows[k];
    const double r1 = bodies.radius[r.b1], r2 = bodies.radius[r.b2];
    return 2.0 * (r1 <= 0.0 ? r2 : r2 <= 0.0 ? r1 : std::min(r1, r2));
  };
  if (!projection::due(nr, [&](std::size_t k) { return info_[k].gap; }, smaller)) return;
  const double beta = prm_.overlap_projection, dt = prm_.dt;
  ContactProblem3& q = proj_;
  q.rows = prob_.rows;
  q.extra = prob_.extra;
  q.colouring = prob_.colouring;
  q.law = choose_law3(LawSpec3{});  // frictionless, no adhesion
  q.vel = bodies.vel;
  for (BodyVel3& v : q.vel) v.v = v.w = Vec3::Zero();
  for (std::size_t k = 0; k < nr; ++k) {
    SphereRow& r = q.rows[k];
    const double g = info_[k].gap;
    r.bn = projection::offset(g, beta, dt);
    r.r = Vec3::Zero();
    r.mu = r.adh = 0.0;
  }
  q.dofs = prob_.dofs;
  for (CellDof3& d : q.dofs) d.v0 = d.v = 0.0;
  nlgs_solve3(q, projection::solver_params(prm_.solver));
  // The contact forces' work on the displacements: sum f_n (dt u_n), u_n
  // the pseudo-velocity across the contact (bodies and cell lengths).
  double work = 0.0;
  for (std::size_t k = 0; k < nr; ++k) {
    const SphereRow& r = prob_.rows[k];
    if (r.r[0] <= 0.0) continue;
    work += r.r[0] * r.n.dot(relative_velocity(q.rows[k], q.vel[r.b1], q.vel[r.b2]));
  }
  for (const CellDof3& d : q.dofs)
    for (std::size_t i = 0; i < d.rows.size(); ++i)
      if (prob_.rows[d.rows[i]].r[0] > 0.0) work += prob_.rows[d.rows[i]].r[0] * d.a[i][0] * d.v;
  for (std::size_t i = 0; i < bodies.size(); ++i) xm_[i] += dt * q.vel[i].v;
  for (const CellDof3& d : q.dofs) cm_[d.axis] += dt * d.v;
  last_.projection_work = work;
}

}  // namespace cd
