// What the 2D World (2d/world.hpp) and World3 (3d/world3.hpp) share besides
// their stages: the bodies, the clock, the stage timers, the last step's
// statistics, contact problem and contact records, the solve stage's solver
// slot and problem hook, the warm-start memory by contact key, and the
// colour stage. An engine derives from WorldShell<its bodies, its contact
// problem, its contact record, its remembered impulse> and writes the
// stages that differ (predict, detect, build, integrate, observe).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "colour_rows.hpp"
#include "solver.hpp"
#include "stages.hpp"
#include "warm_start.hpp"

namespace cd {

template <class BodiesT, class Problem, class Info, class Impulse>
class WorldShell {
 public:
  using Row = typename decltype(Problem::rows)::value_type;

  BodiesT bodies;
  double time = 0.0;
  std::int64_t steps = 0;
  StageTimes times;

  const StepStats& last() const { return last_; }
  // The contact problem of the last step (solved), in colour order; its
  // `vel` is empty outside the solve stage (the velocities are in bodies).
  const Problem& problem() const { return prob_; }
  const std::vector<Row>& rows() const { return prob_.rows; }
  // The last step's contact records (gap, key, images, ...), row by row.
  const std::vector<Info>& infos() const { return info_; }

  // The solve stage's solver (default: the engine's NLGS): a study may put
  // another one in (cd/bench), the rest of the step unchanged.
  using Solver = std::function<SolveStats(Problem&, const SolverParams&)>;
  void set_solver(Solver s) { solver_ = std::move(s); }
  // Called with the problem just before it is solved (its impulses the warm
  // start, already in its velocities): --dump-problem writes it out.
  using ProblemHook = std::function<void(const Problem&, const SolverParams&)>;
  void set_problem_hook(ProblemHook h) { hook_ = std::move(h); }

  // Warm-start memory: the previous step's impulses by contact key
  // (core/warm_start.hpp). Part of the state a bit-identical restart
  // restores (the checkpoints).
  using WarmStart = cd::WarmStart<Impulse>;
  const WarmStart& warm_start() const { return warm_; }
  void set_warm_start(WarmStart w) { warm_ = std::move(w); }

 protected:
  // The colour stage: the rows coloured by their bodies (core/colour_rows.hpp),
  // then the rows, their records and the engine's other per-row arrays
  // (`more`; an empty one stays empty) put in colour order.
  template <class... More>
  void colour_and_permute(bool parallel, std::vector<More>&... more) {
    prob_.colouring = colour_by_bodies(
        static_cast<int>(prob_.rows.size()), bodies.size(), [&](int i) { return prob_.rows[i].b1; },
        [&](int i) { return prob_.rows[i].b2; }, [&](std::int32_t b) { return bodies.is_dynamic(b); });
    const std::vector<std::int32_t>& perm = prob_.colouring.perm;
    permute(prob_.rows, perm, parallel);
    permute(info_, perm, parallel);
    (permute(more, perm, parallel), ...);
  }

  // The solve: the problem takes the bodies' velocities, the hook sees it,
  // the study's solver or `nlgs` solves it, and the velocities go back.
  template <class Nlgs>
  void solve_problem(const SolverParams& prm, Nlgs&& nlgs) {
    prob_.vel.swap(bodies.vel);
    if (hook_) hook_(prob_, prm);
    last_.solve = solver_ ? solver_(prob_, prm) : nlgs(prob_, prm);
    prob_.vel.swap(bodies.vel);
  }

  // The solved impulses, impulse(k) of row k, kept for the next step's
  // warm start under the rows' contact keys.
  template <class F>
  void keep_warm(F&& impulse) {
    warm_.keep(prob_.rows.size(), [&](std::size_t k) { return info_[k].key; }, impulse);
  }

  // After the stages: the clock, steps times dt (not a running sum: no drift).
  void count_step(double dt) {
    ++steps;
    time = static_cast<double>(steps) * dt;
  }

  StepStats last_;
  Problem prob_;
  std::vector<Info> info_;
  WarmStart warm_;

 private:
  // a[k] = a[perm[k]] (rows to colour order).
  template <class T>
  static void permute(std::vector<T>& a, const std::vector<std::int32_t>& perm, bool parallel) {
    if (a.empty()) return;
    std::vector<T> b(a.size());
#pragma omp parallel for schedule(static) if (parallel)
    for (std::size_t k = 0; k < a.size(); ++k) b[k] = a[perm[k]];
    a.swap(b);
  }

  Solver solver_;
  ProblemHook hook_;
};

}  // namespace cd
