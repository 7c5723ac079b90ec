#include "problem.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <variant>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

#include "law.hpp"
#include "nlgs.hpp"
#include "problem_file.hpp"
#include "siconos_dat.hpp"
#include "text_reader.hpp"
#include "coupling.hpp"
#include "matrix_form.hpp"

namespace cd {

namespace {

void check_shape(const Problem& p) {
  const Eigen::Index n = 2 * static_cast<Eigen::Index>(p.nc);
  if (p.dim != 2 || p.W.rows() != n || p.W.cols() != n || p.q.size() != n || p.mu.size() != p.nc)
    throw std::invalid_argument(fmt::format(
        "problem shape: dim {}, nc {}, W {}x{}, q {}, mu {} (expected dim 2, W {}x{}, q {}, mu {})",
        p.dim, p.nc, p.W.rows(), p.W.cols(), p.q.size(), p.mu.size(), n, n, n, p.nc));
}

Eigen::VectorXd checked_diagonal(const Problem& p) {
  Eigen::VectorXd d = p.W.diagonal();
  for (int k = 0; k < p.nc; ++k)
    if (!(d[2 * k] > 0.0))
      throw std::invalid_argument(
          fmt::format("contact {}: W_nn = {} is not positive", k, d[2 * k]));
  return d;
}

}  // namespace

Problem read_problem(std::istream& in, const std::string& name) {
  SiconosDat d = read_siconos_dat(in, name, 2);
  return Problem{d.dim, d.nc, std::move(d.W), std::move(d.q), std::move(d.mu)};
}

Problem read_problem(const std::string& path) {
  SiconosDat d = read_siconos_dat(path, 2);
  return Problem{d.dim, d.nc, std::move(d.W), std::move(d.q), std::move(d.mu)};
}

void write_problem(const Problem& p, std::ostream& out, Storage s) {
  check_shape(p);
  const int n = 2 * p.nc;
  Eigen::SparseMatrix<double> W = p.W;
  W.makeCompressed();
  out << fmt::format("{}\n{}\n{}\n{}\n{}\n", p.dim, p.nc, static_cast<int>(s), n, n);
  if (s == Storage::Dense) {
    const Eigen::MatrixXd D(W);
    out << fmt::format("{}\t{}\n", n, n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) out << fmt::format("{:.17g} ", D(i, j));
      out << '\n';
    }
  } else {
    double norm1 = 0;
    for (int j = 0; j < n; ++j) norm1 = std::max(norm1, W.col(j).cwiseAbs().sum());
    const int nnz = static_cast<int>(W.nonZeros());
    // Origin 2 = compressed column (Siconos NSM_CSC); the version line is
    // skipped by every reader but must be there.
    out << "2\nCSparse listing (compressed column) written by cdlab\n";
    out << fmt::format("{}-by-{}, nzmax: {} nnz: {}, 1-norm: {:g}\n", n, n, nnz, nnz, norm1);
    const int* outer = W.outerIndexPtr();
    for (int j = 0; j < n; ++j) {
      out << fmt::format("    col {} : locations {} to {}\n", j, outer[j], outer[j + 1] - 1);
      for (Eigen::SparseMatrix<double>::InnerIterator it(W, j); it; ++it)
        out << fmt::format("      {} : {:.17g}\n", it.row(), it.value());
    }
  }
  for (int i = 0; i < n; ++i) out << fmt::format("{:.17g} ", p.q[i]);
  out << '\n';
  for (int k = 0; k < p.nc; ++k) out << fmt::format("{:.17g} ", p.mu[k]);
  out << '\n';
}

void write_problem(const Problem& p, const std::string& path, Storage s) {
  problem_file::write_path(path, [&](std::ostream& out) { write_problem(p, out, s); });
}

// ---- cdlab's own format of a step's problem (contact_problem.hpp) -------

void write_contact_problem(const ContactProblem& p, const SolverParams& prm, std::ostream& out) {
  // %a: hexadecimal floats, read back to the same bits by strtod.
  auto x = [](double v) { return fmt::format("{:a}", v); };
  out << "cdlab-contact-problem 1\n";
  out << "law " << law_name(p.law) << "\nrotation " << (p.rotation ? 1 : 0) << "\n";
  problem_file::write_solver(out, prm);
  out << "bodies " << p.vel.size() << "\n";
  for (const BodyVel& v : p.vel)
    out << fmt::format("{} {} {} {} {}\n", x(v.vx), x(v.vy), x(v.w), x(v.inv_m), x(v.inv_I));
  problem_file::write_colouring(out, p.colouring);
  out << "rows " << p.rows.size() << "\n";
  for (const ContactRow& r : p.rows)
    out << fmt::format("{} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {}\n", r.b1, r.b2,
                       x(r.nx), x(r.ny), x(r.c1n), x(r.c1t), x(r.c2n), x(r.c2t), x(r.wnn),
                       x(r.wnt), x(r.wtt), x(r.bn), x(r.bt), x(r.pn), x(r.pt), x(r.mu),
                       x(r.adh));
  problem_file::write_dofs(
      out, p.dofs, [](const BoundaryDof&) { return ""; },
      [&](const BoundaryDof& d, std::size_t m) { return x(d.an[m]) + ' ' + x(d.at[m]); });
}

