// cdproblem: replays a frozen contact problem (.dat, Siconos text format).
//   cdproblem solve FILE.dat [--tol 1e-6] [--max-sweeps N] [--check-every K] [--lemke]
// Prints the problem size, the NLGS residual every K sweeps and the time; with
// --lemke, the reference LCP solve instead. A malformed file is one message
// naming the file, line and what was wrong, and exit code 2 (as cdsim).
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "lemke.hpp"
#include "problem.hpp"

namespace {

// Lemke's dense tableau is 4nc x (8nc + 1) doubles and each pivot touches all
// of it: past this size it is minutes and gigabytes, not a reference.
constexpr int kLemkeMaxContacts = 1000;

int solve(const std::string& path, const cd::NlgsOptions& opt, bool lemke) {
  const cd::Problem p = cd::read_problem(path);
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
  const cd::NlgsStats st = cd::solve_nlgs(p, r, opt);
  fmt::print("{:>8} {:>12} {:>14} {:>14}\n", "sweep", "max|dr|/|r|", "residual max",
             "residual mean");
  for (const cd::NlgsCheckpoint& c : st.history)
    fmt::print("{:>8} {:>12.3e} {:>14.3e} {:>14.3e}\n", c.sweep, c.dr_rel, c.residual_max,
               c.residual_mean);
  fmt::print(
      "nlgs: {} after {} sweeps, residual max {:.3e} mean {:.3e} (mean |r| {:.3e}), "
      "time {:.3g} s ({:.3g} ms/sweep)\n",
      st.converged ? "converged" : "NOT converged (sweep cap)", st.sweeps, st.residual.max,
      st.residual.mean, st.residual.r_mean, st.time, st.sweeps ? 1e3 * st.time / st.sweeps : 0.0);
  return st.converged ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdproblem: solve frozen 2D frictional contact problems (.dat)"};
  app.require_subcommand(1);
  CLI::App* cmd = app.add_subcommand("solve", "solve one problem file with NLGS (or Lemke)");
  std::string path;
  cd::NlgsOptions opt;
  bool lemke = false;
  cmd->add_option("file", path, "problem file (.dat)")->required();
  cmd->add_option("--tol", opt.tol, "tolerance on max|dr|/mean|r| and on the law residual")
      ->capture_default_str();
  cmd->add_option("--max-sweeps", opt.max_sweeps, "sweep cap")->capture_default_str();
  cmd->add_option("--check-every", opt.check_every, "residual checkpoint every K sweeps")
      ->capture_default_str();
  cmd->add_flag("--lemke", lemke, "solve as an LCP with Lemke's method (small problems)");
  CLI11_PARSE(app, argc, argv);
  try {
    return solve(path, opt, lemke);
  } catch (const std::exception& e) {
    std::cerr << "cdproblem: error: " << e.what() << "\n";
    return 2;
  }
}
