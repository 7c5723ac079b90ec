#include "problem.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <variant>
#include <cctype>
#include <cerrno>
#include <chrono>
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
#include "block_rows.hpp"
#include "coupling.hpp"
#include "colour_blocks.hpp"

namespace cd {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

Residual residual_of(const Problem& p, const Eigen::VectorXd& r, const Eigen::VectorXd& u,
                     const Eigen::VectorXd& diag) {
  Residual res;
  if (p.nc == 0) return res;
  double rmax = 0, rsum = 0, psum = 0;
  for (int k = 0; k < p.nc; ++k) {
    const double rn = r[2 * k], rt = r[2 * k + 1];
    const double e = law_residual(u[2 * k], u[2 * k + 1], rn, rt, p.mu[k], 0.0, 1.0 / diag[2 * k]);
    rmax = std::max(rmax, e);
    rsum += e;
    psum += std::sqrt(rn * rn + rt * rt);
  }
  res.r_mean = psum / p.nc;
  const double scale = res.r_mean > 0 ? res.r_mean : 1.0;
  res.max = rmax / scale;
  res.mean = rsum / p.nc / scale;
  return res;
}

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
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
  write_problem(p, out, s);
  if (!out.flush()) throw std::runtime_error(fmt::format("{}: write failed", path));
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
  out << "dofs " << p.dofs.size() << "\n";
  for (const BoundaryDof& d : p.dofs) {
    out << problem_file::dof_scalars(d) << ' ' << d.rows.size() << '\n';
    for (std::size_t m = 0; m < d.rows.size(); ++m)
      out << fmt::format("{} {} {}\n", d.rows[m], x(d.an[m]), x(d.at[m]));
  }
}

void write_contact_problem(const ContactProblem& p, const SolverParams& prm,
                           const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
  write_contact_problem(p, prm, out);
  if (!out.flush()) throw std::runtime_error(fmt::format("{}: write failed", path));
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
  rd.expect("dofs", "after the rows");
  const long long nd = rd.count("the number of dofs", 16, 5);
  p.dofs.resize(nd);
  for (long long d = 0; d < nd; ++d) {
    BoundaryDof& D = p.dofs[d];
    const std::string w = fmt::format(" of dof {}", d);
    problem_file::read_dof_scalars(rd, D, w);
    const long long m = rd.count("the number of rows" + w, nr, 3);
    D.rows.resize(m);
    D.an.resize(m);
    D.at.resize(m);
    for (long long j = 0; j < m; ++j) {
      D.rows[j] = static_cast<std::int32_t>(rd.integer("a row" + w, 0, nr - 1));
      D.an[j] = rd.number("an" + w);
      D.at[j] = rd.number("at" + w);
    }
  }
  if (!rd.token().empty()) rd.fail("unexpected text after the last dof");
  return p;
}

ContactProblem read_contact_problem(const std::string& path, SolverParams& prm) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open for reading", path));
  return read_contact_problem(in, path, prm);
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
  Triplets h, mh;
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
  // inv_mass sum (an p_n + at p_t). Its v0 part is already in the rows'
  // offsets (World::set_cell_dofs) and v = v0 before the solve, so it adds
  // inv_mass a a^T to W and nothing to q.
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
  Eigen::SparseMatrix<double> H(3 * nb + nd, 2 * nc), MH(3 * nb + nd, 2 * nc);
  H.setFromTriplets(h.begin(), h.end());
  MH.setFromTriplets(mh.begin(), mh.end());
  Eigen::VectorXd U = Eigen::VectorXd::Zero(3 * nb + nd), p(2 * nc), b(2 * nc);
  for (int i = 0; i < nb; ++i) U.segment<3>(3 * i) << V[i].vx, V[i].vy, V[i].w;
  for (int k = 0; k < nc; ++k) {
    p.segment<2>(2 * k) << rows[k].pn, rows[k].pt;
    b.segment<2>(2 * k) << rows[k].bn, rows[k].bt;
  }
  Problem P;
  P.nc = nc;
  P.W = Eigen::SparseMatrix<double>(H.transpose() * MH);
  P.W.makeCompressed();
  // The bodies' velocities hold the warm start (G U includes W_body p), the
  // dofs' do not (v = v0): q = G U - W_body p + b, the dof rows of U zero.
  Eigen::SparseMatrix<double> Hb = H.topRows(3 * nb), MHb = MH.topRows(3 * nb);
  const Eigen::SparseMatrix<double> Wb(Hb.transpose() * MHb);
  P.q = Hb.transpose() * U.head(3 * nb) - Wb * p + b;
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
  return residual_of(p, r, u, checked_diagonal(p));
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
  double e2 = 0;
  for (int k = 0; k < p.nc; ++k) {
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
    e2 += dn * dn + dt * dt;
  }
  const double nq = p.q.norm();
  return nq > std::numeric_limits<double>::epsilon() ? std::sqrt(e2) / nq : std::sqrt(e2);
}