void write_contact_problem(const ContactProblem& p, const SolverParams& prm,
                           const std::string& path) {
  problem_file::write_path(path, [&](std::ostream& out) { write_contact_problem(p, prm, out); });
}

ContactProblem read_contact_problem(std::istream& in, const std::string& name, SolverParams& prm) {
  TextReader rd(in, name);
  rd.expect("cdlab-contact-problem", "at the start (not a cdlab problem file)");
  if (rd.integer("the format version", 1, 1) != 1) rd.fail("unknown format version");
  ContactProblem p;
  p.law = problem_file::read_law<LocalLaw>(rd, [](const LocalLaw& l) { return law_name(l); });
  rd.expect("rotation", "after the law");
  p.rotation = rd.integer("rotation (0 or 1)", 0, 1) == 1;
  problem_file::read_solver(rd, prm, "after rotation");
  rd.expect("bodies", "after the solver's parameters");
  const long long nb = rd.count("the number of bodies", INT_MAX, 5);
  p.vel.resize(nb);
  for (long long i = 0; i < nb; ++i) {
    BodyVel& v = p.vel[i];
    const std::string w = fmt::format(" of body {}", i);
    v.vx = rd.number("vx" + w);
    v.vy = rd.number("vy" + w);
    v.w = rd.number("w" + w);
    v.inv_m = rd.non_negative("inv_m" + w);
    v.inv_I = rd.non_negative("inv_I" + w);
  }
  p.colouring = problem_file::read_colouring(rd, 64, "after the bodies");
  const long long nr = problem_file::read_row_count(rd, p.colouring, 17);
  p.rows.resize(nr);
  for (long long k = 0; k < nr; ++k) {
    ContactRow& r = p.rows[k];
    const std::string w = fmt::format(" of row {}", k);
    problem_file::read_row_bodies(rd, r, nb, w);
    for (double* f : {&r.nx, &r.ny, &r.c1n, &r.c1t, &r.c2n, &r.c2t, &r.wnn, &r.wnt, &r.wtt,
                      &r.bn, &r.bt, &r.pn, &r.pt})
      *f = rd.number("a number" + w);
    r.mu = rd.non_negative("the friction coefficient mu" + w);
    r.adh = rd.non_negative("the adhesion impulse" + w);
    if (!(r.wnn > 0)) rd.fail(fmt::format("W_nn{} is {}, not positive", w, r.wnn));
  }
  p.dofs = problem_file::read_dofs<BoundaryDof>(
      rd, "after the rows", 16, nr, 3, [](BoundaryDof&, const std::string&) {},
      [&](BoundaryDof& D, const std::string& w) {
        D.an.push_back(rd.number("an" + w));
        D.at.push_back(rd.number("at" + w));
      });
  if (!rd.token().empty()) rd.fail("unexpected text after the last dof");
  return p;
}

ContactProblem read_contact_problem(const std::string& path, SolverParams& prm) {
  return problem_file::read_path(path, [&](std::istream& in) { return read_contact_problem(in, path, prm); });
}

