#include "problem.hpp"

#include <algorithm>
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

namespace cd {

namespace {

// Whitespace-token reader over the whole file, keeping line numbers for the
// error messages. The CSparse listing mixes free text (two header lines) with
// numbers, so the reader can also hand out whole lines.
class Reader {
 public:
  Reader(std::istream& in, std::string name) : name_(std::move(name)) {
    for (std::string l; std::getline(in, l);) lines_.push_back(std::move(l));
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(fmt::format("{}:{}: {}", name_, last_ + 1, what));
  }

  // Next token, empty at end of file.
  std::string_view token() {
    while (li_ < lines_.size()) {
      const std::string& l = lines_[li_];
      while (col_ < l.size() && std::isspace(static_cast<unsigned char>(l[col_]))) ++col_;
      if (col_ < l.size()) {
        const std::size_t b = col_;
        while (col_ < l.size() && !std::isspace(static_cast<unsigned char>(l[col_]))) ++col_;
        last_ = li_;
        return std::string_view(l).substr(b, col_ - b);
      }
      ++li_;
      col_ = 0;
    }
    last_ = lines_.empty() ? 0 : lines_.size() - 1;
    return {};
  }

  // The line after the one the cursor is on (the rest of that one is dropped).
  const std::string& next_line(const char* what) {
    if (col_ > 0) {
      ++li_;
      col_ = 0;
    }
    if (li_ >= lines_.size()) fail(fmt::format("unexpected end of file, expected {}", what));
    last_ = li_;
    return lines_[li_++];
  }

  std::string_view need(const std::string& what) {
    const std::string_view t = token();
    if (t.empty()) fail(fmt::format("unexpected end of file, expected {}", what));
    for (char c : t)
      if (!std::isprint(static_cast<unsigned char>(c)))
        fail(
            fmt::format("binary data where {} was expected: not a .dat text file "
                        "(FCLib .hdf5 problems are not read)",
                        what));
    return t;
  }

  void expect(std::string_view word, const std::string& where) {
    const std::string_view t = need(fmt::format("'{}' {}", word, where));
    if (t != word) fail(fmt::format("expected '{}' {}, got '{}'", word, where, t));
  }

  long long integer(const std::string& what, long long lo, long long hi) {
    const std::string t(need(what));
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (*end != '\0' || errno != 0)
      fail(fmt::format("expected {} (an integer), got '{}'", what, t));
    if (v < lo || v > hi) fail(fmt::format("{} is {}, expected {} to {}", what, v, lo, hi));
    return v;
  }

  double number(const std::string& what) {
    const std::string t(need(what));
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0') fail(fmt::format("expected {} (a number), got '{}'", what, t));
    if (!std::isfinite(v)) fail(fmt::format("{} is '{}', not a finite number", what, t));
    return v;
  }

