#include "problem3.hpp"

#include <algorithm>
#include <cstdio>
#include <climits>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <variant>
#include <vector>

#include <Eigen/SparseCholesky>
#include <fmt/format.h>
#include <hdf5.h>

// fclib.h has no extern "C" guard of its own.
extern "C" {
#include <fclib.h>
}

#include "contact_problem3.hpp"
#include "matrix_form.hpp"
#include "siconos_dat.hpp"
#include "sweep.hpp"

namespace cd {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// An fclib_matrix as an Eigen matrix. Triplet storage (nz >= 0): the data
// and Siconos' reader use p for column indices and i for row indices (the
// header's comment says the opposite); nz = -1 compressed columns, nz = -2
// compressed rows. Indices are checked against the size.
SpMat to_eigen(const fclib_matrix* m, const std::string& what, const std::string& path) {
  if (!m) throw std::runtime_error(fmt::format("{}: {} is missing", path, what));
  matrix_form::Triplets t;
  auto add = [&](long long i, long long j, double v) {
    if (i < 0 || i >= m->m || j < 0 || j >= m->n)
      throw std::runtime_error(fmt::format("{}: {} ({}x{}) has an entry at ({}, {})", path, what,
                                           m->m, m->n, i, j));
    if (!std::isfinite(v))
      throw std::runtime_error(fmt::format("{}: {} has a non-finite entry at ({}, {})", path, what, i, j));
    t.emplace_back(static_cast<int>(i), static_cast<int>(j), v);
  };
  if (m->nz >= 0) {
    for (int k = 0; k < m->nz; ++k) add(m->i[k], m->p[k], m->x[k]);
  } else if (m->nz == -1 || m->nz == -2) {
    const int outer = m->nz == -1 ? m->n : m->m;
    for (int o = 0; o < outer; ++o)
      for (int k = m->p[o]; k < m->p[o + 1]; ++k)
        if (m->nz == -1) add(m->i[k], o, m->x[k]);
        else add(o, m->i[k], m->x[k]);
  } else {
    throw std::runtime_error(fmt::format("{}: {} has unknown storage nz = {}", path, what, m->nz));
  }
  SpMat A(m->m, m->n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

bool has_group(hid_t f, const char* name) { return H5Lexists(f, name, H5P_DEFAULT) > 0; }

void check_shape(const Problem3& p) {
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(p.nc);
  if (p.W.rows() != n || p.W.cols() != n || p.q.size() != n || p.mu.size() != p.nc ||
      (p.mu_b.size() != 0 && p.mu_b.size() != p.nc))
    throw std::invalid_argument(fmt::format(
        "3D problem shape: nc {}, W {}x{}, q {}, mu {}, mu_b {} (expected W {}x{}, q {}, mu {})",
        p.nc, p.W.rows(), p.W.cols(), p.q.size(), p.mu.size(), p.mu_b.size(), n, n, n, p.nc));
}

// ---- rows and their coupling through the 3x3 blocks of W -----------------

struct Row3 {
  Mat3 S;      // symmetric part of W_kk: the local solver's block
  Vec3 b;      // q_k
  Vec3 r;      // impulse
  Cone3 cone;
  double adh;  // adhesion impulse (0 for FCLib problems)
};

// No boundary dofs in a frozen problem; the sweep's interface asks for a type.
struct NoDof {
  double v = 0, v0 = 0;
};
double update_dof(NoDof&, Row3*) { return 0.0; }

struct MatrixCoupling3 {
  const Row3* base = nullptr;
  std::vector<std::int32_t> start, col;  // block row i: [start[i], start[i+1])
  std::vector<Mat3> blk;

  Vec3 velocity(const Row3& r) const {
    const std::size_t i = &r - base;
    Vec3 u = r.b;
    for (std::int32_t k = start[i]; k < start[i + 1]; ++k) u.noalias() += blk[k] * base[col[k]].r;
    return u;
  }

  template <class L, bool Write1>
  void update(Row3& r, double& dp2, double& pabs) const {
    const Vec3 bl = velocity(r) - r.S * r.r;  // the law sees u = S r' + bl
    Vec3 rn;
    L::solve(r, bl, rn);
    dp2 = (rn - r.r).squaredNorm();
    pabs = rn.norm();
    r.r = rn;
  }
};

double row_residual(const MatrixCoupling3& c, const Row3& r) {
  return law_residual3(c.velocity(r), r.r, r.cone, r.adh, 1.0 / r.S(0, 0));
}
double impulse_norm(const Row3& r) { return r.r.norm(); }

// The laws, chosen once per problem (no friction test inside the sweep).
struct Frictionless3 {
  static void solve(const Row3& r, const Vec3& b, Vec3& out) {
    out = Vec3(std::max(-r.adh, -b[0] / r.S(0, 0)), 0.0, 0.0);
  }
};
struct Coulomb3 {
  static void solve(const Row3& r, const Vec3& b, Vec3& out) {
    solve_local3(r.S, b, r.cone, r.adh, out);
  }
};

}  // namespace

Problem3 to_matrix(const ContactProblem3& cp) {
  if (std::visit([](auto l) { return decltype(l)::cohesive; }, cp.law))
    throw std::invalid_argument("a cohesive problem (adhesion impulse > 0) has no FCLib matrix form");
  if (cp.compliance > 0)
    throw std::invalid_argument("a problem with compliant contacts (compliance > 0) has no FCLib matrix form");
  const auto& rows = cp.rows;
  const auto& V = cp.vel;
  const int nc = static_cast<int>(rows.size()), nb = static_cast<int>(V.size());
  const int nd = static_cast<int>(cp.dofs.size());
  // H (6nb + nd x 3nc): column 3k + j is row k's frame vector e_j (n, t1,
  // t2); body b's rows 6b..6b+2 its velocity, 6b+3..6b+5 its angular
  // velocity (u_k,j = e_j.(v2 - v1) + w2.(c2 x e_j) - w1.(c1 x e_j)), then
  // one row per cell dof (u_k,j += a_j v). MH = M^-1 H keeps only what has
  // an inverse mass, so W = H^T MH has no structural entry through a wall.
  matrix_form::Triplets h, mh;
  h.reserve(36 * static_cast<std::size_t>(nc));
  mh.reserve(36 * static_cast<std::size_t>(nc));
  auto add = [&](int b, const Vec3& lin, const Vec3& ang, int col) {
    for (int i = 0; i < 3; ++i) {
      h.emplace_back(6 * b + i, col, lin[i]);
      h.emplace_back(6 * b + 3 + i, col, ang[i]);
      if (V[b].inv_m != 0.0) mh.emplace_back(6 * b + i, col, V[b].inv_m * lin[i]);
      if (V[b].inv_I != 0.0) mh.emplace_back(6 * b + 3 + i, col, V[b].inv_I * ang[i]);
    }
  };
  for (int k = 0; k < nc; ++k) {
    const SphereRow& r = rows[k];
    const Vec3 e[3] = {r.n, r.t1, r.t2};
    for (int j = 0; j < 3; ++j) {
      add(r.b2, e[j], r.c2.cross(e[j]), 3 * k + j);
      add(r.b1, -e[j], -r.c1.cross(e[j]), 3 * k + j);
    }
  }
  // A cell dof is one more body (matrix_form::condense: inv_mass a a^T in
  // W, nothing in q).
  for (int d = 0; d < nd; ++d) {
    const CellDof3& D = cp.dofs[d];
    for (std::size_t m = 0; m < D.rows.size(); ++m)
      for (int j = 0; j < 3; ++j) {
        h.emplace_back(6 * nb + d, 3 * D.rows[m] + j, D.a[m][j]);
        mh.emplace_back(6 * nb + d, 3 * D.rows[m] + j, D.inv_mass * D.a[m][j]);
      }
  }
  Eigen::VectorXd U(6 * nb), r(3 * nc), b(3 * nc);
  for (int i = 0; i < nb; ++i) U.segment<6>(6 * i) << V[i].v, V[i].w;
  for (int k = 0; k < nc; ++k) {
    r.segment<3>(3 * k) = rows[k].r;
    b.segment<3>(3 * k) = Vec3(rows[k].bn, cp.extra.empty() ? 0.0 : cp.extra[k].bt1,
                               cp.extra.empty() ? 0.0 : cp.extra[k].bt2);
  }
  Problem3 P;
  P.nc = nc;
  matrix_form::condense(6 * nb + nd, 3 * nc, 6 * nb, h, mh, U, r, b, P.W, P.q);
  P.mu.resize(nc);
  for (int k = 0; k < nc; ++k) P.mu[k] = rows[k].mu;
  if (std::visit([](auto l) { return decltype(l)::orthotropic; }, cp.law)) {
    P.mu_b.resize(nc);
    for (int k = 0; k < nc; ++k) P.mu_b[k] = cp.extra[k].mu_b;
  }
  return P;
}

void write_fclib(const Problem3& p, const std::string& path, const std::string& title,
                 const std::string& description, const Eigen::VectorXd* solution, const Eigen::VectorXd* guess) {
  check_shape(p);
  if (p.mu_b.size())
    throw std::invalid_argument(path + ": an orthotropic cone has no FCLib form (one mu a contact)");
  SpMat W = p.W;
  W.makeCompressed();
  // FCLib's structs hold non-const pointers; it only reads through them.
  fclib_matrix m{};
  m.nzmax = static_cast<int>(W.nonZeros());
  m.m = static_cast<int>(W.rows());
  m.n = static_cast<int>(W.cols());
  m.p = W.outerIndexPtr();
  m.i = W.innerIndexPtr();
  m.x = W.valuePtr();
  m.nz = -1;  // compressed columns
  Eigen::VectorXd q = p.q, mu = p.mu;
  std::string t = title, d = description, math = "";
  fclib_info info{t.data(), d.data(), math.data()};
  fclib_local L{};
  L.W = &m;
  L.mu = mu.data();
  L.q = q.data();
  L.spacedim = 3;
  L.info = &info;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  std::remove(path.c_str());  // fclib_write_local adds to an existing file
  if (!fclib_write_local(&L, path.c_str()))
    throw std::runtime_error(fmt::format("{}: FCLib could not write the problem", path));
  auto as_solution = [&](const Eigen::VectorXd& r, Eigen::VectorXd& rr, Eigen::VectorXd& u) {
    if (r.size() != p.q.size())
      throw std::invalid_argument(fmt::format("{}: a solution of {} values for {} contacts", path, r.size(), p.nc));
    rr = r;
    u = p.W * r + p.q;
    fclib_solution s{};
    s.u = u.data();
    s.r = rr.data();
    return s;
  };
  Eigen::VectorXd r1, u1, r2, u2;
  if (solution) {
    fclib_solution s = as_solution(*solution, r1, u1);
    if (!fclib_write_solution(&s, path.c_str()))
      throw std::runtime_error(fmt::format("{}: FCLib could not write the solution", path));
  }
  if (guess) {
    fclib_solution s = as_solution(*guess, r2, u2);
    if (!fclib_write_guesses(1, &s, path.c_str()))
      throw std::runtime_error(fmt::format("{}: FCLib could not write the guess", path));
  }
}

Fclib3 read_fclib(const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported here, not printed by HDF5
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw std::runtime_error(fmt::format("{}: not an HDF5 file (or cannot be opened)", path));
  bool local = false, global = false, solution = false;
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) throw std::runtime_error(fmt::format("{}: cannot open as HDF5", path));
    local = has_group(f, "/fclib_local");
    global = has_group(f, "/fclib_global");
    solution = has_group(f, "/solution");
    H5Fclose(f);
  }
  Fclib3 out;
  Problem3& p = out.problem;
  if (local) {
    std::unique_ptr<fclib_local, void (*)(fclib_local*)> L(fclib_read_local(path.c_str()),
                                                           fclib_delete_local);
    if (!L) throw std::runtime_error(fmt::format("{}: fclib_read_local failed", path));
    if (L->spacedim != 3)
      throw std::runtime_error(fmt::format("{}: space dimension {}, expected 3", path, L->spacedim));
    if (L->V || L->R) throw std::runtime_error(fmt::format("{}: mixed problem (V, R): not supported", path));
    p.W = to_eigen(L->W, "W", path);
    if (p.W.rows() != p.W.cols() || p.W.rows() % 3)
      throw std::runtime_error(fmt::format("{}: W is {}x{}", path, p.W.rows(), p.W.cols()));
    p.nc = static_cast<int>(p.W.rows() / 3);
    p.q = Eigen::Map<const Eigen::VectorXd>(L->q, 3 * p.nc);
    p.mu = Eigen::Map<const Eigen::VectorXd>(L->mu, p.nc);
  } else if (global) {
    std::unique_ptr<fclib_global, void (*)(fclib_global*)> G(fclib_read_global(path.c_str()),
                                                             fclib_delete_global);
    if (!G) throw std::runtime_error(fmt::format("{}: fclib_read_global failed", path));
    if (G->spacedim != 3)
      throw std::runtime_error(fmt::format("{}: space dimension {}, expected 3", path, G->spacedim));
    if (G->G) throw std::runtime_error(fmt::format("{}: equality constraints (G): not supported", path));
    const SpMat M = to_eigen(G->M, "M", path), H = to_eigen(G->H, "H", path);
    if (M.rows() != M.cols() || H.rows() != M.rows() || H.cols() % 3)
      throw std::runtime_error(fmt::format("{}: M {}x{}, H {}x{}", path, M.rows(), M.cols(), H.rows(), H.cols()));
    p.nc = static_cast<int>(H.cols() / 3);
    out.global = true;
    out.bodies_dofs = static_cast<int>(M.rows());
    // W = H^T M^-1 H, q = H^T M^-1 f + w (FCLib: M v = H r + f, u = H^T v + w).
    Eigen::SimplicialLDLT<SpMat> chol(M);
    if (chol.info() != Eigen::Success || chol.vectorD().minCoeff() <= 0)
      throw std::runtime_error(fmt::format("{}: M is not symmetric positive definite", path));
    const SpMat X = chol.solve(H);
    p.W = SpMat(H.transpose() * X);
    p.W.prune(0.0);
    p.W.makeCompressed();
    const Eigen::VectorXd f = Eigen::Map<const Eigen::VectorXd>(G->f, M.rows());
    p.q = H.transpose() * chol.solve(f) + Eigen::Map<const Eigen::VectorXd>(G->w, 3 * p.nc);
    p.mu = Eigen::Map<const Eigen::VectorXd>(G->mu, p.nc);
  } else {
    throw std::runtime_error(fmt::format("{}: no fclib_local or fclib_global group", path));
  }
  if (!p.q.allFinite() || !p.mu.allFinite() || (p.nc && p.mu.minCoeff() < 0))
    throw std::runtime_error(fmt::format("{}: q or mu not finite, or mu < 0", path));
  if (solution) {
    fclib_solution* s = fclib_read_solution(path.c_str());
    if (s && s->r) out.r_ref = Eigen::Map<const Eigen::VectorXd>(s->r, 3 * p.nc);
    if (s && s->v && out.global) out.v_ref = Eigen::Map<const Eigen::VectorXd>(s->v, out.bodies_dofs);
    if (s) fclib_delete_solutions(s, 1);
  }
  return out;
}

