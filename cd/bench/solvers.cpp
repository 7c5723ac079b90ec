// solvers: a study of contact solvers on frozen step problems
// (docs/accuracy.md). Every solver starts from the problem as dumped (cdsim
// --dump-problem: the step's warm start) and is judged by the same two
// figures, computed the same way for all:
//   residual  the production law residual (law.hpp law_residual per row, the
//             row's W_nn, max over rows / mean |p|): cd::law_residuals on the
//             ContactProblem whose impulses, body velocities and boundary
//             dofs are set from the solver's impulses;
//   siconos   Siconos' fc2d error of the same impulses on the matrix form
//             (cd::siconos_error, cd::to_matrix).
// Methods:
//   nlgs       the production solver: cd::sweep::solve (core/sweep.hpp) over
//              cd::sweep::BodyCoupling (2d/coupling.hpp) with the problem's law;
//              run in chunks of `check` sweeps (an even number, so that the
//              forward/backward order is the continuous solve's);
//   sor:W      the same sweep and coupling with the law wrapped in an
//              over-relaxation p <- p + W (p_local - p), projected back on the
//              law's admissible set (p_n >= -a, |p_t| <= mu (p_n + a));
//   sor-adapt  as sor, W raised by 0.05 after every check that lowered the
//              residual, multiplied by 0.8 (not below 1) after one that did not;
//   cold       nlgs from zero impulses (what the warm start is worth);
//   apgd       Nesterov-accelerated projected gradient on the matrix form
//              (Mazhar et al. 2015, Chrono's APGD) with the gradient restart
//              of O'Donoghue & Candes, step 1/lambda_max(W) (power
//              iteration), and De Saxce's term (mu |u_t|, 0) added to the
//              gradient at every iterate so that its fixed points are Coulomb
//              solutions, not those of the convex relaxation (CCP);
//   ssn:K      K production NLGS sweeps, then a semismooth Newton on the
//              natural map of the law (the production residual's own
//              function, rho = 1/W_nn per contact) with Eigen's SparseLU, a
//              Levenberg-Marquardt shift eps |J| and a backtracking line search
//              on |Phi|^2; back to NLGS chunks if Newton stalls.
// Each method runs until the residual is <= every target (--targets) or the
// time limit; the time to reach each target is the wall time of the solver's
// own work: the residual checks are timed and subtracted.
// Usage: solvers FILE.cdp... [--methods nlgs,sor:1.5,...] [--targets 1e-4]
//        [--threads 1,2] [--check 10] [--time-limit 20] [--csv DIR]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/SparseLU>
#include <fmt/format.h>

#include "contact_problem.hpp"
#include "coupling.hpp"
#include "law.hpp"
#include "machine.hpp"
#include "nlgs.hpp"
#include "problem.hpp"
#include "sweep.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using cd::ContactProblem;
using cd::ContactRow;
using Eigen::VectorXd;

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// ---- impulses <-> problem -----------------------------------------------

VectorXd impulses(const ContactProblem& p) {
  VectorXd r(2 * p.rows.size());
  for (std::size_t k = 0; k < p.rows.size(); ++k) {
    r[2 * k] = p.rows[k].pn;
    r[2 * k + 1] = p.rows[k].pt;
  }
  return r;
}

// Sets the impulses of p to r: the body velocities get the change (as the
// sweep keeps them), each boundary dof its exact value v0 + inv_mass sum(a.p)
// (what the matrix form eliminates), its change going into the rows' offsets.
void set_impulses(ContactProblem& p, const VectorXd& r) {
  std::vector<ContactRow> d = p.rows;
  for (std::size_t k = 0; k < d.size(); ++k) {
    d[k].pn = r[2 * k] - p.rows[k].pn;
    d[k].pt = r[2 * k + 1] - p.rows[k].pt;
    p.rows[k].pn = r[2 * k];
    p.rows[k].pt = r[2 * k + 1];
  }
  cd::apply_impulses(d, p.vel, p.rotation);
  for (cd::BoundaryDof& D : p.dofs) {
    double s = 0;
    for (std::size_t m = 0; m < D.rows.size(); ++m)
      s += D.an[m] * p.rows[D.rows[m]].pn + D.at[m] * p.rows[D.rows[m]].pt;
    const double dv = D.v0 + D.inv_mass * s - D.v;
    for (std::size_t m = 0; m < D.rows.size(); ++m) {
      p.rows[D.rows[m]].bn += D.an[m] * dv;
      p.rows[D.rows[m]].bt += D.at[m] * dv;
    }
    D.v += dv;
  }
}

// ---- the judge -----------------------------------------------------------

