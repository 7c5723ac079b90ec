#include "problem3.hpp"

#include <algorithm>
#include <cstdio>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
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

// ---- reading FCLib files ----------------------------------------------------
//
// The file is read here with the HDF5 C API, not with fclib_read_local or
// fclib_read_global: those allocate every array from the counts the file
// states (W/m, W/nzmax, ...) and read each dataset whole into it without
// looking at its extent, so a dataset longer than its count overruns the heap
// and a shorter one leaves values never written (and a failed read goes on
// regardless). Here every dataset's extent, type and storage is checked
// before anything is allocated for it, every count against the others, every
// sparse structure before it is used, and every value is finite. The layout
// is FCLib's: /fclib_local/{spacedim, W/{m, n, nz, nzmax, p, i, x},
// vectors/{q, mu}}, /fclib_global/{spacedim, M/..., H/..., vectors/{f, w, mu}},
// /solution/{r, v}.

// An HDF5 identifier, closed with its scope.
class H5Handle {
 public:
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~H5Handle() {
    if (id_ >= 0) close_(id_);
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// A sparse matrix's counts as the file states them (FCLib's fclib_matrix):
// nz >= 0 triplets, -1 compressed columns, -2 compressed rows.
struct SparseHeader {
  std::string group, name;  // "/fclib_local/W", "W"
  long long m = 0, n = 0, nz = 0, nzmax = 0;
};

class FclibFile {
 public:
  explicit FclibFile(std::string path)
      : path_(std::move(path)), file_(H5Fopen(path_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose) {
    if (file_.get() < 0) fail("cannot open as HDF5");
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(fmt::format("{}: {}", path_, what));
  }

  // Whether the object `name` (an absolute path) exists: each link on the
  // way is looked up in turn, as H5Lexists wants.
  bool has(const std::string& name) const {
    for (std::size_t k = name.find('/', 1);; k = name.find('/', k + 1)) {
      if (H5Lexists(file_.get(), name.substr(0, k).c_str(), H5P_DEFAULT) <= 0) return false;
      if (k == std::string::npos) return true;
    }
  }

  // A count of the header: one integer that fits an int.
  long long count(const std::string& name) const {
    const std::vector<long long> v = read_ints(name, 1, "expected 1 (a count)");
    if (v[0] < INT_MIN || v[0] > INT_MAX) fail(fmt::format("dataset {} is {}, out of range", name, v[0]));
    return v[0];
  }

  // Exactly n integers (what the header says, `says`).
  std::vector<long long> read_ints(const std::string& name, long long n, const std::string& says) const {
    return read<long long>(name, n, n, says, H5T_INTEGER, H5T_NATIVE_LLONG);
  }

  // n_min to n_max finite numbers.
  std::vector<double> read_doubles(const std::string& name, long long n_min, long long n_max, const std::string& says,
                                   bool fill_allowed = false) const {
    std::vector<double> v = read<double>(name, n_min, n_max, says, H5T_FLOAT, H5T_NATIVE_DOUBLE, fill_allowed);
    for (std::size_t k = 0; k < v.size(); ++k)
      if (!std::isfinite(v[k])) fail(fmt::format("dataset {}: value {} is {}, not a finite number", name, k, v[k]));
    return v;
  }

  Eigen::VectorXd read_vector(const std::string& name, long long n, const std::string& says,
                              bool fill_allowed = false) const {
    const std::vector<double> v = read_doubles(name, n, n, says, fill_allowed);
    return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  }

  SparseHeader sparse_header(const std::string& group, const std::string& name) const {
    if (!has(group)) fail(fmt::format("group {} ({}) is missing", group, name));
    SparseHeader h{group, name, count(group + "/m"), count(group + "/n"), count(group + "/nz"),
                   count(group + "/nzmax")};
    for (const auto& [key, v] : {std::pair{"m", h.m}, std::pair{"n", h.n}, std::pair{"nzmax", h.nzmax}})
      if (v < 0) fail(fmt::format("dataset {}/{} is {}: a size must be >= 0", group, key, v));
    if (h.nz < -2)
      fail(fmt::format("dataset {}/nz is {}: expected -1 (compressed columns), -2 (compressed rows) or a "
                       "number of triplets >= 0", group, h.nz));
    if (h.nz > h.nzmax)
      fail(fmt::format("dataset {}/nz is {}, more than {}/nzmax = {}", group, h.nz, group, h.nzmax));
    return h;
  }

  // The matrix a checked header describes: its arrays' lengths, the
  // pointers (from 0, never decreasing, at most nzmax) and indices (within
  // the matrix) are checked before any is used. Triplets: p holds column
  // indices and i row indices (as the data and Siconos' reader have it; the
  // header's comment says the opposite); duplicates are summed.
  SpMat sparse(const SparseHeader& h) const {
    const std::string& g = h.group;
    matrix_form::Triplets t;
    auto add = [&](long long i, long long j, double v) {
      t.emplace_back(static_cast<int>(i), static_cast<int>(j), v);
    };
    auto check_index = [&](const std::string& what, std::size_t k, long long v, long long size,
                           const char* of) {
      if (v < 0 || v >= size)
        fail(fmt::format("dataset {}/{}: value {} is {}, outside the {} {} of {} ({}x{})", g, what, k, v, size, of,
                         h.name, h.m, h.n));
    };
    if (h.nz >= 0) {
      const std::string says = fmt::format("the header says {} ({}/nz)", h.nz, g);
      const std::vector<long long> col = read_ints(g + "/p", h.nz, says), row = read_ints(g + "/i", h.nz, says);
      const std::vector<double> x =
          read_doubles(g + "/x", h.nz, h.nzmax,
                       fmt::format("the header says {} to {} ({}/nz to {}/nzmax)", h.nz, h.nzmax, g, g));
      t.reserve(col.size());
      for (std::size_t k = 0; k < col.size(); ++k) {
        check_index("p", k, col[k], h.n, "columns");
        check_index("i", k, row[k], h.m, "rows");
        add(row[k], col[k], x[k]);
      }
    } else {
      const bool cols = h.nz == -1;
      const long long outer = cols ? h.n : h.m, inner = cols ? h.m : h.n;
      const std::vector<long long> p = read_ints(
          g + "/p", outer + 1,
          fmt::format("the header says {} ({}/{} + 1, compressed {})", outer + 1, g, cols ? "n" : "m",
                      cols ? "columns" : "rows"));
      const std::string says = fmt::format("the header says {} ({}/nzmax)", h.nzmax, g);
      const std::vector<long long> idx = read_ints(g + "/i", h.nzmax, says);
      const std::vector<double> x = read_doubles(g + "/x", h.nzmax, h.nzmax, says);
      if (p[0] != 0) fail(fmt::format("dataset {}/p: value 0 is {}, expected 0", g, p[0]));
      for (std::size_t o = 1; o < p.size(); ++o) {
        if (p[o] < p[o - 1])
          fail(fmt::format("dataset {}/p: value {} is {}, less than value {} ({}): pointers never decrease", g, o,
                           p[o], o - 1, p[o - 1]));
        if (p[o] > h.nzmax)
          fail(fmt::format("dataset {}/p: value {} is {}, past the {} entries of {}/nzmax", g, o, p[o], h.nzmax, g));
      }
      t.reserve(static_cast<std::size_t>(p.back()));
      for (long long o = 0; o < outer; ++o)
        for (long long k = p[o]; k < p[o + 1]; ++k) {
          check_index("i", k, idx[k], inner, cols ? "rows" : "columns");
          if (cols) add(idx[k], o, x[k]);
          else add(o, idx[k], x[k]);
        }
    }
    SpMat A(h.m, h.n);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
  }

 private:
  // A 1-D (or scalar) dataset of class `cls`, of n_min to n_max values,
  // which the file really holds: its extent is checked before anything is
  // allocated, and its storage is in this file (not external or virtual)
  // and holds them (an unfiltered dataset stores at least its size in
  // bytes), so that no count the file states makes a large allocation
  // without the data to fill it. A dataset never written, or written in
  // part, reads as its fill value where it was not: refused, unless
  // `fill_allowed` and a fill value is defined (the stored solution: its
  // size is that of q, which is stored).
  template <class T>
  std::vector<T> read(const std::string& name, long long n_min, long long n_max, const std::string& says,
                      H5T_class_t cls, hid_t memtype, bool fill_allowed = false) const {
    if (!has(name)) fail(fmt::format("dataset {} is missing", name));
    const H5Handle ds(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (ds.get() < 0) fail(fmt::format("{} is not a dataset (or cannot be opened)", name));
    const H5Handle type(H5Dget_type(ds.get()), H5Tclose), space(H5Dget_space(ds.get()), H5Sclose),
        dcpl(H5Dget_create_plist(ds.get()), H5Pclose);
    if (type.get() < 0 || space.get() < 0 || dcpl.get() < 0) fail(fmt::format("dataset {} cannot be read", name));
    if (H5Tget_class(type.get()) != cls)
      fail(fmt::format("dataset {} does not hold {}", name,
                       cls == H5T_INTEGER ? "integers" : "floating-point numbers"));
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0 || rank > 1)
      fail(fmt::format("dataset {} has rank {}, expected a list of values (rank 1)", name, rank));
    hsize_t n = 1;
    if (H5Sget_simple_extent_type(space.get()) == H5S_NULL) n = 0;
    else if (rank == 1 && H5Sget_simple_extent_dims(space.get(), &n, nullptr) != 1)
      fail(fmt::format("dataset {} cannot be read", name));
    if (n < static_cast<hsize_t>(n_min) || n > static_cast<hsize_t>(n_max))
      fail(fmt::format("dataset {} has {} value{}, {}", name, n, n == 1 ? "" : "s", says));
    if (n == 0) return {};
    const H5D_layout_t layout = H5Pget_layout(dcpl.get());
    if (layout == H5D_VIRTUAL || H5Pget_external_count(dcpl.get()) != 0)
      fail(fmt::format("dataset {} keeps its values in another file", name));
    H5D_space_status_t status;
    H5D_fill_value_t fill;
    const hsize_t bytes = H5Dget_storage_size(ds.get());
    const bool stored = H5Dget_space_status(ds.get(), &status) >= 0 && status == H5D_SPACE_STATUS_ALLOCATED &&
                        (H5Pget_nfilters(dcpl.get()) != 0 || bytes / n >= H5Tget_size(type.get()));
    if (!stored && (!fill_allowed || H5Pfill_value_defined(dcpl.get(), &fill) < 0 || fill == H5D_FILL_VALUE_UNDEFINED))
      fail(fmt::format("dataset {} has {} value{} but the file stores only {} bytes of them", name, n,
                       n == 1 ? "" : "s", bytes));
    std::vector<T> v(n);
    if (H5Dread(ds.get(), memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
      fail(fmt::format("HDF5 cannot read dataset {} (damaged, or a filter it lacks)", name));
    return v;
  }

  std::string path_;
  H5Handle file_;
};

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
  // an inverse mass, so W = H^T MH has no structural entry through a wall;
  // with inertia tensors (polyhedra), a body's angular block of M^-1 is its
  // world inverse inertia J (zero for a driven body).
  const bool tensors = !cp.inv_inertia.empty();
  if (tensors && cp.inv_inertia.size() != cp.vel.size())
    throw std::invalid_argument(fmt::format("3D contact problem: {} inverse inertia tensors for {} bodies",
                                            cp.inv_inertia.size(), cp.vel.size()));
  matrix_form::Triplets h, mh;
  h.reserve(36 * static_cast<std::size_t>(nc));
  mh.reserve(36 * static_cast<std::size_t>(nc));
  auto add = [&](int b, const Vec3& lin, const Vec3& ang, int col) {
    for (int i = 0; i < 3; ++i) {
      h.emplace_back(6 * b + i, col, lin[i]);
      h.emplace_back(6 * b + 3 + i, col, ang[i]);
      if (V[b].inv_m != 0.0) mh.emplace_back(6 * b + i, col, V[b].inv_m * lin[i]);
      if (!tensors && V[b].inv_I != 0.0) mh.emplace_back(6 * b + 3 + i, col, V[b].inv_I * ang[i]);
    }
    if (tensors && !cp.inv_inertia[b].isZero(0.0)) {
      const Vec3 Ja = cp.inv_inertia[b] * ang;
      for (int i = 0; i < 3; ++i) mh.emplace_back(6 * b + 3 + i, col, Ja[i]);
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
  const FclibFile file(path);
  Fclib3 out;
  Problem3& p = out.problem;
  // "the header says N (3 × nc contacts)"
  const auto per_contact = [&](int k) {
    return fmt::format("the header says {} ({}{} contacts)", static_cast<long long>(k) * p.nc,
                       k == 1 ? "" : fmt::format("{} × ", k), p.nc);
  };
  const auto spacedim = [&](const std::string& name) {
    const long long d = file.count(name);
    if (d != 3) file.fail(fmt::format("dataset {} is {}: space dimension {}, expected 3", name, d, d));
  };
  if (file.has("/fclib_local")) {
    spacedim("/fclib_local/spacedim");
    if (file.has("/fclib_local/V") || file.has("/fclib_local/R"))
      file.fail("mixed problem (V, R): not supported");
    const SparseHeader W = file.sparse_header("/fclib_local/W", "W");
    if (W.m != W.n || W.m % 3)
      file.fail(fmt::format("W is {}x{} (datasets /fclib_local/W/m and n): expected square, 3 rows a contact",
                            W.m, W.n));
    p.nc = static_cast<int>(W.m / 3);
    // q first: the file holds its 3nc values, which bounds what W's size
    // makes the matrix allocate (its column pointers).
    p.q = file.read_vector("/fclib_local/vectors/q", 3LL * p.nc, per_contact(3));
    p.mu = file.read_vector("/fclib_local/vectors/mu", p.nc, per_contact(1));
    p.W = file.sparse(W);
  } else if (file.has("/fclib_global")) {
    spacedim("/fclib_global/spacedim");
    if (file.has("/fclib_global/G")) file.fail("equality constraints (G): not supported");
    const SparseHeader Mh = file.sparse_header("/fclib_global/M", "M"),
                       Hh = file.sparse_header("/fclib_global/H", "H");
    if (Mh.m != Mh.n || Mh.m == 0)
      file.fail(fmt::format("M is {}x{} (datasets /fclib_global/M/m and n): expected square, one row a body dof",
                            Mh.m, Mh.n));
    if (Hh.m != Mh.m || Hh.n % 3)
      file.fail(fmt::format("H is {}x{} and M {}x{} (datasets /fclib_global/H/m and n): expected a row a body dof "
                            "and 3 columns a contact", Hh.m, Hh.n, Mh.m, Mh.n));
    p.nc = static_cast<int>(Hh.n / 3);
    out.global = true;
    out.bodies_dofs = static_cast<int>(Mh.m);
    // The vectors first: the file holds them, which bounds what the sizes
    // of M and H make the matrices allocate.
    const Eigen::VectorXd f = file.read_vector(
        "/fclib_global/vectors/f", Mh.m, fmt::format("the header says {} (/fclib_global/M/m, the body dofs)", Mh.m));
    const Eigen::VectorXd w = file.read_vector("/fclib_global/vectors/w", 3LL * p.nc, per_contact(3));
    p.mu = file.read_vector("/fclib_global/vectors/mu", p.nc, per_contact(1));
    const SpMat M = file.sparse(Mh), H = file.sparse(Hh);
    // W = H^T M^-1 H, q = H^T M^-1 f + w (FCLib: M v = H r + f, u = H^T v + w).
    Eigen::SimplicialLDLT<SpMat> chol(M);
    if (chol.info() != Eigen::Success || chol.vectorD().minCoeff() <= 0)
      file.fail("M is not symmetric positive definite");
    const SpMat X = chol.solve(H);
    p.W = SpMat(H.transpose() * X);
    p.W.prune(0.0);
    p.W.makeCompressed();
    p.q = H.transpose() * chol.solve(f) + w;
    if (!p.W.coeffs().allFinite() || !p.q.allFinite())
      file.fail("W or q, condensed from M, H, f and w, is not finite");
  } else {
    file.fail("no fclib_local or fclib_global group");
  }
  for (Eigen::Index k = 0; k < p.mu.size(); ++k)
    if (p.mu[k] < 0)
      file.fail(fmt::format("dataset /fclib_{}/vectors/mu: value {} is {}, a friction coefficient is >= 0",
                            out.global ? "global" : "local", k, p.mu[k]));
  // The stored solution, if any: r (3 a contact) and, global, v. Siconos'
  // global files declare both and never write them: they read as HDF5's fill
  // value, 0 (GlobalFilesStoreZeroAsSolution).
  if (file.has("/solution/r")) out.r_ref = file.read_vector("/solution/r", 3LL * p.nc, per_contact(3), true);
  if (out.global && file.has("/solution/v"))
    out.v_ref = file.read_vector("/solution/v", out.bodies_dofs,
                                 fmt::format("the header says {} (/fclib_global/M/m, the body dofs)", out.bodies_dofs),
                                 true);
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
