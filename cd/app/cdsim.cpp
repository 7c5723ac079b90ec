// cdsim: runs a scene, 2D (disks, polygons) or 3D (spheres; `dimension = 3`).
//   cdsim SCENE.toml [--set section.key=value]... [--out DIR] [--threads N] [--quiet] [--fresh]
//         [--dump-problem STEP|last|last-K]... [--print-scene]
// Everything is checked (scene, particles, output folder) before anything is
// written; any error is one message naming the problem, and exit code 2.
// Exit codes: 0 done; 2 bad input (usage, scene, start sample, checkpoint,
// output folder); 3 the run diverged (non-finite state: the watchdog);
// 4 could not write (disk full, a file made unwritable: the last checkpoint
// and the whole rows before it are intact; or the output folder was removed
// or replaced while the run wrote: nothing more written); 6 the output folder is being
// written by another cdsim; 128 + signal when stopped by SIGINT, SIGTERM or
// SIGHUP (at the next series row, with a checkpoint when checkpoints are on).
#include <omp.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_checks.hpp"
#include "cli_errors.hpp"
#include "config.hpp"
#include "files.hpp"
#include "load.hpp"
#include "parallel.hpp"
#include "output.hpp"
#include "run.hpp"
#include "run_plan.hpp"
#include "derived.hpp"
#include "run3.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "shear_policy.hpp"