NlgsStats solve_nlgs(const Problem& p, Eigen::VectorXd& r, const NlgsOptions& opt) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  check_shape(p);
  const int nc = p.nc;
  if (r.size() != 2 * nc) r = Eigen::VectorXd::Zero(2 * nc);
  NlgsStats st;
  const Eigen::VectorXd diag = checked_diagonal(p);

  // Block rows of W: for contact a, the 2x2 blocks W_ab of every b it
  // couples to (W is column-major: entry (i, j) goes to block (i/2, j/2)).
  auto brow = block_rows<2>(p.W, nc, std::array<double, 4>{0, 0, 0, 0},
                           [](std::array<double, 4>& b, int i, int j, double v) { b[2 * i + j] += v; });

  // Rows in colour order. A dumped W need not be exactly symmetric (the
  // slider-crank files' W_nt and W_tn differ by 6e-7 relative), but the
  // local solver takes a symmetric block: the row holds the symmetric part
  // S of W_kk and the law sees b = u_k - S r_k with u_k from the true
  // blocks, so a fixed point of the sweep satisfies u = W r + q exactly.
  // (Rejected: a non-symmetric local solver, only to serve dumped round-off.)
  const Colouring col = colour_blocks(nc, block_adjacency(brow));
  const std::vector<std::int32_t> inv = inverse_permutation(col.perm);
  std::vector<ContactRow> rows(nc);
  bool friction = false;
  for (int i = 0; i < nc; ++i) {
    const int k = col.perm[i];
    ContactRow& w = rows[i];
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
    friction = friction || p.mu[k] > 0;
  }
  MatrixCoupling c;
  c.base = rows.data();
  colour_ordered_rows(brow, col.perm, inv, c.start, c.col, c.blk);

  const SolverParams prm = solver_params(opt);
  const int every = std::max(1, opt.check_every);
  auto record = [&](int sweep, double dp_rel) {
    SolveStats s;
    sweep::residuals(rows, c, INT_MAX, s);
    st.history.push_back({sweep, dp_rel, s.residual_max, s.residual_mean});
  };
  SolveStats s;
  if (nc > 0)
    s = std::visit(
        [&](auto law) {
          using L = decltype(law);
          return sweep::solve<L>(rows, col, c, prm, static_cast<std::vector<BoundaryDof>*>(nullptr), [&](int it, double dp) {
            if (it % every == 0) record(it, dp);
          });
        },
        choose_law(friction, false));
  st.sweeps = s.iterations;
  st.converged = !s.cap_hit;
  st.dr_rel = s.dp_rel;
  for (int i = 0; i < nc; ++i) {
    r[2 * col.perm[i]] = rows[i].pn;
    r[2 * col.perm[i] + 1] = rows[i].pt;
  }
  if (nc > 0 && (st.history.empty() || st.history.back().sweep != st.sweeps))
    record(st.sweeps, st.dr_rel);
  st.residual = residual_of(p, r, p.W * r + p.q, diag);
  st.siconos_error = siconos_error(p, r);
  st.time = std::chrono::duration<double>(clock::now() - t0).count();
  return st;
}

}  // namespace cd