struct Judge {
  const ContactProblem* p0;  // as dumped
  const cd::Problem* P;      // its matrix form
  double spent = 0;          // seconds spent judging (subtracted from the solvers' times)
  struct Figures {
    double res_max, res_mean, siconos;
  };
  Figures of_problem(const ContactProblem& p) {
    const auto t0 = Clock::now();
    cd::SolveStats st;
    cd::SolverParams prm;
    prm.min_parallel = std::numeric_limits<int>::max();
    cd::law_residuals(p, prm, st);
    Figures f{st.residual_max, st.residual_mean, cd::siconos_error(*P, impulses(p))};
    spent += seconds(t0, Clock::now());
    return f;
  }
  Figures of_impulses(const VectorXd& r) {
    const auto t0 = Clock::now();
    ContactProblem p = *p0;
    set_impulses(p, r);
    spent += seconds(t0, Clock::now());
    return of_problem(p);
  }
};

struct Point {
  double time;
  long iters;  // sweeps, or gradient steps, or NLGS sweeps + Newton steps
  double res_max, res_mean, siconos;
};

// ---- the sweep with a relaxed law ---------------------------------------

// Over-relaxation as a law (the sweep's template parameter): the exact local
// solution, relaxed by omega and projected back on the admissible set. The
// sweep and its coupling are the production ones.
inline double g_omega = 1.0;  // read-only during a solve
template <class L>
struct Relaxed {
  static constexpr bool tangential = L::tangential;
  static constexpr const char* name = "relaxed";
  static void solve(const ContactRow& r, double un, double ut, double& pn, double& pt) {
    L::solve(r, un, ut, pn, pt);
    const double w = g_omega;
    pn = std::max(r.pn + w * (pn - r.pn), -r.adh);
    if constexpr (L::tangential) {
      const double lim = r.mu * (pn + r.adh);
      pt = std::clamp(r.pt + w * (pt - r.pt), -lim, lim);
    }
  }
};

// `sweeps` production sweeps (relaxed if omega != 1) on p, in place.
void sweeps(ContactProblem& p, int n, double omega, int min_parallel) {
  cd::SolverParams prm;
  prm.tol = -1;  // never converged: exactly n sweeps
  prm.max_iter = n;
  prm.min_parallel = min_parallel;
  std::vector<cd::BoundaryDof>* dofs = p.dofs.empty() ? nullptr : &p.dofs;
  g_omega = omega;
  std::visit(
      [&](auto law) {
        using L0 = decltype(law);
        auto run = [&](auto c) {
          if (omega == 1.0)
            cd::sweep::solve<L0>(p.rows, p.colouring, c, prm, dofs, {});
          else
            cd::sweep::solve<Relaxed<L0>>(p.rows, p.colouring, c, prm, dofs, {});
        };
        if (p.rotation)
          run(cd::sweep::BodyCoupling<true>{p.vel.data()});
        else
          run(cd::sweep::BodyCoupling<false>{p.vel.data()});
      },
      p.law);
}

struct Run {
  std::vector<Point> hist;
  bool reached = false;
};

struct Limits {
  double target;  // smallest target
  double time_limit;
  long max_iters;
};

// NLGS / SOR in chunks of `check` sweeps.
Run run_sweeps(const ContactProblem& p0, Judge& J, double omega, bool adapt, bool cold, int check,
               int min_parallel, const Limits& lim) {
  Run out;
  ContactProblem p = p0;
  if (cold) set_impulses(p, VectorXd::Zero(2 * p.rows.size()));
  J.spent = 0;
  const auto t0 = Clock::now();
  long it = 0;
  double prev = std::numeric_limits<double>::infinity();
  double w = adapt ? 1.0 : omega;
  for (;;) {
    sweeps(p, check, w, min_parallel);
    it += check;
    const Judge::Figures f = J.of_problem(p);
    const double t = seconds(t0, Clock::now()) - J.spent;
    out.hist.push_back({t, it, f.res_max, f.res_mean, f.siconos});
    if (f.res_max <= lim.target) {
      out.reached = true;
      break;
    }
    if (t > lim.time_limit || it >= lim.max_iters || !std::isfinite(f.res_max)) break;
    if (adapt) w = f.res_max < prev ? std::min(1.9, w + 0.05) : std::max(1.0, 0.8 * w);
    prev = f.res_max;
  }
  return out;
}

// ---- matrix-form pieces ----------------------------------------------------

