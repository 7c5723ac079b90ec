// What the matrix-form replays of frozen contact problems report, whatever
// the dimension (2d/problem.hpp, 3d/problem3.hpp): the law residual over
// contacts, the NLGS options and statistics with their residual history.
#pragma once
#include <vector>

#include "solver.hpp"

namespace cd {

// Law residual of (r, u = W r + q): max and mean over contacts of the
// per-contact law residual, both divided by the mean impulse norm
// mean_k |r_k| (1 if that is 0, i.e. absolute).
struct Residual {
  double max = 0, mean = 0;
  double r_mean = 0;  // mean_k |r_k|, the scale used
};

struct NlgsOptions {
  double tol = 1e-6;     // the production test: rms |dr| / mean |r| over a sweep < tol
  int max_sweeps = 10000;
  int check_every = 10;  // law residual into the history every k sweeps (and at the end)
  int min_parallel = 0;  // > 0: the sweep's parallel threshold (0: the production default)
};

// The sweep's parameters for a frozen-problem solve.
inline SolverParams solver_params(const NlgsOptions& opt) {
  SolverParams prm;
  prm.tol = opt.tol;
  prm.max_iter = opt.max_sweeps;
  if (opt.min_parallel > 0) prm.min_parallel = opt.min_parallel;
  return prm;
}

struct NlgsCheckpoint {
  int sweep;
  double dr_rel, residual_max, residual_mean;
};

struct NlgsStats {
  int sweeps = 0;
  bool converged = false;  // dr_rel < tol before the sweep cap
  double dr_rel = 0;       // last sweep's rms |dr| / mean |r|
  Residual residual;       // at the end (recomputed from r)
  double siconos_error = 0;  // Siconos' error at the end (fc2d or fc3d)
  double time = 0;         // wall-clock seconds of the solve (setup included)
  std::vector<NlgsCheckpoint> history;
};

}  // namespace cd
