// cdanalysis fit dilatancy: sin phi = sin phi_c + sin psi over the rows of
// shear runs, transient and steady (dilatancy.hpp); 2D only.
#include <fmt/core.h>

#include <cmath>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/dilatancy.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {

Handler fit_dilatancy(CLI::App& sub) {
  struct Opt {
    std::vector<std::string> runs;
    std::string toml_out, out, strain_range;
    std::size_t blocks_per_bin = 4;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("runs", o->runs, "run or campaign folders (series.csv with q_over_p, volume_strain_rate, "
                                  "shear_rate)")->required();
  sub.add_option("--blocks-per-bin", o->blocks_per_bin,
                 "blocks of ceil(4 tau) rows averaged into one point (consecutive in strain)")
      ->check(CLI::Range(2, 1000000))
      ->capture_default_str();
  sub.add_option("--strain,--window", o->strain_range,
                 "use the rows with a <= strain <= b only (a:b; default all: this fit uses the transient too)");
  sub.add_option("--out", o->out, "folder for the binned points, the fit curve and the plot (png, svg)");
  sub.add_option("--toml", o->toml_out, "write the fit parameters (fixed and free slope) to this TOML file")
      ->check(writable_file());
  return [o] {
    DilatancyOptions opt;
    opt.blocks_per_bin = o->blocks_per_bin;
    if (!o->strain_range.empty()) opt.strain = parse_range(o->strain_range);
    std::vector<RunDilatancy> rd;
    std::vector<std::string> left_out;
    const auto all = expand_runs(o->runs);
    for (const auto& r : all) {
      // A run too short for its bins is skipped with the reason (the
      // transient data of the other runs still make a fit); none usable: error.
      refuse_3d(r, "fit dilatancy (sin psi from the 2D Mohr circle of the strain rate)");
      try {
        rd.push_back(run_dilatancy(r, read_series(r), opt));
      } catch (const AnalysisError& e) {
        if (all.size() == 1) throw;
        fmt::print("{}: skipped: {}\n", r, e.what());
        left_out.push_back(r);
        continue;
      }
      const auto& d = rd.back();
      fmt::print("{}: {} rows ({} skipped), tau {:.3g} rows, blocks of {} rows, {} bins, reliability of "
                 "sin psi {:.3f}\n",
                 r, d.rows, d.skipped, d.tau, d.block_rows, d.bins.size(), d.reliability);
    }
    if (rd.empty()) throw AnalysisError("fit dilatancy: no usable run (each was skipped, see above)");
    const auto f = fit_dilatancy_runs(std::move(rd));
    print_fit(f.fixed, dilatancy());
    print_fit(f.free, dilatancy_free());
    const double b = f.free["b"], be = f.free.err("b");
    fmt::print("slope check: b = {:.4f} +- {:.4f}, (b - 1)/err = {:.2f}{}\n", b, be, (b - 1) / be,
               std::abs(b - 1) > 3 * be ? "  (b differs from the model's 1 by more than 3 sigma; a free "
                                          "slope is biased towards 0 by the reliability of sin psi)"
                                        : "");
    write_toml(o->toml_out, {f.fixed, f.free}, {dilatancy(), dilatancy_free()});
    if (!o->out.empty() && !plot_dilatancy(o->out, f))
      fmt::print(stderr, "warning: gnuplot failed; the script is in {}\n", o->out);
    return with_reservations("fit dilatancy", left_out, f.fixed);
  };
}

}  // namespace cda::cli
