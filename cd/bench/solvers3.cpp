// solvers3: accelerations of the 3D sweep on a frozen step, by
// what they do to the loaded-contact set, the figure whose slow convergence
// biases z in dense shear (docs/accuracy.md, "What z measures"). A .cdp3 step
// (cdsim --dump-problem) is put in matrix form (to_matrix: W = H^T M^-1 H
// with the cell dofs condensed, q, mu) and solved from its warm start by:
//   gs        symmetric Gauss-Seidel in row order with the exact local solve
//             on the symmetric part of W_kk (what the production sweep
//             computes, up to the order of the rows and the cell dof, which
//             the matrix form solves as a row of W instead of a damped step);
//   nncg      gs's symmetric pair as the map of the nonsmooth nonlinear
//             conjugate gradient (Silcowitz, Niebe & Erleben, VRIPHYS 2010):
//             x+ = G(x) + beta p, p+ = beta p + (G(x) - x),
//             beta = |G(x) - x|^2 / |previous|^2 (Fletcher-Reeves), p
//             cleared when beta > 1;
//   anderson:M  core/sweep.hpp's Anderson mixing of the pair map over M
//             pairs with its stall rule (Stall), the production code itself
//             on these rows; anderson:M:raw without the stall rule;
//   sm:P:C    core/sweep.hpp's subspace correction (Subspace: the
//             sticking and sliding rows' linear problem by at most C
//             Jacobi-preconditioned CG iterations) after every P-th gs
//             pair; production corrects every Subspace::kSubspaceEvery
//             pairs and holds the cell dofs, which the matrix form moves;
//             the CG iterations are reported with the sweeps ("work");
//   METHOD+scale  the method, with every pair's iterate rescaled along
//             itself, r <- s r, s the zero of the De Saxce-modified power
//             sum_k r_k.(s W r + q + mu |u_t| e_n)_k (a one-dimensional
//             coarse correction: the slow mode were the impulses' level).
// A reference is the gs solution after --ref-sweeps sweeps (or at a law
// residual of --ref-residual). Every --every pairs each method reports, on
// the iterate the pair produced (before any mixing): the law residual (max,
// mean; problem_residual), the loaded contacts (r_n > 0) and their excess
// over the reference's, the sum of normal impulses against the reference's,
// and rms |r - r_ref| / mean |r_ref|; and where the production criterion
// (rms |dr| / mean |r| of a sweep) first meets each of --tols, the same.
//   solvers3 FILE.cdp3 [--methods gs,nncg,anderson:5,sm:2:10] [--pairs 1000]
//            [--every 5] [--ref-sweeps 20000] [--tols 1e-3,1e-4] [--csv OUT.csv]
// One thread.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "contact_problem3.hpp"
#include "law3.hpp"
#include "problem3.hpp"
#include "sweep.hpp"

using namespace cd;

namespace {

// W in 3x3 blocks: row i's off-diagonal blocks (j, W_ij) and its diagonal.
struct Blocks {
  int nc = 0;
  std::vector<int> start, col;
  std::vector<Mat3> off;
  std::vector<Mat3> diag, sym;
  std::vector<Vec3> q;
  std::vector<Cone3> cone;

  explicit Blocks(const Problem3& p) : nc(p.nc), diag(p.nc, Mat3::Zero()), sym(p.nc), q(p.nc), cone(p.nc) {
    std::vector<std::vector<std::pair<int, Mat3>>> rows(nc);
    auto find = [&](int i, int j) -> Mat3& {
      for (auto& e : rows[i])
        if (e.first == j) return e.second;
      rows[i].emplace_back(j, Mat3::Zero());
      return rows[i].back().second;
    };
    for (int c = 0; c < p.W.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(p.W, c); it; ++it) {
        const int i = static_cast<int>(it.row()) / 3, j = c / 3;
        if (i == j) diag[i](it.row() % 3, c % 3) += it.value();
        else find(i, j)(it.row() % 3, c % 3) += it.value();
      }
    start.push_back(0);
    for (int i = 0; i < nc; ++i) {
      std::sort(rows[i].begin(), rows[i].end(), [](auto& a, auto& b) { return a.first < b.first; });
      for (auto& e : rows[i]) {
        col.push_back(e.first);
        off.push_back(e.second);
      }
      start.push_back(static_cast<int>(col.size()));
      sym[i] = 0.5 * (diag[i] + diag[i].transpose());
      q[i] = p.q.segment<3>(3 * i);
      cone[i] = p.cone(i);
    }
  }

