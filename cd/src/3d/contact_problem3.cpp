#include "contact_problem3.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "cell_dof.hpp"
#include "problem_file.hpp"
#include "text_reader.hpp"

namespace cd {

namespace {

// core/cell_dof.hpp's damped update, with the 3D rows' impulses and the
// responses of their blocks' diagonals, (1/W_nn, 1/W_tt, 1/W_tt) for
// sphere rows, the reciprocals of W's diagonal for block rows.
template <class Row, class Response>
double update_dof3(CellDof3& d, Row* rows, Response response) {
  return cell_dof::update(
      d,
      [&](std::size_t i, double& s, double& k) {
        const Row& r = rows[d.rows[i]];
        const Vec3& a = d.a[i];
        s += a.dot(r.r);
        if (r.r[0] + r.adh > 0.0) k += response(r, a);
      },
      [&](std::size_t i, double dv) {
        const std::int32_t j = d.rows[i];
        rows[j].bn += d.a[i][0] * dv;
        if (d.extra) {
          d.extra[j].bt1 += d.a[i][1] * dv;
          d.extra[j].bt2 += d.a[i][2] * dv;
        }
      });
}

}  // namespace

double update_dof(CellDof3& d, SweepRow3* rows) {
  return update_dof3(d, rows, [](const SweepRow3& r, const Vec3& a) {
    return a[0] * a[0] * r.iwnn + (a[1] * a[1] + a[2] * a[2]) * r.iwtt;
  });
}

double update_dof(CellDof3& d, BlockRow3* rows) {
  return update_dof3(d, rows, [](const BlockRow3& r, const Vec3& a) {
    return a[0] * a[0] / r.W(0, 0) + a[1] * a[1] / r.W(1, 1) + a[2] * a[2] / r.W(2, 2);
  });
}

namespace {

// The sweep's rows' impulses and b_n (the dofs move it) back into the problem's.
template <class Row>
void give_back(ContactProblem3& p, const std::vector<Row>& rows, int min_parallel) {
  const int n = static_cast<int>(rows.size());
#pragma omp parallel for schedule(static) if (n >= min_parallel)
  for (int k = 0; k < n; ++k) {
    p.rows[k].r = rows[k].r;
    p.rows[k].bn = rows[k].bn;
  }
}

// The problem of bodies with inverse inertia tensors: its rows as
// block_coupling3.hpp's BlockRow3.
SolveStats nlgs_solve_blocks3(ContactProblem3& p, const SolverParams& prm, const SweepObserver& observer) {
  const int n = static_cast<int>(p.rows.size());
  if (p.inv_inertia.size() != p.vel.size())
    throw std::invalid_argument(fmt::format("3D contact problem: {} inverse inertia tensors for {} bodies",
                                            p.inv_inertia.size(), p.vel.size()));
  if (p.compliance > 0)
    throw std::invalid_argument("3D contact problem: compliant contacts need bodies of scalar inertia (spheres)");
  std::vector<BlockRow3> rows(n);
#pragma omp parallel for schedule(static) if (n >= prm.min_parallel)
  for (int k = 0; k < n; ++k) rows[k] = make_block_row3(p.rows[k], p.vel.data(), p.inv_inertia.data());
  RowExtra3* extra = p.extra.empty() ? nullptr : p.extra.data();
  for (CellDof3& d : p.dofs) d.extra = extra;
  std::vector<CellDof3>* dofs = p.dofs.empty() ? nullptr : &p.dofs;
  const SolveStats st = std::visit(
      [&](auto law) {
        using L = decltype(law);
        sweep::BlockCoupling3 c{p.vel.data(), extra, rows.data(), static_cast<int>(p.vel.size())};
        return sweep::solve<L>(rows, p.colouring, c, prm, dofs, observer);
      },
      p.law);
  give_back(p, rows, prm.min_parallel);
  return st;
}

}  // namespace

SolveStats nlgs_solve3(ContactProblem3& p, const SolverParams& prm, const SweepObserver& observer) {
  if (!p.inv_inertia.empty()) return nlgs_solve_blocks3(p, prm, observer);
  // The rows as the sweep streams them, made once per solve (a few percent
  // of one sweep), given back after: the impulses and b_n (the dofs move it).
  const int n = static_cast<int>(p.rows.size());
  std::vector<SweepRow3> rows(n);
  int bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad) if (n >= prm.min_parallel)
  for (int k = 0; k < n; ++k)
    if (!make_sweep_row3(p.rows[k], p.vel.data(), rows[k])) bad = std::min(bad, k);
  if (bad < n)
    throw std::invalid_argument(fmt::format(
        "3D contact problem, row {}: not a sphere's row (a lever arm off the normal of a body that turns, or a "
        "frame (n, t1, t2) that is not orthonormal and right-handed)",
        bad));
  RowExtra3* extra = p.extra.empty() ? nullptr : p.extra.data();
  for (CellDof3& d : p.dofs) d.extra = extra;
  std::vector<CellDof3>* dofs = p.dofs.empty() ? nullptr : &p.dofs;
  // Compliant contacts: the law's memory (the impulses at the start), and
  // the compliant block's reciprocals in the rows (coupling3.hpp).
  std::vector<Vec3> r0;
  const double rho_t = p.tangential_compliance();
  if (p.compliance > 0) {
    r0.resize(n);
    for (int k = 0; k < n; ++k) {
      r0[k] = rows[k].r;
      rows[k].iwnn = 1.0 / (p.rows[k].wnn + p.compliance);
      rows[k].iwtt = 1.0 / (p.rows[k].wtt + rho_t);
    }
  }
  const SolveStats st = std::visit(
      [&](auto law) {
        using L = decltype(law);
        if (p.compliance > 0) {
          sweep::CompliantCoupling3 c{p.vel.data(), extra, rows.data(), static_cast<int>(p.vel.size()),
                                      {r0.data(), p.compliance, rho_t}};
          return sweep::solve<L>(rows, p.colouring, c, prm, dofs, observer);
        }
        sweep::BodyCoupling3 c{p.vel.data(), extra, rows.data(), static_cast<int>(p.vel.size())};
        return sweep::solve<L>(rows, p.colouring, c, prm, dofs, observer);
      },
      p.law);
  give_back(p, rows, prm.min_parallel);
  return st;
}