Problem assemble_problem(const std::vector<BodyVel>& V, const std::vector<ContactRow>& rows,
                         bool rotation, const std::vector<BoundaryDof>* dofs) {
  const int nc = static_cast<int>(rows.size());
  const int nb = static_cast<int>(V.size());
  const int nd = dofs ? static_cast<int>(dofs->size()) : 0;
  // H (3nb + nd x 2nc): column 2k is the normal of contact k, 2k+1 its
  // tangent; body rows 3b (x), 3b+1 (y), 3b+2 (rotation), then one row per
  // boundary dof. MH = M^-1 H keeps only the dynamic bodies, so W = H^T MH
  // has no structural entry through a wall.
  matrix_form::Triplets h, mh;
  h.reserve(12 * nc);
  mh.reserve(12 * nc);
  auto add = [&](int b, int dof, int col, double v) {
    h.emplace_back(3 * b + dof, col, v);
    const double inv = dof < 2 ? V[b].inv_m : V[b].inv_I;
    if (inv != 0.0) mh.emplace_back(3 * b + dof, col, inv * v);
  };
  for (int k = 0; k < nc; ++k) {
    const ContactRow& r = rows[k];
    const double tx = -r.ny, ty = r.nx;
    add(r.b2, 0, 2 * k, r.nx);
    add(r.b2, 1, 2 * k, r.ny);
    add(r.b2, 0, 2 * k + 1, tx);
    add(r.b2, 1, 2 * k + 1, ty);
    add(r.b1, 0, 2 * k, -r.nx);
    add(r.b1, 1, 2 * k, -r.ny);
    add(r.b1, 0, 2 * k + 1, -tx);
    add(r.b1, 1, 2 * k + 1, -ty);
    if (rotation) {
      add(r.b2, 2, 2 * k, -r.c2t);
      add(r.b2, 2, 2 * k + 1, r.c2n);
      add(r.b1, 2, 2 * k, r.c1t);
      add(r.b1, 2, 2 * k + 1, -r.c1n);
    }
  }
  // A boundary dof is one more body: u_k += (an, at) v, and v = v0 +
  // inv_mass sum (an p_n + at p_t) (its v0 part is in the rows' offsets,
  // World::set_cell_dofs; matrix_form::condense).
  for (int d = 0; d < nd; ++d) {
    const BoundaryDof& D = (*dofs)[d];
    for (std::size_t m = 0; m < D.rows.size(); ++m) {
      const int k = D.rows[m];
      for (const auto& [col, a] : {std::pair{2 * k, D.an[m]}, std::pair{2 * k + 1, D.at[m]}}) {
        h.emplace_back(3 * nb + d, col, a);
        if (D.inv_mass != 0.0) mh.emplace_back(3 * nb + d, col, D.inv_mass * a);
      }
    }
  }
  Eigen::VectorXd U(3 * nb), p(2 * nc), b(2 * nc);
  for (int i = 0; i < nb; ++i) U.segment<3>(3 * i) << V[i].vx, V[i].vy, V[i].w;
  for (int k = 0; k < nc; ++k) {
    p.segment<2>(2 * k) << rows[k].pn, rows[k].pt;
    b.segment<2>(2 * k) << rows[k].bn, rows[k].bt;
  }
  Problem P;
  P.nc = nc;
  matrix_form::condense(3 * nb + nd, 2 * nc, 3 * nb, h, mh, U, p, b, P.W, P.q);
  P.mu.resize(nc);
  for (int k = 0; k < nc; ++k) P.mu[k] = rows[k].mu;
  return P;
}

Problem assemble_problem(const Bodies& bodies, const std::vector<ContactRow>& rows, bool rotation) {
  return assemble_problem(bodies.vel, rows, rotation, nullptr);
}

Problem to_matrix(const ContactProblem& p) {
  for (const ContactRow& r : p.rows)
    if (r.adh != 0.0)
      throw std::invalid_argument(
          "a cohesive problem (adhesion impulse > 0) has no Siconos matrix form");
  return assemble_problem(p.vel, p.rows, p.rotation, p.dofs.empty() ? nullptr : &p.dofs);
}

Residual problem_residual(const Problem& p, const Eigen::VectorXd& r) {
  check_shape(p);
  if (r.size() != p.q.size())
    throw std::invalid_argument(fmt::format("r has {} entries, expected {}", r.size(), p.q.size()));
  const Eigen::VectorXd u = p.W * r + p.q;
  const Eigen::VectorXd diag = checked_diagonal(p);
  return matrix_form::residual_over(p.nc, [&](int k) {
    const double rn = r[2 * k], rt = r[2 * k + 1];
    return std::pair{law_residual(u[2 * k], u[2 * k + 1], rn, rt, p.mu[k], 0.0, 1.0 / diag[2 * k]),
                     std::sqrt(rn * rn + rt * rt)};
  });
}

namespace {

// Contacts coupled through the blocks of W (a frozen problem): row i holds
// W_ii's symmetric part (the local solver's block), q_i as offsets and r_i;
// u_i = q_i + sum_j W_ij r_j over the stored blocks of W's block row i, the
// diagonal one included (non-symmetric, as dumped). A row reads the
// impulses of the rows it couples to and writes only its own: rows of one
// colour share no block, so they may be updated at once.
struct MatrixCoupling {
  const ContactRow* base = nullptr;
  std::vector<std::int32_t> start, col;  // block row i: [start[i], start[i+1])
  std::vector<std::array<double, 4>> blk;  // (nn, nt, tn, tt)