namespace {

// Threads that would spin against other work (docs/accuracy.md, "Performance
// of a step"): warned once, before the run, with the machine's load.
void warn_if_oversubscribed(std::size_t bodies) {
  const char* wait = std::getenv("OMP_WAIT_POLICY");
  const bool sleeps = wait && (std::string(wait) == "passive" || std::string(wait) == "PASSIVE");
  if (const auto l = cd::load_average(); !l.empty() && !sleeps && bodies >= std::size_t(cd::kMinParallelBodies)) {
    const std::string w = cd::oversubscription_warning(omp_get_max_threads(), l[0], omp_get_num_procs());
    if (!w.empty()) fmt::print(stderr, "cdsim: warning: {}\n", w);
  }
}

// The closing lines: the run's accuracy and cost, the warnings they call
// for, and how it ended. Returns the exit code (0, or 128 + the signal that
// stopped it).
int report(const cd::RunSummary& s, const cd::Scene& scene, const std::string& out, std::int64_t max_steps) {
  const double per_step = s.steps ? s.wall_time / s.steps : 0.0;
  fmt::print(
      "cdsim: {} steps in {:.2f} s ({:.3g} ms/step, {} threads); iterations/step mean {:.1f}, "
      "max {}, cap hit {} times ({:.1f} % of steps); law residual max {:.2e}; overlap max "
      "{:.2e} d ({:.2e} of the smaller grain's diameter)\n",
      s.steps, s.wall_time, 1e3 * per_step, omp_get_max_threads(), s.mean_iterations,
      s.max_iterations, s.cap_hits, s.steps ? 100.0 * double(s.cap_hits) / double(s.steps) : 0.0,
      s.max_residual, s.max_overlap, s.max_overlap_small);
  if (scene.anderson > 0)  // how often the mixing stalled and the solve went on as plain NLGS
    fmt::print("cdsim: Anderson's mixing stalled and went off on {} steps ({:.1f} % of steps){}\n", s.anderson_off,
               s.steps ? 100.0 * double(s.anderson_off) / double(s.steps) : 0.0,
               s.cap_hits ? fmt::format(", on {} of the {} steps at the sweep cap", s.cap_anderson_off, s.cap_hits)
                          : std::string());
  if (scene.subspace > 0)  // the corrections' cost, in CG iterations (each about half a sweep's cost)
    fmt::print("cdsim: subspace corrections: {:.1f} CG iterations a step; stalled and stopped on {} steps ({:.1f} % of steps)\n",
               s.steps ? double(s.subspace_iterations) / double(s.steps) : 0.0, s.subspace_off,
               s.steps ? 100.0 * double(s.subspace_off) / double(s.steps) : 0.0);
  // A pressure-driven length held at its approach floor (a quarter of the
  // alert distance a step) by a load the floor does not let through even
  // from rest (core/cell_dof.hpp, load_past_floor) brings less than the
  // imposed pressure's impulse: on such steps the pressure is not applied,
  // and a run held so on more than 1 % of its steps measures at another
  // pressure. (A collapse from a loose start, held at the floor by the
  // speed it gathered, is the floor's purpose and is not counted.)
  const double floor_share = s.steps ? double(s.floor_steps) / double(s.steps) : 0.0;
  if (s.floor_steps > 0)
    fmt::print("cdsim: the cell's compaction was held at its floor on {} steps ({:.1f} % of steps)\n",
               s.floor_steps, 100.0 * floor_share);
  fmt::print("cdsim: outputs in {}/ (the run's cost: summary.toml)\n", out);
  // Over the whole run (every session), as summary.toml says.
  if (s.cap_share() > 0.01)
    fmt::print(stderr,
               "cdsim: warning: {:.1f} % of the run's steps ({} of {}) stopped at the sweep cap "
               "(solver.max_iter = {}) before reaching solver.tol: their contact laws are not "
               "converged (raise solver.max_iter or solver.tol, or shorten the time step; "
               "docs/accuracy.md)\n",
               100.0 * s.cap_share(), static_cast<long long>(s.totals.cap_steps), s.last_step,
               scene.max_iter);
  // With the mixing on, which setting ends such steps (docs/accuracy.md,
  // "Anderson at an explicit tolerance"): a law-residual stop when the run
  // has none (without one, plain NLGS capped as many steps or more, 2D and
  // 3D, measured), or more sweeps.
  if (s.cap_share() > 0.01 && scene.anderson > 0 && s.cap_hits > 0)
    fmt::print(stderr,
               "cdsim: warning: of this session's {} steps at the sweep cap, {} ended as plain NLGS after Anderson's "
               "mixing (solver.anderson = {}) stalled and went off, and {} with it on; {} (docs/accuracy.md)\n",
               s.cap_hits, s.cap_anderson_off, scene.anderson, s.cap_hits - s.cap_anderson_off,
               scene.residual_tol > 0
                   ? std::string("a larger solver.max_iter ends such steps")
                   : fmt::format("the setting that ends such steps is a law-residual stop, solver.residual_tol "
                                 "({:g} is the policy's with plain NLGS below I = 0.01), or a larger "
                                 "solver.max_iter: plain NLGS (solver.anderson = 0) without one capped as many "
                                 "steps or more",
                                 cd::kShearBands.front().plain.residual_tol));
  // The overlap users read: relative to the smaller grain of the pair.
  constexpr double kOverlapWarn = 0.01;
  if (s.max_overlap_small > kOverlapWarn)
    fmt::print(stderr,
               "cdsim: warning: the largest overlap reached {:.3g} of the smaller grain's "
               "diameter (> {}): see the series' max_overlap_small column; a smaller time step "
               "or tolerance reduces it\n",
               s.max_overlap_small, kOverlapWarn);
  if (floor_share > 0.01)
    fmt::print(stderr,
               "cdsim: warning: the cell's compaction was held at its floor on {:.1f} % of the steps (a "
               "length may shrink by at most a quarter of contact.alert a step): the imposed pressure was "
               "not fully applied on them; raise contact.alert or shear.cell_mass\n",
               100.0 * floor_share);
  const bool checkpoints = scene.checkpoint_interval > 0 || scene.checkpoint_strain > 0 ||
                           scene.checkpoint_wall > 0 || s.first_step > 0;
  if (s.settled)
    fmt::print("cdsim: settled at step {} of the scene's {} (shear.settle_*: contact stress within {:.2g} p of p, "
               "packing fraction within {:.2g}, over the last shear.settle_time){}\n",
               s.last_step, s.total_steps, s.settle_stress_dev, s.settle_phi_range,
               checkpoints ? "; checkpoint written: the sample"
                           : " (no checkpoint: output.checkpoint_interval, _strain and _wall are 0)");
  else if (s.settle_on && s.status == "done")
    fmt::print(stderr,
               "cdsim: warning: the compaction did not settle within time.duration (shear.settle_*): over "
               "the last window the contact stress was within {:.2g} p of p and the packing fraction within "
               "{:.2g}; the sample may not be jammed at p\n",
               s.settle_stress_dev, s.settle_phi_range);
  if (s.stopped_at_max_steps)
    fmt::print("cdsim: stopped after --max-steps {} (step {} of the scene's {})\n", max_steps,
               s.first_step + s.steps, s.total_steps);
  if (s.stop_signal) {
    fmt::print("cdsim: stopped by signal {} after step {}{}\n", s.stop_signal,
               s.first_step + s.steps,
               checkpoints
                   ? "; checkpoint written: the same command resumes"
                   : " (no checkpoint: output.checkpoint_interval, _strain and _wall are 0)");
    return 128 + s.stop_signal;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdsim: contact dynamics (Moreau-Jean) simulator for rigid grains, 2D or 3D (dimension = 3)"};
  std::string scene_path, out;
  std::vector<std::string> sets;
  int threads = -1;
  bool quiet = false, fresh = false, print_scene = false;
  std::string help_scene;
  app.add_option("scene", scene_path, "scene file (TOML)");
  app.add_option("--set", sets, "override a parameter: section.key=value (repeatable)");
  app.add_option("--out", out, "output folder (default: outputs/<scene name>)");
  app.add_option("--threads", threads, "OpenMP threads, 0 to 1024 (default: solver.threads, 0 = all)")
      ->check(CLI::Range(0, 1024));  // solver.threads' range: the resolved scene.toml must read back
  app.add_flag("--quiet,-q", quiet, "no progress line on stderr");
  app.add_flag("--fresh", fresh, "start over, discarding a checkpoint in the output folder");
  app.add_option("--help-scene", help_scene,
                 "print every scene parameter with its default, unit, rule and meaning; "
                 "--help-scene=md: as the Markdown table of docs/scene-parameters.md")
      ->expected(0, 1)
      ->check(CLI::IsMember({"", "md"}));
  app.add_flag("--print-scene", print_scene,
               "print the resolved scene (the scene.toml the run would write, \"auto\" keys set) and exit");
  std::vector<std::string> dump_words;
  app.add_option("--dump-problem", dump_words,
                 "write step STEP's contact problem into the output folder (repeatable; \"last\" is the "
                 "run's last step, \"last-K\" the step K before it): "
                 "problem_STEP.cdp (2D) or .cdp3 (3D), replayed exactly by cdproblem; .dat (2D, Siconos' "
                 "matrix form) or .hdf5 (3D, FCLib); .impulses")
      ->check(cd::dump_step_word());
  double progress_every = 0;
  app.add_option("--progress", progress_every,
                 "a progress line on stdout (folder, step, share done, ETA) every SECONDS of wall "
                 "clock, even with --quiet or into a log (make's campaigns: every 300 s)")
      ->check(cd::finite_range(0.0, 1e9));
  std::int64_t max_steps = 0;
  app.add_option("--max-steps", max_steps,
                 "stop after N steps (a series row and, with checkpoints on, a checkpoint the "
                 "same command resumes from): to try a scene or a campaign's first steps")
      ->check(cd::positive_count());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; every usage error is bad input: exit 2.
    return cd::cli_error(app, e, "cdsim");
  }
  // A stop asked while the scene is read and built stops the run at its
  // first series row (not the process at once, with nothing to resume).
  cd::install_stop_handlers();
  // Status lines reach a log file as they are printed, even if the run is killed.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // A file size limit (ulimit -f) makes a write fail (exit 4), not kill the run.
  std::signal(SIGXFSZ, SIG_IGN);

  if (app.count("--help-scene")) {
    std::cout << (help_scene == "md" ? cd::parameter_table_markdown() : cd::parameter_table_text());
    return 0;
  }
  if (scene_path.empty()) {
    std::cerr << "cdsim: no scene file given (try: cdsim configs/default.toml)\n";
    return 2;
  }
  try {
    cd::Scene scene = cd::load_scene(scene_path, sets);
    if (quiet) scene.quiet = true;
    if (threads >= 0) scene.threads = threads;
    if (print_scene) {
      std::cout << cd::resolved_toml(scene);
      return 0;
    }
    if (out.empty()) out = "outputs/" + scene.name;
    const bool three = scene.dimension == 3;
    // Everything is built and checked before anything is written.
    std::optional<cd::World> world;
    std::optional<cd::World3> world3;
    const cd::CompleteScene complete = cd::complete_scene(scene);
    if (three) world3.emplace(cd::build_world3(complete));
    else world.emplace(cd::build_world(complete));
    cd::check_output_dir(out);
    if (scene.threads > 0) omp_set_num_threads(scene.threads);
    warn_if_oversubscribed(three ? world3->bodies.size() : world->bodies.size());

    const std::vector<std::int64_t> dump_steps =
        cd::dump_steps(dump_words, cd::plan_of(scene, complete.dt).nsteps);
    cd::RunOptions opt{out, scene.quiet, cd::resolved_toml(scene), fresh, dump_steps, max_steps};
    opt.progress_every = progress_every;
    return report(three ? cd::run3(*world3, scene, opt) : cd::run(*world, scene, opt), scene, out, max_steps);
  } catch (const cd::RunDiverged& e) {
    std::cerr << "cdsim: run diverged: " << e.what() << "\n";
    return 3;
  } catch (const cd::FolderGone& e) {
    // Not a resumable write failure: the folder is another's now.
    std::cerr << "cdsim: " << e.what() << "\n";
    return 4;
  } catch (const cd::WriteError& e) {
    std::cerr << "cdsim: " << e.what()
              << "; the run stopped there: series.csv holds whole rows and the last checkpoint (if any) "
                 "is intact, so the same command resumes once the file can be written\n";
    return 4;
  } catch (const cd::FolderBusy& e) {
    std::cerr << "cdsim: " << e.what() << "\n";
    return 6;
  } catch (const std::exception& e) {
    std::cerr << "cdsim: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
