// cdanalysis fit nu-i: nu(I) = nu_max - a I over steady runs (state_fit.cpp);
// runs at imposed volume (nu exact, I measured): fitted as I = (nu_max - nu)/a.
#include <memory>

#include "analysis/app/command.hpp"

namespace cda::cli {

Handler fit_nu_i(CLI::App& sub) {
  auto o = std::make_shared<StateFitOptions>();
  sub.add_option("runs", o->runs, "run or campaign folders");
  sub.add_option("--table", o->table, "CSV with columns I, nu and optionally nu_err (or, nu imposed, I_err: fitted "
                                      "in I), instead of runs");
  sub.add_option("--out", o->out, "folder for the plot nu_I.png/svg and its data");
  add_toml_option(sub, o->toml_out);
  add_window_option(sub, o->window);
  return [o] { return run_state_fit(*o, true); };
}

}  // namespace cda::cli