  Vec3 velocity(int i, const std::vector<Vec3>& r) const {
    Vec3 u = q[i] + diag[i] * r[i];
    for (int k = start[i]; k < start[i + 1]; ++k) u.noalias() += off[k] * r[col[k]];
    return u;
  }
  void update(int i, std::vector<Vec3>& r, double& d2, double& pn) const {
    const Vec3 b = velocity(i, r) - sym[i] * r[i];
    Vec3 out;
    solve_local3(sym[i], b, cone[i], 0.0, out);
    d2 += (out - r[i]).squaredNorm();
    pn += out.norm();
    r[i] = out;
  }
  // One symmetric pair: forward, then backward. Returns the smaller of the
  // two sweeps' production criteria, rms |dr| / mean |r|, and in d2back the
  // backward sweep's sum of |dr|^2 (what the production stall rule reads).
  double pair(std::vector<Vec3>& r, double& d2back) const {
    double d1 = 0, p1 = 0, d2 = 0, p2 = 0;
    for (int i = 0; i < nc; ++i) update(i, r, d1, p1);
    for (int i = nc - 1; i >= 0; --i) update(i, r, d2, p2);
    d2back = d2;
    return std::min(std::sqrt(d1 / nc) / (p1 / nc), std::sqrt(d2 / nc) / (p2 / nc));
  }
  Eigen::VectorXd flat(const std::vector<Vec3>& r) const {
    Eigen::VectorXd x(3 * nc);
    for (int i = 0; i < nc; ++i) x.segment<3>(3 * i) = r[i];
    return x;
  }
};

struct Figures {
  double rmax, rmean, sum_n, dist;
  int loaded;
};

Figures figures(const Problem3& P, const Blocks& B, const std::vector<Vec3>& r, const std::vector<Vec3>* ref) {
  Figures f{};
  const Residual res = problem_residual(P, B.flat(r));
  f.rmax = res.max;
  f.rmean = res.mean;
  double d2 = 0, pref = 0;
  for (int i = 0; i < B.nc; ++i) {
    f.sum_n += r[i][0];
    if (r[i][0] > 0) ++f.loaded;
    if (ref) {
      d2 += (r[i] - (*ref)[i]).squaredNorm();
      pref += (*ref)[i].norm();
    }
  }
  f.dist = ref && pref > 0 ? std::sqrt(d2 / B.nc) / (pref / B.nc) : 0;
  return f;
}

// The rows as core/sweep.hpp's Anderson sees them (its AddsImpulse
// interface): the production mixing and stall rule run here unchanged.
struct VecRows {
  static constexpr int kImpulseDim = 3;
  void read_impulse(const Vec3& r, double* x) const {
    x[0] = r[0];
    x[1] = r[1];
    x[2] = r[2];
  }
  void add_impulse(Vec3& r, const double* dx) const { r += Vec3(dx[0], dx[1], dx[2]); }
};

// The scale s that the De Saxce-modified energy prefers along r itself:
// sum_k r_k . (s W r + q + mu |u_t| e_n)_k = 0 with |u_t| at s = 1, i.e.
// s = -(q.r + sum mu r_n |u_t|) / r.W r; r <- s r (the cone is a cone, so
// s r stays admissible). Returns s.
double rescale(const Blocks& B, std::vector<Vec3>& r) {
  double rwr = 0, qr = 0, ds = 0;
  for (int i = 0; i < B.nc; ++i) {
    const Vec3 u = B.velocity(i, r);
    const Vec3 wr = u - B.q[i];
    rwr += r[i].dot(wr);
    qr += r[i].dot(B.q[i]);
    ds += B.cone[i].mu_a * r[i][0] * std::hypot(u[1], u[2]);
  }
  if (!(rwr > 0)) return 1.0;
  const double sc = std::clamp(-(qr + ds) / rwr, 0.5, 2.0);
  for (Vec3& x : r) x *= sc;
  return sc;
}

// The rows as core/sweep.hpp's Subspace sees them: W's blocks in place of
// the bodies (the cell dofs condensed in, so the corrections move them too,
// where production holds them), the sphere's diagonal preconditioner.
struct BlockRows : VecRows {
  const Blocks& B;
  const Vec3* base;
  template <class L>
  static constexpr bool kSubspaceLaw = true;
  using Scratch = int;
  Scratch subspace_scratch() const { return 0; }
  int index(const Vec3& r) const { return static_cast<int>(&r - base); }
  template <class L>
  void subspace_row(const Vec3& r, double* free, double* diag, double* u) const {
    const int i = index(r);
    Vec3 v = B.q[i] + B.diag[i] * r;
    for (int k = B.start[i]; k < B.start[i + 1]; ++k) v.noalias() += B.off[k] * base[B.col[k]];
    for (int k = 0; k < 3; ++k) {
      u[k] = v[k];
      diag[k] = B.diag[i](k, k);
    }
    const bool closed = r[0] > 0, sticks = closed && std::hypot(r[1], r[2]) < (1.0 - 1e-9) * B.cone[i].mu_a * r[0];
    free[0] = closed ? 1.0 : 0.0;
    free[1] = free[2] = sticks ? 1.0 : 0.0;
  }
  void subspace_apply(const Vec3*, const std::vector<int>& live, const double* p, double* y, Scratch&) const {
    for (const int i : live) {
      Vec3 w = B.diag[i] * Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      for (int k = B.start[i]; k < B.start[i + 1]; ++k) {
        const int j = B.col[k];
        w.noalias() += B.off[k] * Vec3(p[3 * j], p[3 * j + 1], p[3 * j + 2]);
      }
      y[3 * i] = w[0];
      y[3 * i + 1] = w[1];
      y[3 * i + 2] = w[2];
    }
  }
  template <class L>
  void subspace_put(Vec3& r, const double* d, bool sticking) const {
    Vec3 y(r[0] + d[0], r[1], r[2]);
    if (sticking) {
      y[1] += d[1];
      y[2] += d[2];
    } else {
      y.tail<2>() *= std::max(y[0], 0.0) / r[0];
    }
    r = law3_detail::project_cone(y, B.cone[index(r)].mu_a);
  }
};

struct RoundCone {};  // the law tag Subspace::correct passes on (BlockRows reads none)

void set(std::vector<Vec3>& r, const Eigen::VectorXd& x) {
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = x.segment<3>(3 * i);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Accelerations of the 3D sweep on a frozen step: the loaded-contact set"};
  std::string file, methods_s = "gs,nncg,anderson:5", csv;
  int pairs = 1000, every = 5, ref_sweeps = 20000;
  double ref_residual = 1e-7;
  std::vector<double> tols{3e-3, 2e-3, 1e-3, 3e-4, 1e-4};
  app.add_option("file", file, ".cdp3 problem")->required();
  app.add_option("--methods", methods_s, "gs, nncg, anderson:M[:raw], sm:P:C, each [+scale]");
  app.add_option("--pairs", pairs, "symmetric pairs per method");
  app.add_option("--every", every, "report every K pairs");
  app.add_option("--ref-sweeps", ref_sweeps, "reference: gs sweeps at most");
  app.add_option("--ref-residual", ref_residual, "reference: stop at this law residual (checked every 100 pairs)");
  app.add_option("--tols", tols, "report where the production criterion first meets each of these")->delimiter(',');
  app.add_option("--csv", csv, "write every report line here");
  CLI11_PARSE(app, argc, argv);
  try {
    SolverParams prm;
    const ContactProblem3 cp = read_contact_problem3(file, prm);
    const Problem3 P = to_matrix(cp);
    const Blocks B(P);
    std::vector<Vec3> r0(B.nc);
    for (int i = 0; i < B.nc; ++i) r0[i] = cp.rows[i].r;

    std::vector<Vec3> ref = r0;
    int ref_pairs = 0;
    for (; 2 * ref_pairs < ref_sweeps; ++ref_pairs) {
      double unused;
      (void)B.pair(ref, unused);
      if ((ref_pairs + 1) % 100 == 0 && problem_residual(P, B.flat(ref)).max < ref_residual) break;
    }
    const Figures fr = figures(P, B, ref, nullptr);
    fmt::print("{}: {} contacts, {} off-diagonal blocks; reference: {} sweeps, residual {:.2e}, loaded {}, sum r_n {:.6e}\n",
               file, B.nc, B.col.size(), 2 * (ref_pairs + 1), fr.rmax, fr.loaded, fr.sum_n);
    const Figures f0 = figures(P, B, r0, &ref);
    fmt::print("warm start: residual {:.2e}, loaded {} ({:+d}), sum r_n {:+.3f} %, dist {:.2e}\n", f0.rmax, f0.loaded,
               f0.loaded - fr.loaded, 100 * (f0.sum_n / fr.sum_n - 1), f0.dist);

    std::ofstream out;
    if (!csv.empty()) {
      out.open(csv);
      out << "method,sweeps,residual_max,residual_mean,loaded,loaded_excess,sum_n_rel,dist\n";
    }
    std::stringstream ms(methods_s);
    std::string m;
    while (std::getline(ms, m, ',')) {
      std::vector<Vec3> r = r0;
      std::string base = m;
      const bool scale = base.size() > 6 && base.substr(base.size() - 6) == "+scale";
      if (scale) base.resize(base.size() - 6);
      const bool nncg = base == "nncg";
      int mem = 0;  // anderson:M (the production mixing and stall rule) or anderson:M:raw (no stall rule)
      bool raw = false;
      if (base.rfind("anderson:", 0) == 0) {
        const std::string a = base.substr(9);
        const auto c = a.find(':');
        mem = std::stoi(a.substr(0, c));
        raw = c != std::string::npos && a.substr(c + 1) == "raw";
        if (c != std::string::npos && !raw) throw std::invalid_argument("unknown method " + m);
      }
      // sm:P:C: core/sweep.hpp's subspace correction, C CG iterations at most, every P pairs
      int sm_every = 0, cg = 0;
      std::optional<sweep::Subspace<3>> sm;
      BlockRows::Scratch sm_scratch = 0;
      if (base.rfind("sm:", 0) == 0) {
        const std::string a = base.substr(3);
        const auto c = a.find(':');
        if (c == std::string::npos) throw std::invalid_argument("sm:P:C expected, got " + m);
        sm_every = std::stoi(a.substr(0, c));
        sm.emplace(std::stoi(a.substr(c + 1)), B.nc);
      }
      if (!nncg && mem == 0 && !sm && base != "gs") throw std::invalid_argument("unknown method " + m);
      std::optional<sweep::Anderson<3>> acc;
      if (mem > 0) {
        acc.emplace(mem, B.nc);
        acc->start(r.data(), VecRows{});
      }
      sweep::Stall stall;
      int off_at = 0;
      Eigen::VectorXd x = B.flat(r), p = Eigen::VectorXd::Zero(3 * B.nc);
      double fprev = 0;
      int restarts = 0;
      std::vector<double> stops = tols;  // report the first pair at each tolerance
      fmt::print("{}\n  {:>6} {:>9} {:>9} {:>7} {:>6} {:>9} {:>9}\n", m, "sweeps", "res max", "res mean", "loaded",
                 "excess", "sum r_n", "dist");
      for (int k = 1; k <= pairs; ++k) {
        double d2back = 0;
        const double crit = B.pair(r, d2back);
        if (scale) rescale(B, r);
        const Eigen::VectorXd g = B.flat(r);
        for (double& t : stops)
          if (t > 0 && crit < t) {
            const Figures f = figures(P, B, r, &ref);
            fmt::print("  STOP tol {:.0e} at {} sweeps (+{} cg): residual {:.2e}, loaded excess {:+d}, sum r_n {:+.3f}%, dist {:.2e}\n", t,
                       2 * k, cg, f.rmax, f.loaded - fr.loaded, 100 * (f.sum_n / fr.sum_n - 1), f.dist);
            t = 0;
          }
        if (k % every == 0 || k == pairs) {
          const Figures f = figures(P, B, r, &ref);
          fmt::print("  {:6d} {:9.2e} {:9.2e} {:7d} {:+6d} {:+8.3f}% {:9.2e} {:6d}\n", 2 * k, f.rmax, f.rmean, f.loaded,
                     f.loaded - fr.loaded, 100 * (f.sum_n / fr.sum_n - 1), f.dist, 2 * k + cg);
          if (out.is_open())
            out << fmt::format("{},{},{:.6e},{:.6e},{},{},{:.6e},{:.6e}\n", m, 2 * k, f.rmax, f.rmean, f.loaded,
                               f.loaded - fr.loaded, f.sum_n / fr.sum_n - 1, f.dist);
        }
        if (sm && k % sm_every == 0) cg += sm->correct<RoundCone>(r.data(), BlockRows{{}, B, r.data()}, sm_scratch);
        if (nncg) {
          const Eigen::VectorXd d = g - x;  // -grad
          const double fn = d.squaredNorm();
          const double beta = fprev > 0 ? fn / fprev : 0.0;
          if (beta > 1.0 || fprev == 0) {
            p = d;
            if (fprev > 0) ++restarts;
            x = g;
          } else {
            x = g + beta * p;
            p = beta * p + d;
            set(r, x);
          }
          fprev = fn;
        } else if (acc && !raw && stall.stalled(d2back)) {
          acc.reset();  // stalled: plain gs from here
          off_at = 2 * k;
        } else if (acc) {
          acc->mix(r.data(), VecRows{});
        }
        if (!nncg) x = B.flat(r);
      }
      if (nncg) fmt::print("  restarts {}\n", restarts);
      if (off_at) fmt::print("  anderson off after {} sweeps\n", off_at);
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "solvers3: {}\n", e.what());
    return 2;
  }
  return 0;
}