void apply_impulses(const std::vector<SphereRow>& rows, std::vector<BodyVel3>& vel, const std::vector<Mat3>& J) {
  if (J.empty()) {
    for (const SphereRow& r : rows) push_impulse(r, r.r, vel.data());
    return;
  }
  for (const SphereRow& r : rows) {
    const Vec3 P = r.to_world(r.r);
    BodyVel3& A = vel[r.b1];
    BodyVel3& B = vel[r.b2];
    B.v += B.inv_m * P;
    B.w += J[r.b2] * r.c2.cross(P);
    A.v -= A.inv_m * P;
    A.w -= J[r.b1] * r.c1.cross(P);
  }
}

// ---- .cdp3 files -----------------------------------------------------------

namespace {

using problem_file::hex;
std::string x(double v) { return hex(v); }
std::string x3(const Vec3& v) { return fmt::format("{:a} {:a} {:a}", v[0], v[1], v[2]); }

Vec3 vec3(TextReader& rd, const std::string& what) {
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = rd.number(fmt::format("{}[{}]", what, i));
  return v;
}

}  // namespace

void write_contact_problem(const ContactProblem3& p, const SolverParams& prm, std::ostream& out) {
  const bool tensors = !p.inv_inertia.empty();
  if (tensors && p.compliance > 0)
    throw std::invalid_argument("3D contact problem: compliant contacts need bodies of scalar inertia (spheres)");
  if (tensors && p.inv_inertia.size() != p.vel.size())
    throw std::invalid_argument(fmt::format("3D contact problem: {} inverse inertia tensors for {} bodies",
                                            p.inv_inertia.size(), p.vel.size()));
  // Version 1: rigid; 2: compliant, k_t = k; 3: compliant, k_t != k; 4:
  // rigid, every body's world inverse inertia tensor after the bodies
  // (polyhedra).
  const bool split = p.tangential_compliance() != p.compliance;
  out << "cdlab-contact-problem3 " << (tensors ? 4 : p.compliance > 0 ? (split ? 3 : 2) : 1) << "\n";
  out << "law " << law_name3(p.law) << "\n";
  if (p.compliance > 0) out << "compliance " << x(p.compliance) << "\n";
  if (p.compliance > 0 && split) out << "compliance_t " << x(p.tangential_compliance()) << "\n";
  problem_file::write_solver(out, prm);
  out << "bodies " << p.vel.size() << "\n";
  for (const BodyVel3& v : p.vel) out << fmt::format("{} {} {} {}\n", x3(v.v), x3(v.w), x(v.inv_m), x(v.inv_I));
  if (tensors) {
    // The upper triangle (xx xy xz yy yz zz): the tensors are symmetric.
    out << "inertia\n";
    for (const Mat3& J : p.inv_inertia)
      out << fmt::format("{} {} {} {} {} {}\n", x(J(0, 0)), x(J(0, 1)), x(J(0, 2)), x(J(1, 1)), x(J(1, 2)),
                         x(J(2, 2)));
  }
  problem_file::write_colouring(out, p.colouring);
  out << "rows " << p.rows.size() << "\n";
  for (const SphereRow& r : p.rows)
    out << fmt::format("{} {} {} {} {} {} {} {} {} {} {} {} {}\n", r.b1, r.b2, x3(r.n), x3(r.t1), x3(r.t2),
                       x3(r.c1), x3(r.c2), x(r.wnn), x(r.wtt), x(r.bn), x3(r.r), x(r.mu), x(r.adh));
  out << "extras " << p.extra.size() << "\n";
  for (const RowExtra3& e : p.extra) out << fmt::format("{} {} {}\n", x(e.bt1), x(e.bt2), x(e.mu_b));
  problem_file::write_dofs(
      out, p.dofs, [](const CellDof3& d) { return fmt::format(" {}", d.axis); },
      [](const CellDof3& d, std::size_t m) { return x3(d.a[m]); });
}

