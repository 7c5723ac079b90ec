#include "nlgs.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <variant>

#include "cell_dof.hpp"
#include "law.hpp"
#include "colour_rows.hpp"
#include "coupling.hpp"

namespace cd {

Colouring colour_rows(const std::vector<ContactRow>& rows, const Bodies& bodies) {
  return colour_by_bodies(
      static_cast<int>(rows.size()), bodies.size(), [&](int i) { return rows[i].b1; },
      [&](int i) { return rows[i].b2; }, [&](std::int32_t b) { return bodies.is_dynamic(b); });
}

void apply_impulses(const std::vector<ContactRow>& rows, std::vector<BodyVel>& vel, bool rotation) {
  for (const ContactRow& r : rows) {
    BodyVel& A = vel[r.b1];
    BodyVel& B = vel[r.b2];
    const double px = r.nx * r.pn - r.ny * r.pt, py = r.ny * r.pn + r.nx * r.pt;
    B.vx += B.inv_m * px;
    B.vy += B.inv_m * py;
    A.vx -= A.inv_m * px;
    A.vy -= A.inv_m * py;
    if (rotation) {
      B.w += B.inv_I * (r.c2n * r.pt - r.c2t * r.pn);
      A.w -= A.inv_I * (r.c1n * r.pt - r.c1t * r.pn);
    }
  }
}

void law_residuals(const ContactProblem& p, const SolverParams& prm, SolveStats& st) {
  auto* vel = const_cast<BodyVel*>(p.vel.data());  // read only: velocity() does not write
  if (p.rotation)
    sweep::residuals(p.rows, sweep::BodyCoupling<true>{vel}, prm, st);
  else
    sweep::residuals(p.rows, sweep::BodyCoupling<false>{vel}, prm, st);
}

double update_dof(BoundaryDof& d, ContactRow* rows) {
  // core/cell_dof.hpp's damped update (why damped: there).
  return cell_dof::update(
      d,
      [&](std::size_t i, double& s, double& k) {
        const ContactRow& r = rows[d.rows[i]];
        s += d.an[i] * r.pn + d.at[i] * r.pt;
        if (r.pn + r.adh > 0.0) k += d.an[i] * d.an[i] / r.wnn + d.at[i] * d.at[i] / r.wtt;
      },
      [&](std::size_t i, double dv) {
        ContactRow& r = rows[d.rows[i]];
        r.bn += d.an[i] * dv;
        r.bt += d.at[i] * dv;
      });
}

SolveStats nlgs_solve(ContactProblem& p, const SolverParams& prm, const SweepObserver& observer) {
  // The law and the rotation are resolved once here, never inside the sweep.
  std::vector<BoundaryDof>* dofs = p.dofs.empty() ? nullptr : &p.dofs;
  return std::visit(
      [&](auto law) {
        using L = decltype(law);
        if (p.rotation) {
          sweep::BodyCoupling<true> c{p.vel.data()};
          return sweep::solve<L>(p.rows, p.colouring, c, prm, dofs, observer);
        }
        sweep::BodyCoupling<false> c{p.vel.data()};
        return sweep::solve<L>(p.rows, p.colouring, c, prm, dofs, observer);
      },
      p.law);
}

}  // namespace cd
