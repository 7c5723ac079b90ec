// cdanalysis fit nu-i: nu(I) = nu_max - a I over steady runs (state_fit.cpp).
#include <memory>

#include "analysis/app/command.hpp"

namespace cda::cli {

Handler fit_nu_i(CLI::App& sub) {
  auto o = std::make_shared<StateFitOptions>();
  sub.add_option("runs", o->runs, "run or campaign folders");
  sub.add_option("--table", o->table, "CSV with columns I, nu and optionally nu_err, instead of runs");
  sub.add_option("--out", o->out, "folder for the plot nu_I.png/svg and its data");
  sub.add_option("--toml", o->toml_out, "write the fit parameters to this TOML file")
      ->check(writable_file());
  sub.add_option("--window", o->window, "steady window a:b of each run's abscissa (strain), or a%:b% of each "
                                        "run's span of it (default: detected per run)")
      ->check(window_spec());
  return [o] { return run_state_fit(*o, true); };
}

}  // namespace cda::cli