ContactProblem3 read_contact_problem3(std::istream& in, const std::string& name, SolverParams& prm) {
  TextReader rd(in, name);
  rd.expect("cdlab-contact-problem3", "at the start (not a cdlab 3D problem file)");
  const long long version = rd.integer("the format version", 1, 4);
  ContactProblem3 p;
  p.law = problem_file::read_law<LocalLaw3>(rd, [](const LocalLaw3& l) { return law_name3(l); });
  if (version == 2 || version == 3) {
    rd.expect("compliance", fmt::format("after the law (format version {})", version));
    p.compliance = rd.number("the compliance");
    if (!(p.compliance >= 0) || !std::isfinite(p.compliance))
      rd.fail(fmt::format("the compliance is {}, not a finite number >= 0", p.compliance));
  }
  if (version == 3) {
    rd.expect("compliance_t", "after the compliance (format version 3)");
    p.compliance_t = rd.number("the tangential compliance");
    if (!(p.compliance_t > 0) || !std::isfinite(p.compliance_t))
      rd.fail(fmt::format("the tangential compliance is {}, not a finite number > 0", p.compliance_t));
  }
  problem_file::read_solver(rd, prm, "after the law");
  if (!(prm.tol > 0)) rd.fail(fmt::format("the tolerance is {}, not positive", prm.tol));
  rd.expect("bodies", "after the solver's parameters");
  const long long nb = rd.count("the number of bodies", INT_MAX, 8);  // v, w, inv_m, inv_I
  p.vel.resize(nb);
  for (long long i = 0; i < nb; ++i) {
    BodyVel3& v = p.vel[i];
    const std::string w = fmt::format(" of body {}", i);
    v.v = vec3(rd, "v" + w);
    v.w = vec3(rd, "w" + w);
    v.inv_m = rd.number("inv_m" + w);
    v.inv_I = rd.number("inv_I" + w);
    if (v.inv_m < 0 || v.inv_I < 0) rd.fail(fmt::format("negative inverse mass or inertia{}", w));
  }
  if (version == 4) {
    rd.expect("inertia", "after the bodies (format version 4)");
    p.inv_inertia.resize(nb);
    for (long long i = 0; i < nb; ++i) {
      const std::string w = fmt::format(" of body {}", i);
      Mat3& J = p.inv_inertia[i];
      static constexpr int kRow[6] = {0, 0, 0, 1, 1, 2}, kCol[6] = {0, 1, 2, 1, 2, 2};
      for (int e = 0; e < 6; ++e)
        J(kRow[e], kCol[e]) = J(kCol[e], kRow[e]) =
            rd.number(fmt::format("inverse inertia ({},{}){}", kRow[e], kCol[e], w));
      // Positive semidefinite (zero for a driven body), to round-off.
      const double lmin = Eigen::SelfAdjointEigenSolver<Mat3>(J, Eigen::EigenvaluesOnly).eigenvalues()[0];
      if (!(lmin >= -1e-12 * J.cwiseAbs().maxCoeff()))
        rd.fail(fmt::format("the inverse inertia tensor{} is not positive semidefinite (least eigenvalue {})", w,
                            lmin));
    }
  }
  p.colouring = problem_file::read_colouring(rd, 1 << 16, "after the bodies");
  const long long nr = problem_file::read_row_count(rd, p.colouring, 3);  // b1, b2 and numbers
  p.rows.resize(nr);
  for (long long k = 0; k < nr; ++k) {
    SphereRow& r = p.rows[k];
    const std::string w = fmt::format(" of row {}", k);
    problem_file::read_row_bodies(rd, r, nb, w);
    r.n = vec3(rd, "n" + w);
    r.t1 = vec3(rd, "t1" + w);
    r.t2 = vec3(rd, "t2" + w);
    r.c1 = vec3(rd, "c1" + w);
    r.c2 = vec3(rd, "c2" + w);
    r.wnn = rd.number("W_nn" + w);
    r.wtt = rd.number("W_tt" + w);
    r.bn = rd.number("b_n" + w);
    r.r = vec3(rd, "r" + w);
    r.mu = rd.number("mu" + w);
    r.adh = rd.number("the adhesion impulse" + w);
    if (!(r.wnn > 0) || !(r.wtt > 0)) rd.fail(fmt::format("W_nn or W_tt{} not positive", w));
    if (r.mu < 0 || r.adh < 0) rd.fail(fmt::format("mu or the adhesion impulse{} negative", w));
  }
  rd.expect("extras", "after the rows");
  const long long ne = rd.integer("the number of row extras (0 or the rows)", 0, nr);
  if (ne != 0 && ne != nr) rd.fail(fmt::format("{} row extras for {} rows: expected 0 or {}", ne, nr, nr));
  const bool needs_extra = std::visit([](auto l) { return decltype(l)::extra; }, p.law);
  if (needs_extra && ne == 0) rd.fail(fmt::format("law '{}' needs the rows' extras, the file has none", law_name3(p.law)));
  p.extra.resize(ne);
  for (long long k = 0; k < ne; ++k) {
    RowExtra3& e = p.extra[k];
    const std::string w = fmt::format(" of row extra {}", k);
    e.bt1 = rd.number("b_t1" + w);
    e.bt2 = rd.number("b_t2" + w);
    e.mu_b = rd.number("mu_b" + w);
    if (e.mu_b < 0) rd.fail(fmt::format("mu_b{} negative", w));
  }
  p.dofs = problem_file::read_dofs<CellDof3>(
      rd, "after the extras", 3, nr, 4,
      [&](CellDof3& D, const std::string& w) {
        if (!(D.inv_mass > 0) || !(D.scale > 0)) rd.fail(fmt::format("inv_mass or scale{} not positive", w));
        D.axis = static_cast<int>(rd.integer("the axis" + w, 0, 2));
      },
      [&](CellDof3& D, const std::string& w) { D.a.push_back(vec3(rd, "a" + w)); });
  if (!rd.token().empty()) rd.fail("unexpected text after the last dof");
  return p;
}

ContactProblem3 read_contact_problem3(const std::string& path, SolverParams& prm) {
  return problem_file::read_path(path, [&](std::istream& in) { return read_contact_problem3(in, path, prm); });
}

}  // namespace cd