  void velocity(const ContactRow& r, double& un, double& ut) const {
    const std::size_t i = &r - base;
    un = r.bn;
    ut = r.bt;
    for (std::int32_t b = start[i]; b < start[i + 1]; ++b) {
      const ContactRow& o = base[col[b]];
      const auto& w = blk[b];
      un += w[0] * o.pn + w[1] * o.pt;
      ut += w[2] * o.pn + w[3] * o.pt;
    }
  }

  template <class L, bool Write1>
  void update(ContactRow& r, double& dp2, double& pabs) const {
    double un, ut;
    velocity(r, un, ut);
    double pn, pt;
    L::solve(r, un, ut, pn, pt);
    const double dpn = pn - r.pn, dpt = pt - r.pt;
    r.pn = pn;
    r.pt = pt;
    dp2 = dpn * dpn + dpt * dpt;
    pabs = std::sqrt(pn * pn + pt * pt);
  }
};

}  // namespace

double siconos_error(const Problem& p, const Eigen::VectorXd& r) {
  check_shape(p);
  const Eigen::VectorXd u = p.W * r + p.q;
  return matrix_form::siconos_over(p.q, p.nc, [&](int k) {
    const double mu = p.mu[k], rn = r[2 * k], rt = r[2 * k + 1];
    // r - P_K(r - (u_n + mu |u_t|, u_t)), P_K the projection on the cone
    // |x_t| <= mu x_n (De Saxce's modified velocity, rho = 1).
    double xn = rn - (u[2 * k] + mu * std::abs(u[2 * k + 1]));
    double xt = rt - u[2 * k + 1];
    const double at = std::abs(xt);
    if (mu * at <= -xn) {  // in the polar cone: projects to 0
      xn = 0.0;
      xt = 0.0;
    } else if (at > mu * xn) {  // outside the cone: onto its edge
      xn = (mu * at + xn) / (mu * mu + 1.0);
      xt = mu * xn * (xt > 0 ? 1.0 : xt < 0 ? -1.0 : 0.0);
    }
    const double dn = rn - xn, dt = rt - xt;
    return dn * dn + dt * dt;
  });
}

namespace {

// The 2D rows of matrix_form::nlgs. A dumped W need not be exactly
// symmetric (the slider-crank files' W_nt and W_tn differ by 6e-7
// relative), but the local solver takes a symmetric block: the row holds
// the symmetric part S of W_kk and the law sees b = u_k - S r_k with u_k
// from the true blocks, so a fixed point of the sweep satisfies u = W r + q
// exactly. (Rejected: a non-symmetric local solver, only to serve dumped
// round-off.)
struct Form2 {
  static constexpr int dim = 2;
  using Row = ContactRow;
  using Block = std::array<double, 4>;  // (nn, nt, tn, tt)
  using Coupling = MatrixCoupling;
  const Problem& p;
  const Eigen::VectorXd& diag;

  static Block zero() { return {0, 0, 0, 0}; }
  static void add(Block& b, int i, int j, double v) { b[2 * i + j] += v; }
  template <class Blocks>
  bool row(int k, const Blocks&, const Eigen::VectorXd& r, ContactRow& w) const {
    w = {};
    w.wnn = diag[2 * k];
    w.wnt = 0.5 * (p.W.coeff(2 * k, 2 * k + 1) + p.W.coeff(2 * k + 1, 2 * k));
    w.wtt = diag[2 * k + 1];
    if (p.mu[k] > 0 && !(w.wnn * w.wtt - w.wnt * w.wnt > 0))
      throw std::invalid_argument(fmt::format("contact {}: singular block W_kk with friction", k));
    w.bn = p.q[2 * k];
    w.bt = p.q[2 * k + 1];
    w.pn = r[2 * k];
    w.pt = r[2 * k + 1];
    w.mu = p.mu[k];
    return p.mu[k] > 0;
  }
  template <class Observer>
  SolveStats solve(bool friction, std::vector<ContactRow>& rows, const Colouring& col, const MatrixCoupling& c,
                   const SolverParams& prm, Observer&& observer) const {
    return std::visit(
        [&](auto law) {
          return sweep::solve<decltype(law)>(rows, col, c, prm, static_cast<std::vector<BoundaryDof>*>(nullptr),
                                             observer);
        },
        choose_law(friction, false));
  }
  static void store(const ContactRow& w, Eigen::VectorXd& r, int k) {
    r[2 * k] = w.pn;
    r[2 * k + 1] = w.pt;
  }
};

}  // namespace

NlgsStats solve_nlgs(const Problem& p, Eigen::VectorXd& r, const NlgsOptions& opt) {
  check_shape(p);
  const Eigen::VectorXd diag = checked_diagonal(p);
  return matrix_form::nlgs(p, r, opt, Form2{p, diag});
}

}  // namespace cd
