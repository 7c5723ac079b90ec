// cdanalysis steady RUN: the steady-state mean and error bar of one series column.
#include <fmt/core.h>

#include <filesystem>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {
namespace {

void print_stats(const RunSteady& r) {
  const auto& s = r.stats;
  fmt::print("run        {}\ncolumn     {}\nwindow     {} {} .. {} ({} rows, {})\n", r.run, r.column,
             r.x_column, s.window.x_begin, s.window.x_end, s.window.end - s.window.begin,
             r.detected ? "detected" : "given");
  fmt::print("mean       {:.8g} +- {:.3g}\n", s.mean, s.error());
  fmt::print("blocking   sem {:.3g} +- {:.2g} at block size {}{}\n", s.blocks.sem, s.blocks.sem_err,
             s.blocks.block_size, s.blocks.converged ? "" : " (no plateau: lower bound)");
  fmt::print("autocorr   tau_int {:.3g} +- {:.2g} rows, N_eff {:.1f}, sem {:.3g}{}\n", s.acf.tau,
             s.acf.tau_err, s.acf.n_eff, s.acf.sem, s.acf.converged ? "" : " (window not converged)");
  fmt::print("trend      slope {:.3g} +- {:.3g} per unit {}\n", s.trend.slope, s.trend.slope_se,
             r.x_column);
}

}  // namespace

Handler steady(CLI::App& sub) {
  struct Opt {
    std::string run, column, xcol, window, out;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("run", o->run, "run folder (holding series.csv)")->required();
  sub.add_option("--column", o->column, "column of series.csv (default: q_over_p; 3D runs: shear_stress_ratio)");
  sub.add_option("--x", o->xcol, "abscissa column (default: strain if present, else time)");
  sub.add_option("--window", o->window, "steady window a:b in the abscissa, or a%:b% of the run's span of it "
                                        "(default: detected)")
      ->check(window_spec());
  sub.add_option("--out", o->out, "folder for the time-series plot (png, svg) and its data");
  return [o] {
    const auto series = read_series(o->run);
    const std::string column = o->column.empty() ? mu_column(run_dimension(o->run)) : o->column;
    const std::string x = o->xcol.empty() ? default_x_column(series) : o->xcol;
    const auto range = window_range(o->window, series.column(x));
    const auto r = run_steady(o->run, series, column, x, range);
    print_stats(r);
    if (!o->out.empty()) {
      std::filesystem::create_directories(o->out);
      if (!plot_series(o->out, "series_" + column, series, x, column, &r.stats))
        fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", o->out);
    }
    return 0;
  };
}

}  // namespace cda::cli
