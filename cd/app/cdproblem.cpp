// cdproblem: replays a frozen contact problem with the production solver.
//   cdproblem solve FILE.dat [--tol 1e-6] [--max-sweeps N] [--check-every K] [--lemke]
//   cdproblem solve FILE.cdp|FILE.cdp3 [--tol T] [--max-sweeps N] [--out IMPULSES.txt]
//   cdproblem solve FILE.hdf5 [--tol 1e-6] [--max-sweeps N] [--check-every K] [--lemke --facets E]
// FILE.dat: Siconos' text format (W, q, mu; 2D or 3D, core/siconos_dat.hpp),
// solved by the simulator's sweep through the blocks of W (problem.hpp,
// problem3.hpp); prints the problem size, the sweep's
// change and the law residual every K sweeps, Siconos' error and the time;
// with --lemke, the reference LCP solve instead.
// FILE.cdp, FILE.cdp3: a 2D or 3D step dumped by `cdsim --dump-problem`
// (contact_problem.hpp, contact_problem3.hpp), solved exactly as the step was (same rows, colouring, law, dofs and,
// unless overridden, tolerance and cap): the same impulses to the bit.
// FILE.hdf5: an FCLib 3D problem (local, or global condensed to W, q),
// solved by the 3D NLGS with the exact local solver (3d/problem3.hpp); with
// --lemke, the polyhedral-cone LCP with E face pairs (3d/lemke3.hpp).
// Exit codes: 0 solved to the tolerance; 1 not converged (sweep cap) or
// Lemke failed; 2 bad input (usage, option out of range, malformed file or
// non-finite number: one message naming the file, line (.hdf5: dataset) and
// what was wrong).
#include <chrono>
#include <fstream>
#include <limits>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_checks.hpp"
#include "cli_errors.hpp"
#include "contact_problem3.hpp"
#include "files.hpp"
#include "lemke.hpp"
#include "lemke3.hpp"
#include "nlgs.hpp"
#include "problem.hpp"
#include "problem3.hpp"
#include "siconos_dat.hpp"

