// cdbench3: what the 3D sphere step costs, run
// by `make bench` after cdbench. Measures only; nothing is asserted.
//
// Scenes: N = 1e3 is pile3d (configs/pile3d.toml's scene, make_pile3d)
// deposited and settled at coarse settings; larger N are kx x ky copies of
// it side by side in one box (floor and four walls around them all), a
// layer of the same depth, so that the work per contact is the same at
// every N: 3e3 (3 x 1) and 1e4 (5 x 2) by default, 3e4 (5 x 6) and 1e5
// (10 x 10) with --big (make bench BIG=1). Preparation runs on one thread.
//
// For each N and 1 and 2 OpenMP threads, after warm-up steps that rebuild
// the warm start, `steps` time steps with a fixed number of sweeps (tol = 0,
// max_iter = kSweeps, so that every N and thread count does the same work):
//   ms_step             wall time per step
//   updates_per_s_core  contact updates (rows x sweeps) per second of the
//                       solve stage, per thread
//   t_<stage>_ms        per step, by stage (core/stages.hpp)
// and, at 1e3 on one thread, a converged step (pile3d's tol = 1e-4): its
// sweeps and time, and the sweep alone: one step's contact problem frozen
// and solved again with exactly kKernelSweeps sweeps, timed in CPU seconds
// of the process (best of kKernelRuns), so that the figure holds on a
// loaded machine where the wall clock does not (wall-clock figures scattered
// 1.8-3.1x between runs on a shared machine; this one repeated to 1 %).
// --out DIR writes
//   bench3.csv    one line per (N, threads)
//   summary3.csv  2-thread speedups of the step and the solve, updates/s
//                 per core, the frozen step's updates per CPU second, the
//                 slope of ms/step against N (log-log)
//   machine.csv   CPU, cores, compiler, flags, load average (machine.hpp)
#include <omp.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "machine.hpp"
#include "pile3d.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kSweeps = 50;
constexpr int kKernelSweeps = 200, kKernelRuns = 5;

struct Threads {  // OpenMP threads for one scope
  int saved;
  explicit Threads(int t) : saved(omp_get_max_threads()) { omp_set_num_threads(t); }
  ~Threads() { omp_set_num_threads(saved); }
};

// pile3d with N = 1000 deposited and settled (coarse tolerance: the state,
// not its accuracy, is what the timings need).
cd::World3 base_pile(double settle_time) {
  Threads one(1);
  cd::Pile3dParams q;
  q.n_spheres = 1000;
  q.solver.tol = 1e-2;
  q.solver.max_iter = 200;
  cd::World3 w = cd::make_pile3d(q);
  const int steps = static_cast<int>(std::lround(settle_time / q.dt));
  for (int k = 0; k < steps; ++k) w.step();
  return w;
}

// kx x ky copies of the base pile's spheres, side by side, in one box.
cd::World3 tiled(const cd::World3& base, int kx, int ky, const cd::WorldParams3& p) {
  const double L = base.bodies.pos[2].x();  // the x = L wall of the base box
  cd::World3 w(p);
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(0, 0, 1));
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(1, 0, 0));
  w.bodies.add_plane(cd::Vec3(kx * L, 0, 0), cd::Vec3(-1, 0, 0));
  w.bodies.add_plane(cd::Vec3::Zero(), cd::Vec3(0, 1, 0));
  w.bodies.add_plane(cd::Vec3(0, ky * L, 0), cd::Vec3(0, -1, 0));
  const cd::Bodies3& b = base.bodies;
  for (int j = 0; j < ky; ++j)
    for (int i = 0; i < kx; ++i)
      for (std::size_t s = 0; s < b.size(); ++s) {
        if (b.shape[s] != cd::Shape3::Sphere) continue;
        const int id = w.bodies.add_sphere(b.pos[s] + cd::Vec3(i * L, j * L, 0), b.radius[s], 1.0,
                                           b.vel[s].v, b.vel[s].w);
        w.bodies.mass[id] = b.mass[s];
        w.bodies.inertia[id] = b.inertia[s];
        w.bodies.vel[id].inv_m = b.vel[s].inv_m;
        w.bodies.vel[id].inv_I = b.vel[s].inv_I;
        w.bodies.orient[id] = b.orient[s];
      }
  return w;
}

struct Result {
  int n = 0, threads = 0, steps = 0;
  double contacts = 0, ms_step = 0, updates_per_s_core = 0, solve_ms = 0;
  cd::StageTimes per_step;  // s per step
};

