// cdanalysis profile RUN: is the shear homogeneous? The local shear rate
// across the layers of a shear run (periodic cell or walls protocol) over
// its steady window.
#include <fmt/core.h>

#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {

Handler profile(CLI::App& sub) {
  struct Opt {
    std::string run, window;
    int layers = 5;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("run", o->run, "run folder (series.csv, particle snapshots and their .pvd)")->required();
  sub.add_option("--layers", o->layers, "layers across the gradient direction y")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  sub.add_option("--window", o->window, "as steady's --window (default: the detected steady window of mu)")
      ->check(window_spec());
  return [o] {
    const int layers = o->layers;
    const auto series = read_series(o->run);
    const std::string x = default_x_column(series);
    const auto r =
        run_steady(o->run, series, mu_column(run_dimension(o->run)), x, window_range(o->window, series.column(x)));
    const auto& w = r.stats.window;
    const auto pr = shear_profile(o->run, series, x, w, layers);
    fmt::print("window     {} {:.4g} to {:.4g}: {} particle snapshots\n", x, w.x_begin, w.x_end, pr.snapshots);
    if (pr.walls) {
      fmt::print("local shear rate / imposed rate between layer centres (1: homogeneous), from the displacements "
                 "over each of the {} intervals between them, mean +- sem:\n",
                 pr.snapshots - 1);
      const auto name = [&](int i) { return i == 0 ? std::string("wall") : std::to_string(i - 1); };
      for (int i = 0; i <= layers; ++i)
        fmt::print("  gap {:>4}-{:<4} {:.3f} +- {:.3f}{}\n", name(i), i == layers ? std::string("wall") : name(i + 1),
                   pr.rate[i].v, pr.rate[i].err,
                   i == 0 ? "  (the bottom wall's grains to layer 0's centre)"
                          : (i == layers ? "  (to the top wall's grains)" : ""));
    } else {
      fmt::print("local shear rate / mean rate between layer centres (1: homogeneous), mean +- sem over them:\n");
      for (int i = 0; i < layers; ++i)
        fmt::print("  gap {:>3}-{:<3} {:.3f} +- {:.3f}{}\n", i, (i + 1) % layers, pr.rate[i].v, pr.rate[i].err,
                   i + 1 == layers ? "  (across the periodic boundary)" : "");
    }
    fmt::print("rate_min   {:.3f} +- {:.3f}{}\n", pr.rate_min.v, pr.rate_min.err,
               is_banded(pr.rate_min.v) ? fmt::format("  banded: below {} (a layer moves nearly as a rigid "
                                                      "plug; the run's I is not the local one)",
                                                      kBandedRateMin)
                                        : std::string());
    fmt::print("max_rate   {:.3f} +- {:.3f} (per {}, then averaged)\n", pr.max_rate.v, pr.max_rate.err,
               pr.walls ? "interval" : "snapshot");
    if (pr.walls) {
      fmt::print("bulk_rate  {:.3f} +- {:.3f} (the central half of the gap, where the bulk is measured: the slope "
                 "of its displacement against y / the imposed strain)\n",
                 pr.bulk_rate.v, pr.bulk_rate.err);
      fmt::print("bulk_phi   {:.4f} +- {:.4f} (the central half's packing fraction, each grain's area in it, over the "
                 "{} snapshots; counting whole grains by their centre, as the series' bulk_packing_fraction: "
                 "{:.4f} +- {:.4f})\n",
                 pr.bulk_phi.v, pr.bulk_phi.err, pr.snapshots, pr.bulk_phi_centres.v, pr.bulk_phi_centres.err);
    }
    return 0;
  };
}

}  // namespace cda::cli
