// cdanalysis fit compaction: e = e0 - lambda ln(p/p0) over runs at several
// p (state_fit.cpp).
#include <memory>

#include "analysis/app/command.hpp"

namespace cda::cli {

Handler fit_compaction(CLI::App& sub) {
  auto o = std::make_shared<StateFitOptions>();
  sub.add_option("runs", o->runs, "run or campaign folders");
  sub.add_option("--table", o->table, "CSV with columns p, e and optionally e_err, instead of runs");
  sub.add_option("--p0", o->p0, "reference pressure (default: the geometric mean of the p's)")
      ->check(positive_number());
  sub.add_option("--window", o->window, "steady window a:b of each run's abscissa (strain), or a%:b% of each "
                                        "run's span of it (default: detected per run)")
      ->check(window_spec());
  sub.add_option("--out", o->out, "folder for the plot compaction.png/svg and its data");
  sub.add_option("--toml", o->toml_out, "write the fit parameters to this TOML file")
      ->check(writable_file());
  return [o] { return run_state_fit(*o, false); };
}

}  // namespace cda::cli