 private:
  std::string name_;
  std::vector<std::string> lines_;
  std::size_t li_ = 0, col_ = 0, last_ = 0;
};

using Triplets = std::vector<Eigen::Triplet<double>>;

// Storage 0: "rows<TAB>cols" again, then the column-major array (Siconos
// writes matrix0 in its own order, size1 values a line: a text line is a
// column of W).
void read_dense(Reader& rd, long long n, Triplets& t) {
  const long long r2 = rd.integer("the dense row count", 0, LLONG_MAX);
  const long long c2 = rd.integer("the dense column count", 0, LLONG_MAX);
  if (r2 != n || c2 != n)
    rd.fail(fmt::format("dense W says {}x{}, header said {}x{}", r2, c2, n, n));
  for (long long j = 0; j < n; ++j)
    for (long long i = 0; i < n; ++i) {
      const double v = rd.number(fmt::format("W({},{})", i, j));
      if (v != 0.0) t.emplace_back(static_cast<int>(i), static_cast<int>(j), v);
    }
}

// Storage 2: NumericsSparseMatrix origin, then CSparse's own listing: a
// version line, "M-by-N, nzmax: K nnz: K, 1-norm: X", then per column
// "col j : locations a to b" and b - a + 1 lines "row : value"; or, for a
// triplet matrix, "triplet: M-by-N, nzmax: K nnz: K" and K lines
// "row col : value".
void read_sparse(Reader& rd, long long n, Triplets& t) {
  rd.integer("the sparse origin", 0, 3);
  rd.next_line("the CSparse version line");
  const std::string& h = rd.next_line("the CSparse size line");
  long long m = 0, nn = 0, nzmax = 0, nnz = 0;
  const bool triplet = h.rfind("triplet:", 0) == 0;
  const int got = std::sscanf(h.c_str(),
                              triplet ? "triplet: %lld-by-%lld, nzmax: %lld nnz: %lld"
                                      : "%lld-by-%lld, nzmax: %lld nnz: %lld",
                              &m, &nn, &nzmax, &nnz);
  if (got != 4)
    rd.fail(
        fmt::format("expected the CSparse size line '[triplet: ]M-by-N, nzmax: K nnz: K', "
                    "got '{}'",
                    h));
  if (m != n || nn != n)
    rd.fail(fmt::format("sparse W says {}x{}, header said {}x{}", m, nn, n, n));
  if (nnz < 0 || nnz > n * n) rd.fail(fmt::format("nnz {} is impossible for {}x{}", nnz, n, n));
  t.reserve(nnz);
  if (triplet) {
    for (long long p = 0; p < nnz; ++p) {
      const std::string e = fmt::format("in entry {} of {}", p, nnz);
      const long long i = rd.integer("a row index " + e, 0, n - 1);
      const long long j = rd.integer("a column index " + e, 0, n - 1);
      rd.expect(":", e);
      t.emplace_back(static_cast<int>(i), static_cast<int>(j), rd.number("a value " + e));
    }
    return;
  }
  long long next = 0;  // CSparse locations run on across columns
  for (long long j = 0; j < n; ++j) {
    const std::string c = fmt::format("in column {} of {}", j, n);
    rd.expect("col", c);
    const long long jj = rd.integer("the column number " + c, 0, n - 1);
    if (jj != j) rd.fail(fmt::format("column {} listed where column {} was expected", jj, j));
    rd.expect(":", c);
    rd.expect("locations", c);
    const long long a = rd.integer("the first location " + c, 0, nnz);
    rd.expect("to", c);
    const long long b = rd.integer("the last location " + c, a - 1, nnz - 1);
    if (a != next) rd.fail(fmt::format("column {} starts at location {}, expected {}", j, a, next));
    for (long long p = a; p <= b; ++p) {
      const std::string e = fmt::format("at location {} in column {}", p, j);
      const long long i = rd.integer("a row index " + e, 0, n - 1);
      rd.expect(":", e);
      t.emplace_back(static_cast<int>(i), static_cast<int>(j), rd.number("a value " + e));
    }
    next = b + 1;
  }
  if (next != nnz)
    rd.fail(fmt::format("the columns hold {} entries, the header said {}", next, nnz));
}

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
  Reader rd(in, name);
  Problem p;
  p.dim = static_cast<int>(rd.integer("the dimension", 1, 3));
  if (p.dim != 2)
    rd.fail(fmt::format("dimension {}: only 2D problems (dimension 2) are supported", p.dim));
  p.nc = static_cast<int>(rd.integer("the number of contacts", 0, INT_MAX / 4));
  const long long n = 2LL * p.nc;
  const long long storage = rd.integer("the storage type of W", 0, 2);
  const long long rows = rd.integer("the row count of W", 0, LLONG_MAX);
  const long long cols = rd.integer("the column count of W", 0, LLONG_MAX);
  if (rows != n || cols != n)
    rd.fail(
        fmt::format("W is {}x{}, expected {}x{} for {} contacts in 2D", rows, cols, n, n, p.nc));
  Triplets t;
  if (storage == 0) {
    read_dense(rd, n, t);
  } else if (storage == 2) {
    read_sparse(rd, n, t);
  } else {
    rd.fail("W storage type 1 (sparse block) is not supported: only 0 (dense) and 2 (sparse)");
  }
  p.W.resize(n, n);
  p.W.setFromTriplets(t.begin(), t.end());  // sorts rows; a repeated entry is summed
  p.W.makeCompressed();
  p.q.resize(n);
  for (long long i = 0; i < n; ++i) p.q[i] = rd.number(fmt::format("q[{}] (of {})", i, n));
  p.mu.resize(p.nc);
  for (int k = 0; k < p.nc; ++k) {
    p.mu[k] = rd.number(fmt::format("mu[{}] (of {})", k, p.nc));
    if (p.mu[k] < 0) rd.fail(fmt::format("mu[{}] = {} is negative", k, p.mu[k]));
  }
  // Anything after mu (some dumps append a solution) is ignored.
  return p;
}

Problem read_problem(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open for reading", path));
  return read_problem(in, path);
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

Problem assemble_problem(const Bodies& bodies, const std::vector<ContactRow>& rows, bool rotation) {
  const int nc = static_cast<int>(rows.size());
  const int nb = static_cast<int>(bodies.size());
  // H (3nb x 2nc): column 2k is the normal of contact k, 2k+1 its tangent;
  // body rows 3b (x), 3b+1 (y), 3b+2 (rotation). MH = M^-1 H keeps only the
  // dynamic bodies, so W = H^T MH has no structural entry through a wall.
  Triplets h, mh;
  h.reserve(12 * nc);
  mh.reserve(12 * nc);
  const auto& V = bodies.vel;
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
  Eigen::SparseMatrix<double> H(3 * nb, 2 * nc), MH(3 * nb, 2 * nc);
  H.setFromTriplets(h.begin(), h.end());
  MH.setFromTriplets(mh.begin(), mh.end());
  Eigen::VectorXd U(3 * nb), p(2 * nc), b(2 * nc);
  for (int i = 0; i < nb; ++i) U.segment<3>(3 * i) << V[i].vx, V[i].vy, V[i].w;
  for (int k = 0; k < nc; ++k) {
    p.segment<2>(2 * k) << rows[k].pn, rows[k].pt;
    b.segment<2>(2 * k) << rows[k].bn, rows[k].bt;
  }
  Problem P;
  P.nc = nc;
  P.W = Eigen::SparseMatrix<double>(H.transpose() * MH);
  P.W.makeCompressed();
  P.q = H.transpose() * U - P.W * p + b;
  P.mu.resize(nc);
  for (int k = 0; k < nc; ++k) P.mu[k] = rows[k].mu;
  return P;
}

Residual problem_residual(const Problem& p, const Eigen::VectorXd& r) {
  check_shape(p);
  if (r.size() != p.q.size())
    throw std::invalid_argument(fmt::format("r has {} entries, expected {}", r.size(), p.q.size()));
  const Eigen::VectorXd u = p.W * r + p.q;
  return residual_of(p, r, u, checked_diagonal(p));
}

NlgsStats solve_nlgs(const Problem& p, Eigen::VectorXd& r, const NlgsOptions& opt) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  check_shape(p);
  const int nc = p.nc;
  if (r.size() != 2 * nc) r = Eigen::VectorXd::Zero(2 * nc);
  NlgsStats st;
  const Eigen::VectorXd diag = checked_diagonal(p);
  // Local blocks. A dumped W need not be exactly symmetric (the slider-crank
  // files' W_nt and W_tn differ by 6e-7 relative), but solve_coulomb takes
  // a symmetric block. The local solve therefore uses the symmetric part S of
  // W_kk and the skew part rides with the other contacts' terms in b:
  //   b = u_k - S r_k,   u_k = b + S r_k'   at the local solution,
  // and u_k is then updated with the true columns of W, so a fixed point of
  // the sweep satisfies u = W r + q exactly. (Rejected: a non-symmetric local
  // solver, only to serve dumped round-off.)
  std::vector<Block> blk(nc);
  for (int k = 0; k < nc; ++k) {
    const double wnt = 0.5 * (p.W.coeff(2 * k, 2 * k + 1) + p.W.coeff(2 * k + 1, 2 * k));
    blk[k] = {diag[2 * k], wnt, diag[2 * k + 1]};
    if (p.mu[k] > 0 && !(blk[k].wnn * blk[k].wtt - wnt * wnt > 0))
      throw std::invalid_argument(fmt::format("contact {}: singular block W_kk with friction", k));
  }
  Eigen::VectorXd u = p.W * r + p.q;
  using It = Eigen::SparseMatrix<double>::InnerIterator;
  for (int s = 1; s <= opt.max_sweeps && nc > 0; ++s) {
    double d2max = 0, rsum = 0;
    for (int k = 0; k < nc; ++k) {
      const Block& B = blk[k];
      const double rn = r[2 * k], rt = r[2 * k + 1];
      const double bn = u[2 * k] - (B.wnn * rn + B.wnt * rt);
      const double bt = u[2 * k + 1] - (B.wnt * rn + B.wtt * rt);
      double pn, pt = 0.0;
      if (p.mu[k] > 0)
        solve_coulomb(bn, bt, B, p.mu[k], 0.0, pn, pt);
      else
        solve_frictionless(bn, B, 0.0, pn);
      const double dn = pn - rn, dt = pt - rt;
      // u += W(:, k) dr_k: W's columns play the part of the bodies'
      // velocity increments in the simulator's sweep.
      if (dn != 0.0)
        for (It it(p.W, 2 * k); it; ++it) u[it.row()] += it.value() * dn;
      if (dt != 0.0)
        for (It it(p.W, 2 * k + 1); it; ++it) u[it.row()] += it.value() * dt;
      r[2 * k] = pn;
      r[2 * k + 1] = pt;
      d2max = std::max(d2max, dn * dn + dt * dt);
      rsum += std::sqrt(pn * pn + pt * pt);
    }
    st.sweeps = s;
    const double scale = rsum > 0 ? rsum / nc : 1.0;
    st.dr_rel = std::sqrt(d2max) / scale;
    const bool dr_ok = st.dr_rel < opt.tol;
    if (dr_ok || s % std::max(1, opt.check_every) == 0 || s == opt.max_sweeps) {
      u = p.W * r + p.q;  // also clears the round-off the increments accumulate
      st.residual = residual_of(p, r, u, diag);
      st.history.push_back({s, st.dr_rel, st.residual.max, st.residual.mean});
      if (dr_ok && st.residual.max < opt.tol) {
        st.converged = true;
        break;
      }
    }
  }
  if (nc == 0) st.converged = true;
  if (st.history.empty() || st.history.back().sweep != st.sweeps)
    st.residual = residual_of(p, r, p.W * r + p.q, diag);
  st.time = std::chrono::duration<double>(clock::now() - t0).count();
  return st;
}

}  // namespace cd
