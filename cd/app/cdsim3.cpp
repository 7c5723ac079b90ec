// cdsim3: the 3D sphere engine's interim command line (issue 12), running
// the pile3d deposition scene (cd/src/3d/pile3d.hpp) until a scene file
// with `dimension = 3` lands in cdsim. Writes series.csv and spheres_NNNNN.vtp
// (one point per sphere: radius, velocity, omega, orientation) into --out.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <omp.h>

#include "files.hpp"
#include "output3.hpp"
#include "pile3d.hpp"

int main(int argc, char** argv) {
  CLI::App app{"cdsim3: 3D spheres (contact dynamics), the pile3d deposition scene"};
  cd::Pile3dParams q;
  double time = 1.0;
  int every = 0, series = 10, threads = 0;
  std::string out = "outputs/pile3d";
  app.add_option("--n", q.n_spheres, "number of spheres")->check(CLI::PositiveNumber);
  app.add_option("--time", time, "simulated time (s)");
  app.add_option("--dt", q.dt, "time step (s)");
  app.add_option("--mu", q.mu, "friction coefficient (grains and walls)");
  app.add_option("--tol", q.solver.tol, "NLGS tolerance (rms |dp| / mean |p|)");
  app.add_option("--max-iter", q.solver.max_iter, "NLGS sweep cap");
  app.add_option("--alert", q.alert_rel, "alert distance / r_mean");
  app.add_option("--overlap-correction", q.overlap_correction,
                 "beta: overlaps separate at beta |gap|/dt (0: pure CD)");
  app.add_option("--seed", q.seed, "random seed (radii, jitter)");
  app.add_option("--out", out, "output folder");
  app.add_option("--vtk-every", every, "a spheres_NNNNN.vtp every k steps (0: first and last only)");
  app.add_option("--series-every", series, "a series.csv row every k steps");
  app.add_option("--threads", threads, "OpenMP threads (0: all)");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  try {
    cd::check_output_dir(out);
    std::filesystem::create_directories(out);
    cd::World3 w = cd::make_pile3d(q);
    const auto steps = static_cast<std::int64_t>(std::llround(time / q.dt));
    std::ofstream csv(out + "/series.csv");
    csv << "t,contacts,active,max_overlap,mean_overlap,kinetic_energy,sweeps,dp_rel,residual_max,cap_hit,wall\n";
    int snap = 0;
    auto snapshot = [&] { cd::write_spheres_vtp(w, fmt::format("{}/spheres_{:05d}.vtp", out, snap++)); };
    snapshot();
    const auto t0 = std::chrono::steady_clock::now();
    double omax = 0, wall = 0;
    long long sweeps = 0, updates = 0, caps = 0;
    for (std::int64_t k = 1; k <= steps; ++k) {
      w.step();
      const auto& s = w.last();
      omax = std::max(omax, s.max_overlap);
      sweeps += s.solve.iterations;
      updates += static_cast<long long>(s.solve.iterations) * s.contacts;
      caps += s.solve.cap_hit;
      wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (k % series == 0 || k == steps)
        csv << fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", w.time, s.contacts, s.active, s.max_overlap,
                           s.mean_overlap, w.kinetic_energy(), s.solve.iterations, s.solve.dp_rel,
                           s.solve.residual_max, s.solve.cap_hit ? 1 : 0, wall);
      if ((every > 0 && k % every == 0) || k == steps) snapshot();
    }
    // Overlaps in d_ref = the mean diameter 1.5 r_mean; the target is in r_mean.
    std::printf(
        "pile3d N=%d: %lld steps in %.2f s wall (%d threads); largest overlap %.3g r_mean (%.3g d); "
        "final KE %.3g J; %lld sweeps (%lld capped steps), %.3g row updates/s\n",
        q.n_spheres, static_cast<long long>(steps), wall, omp_get_max_threads(), 1.5 * omax, omax,
        w.kinetic_energy(), sweeps, caps, updates / std::max(wall, 1e-9));
    std::printf("stage times (s):");
    for (int i = 0; i < cd::kStages - 1; ++i) std::printf(" %s %.2f", cd::kStageNames[i], w.times.t[i]);
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cdsim3: %s\n", e.what());
    return 1;
  }
  return 0;
}