namespace {

// Lemke's dense tableau is 4nc x (8nc + 1) doubles and each pivot touches all
// of it: past this size it is minutes and gigabytes, not a reference.
constexpr int kLemkeMaxContacts = 1000;

// A matrix-form NLGS solve (2D or 3D): the residual history, then one
// line; the exit status (1: not converged).
int report_nlgs(const cd::NlgsStats& st) {
  fmt::print("{:>8} {:>12} {:>14} {:>14}\n", "sweep", "rms|dr|/|r|", "residual max",
             "residual mean");
  for (const cd::NlgsCheckpoint& c : st.history)
    fmt::print("{:>8} {:>12.3e} {:>14.3e} {:>14.3e}\n", c.sweep, c.dr_rel, c.residual_max,
               c.residual_mean);
  fmt::print(
      "nlgs: {} after {} sweeps (rms |dr|/|r| {:.3e}), residual max {:.3e} mean {:.3e} "
      "(mean |r| {:.3e}), Siconos error {:.3e}, time {:.3g} s ({:.3g} ms/sweep)\n",
      st.converged ? "converged" : "NOT converged (sweep cap)", st.sweeps, st.dr_rel,
      st.residual.max, st.residual.mean, st.residual.r_mean, st.siconos_error, st.time,
      st.sweeps ? 1e3 * st.time / st.sweeps : 0.0);
  return st.converged ? 0 : 1;
}

int solve2(const cd::Problem& p, const std::string& path, const cd::NlgsOptions& opt, bool lemke) {
  double wmin = p.nc ? p.W.diagonal().minCoeff() : 0, wmax = p.nc ? p.W.diagonal().maxCoeff() : 0;
  fmt::print(
      "{}: dim {}, {} contacts, W {}x{} with {} entries (diagonal {:.4g} to {:.4g}), "
      "mu {:.4g} to {:.4g}\n",
      path, p.dim, p.nc, p.W.rows(), p.W.cols(), p.W.nonZeros(), wmin, wmax,
      p.nc ? p.mu.minCoeff() : 0.0, p.nc ? p.mu.maxCoeff() : 0.0);
  if (lemke) {
    if (p.nc > kLemkeMaxContacts)
      throw std::runtime_error(fmt::format(
          "{} contacts: Lemke's dense tableau is meant for small problems (<= {} contacts)", p.nc,
          kLemkeMaxContacts));
    const cd::LemkeResult L = cd::solve_lemke(p);
    const cd::Residual res = cd::problem_residual(p, L.r);
    fmt::print(
        "lemke: {}, {} pivots, residual max {:.3e} mean {:.3e} (mean |r| {:.3e}), "
        "time {:.3g} s\n",
        cd::to_string(L.status), L.pivots, res.max, res.mean, res.r_mean, L.time);
    return L.status == cd::LemkeStatus::Solved ? 0 : 1;
  }
  Eigen::VectorXd r;
  return report_nlgs(cd::solve_nlgs(p, r, opt));
}

// Lemke's tableau for the polyhedral LCP is (2e + 2) nc unknowns square.
constexpr int kLemke3MaxUnknowns = 4000;

// A 3D problem in matrix form (FCLib or Siconos .dat), `what` the line that
// describes it.
int solve3(const cd::Problem3& p, const std::string& what, const cd::NlgsOptions& opt, bool lemke, int facets) {
  fmt::print("{}, W {}x{} with {} entries, mu {:.4g} to {:.4g}\n", what, p.W.rows(), p.W.cols(), p.W.nonZeros(),
             p.nc ? p.mu.minCoeff() : 0.0, p.nc ? p.mu.maxCoeff() : 0.0);
  if (lemke) {
    if ((2 * facets + 2) * p.nc > kLemke3MaxUnknowns)
      throw std::runtime_error(fmt::format(
          "{} contacts with {} face pairs: {} LCP unknowns, Lemke's dense tableau is meant for "
          "<= {}", p.nc, facets, (2 * facets + 2) * p.nc, kLemke3MaxUnknowns));
    const cd::Lemke3Result L = cd::solve_lemke(p, facets);
    const cd::Residual res = cd::problem_residual(p, L.r);
    fmt::print(
        "lemke ({} face pairs): {}, {} pivots, LCP error {:.3e}, round-cone residual max {:.3e} "
        "mean {:.3e}, Siconos error {:.3e}, time {:.3g} s\n",
        facets, cd::to_string(L.status), L.pivots, L.lcp_error, res.max, res.mean,
        cd::siconos_error(p, L.r), L.time);
    return L.status == cd::LemkeStatus::Solved ? 0 : 1;
  }
  Eigen::VectorXd r;
  return report_nlgs(cd::solve_nlgs(p, r, opt));
}

int solve_fclib(const std::string& path, const cd::NlgsOptions& opt, bool lemke, int facets) {
  const cd::Fclib3 f = cd::read_fclib(path);
  const cd::Problem3& p = f.problem;
  if (f.r_ref.size()) {
    // Siconos' global test files store zeros there (test_frozen3): say so
    // rather than print the error of r = 0 as if it were a reference.
    const bool zero = f.r_ref.cwiseAbs().maxCoeff() == 0.0;
    fmt::print("stored solution: {}Siconos error {:.3e}\n", zero ? "r = 0 everywhere (a placeholder, not a solution), " : "",
               cd::siconos_error(p, f.r_ref));
  }
  return solve3(p,
                fmt::format("{}: dim 3, {} contacts ({})", path, p.nc,
                            f.global ? fmt::format("global, {} body dofs, condensed", f.bodies_dofs) : "local"),
                opt, lemke, facets);
}

// A Siconos .dat file: 2D or 3D, as its first number says.
int solve_dat(const std::string& path, const cd::NlgsOptions& opt, bool lemke, int facets) {
  cd::SiconosDat d = cd::read_siconos_dat(path);
  if (d.dim == 3) {
    cd::Problem3 p;
    p.nc = d.nc;
    p.W = std::move(d.W);
    p.q = std::move(d.q);
    p.mu = std::move(d.mu);
    return solve3(p, fmt::format("{}: dim 3, {} contacts (Siconos .dat)", path, p.nc), opt, lemke, facets);
  }
  return solve2(cd::Problem{d.dim, d.nc, std::move(d.W), std::move(d.q), std::move(d.mu)}, path, opt, lemke);
}

// The dumped steps of the two engines (.cdp, .cdp3), as solve_step sees
// them: read, describe, solve, and the impulses as hex floats, a row a line.
struct Step2 {
  using Problem = cd::ContactProblem;
  static Problem read(const std::string& path, cd::SolverParams& prm) { return cd::read_contact_problem(path, prm); }
  static std::string describe(const Problem& p) {
    return fmt::format("{} rows, {} bodies, {} colours, {} boundary dofs, law {}, rotation {}", p.rows.size(),
                       p.vel.size(), p.colouring.split.size(), p.dofs.size(), cd::law_name(p.law),
                       p.rotation ? "on" : "off");
  }
  static cd::SolveStats solve(Problem& p, const cd::SolverParams& prm) { return cd::nlgs_solve(p, prm); }
  static std::string impulses(const Problem& p) {
    std::string text;
    for (const cd::ContactRow& r : p.rows) text += fmt::format("{:a} {:a}\n", r.pn, r.pt);
    return text;
  }
};

struct Step3 {
  using Problem = cd::ContactProblem3;
  static Problem read(const std::string& path, cd::SolverParams& prm) { return cd::read_contact_problem3(path, prm); }
  // ", compliant (rho = ...)" with rho_t when k_t != k; "" if rigid.
  static std::string compliance(const Problem& p) {
    if (!(p.compliance > 0)) return "";
    const double rt = p.tangential_compliance();
    return rt != p.compliance ? fmt::format(", compliant (rho = {:.6g}, rho_t = {:.6g})", p.compliance, rt)
                              : fmt::format(", compliant (rho = {:.6g})", p.compliance);
  }
  static std::string describe(const Problem& p) {
    return fmt::format("{} rows, {} bodies, {} colours, {} cell dofs, law {}{}", p.rows.size(), p.vel.size(),
                       p.colouring.split.size(), p.dofs.size(), cd::law_name3(p.law), compliance(p));
  }
  static cd::SolveStats solve(Problem& p, const cd::SolverParams& prm) { return cd::nlgs_solve3(p, prm); }
  static std::string impulses(const Problem& p) {
    std::string text;
    for (const cd::SphereRow& r : p.rows) text += fmt::format("{:a} {:a} {:a}\n", r.r[0], r.r[1], r.r[2]);
    return text;
  }
};

// A dumped step: the production solve of its rows, with the step's own
// tolerance and cap unless given. Writes the impulses (row order, hex
// floats: exact) to `out` if given.
template <class Step>
int solve_step(const std::string& path, double tol, int max_sweeps, double residual_tol, int anderson,
               int subspace, const std::string& out) {
  cd::SolverParams prm;
  typename Step::Problem p = Step::read(path, prm);
  if (tol > 0) prm.tol = tol;
  if (max_sweeps > 0) prm.max_iter = max_sweeps;
  if (residual_tol >= 0) prm.residual_tol = residual_tol;
  if (anderson >= 0) prm.anderson = anderson;
  if (subspace >= 0) prm.subspace = subspace;
  fmt::print("{}: {}\n", path, Step::describe(p));
  const auto t0 = std::chrono::steady_clock::now();
  const cd::SolveStats st = Step::solve(p, prm);
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print(
      "nlgs: {} after {} sweeps (rms |dp|/|p| {:.3e}, tol {:.3g}), residual max {:.3e} mean "
      "{:.3e} (mean |p| {:.3e}), time {:.3g} s\n",
      st.cap_hit ? "NOT converged (sweep cap)" : st.residual_met ? "converged (law residual)" : "converged",
      st.iterations, st.dp_rel, prm.tol, st.residual_max, st.residual_mean, st.p_mean, t);
  if (st.anderson_off > 0) fmt::print("anderson: stalled, off after {} sweeps (plain NLGS from there)\n", st.anderson_off);
  if (prm.subspace > 0)
    fmt::print("subspace: {} CG iterations{}\n", st.subspace_iterations,
               st.subspace_off > 0 ? fmt::format(", stalled and stopped after {} sweeps", st.subspace_off) : "");
  if (!out.empty()) {
    cd::write_file_atomic(out, Step::impulses(p));  // WriteError (exit 4) if it cannot be written
  }
  return st.cap_hit ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdproblem: solve frozen frictional contact problems (2D .dat, .cdp; 3D .cdp3, FCLib .hdf5)"};
  app.require_subcommand(1);
  CLI::App* cmd = app.add_subcommand("solve", "solve one problem file with NLGS (or Lemke)");
  std::string path;
  cd::NlgsOptions opt;
  bool lemke = false;
  cmd->add_option("file", path, "problem file (.dat: Siconos matrix form, 2D or 3D; .cdp, .cdp3: a 2D or 3D step dumped by cdsim; .hdf5: FCLib 3D)")->required();
  cmd->add_option("--tol", opt.tol, "tolerance on the sweep's rms |dr|/mean|r| (the production test), in (0, 1]")
      ->check(cd::finite_range(0.0, 1.0, true))
      ->capture_default_str();
  cmd->add_option("--max-sweeps", opt.max_sweeps, "sweep cap")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  cmd->add_option("--check-every", opt.check_every, "residual checkpoint every K sweeps")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  cmd->add_flag("--lemke", lemke, "solve as an LCP with Lemke's method (small problems)");
  int facets = 4;
  cmd->add_option("--facets", facets, "(3D .hdf5 or .dat with --lemke) face pairs e of the polyhedral cone")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  std::string out;
  cmd->add_option("--out", out, "(.cdp, .cdp3) write the impulses, one row a line, as hex floats");
  double residual_tol = -1;
  cmd->add_option("--residual-tol", residual_tol,
                  "(.cdp, .cdp3) also stop when the largest law residual is below this (checked every 10 "
                  "sweeps; solver.residual_tol); 0: off; default: the step's own")
      ->check(cd::finite_range(0.0, 1.0));
  int anderson = -1;
  cmd->add_option("--anderson", anderson,
                  "(.cdp, .cdp3) Anderson acceleration over this many symmetric pairs (solver.anderson); 0: off; "
                  "default: the step's own")
      ->check(CLI::Range(0, cd::kAndersonMaxMemory));
  int subspace = -1;
  cmd->add_option("--subspace", subspace,
                  "(.cdp3) the subspace correction with at most this many CG iterations (solver.subspace); 0: off; "
                  "default: the step's own")
      ->check(CLI::Range(0, 1000));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cd::cli_error(app, e, "cdproblem");  // --help: 0; every usage error: bad input (2)
  }
  try {
    const auto ends = [&](const std::string& e) { return path.size() > e.size() && path.ends_with(e); };
    if (ends(".cdp") || ends(".cdp3")) {
      if (lemke) throw std::runtime_error("--lemke takes a .dat or .hdf5 problem (matrix form)");
      const bool tol_given = cmd->count("--tol") > 0, cap_given = cmd->count("--max-sweeps") > 0;
      return (ends(".cdp") ? solve_step<Step2> : solve_step<Step3>)(path, tol_given ? opt.tol : 0.0,
                                                       cap_given ? opt.max_sweeps : 0, residual_tol, anderson, subspace, out);
    }
    if (ends(".hdf5")) return solve_fclib(path, opt, lemke, facets);
    return solve_dat(path, opt, lemke, facets);
  } catch (const cd::WriteError& e) {
    std::cerr << "cdproblem: " << e.what() << "\n";
    return 4;
  } catch (const std::exception& e) {
    std::cerr << "cdproblem: error: " << e.what() << "\n";
    return 2;
  }
}