Problem3 read_dat3(const std::string& path) {
  SiconosDat d = read_siconos_dat(path, 3);
  Problem3 p;
  p.nc = d.nc;
  p.W = std::move(d.W);
  p.q = std::move(d.q);
  p.mu = std::move(d.mu);
  return p;
}

Residual problem_residual(const Problem3& p, const Eigen::VectorXd& r) {
  check_shape(p);
  if (p.nc == 0) return {};
  const Eigen::VectorXd u = p.W * r + p.q;
  return matrix_form::residual_over(p.nc, [&](int k) {
    const Vec3 rk = r.segment<3>(3 * k);
    return std::pair{law_residual3(u.segment<3>(3 * k), rk, p.cone(k), 0.0, 1.0 / p.W.coeff(3 * k, 3 * k)),
                     rk.norm()};
  });
}

double siconos_error(const Problem3& p, const Eigen::VectorXd& r) {
  check_shape(p);
  const Eigen::VectorXd u = p.W * r + p.q;
  return matrix_form::siconos_over(
      p.q, p.nc, [&](int k) { return siconos_term3(u.segment<3>(3 * k), r.segment<3>(3 * k), p.mu[k]); });
}

namespace {

// The 3D rows of matrix_form::nlgs. As in 2D: the row holds the symmetric
// part S of W_kk (a condensed W is symmetric only to round-off) and the
// law sees b = u_k - S r_k with u_k from the true blocks, so a fixed point
// satisfies u = W r + q exactly.
struct Form3 {
  static constexpr int dim = 3;
  using Row = Row3;
  using Block = Mat3;
  using Coupling = MatrixCoupling3;
  const Problem3& p;