// Projection on the 2D Coulomb cone |x_t| <= mu x_n.
inline void project_cone(double mu, double& xn, double& xt) {
  const double at = std::abs(xt);
  if (at <= mu * xn) return;
  if (mu * at <= -xn) {
    xn = xt = 0;
    return;
  }
  xn = (mu * at + xn) / (mu * mu + 1.0);
  xt = mu * xn * (xt > 0 ? 1.0 : -1.0);
}

double lambda_max(const Eigen::SparseMatrix<double>& W) {
  VectorXd x = VectorXd::Ones(W.rows()).normalized();
  double l = 0;
  for (int i = 0; i < 50; ++i) {
    VectorXd y = W * x;
    l = y.norm();
    if (l == 0) return 1;
    x = y / l;
  }
  return 1.05 * l;  // a margin: power iteration underestimates
}

// APGD with restart and De Saxce's term.
Run run_apgd(const cd::Problem& P, const VectorXd& r0, Judge& J, int check, const Limits& lim) {
  Run out;
  J.spent = 0;
  const auto t0 = Clock::now();
  const int nc = P.nc;
  const double L = lambda_max(P.W), t = 1.0 / L;
  VectorXd g = r0, y = r0, gnew(2 * nc), grad(2 * nc);
  double theta = 1;
  long it = 0;
  for (;;) {
    grad = P.W * y + P.q;
    for (int k = 0; k < nc; ++k) grad[2 * k] += P.mu[k] * std::abs(grad[2 * k + 1]);
    gnew = y - t * grad;
    for (int k = 0; k < nc; ++k) project_cone(P.mu[k], gnew[2 * k], gnew[2 * k + 1]);
    const double th2 = theta * theta;
    const double thnew = 0.5 * (-th2 + std::sqrt(th2 * th2 + 4 * th2));
    const double beta = theta * (1 - theta) / (th2 + thnew);
    if (grad.dot(gnew - g) > 0) {  // restart (the step went uphill)
      y = gnew;
      theta = 1;
    } else {
      y = gnew + beta * (gnew - g);
      theta = thnew;
    }
    g = gnew;
    ++it;
    if (it % check == 0) {
      const Judge::Figures f = J.of_impulses(g);
      const double tt = seconds(t0, Clock::now()) - J.spent;
      out.hist.push_back({tt, it, f.res_max, f.res_mean, f.siconos});
      if (f.res_max <= lim.target) {
        out.reached = true;
        break;
      }
      if (tt > lim.time_limit || it >= lim.max_iters || !std::isfinite(f.res_max)) break;
    }
  }
  return out;
}

// Natural map of the law (the production residual's function, one rho per
// contact) and its generalized Jacobian, rows of W in row-major form.
struct NaturalMap {
  const cd::Problem& P;
  Eigen::SparseMatrix<double, Eigen::RowMajor> Wr;
  VectorXd rho;
  explicit NaturalMap(const cd::Problem& p) : P(p), Wr(p.W), rho(p.nc) {
    for (int k = 0; k < p.nc; ++k) rho[k] = 1.0 / p.W.coeff(2 * k, 2 * k);
  }
  VectorXd phi(const VectorXd& r) const {
    const VectorXd u = P.W * r + P.q;
    VectorXd f(r.size());
    for (int k = 0; k < P.nc; ++k) {
      const double rn = r[2 * k], rt = r[2 * k + 1], rh = rho[k];
      f[2 * k] = rn - std::max(0.0, rn - rh * u[2 * k]);
      const double l = P.mu[k] * std::max(rn, 0.0);
      f[2 * k + 1] = rt - std::clamp(rt - rh * u[2 * k + 1], -l, l);
    }
    return f;
  }
  Eigen::SparseMatrix<double> jacobian(const VectorXd& r, double shift) const {
    const VectorXd u = P.W * r + P.q;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(Wr.nonZeros() + 4 * r.size());
    auto wrow = [&](int i, double s) {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Wr, i); it; ++it)
        t.emplace_back(i, static_cast<int>(it.col()), s * it.value());
    };
    for (int k = 0; k < P.nc; ++k) {
      const int n = 2 * k, tg = 2 * k + 1;
      const double rn = r[n], rt = r[tg], rh = rho[k];
      if (rn - rh * u[n] > 0)
        wrow(n, rh);
      else
        t.emplace_back(n, n, 1.0);
      const double l = P.mu[k] * std::max(rn, 0.0), z = rt - rh * u[tg];
      if (std::abs(z) <= l) {
        wrow(tg, rh);
      } else {
        t.emplace_back(tg, tg, 1.0);
        if (rn > 0) t.emplace_back(tg, n, -(z > 0 ? 1.0 : -1.0) * P.mu[k]);
      }
      t.emplace_back(n, n, shift);
      t.emplace_back(tg, tg, shift);
    }
    Eigen::SparseMatrix<double> Jm(r.size(), r.size());
    Jm.setFromTriplets(t.begin(), t.end());
    Jm.makeCompressed();
    return Jm;
  }
};

