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
  add_window_option(sub, o->window);
  sub.add_option("--out", o->out, "folder for the plot compaction.png/svg and its data");
  add_toml_option(sub, o->toml_out);
  return [o] { return run_state_fit(*o, false); };
}

}  // namespace cda::cli