  static Block zero() { return Mat3::Zero(); }
  static void add(Mat3& b, int i, int j, double v) { b(i, j) += v; }
  template <class Blocks>
  bool row(int k, const Blocks& blocks, const Eigen::VectorXd& r, Row3& w) const {
    Mat3 Wkk = Mat3::Zero();
    for (const auto& e : blocks)
      if (e.first == k) Wkk = e.second;
    w.S = 0.5 * (Wkk + Wkk.transpose());
    if (!(w.S(0, 0) > 0.0) || (p.mu[k] > 0 && w.S.llt().info() != Eigen::Success))
      throw std::invalid_argument(
          fmt::format("contact {}: diagonal block W_kk not positive definite (W_nn = {})", k, w.S(0, 0)));
    w.b = p.q.segment<3>(3 * k);
    w.r = r.segment<3>(3 * k);
    w.cone = p.cone(k);
    w.adh = 0.0;
    return w.cone.mu_a > 0 || w.cone.mu_b > 0;
  }
  template <class Observer>
  SolveStats solve(bool friction, std::vector<Row3>& rows, const Colouring& col, const MatrixCoupling3& c,
                   const SolverParams& prm, Observer&& observer) const {
    std::vector<NoDof>* nodofs = nullptr;
    return friction ? sweep::solve<Coulomb3>(rows, col, c, prm, nodofs, observer)
                    : sweep::solve<Frictionless3>(rows, col, c, prm, nodofs, observer);
  }
  static void store(const Row3& w, Eigen::VectorXd& r, int k) { r.segment<3>(3 * k) = w.r; }
};

}  // namespace

NlgsStats solve_nlgs(const Problem3& p, Eigen::VectorXd& r, const NlgsOptions& opt) {
  check_shape(p);
  return matrix_form::nlgs(p, r, opt, Form3{p});
}

}  // namespace cd