// K NLGS sweeps, then semismooth Newton; NLGS chunks again if Newton stalls.
Run run_ssn(const ContactProblem& p0, const cd::Problem& P, Judge& J, int k_nlgs, int check,
            int min_parallel, const Limits& lim, double lm) {
  Run out;
  ContactProblem p = p0;
  J.spent = 0;
  const auto t0 = Clock::now();
  long it = 0;
  sweeps(p, k_nlgs, 1.0, min_parallel);
  it += k_nlgs;
  NaturalMap F(P);
  VectorXd r = impulses(p);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  bool pattern = false;
  int stalls = 0;
  for (;;) {
    const VectorXd f = F.phi(r);
    const double m0 = f.squaredNorm();
    bool ok = false;
    if (stalls < 3) {
      const Eigen::SparseMatrix<double> Jm = F.jacobian(r, lm);
      if (!pattern) {
        lu.analyzePattern(Jm);
        pattern = true;
      }
      lu.factorize(Jm);
      if (lu.info() == Eigen::Success) {
        const VectorXd d = lu.solve(-f);
        double a = 1;
        for (int ls = 0; ls < 20; ++ls, a *= 0.5) {
          const VectorXd rn = r + a * d;
          if (F.phi(rn).squaredNorm() < (1 - 1e-4 * a) * m0) {
            r = rn;
            ok = true;
            break;
          }
        }
      }
      if (!ok) {
        ++stalls;
        pattern = false;  // the active set changed the pattern
      }
      ++it;
    }
    if (!ok) {  // Newton stalled: NLGS chunk from r
      set_impulses(p, r);
      sweeps(p, check, 1.0, min_parallel);
      it += check;
      r = impulses(p);
      stalls = 0;
    }
    const Judge::Figures fig = J.of_impulses(r);
    const double tt = seconds(t0, Clock::now()) - J.spent;
    out.hist.push_back({tt, it, fig.res_max, fig.res_mean, fig.siconos});
    if (fig.res_max <= lim.target) {
      out.reached = true;
      break;
    }
    if (tt > lim.time_limit || it >= lim.max_iters || !std::isfinite(fig.res_max)) break;
    pattern = false;  // the Jacobian's pattern follows the active set
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"solvers: contact solvers against the production NLGS on frozen .cdp problems"};
  std::vector<std::string> files;
  std::string methods_s = "nlgs,cold,sor:1.3,sor:1.6,sor-adapt,apgd,ssn:20";
  std::vector<double> targets{1e-4};
  std::vector<int> threads{1};
  int check = 10;
  double time_limit = 20, lm = 1e-3;
  long max_iters = 200000;
  std::string csv;
  bool campaign = true;
  app.add_option("files", files, ".cdp problems (cdsim --dump-problem)")->required();
  app.add_option("--methods", methods_s, "comma-separated: nlgs, cold, sor:W, sor-adapt, apgd, ssn:K");
  app.add_option("--targets", targets, "law residual targets (max over rows / mean |p|)");
  app.add_option("--threads", threads, "thread counts (sweep methods; the matrix ones run on one)");
  app.add_option("--check", check, "iterations between residual checks (even)");
  app.add_option("--time-limit", time_limit, "seconds per method and problem");
  app.add_option("--max-iters", max_iters, "iteration cap per method and problem");
  app.add_option("--lm", lm, "Levenberg-Marquardt shift of the Newton matrix (times 1/W_nn scale)");
  app.add_option("--csv", csv, "directory for history.csv, summary.csv and machine.csv");
  app.add_flag("!--no-campaign", campaign,
               "skip the extra target: the residual production NLGS reaches at the problem's own tol");
  CLI11_PARSE(app, argc, argv);
  check += check % 2;
  const std::string load_start = cdbench::load_average();

  std::vector<std::string> methods;
  {
    std::stringstream ss(methods_s);
    for (std::string m; std::getline(ss, m, ',');) methods.push_back(m);
  }
  std::ofstream hist_out, sum_out;
  if (!csv.empty()) {
    std::filesystem::create_directories(csv);
    hist_out.open(csv + "/history.csv");
    hist_out << "problem,method,threads,time_s,iters,res_max,res_mean,siconos\n";
    sum_out.open(csv + "/summary.csv");
    sum_out << "problem,rows,method,threads,target,reached,time_s,iters,ratio_to_nlgs,siconos\n";
  }

  for (const std::string& file : files) {
    cd::SolverParams prm0;
    const ContactProblem p0 = cd::read_contact_problem(file, prm0);
    const cd::Problem P = cd::to_matrix(p0);
    Judge J{&p0, &P};
    const std::string name = std::filesystem::path(file).parent_path().filename().string() + "/" +
                             std::filesystem::path(file).stem().string();
    std::vector<double> tg = targets;
    // The campaign target: what the production solve reaches at its own tol.
    if (campaign) {
      ContactProblem p = p0;
      omp_set_num_threads(1);
      const auto t0 = Clock::now();
      const cd::SolveStats st = cd::nlgs_solve(p, prm0);
      const double t = seconds(t0, Clock::now());
      fmt::print("{}: {} rows, production solve (tol {:g}, cap {}): {} sweeps{}, residual max {:.3e} "
                 "mean {:.3e}, {:.1f} ms\n",
                 name, p0.rows.size(), prm0.tol, prm0.max_iter, st.iterations,
                 st.cap_hit ? " (CAP)" : "", st.residual_max, st.residual_mean, 1e3 * t);
      tg.push_back(st.residual_max);
    }
    std::sort(tg.begin(), tg.end(), std::greater<>());
    const Limits lim{tg.back(), time_limit, max_iters};
    fmt::print("{:<14} {:>3} | {}\n", "method", "thr",
               fmt::join(std::vector<std::string>(tg.size(), "  target: time ms (iters)  ratio"), " |"));
    std::vector<double> ref(tg.size() * 8, std::nan(""));
    for (int nt : threads) {
      omp_set_num_threads(nt);
      for (const std::string& m : methods) {
        const bool matrix = m == "apgd" || m.rfind("ssn", 0) == 0;
        if (matrix && nt != threads.front()) continue;
        Run run;
        const int minpar = nt > 1 ? 0 : std::numeric_limits<int>::max();
        if (m == "nlgs") run = run_sweeps(p0, J, 1.0, false, false, check, minpar, lim);
        else if (m == "cold") run = run_sweeps(p0, J, 1.0, false, true, check, minpar, lim);
        else if (m == "sor-adapt") run = run_sweeps(p0, J, 1.0, true, false, check, minpar, lim);
        else if (m.rfind("sor:", 0) == 0)
          run = run_sweeps(p0, J, std::stod(m.substr(4)), false, false, check, minpar, lim);
        else if (m == "apgd") run = run_apgd(P, impulses(p0), J, check, lim);
        else if (m.rfind("ssn:", 0) == 0)
          run = run_ssn(p0, P, J, std::stoi(m.substr(4)), check, minpar, lim, lm);
        else {
          std::cerr << "solvers: unknown method " << m << "\n";
          return 2;
        }
        for (const Point& q : run.hist)
          if (hist_out)
            hist_out << fmt::format("{},{},{},{:.6g},{},{:.6e},{:.6e},{:.6e}\n", name, m, nt, q.time,
                                    q.iters, q.res_max, q.res_mean, q.siconos);
        std::vector<std::string> cells;
        for (std::size_t i = 0; i < tg.size(); ++i) {
          const Point* hit = nullptr;
          for (const Point& q : run.hist)
            if (q.res_max <= tg[i]) {
              hit = &q;
              break;
            }
          double ratio = std::nan("");
          if (m == "nlgs" && nt == threads.front() && hit) ref[i] = hit->time;
          if (hit) ratio = hit->time / ref[i];
          cells.push_back(hit ? fmt::format("{:8.2e}: {:8.1f} ({:6}) {:6.2f}", tg[i], 1e3 * hit->time,
                                            hit->iters, ratio)
                              : fmt::format("{:8.2e}: not reached ({:.1e})", tg[i],
                                            run.hist.empty() ? NAN : run.hist.back().res_max));
          if (sum_out)
            sum_out << fmt::format("{},{},{},{},{:.3e},{},{:.6g},{},{:.4g},{:.3e}\n", name,
                                   p0.rows.size(), m, nt, tg[i], hit ? 1 : 0,
                                   hit ? hit->time : NAN, hit ? hit->iters : -1, ratio,
                                   hit ? hit->siconos : NAN);
        }
        fmt::print("{:<14} {:>3} | {}\n", m, nt, fmt::join(cells, " |"));
        std::cout.flush();
      }
    }
  }
  if (!csv.empty()) {
    std::ofstream mo(csv + "/machine.csv");
    mo << "key,value\n";
    for (const auto& [k, v] : cdbench::machine(load_start)) mo << k << ",\"" << v << "\"\n";
  }
  return 0;
}