Result measure(cd::World3 w, int threads, int steps) {
  Threads t(threads);
  for (int k = 0; k < 3; ++k) w.step();  // warm start, caches, thread team
  const cd::StageTimes t0 = w.times;
  double rows = 0, sweeps = 0;
  const auto c0 = Clock::now();
  for (int k = 0; k < steps; ++k) {
    w.step();
    rows += w.last().contacts;
    sweeps += double(w.last().contacts) * w.last().solve.iterations;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - c0).count();
  Result r;
  r.threads = threads;
  r.steps = steps;
  r.contacts = rows / steps;
  r.ms_step = 1e3 * wall / steps;
  for (int s = 0; s < cd::kStages; ++s) r.per_step.t[s] = (w.times.t[s] - t0.t[s]) / steps;
  const double solve = w.times[cd::Stage::Solve] - t0[cd::Stage::Solve];
  r.solve_ms = 1e3 * solve / steps;
  r.updates_per_s_core = sweeps / solve / threads;
  return r;
}

double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// The sweep alone on one thread: the next step's contact problem of w,
// frozen, solved kKernelRuns times from its warm start with exactly
// kKernelSweeps sweeps; contact updates per CPU second, the best run.
// compliance > 0: the same problem with compliant contacts of that rho
// (coupling3.hpp's BodyCouplingT3: what the option costs an update).
double kernel_updates_per_cpu_s(cd::World3 w, double compliance = 0.0) {
  Threads one(1);
  cd::ContactProblem3 frozen;
  cd::SolverParams prm;
  w.set_problem_hook([&](const cd::ContactProblem3& p, const cd::SolverParams& s) {
    frozen = p;
    prm = s;
  });
  w.step();
  frozen.compliance = compliance;  // k_t = k (compliance_t 0)
  prm.tol = 0.0;  // never met: exactly kKernelSweeps sweeps
  prm.residual_tol = 0.0;
  prm.max_iter = kKernelSweeps;
  double best = 0.0;
  for (int k = 0; k < kKernelRuns; ++k) {
    cd::ContactProblem3 p = frozen;
    const double t0 = cpu_seconds();
    const cd::SolveStats st = cd::nlgs_solve3(p, prm);
    const double t = cpu_seconds() - t0;
    best = std::max(best, double(p.rows.size()) * st.iterations / t);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string load_start = cdbench::load_average();
  CLI::App app{"cdbench3: cost of the 3D sphere step against N and threads (make bench)"};
  std::string out = "outputs/bench/3d";
  bool big = false;
  double settle = 0.6;
  app.add_option("--out", out, "output folder");
  app.add_flag("--big", big, "also N = 3e4 and 1e5 (minutes; make bench BIG=1)");
  app.add_option("--settle", settle, "simulated time the 1e3 base pile settles (s)");
  CLI11_PARSE(app, argc, argv);

  const auto p0 = Clock::now();
  const cd::World3 base = base_pile(settle);
  std::printf("cdbench3: base pile (N = 1000) settled for %.2f s simulated in %.1f s; KE %.3g J\n", settle,
              std::chrono::duration<double>(Clock::now() - p0).count(), base.kinetic_energy());

  // Converged step at 1e3 on one thread: what a real run's step costs.
  {
    cd::World3 w = base;
    cd::WorldParams3 p = w.params();
    p.solver.tol = 1e-4;
    p.solver.max_iter = 2000;
    w.set_params(p);
    const Result r = measure(w, 1, 20);
    std::printf("cdbench3: converged (tol 1e-4) N = 1000, 1 thread: %.2f ms/step, %.0f contacts\n", r.ms_step,
                r.contacts);
  }
  const double kernel = kernel_updates_per_cpu_s(base);
  std::printf("cdbench3: frozen step N = 1000, %d sweeps, 1 thread: %.3g contact updates per CPU second (best of %d)\n",
              kKernelSweeps, kernel, kKernelRuns);
  // Compliant contacts, rho = W_nn / 100 of a pair of mean spheres (kappa ~
  // 1e4 in dense shear's units): the same frozen step.
  // The mean over the spheres only: planes and driven bodies (inv_m = 0)
  // would lower it.
  double wnn = 0.0;
  std::size_t spheres = 0;
  for (std::size_t i = 0; i < base.bodies.size(); ++i)
    if (base.bodies.vel[i].inv_m > 0) wnn += base.bodies.vel[i].inv_m, ++spheres;
  wnn = spheres ? 2.0 * wnn / static_cast<double>(spheres) : 0.0;
  const double kernel_c = kernel_updates_per_cpu_s(base, 0.01 * wnn);
  std::printf("cdbench3: the same step with compliant contacts: %.3g contact updates per CPU second (%.2fx rigid)\n",
              kernel_c, kernel_c / kernel);

  struct Size {
    int kx, ky;
  };
  std::vector<Size> sizes = {{1, 1}, {3, 1}, {5, 2}};
  if (big) sizes.insert(sizes.end(), {{5, 6}, {10, 10}});
  std::vector<Result> res;
  for (const Size& s : sizes) {
    cd::WorldParams3 p = base.params();
    p.solver.tol = 0.0;  // never met: exactly kSweeps sweeps
    p.solver.max_iter = kSweeps;
    const cd::World3 w = tiled(base, s.kx, s.ky, p);
    const int n = 1000 * s.kx * s.ky;
    const int steps = std::max(3, static_cast<int>(std::lround(2e7 / (3.0 * n * kSweeps))));
    for (int t : {1, 2}) {
      Result r = measure(w, t, steps);
      r.n = n;
      std::printf("cdbench3: N = %6d, %d thread(s): %8.2f ms/step, %7.0f contacts, solve %.2f ms, "
                  "%.3g contact updates/s/core\n", n, t, r.ms_step, r.contacts, r.solve_ms,
                  r.updates_per_s_core);
      std::fflush(stdout);
      res.push_back(r);
    }
  }

  // Summary: speedups, updates/s/core, slope of ms/step (1 thread) against N.
  std::vector<std::tuple<std::string, double, std::string>> summary;
  summary.emplace_back("frozen_step_updates_per_cpu_s/1000", kernel, "1/s");
  summary.emplace_back("frozen_step_updates_per_cpu_s_compliant/1000", kernel_c, "1/s");
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (std::size_t i = 0; i + 1 < res.size(); i += 2) {
    const Result &a = res[i], &b = res[i + 1];
    summary.emplace_back(fmt::format("speedup_step_2t/{}", a.n), a.ms_step / b.ms_step, "");
    summary.emplace_back(fmt::format("speedup_solve_2t/{}", a.n), a.solve_ms / b.solve_ms, "");
    summary.emplace_back(fmt::format("updates_per_s_core_1t/{}", a.n), a.updates_per_s_core, "1/s");
    summary.emplace_back(fmt::format("updates_per_s_core_2t/{}", a.n), b.updates_per_s_core, "1/s");
    summary.emplace_back(fmt::format("ms_per_step_1t/{}", a.n), a.ms_step, "ms");
    const double x = std::log(double(a.n)), y = std::log(a.ms_step);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++m;
  }
  if (m >= 2) summary.emplace_back("slope_ms_step_vs_N", (m * sxy - sx * sy) / (m * sxx - sx * sx), "log-log");
  std::printf("\nSummary (load average at start %s)\n", load_start.c_str());
  for (const auto& [k, v, u] : summary) std::printf("  %s = %.4g %s\n", k.c_str(), v, u.c_str());

  std::filesystem::create_directories(out);
  {
    std::ofstream f(out + "/bench3.csv");
    f << "N,threads,steps,contacts,ms_step,solve_ms,updates_per_s_core";
    for (const char* s : cd::kStageNames) f << ",t_" << s << "_ms";
    f << "\n";
    for (const Result& r : res) {
      f << fmt::format("{},{},{},{:.1f},{:.4g},{:.4g},{:.4g}", r.n, r.threads, r.steps, r.contacts, r.ms_step,
                       r.solve_ms, r.updates_per_s_core);
      for (double t : r.per_step.t) f << fmt::format(",{:.4g}", 1e3 * t);
      f << "\n";
    }
  }
  {
    std::ofstream f(out + "/summary3.csv");
    f << "metric,value,unit\n";
    for (const auto& [k, v, u] : summary) f << fmt::format("{},{:.6g},{}\n", k, v, u);
  }
  cdbench::write_machine_csv(out + "/machine.csv", cdbench::machine(load_start));
  std::printf("cdbench3: wrote %s/{bench3,summary3,machine}.csv\n", out.c_str());
  return 0;
}
