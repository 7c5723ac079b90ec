// cdanalysis: steady-state statistics, fabric, fits and reports of cdsim
// runs. Every failure prints one line naming the file or quantity at fault.
// Exit codes (error.hpp): 0 done; 1 analysis refused (a degenerate fit, no
// steady window, a compare-fits FAIL); 2 bad input (usage, unreadable or
// malformed file, non-finite value, option out of range).
//
// The subcommands are the tables below, one file each in commands/.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <string>
#include <vector>

#include "analysis/app/command.hpp"

using namespace cda;
using namespace cda::cli;

namespace {

const Command kCommands[] = {
    {"steady", "steady-state mean and error bar of one series column", cli::steady},
    {"fabric", "anisotropies, stress and connectivity of a contact snapshot", cli::fabric},
    {"profile", "is the shear homogeneous? local shear rate across the layers of a shear run (periodic or walls), over its "
                "steady window (run.hpp shear_profile)",
     cli::profile},
    // "fit" (the group below) comes here in --help
    {"compare-fits",
     "compare the parameters of two fit TOML files (as written by --toml or report). A parameter FAILs when "
     "|new - ref| > TOL_SIGMA sqrt(err_ref^2 + err_new^2) AND |new - ref| > TOL_REL |ref|; a model or parameter "
     "of REFERENCE missing from NEW, a non-finite value, or a fit no longer converged FAILs too. Exit status: 0 "
     "all OK, 1 some FAIL, 2 a file unreadable.",
     cli::compare_fits},
    {"report", "tables, fits, plots and index.html for a campaign", cli::report},
    {"draw", "a PNG of a snapshot without ParaView: grains with their outlines and the force chains (3D: a slice)",
     cli::draw},
};
constexpr std::size_t kFitPosition = 3;  // "fit" after profile

const Command kFits[] = {
    {"mu-i", "mu(I) = mu1 + (mu2 - mu1)/(1 + I0/I) over steady runs", cli::fit_mu_i},
    {"cohesion",
     "c/p = k0 eta/(1 - beta ln(1 - I/(1 + alpha eta)^(1/2))) over steady runs: eta from scene.toml ([contact] "
     "cohesion_number), I the measured inertial_number, c/p = (q/p - sin phi)/cos phi with sin phi(I) from the "
     "eta = 0 runs among those given; 3D runs: c/p = mu - mu0(I), mu the shear_stress_ratio, mu0(I) that of the "
     "eta = 0 runs",
     cli::fit_cohesion},
    {"dilatancy",
     "sin phi = sin phi_c + sin psi over the rows of shear runs (transient and steady), sin phi = q/p, sin psi = "
     "volume_strain_rate/sqrt(volume_strain_rate^2 + shear_rate^2); also the free slope b",
     cli::fit_dilatancy},
    {"angularity",
     "mu*(alpha) = mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)) and nu*(alpha) of the same form over steady shear "
     "runs, alpha = 2 pi/n_s (disks 0) from each run's shapes, or over a table (--table); also the table of z, "
     "anisotropies, sliding and side-side shares, partial strengths q_sv/p, q_ss/p and the check q/p ~ (sum a)/2 "
     "per run",
     cli::fit_angularity},
    {"nu-i",
     "nu(I) = nu_max - a I over steady runs (packing_fraction against the measured inertial number; runs at "
     "imposed volume, nu exact: fitted as I = (nu_max - nu)/a, weighted by I's error bars)",
     cli::fit_nu_i},
    {"compaction",
     "e = e0 - lambda ln(p/p0) over steady (or compacted) runs at several p: e = 1/nu - 1 from the steady "
     "packing_fraction, p the steady mean of the series' p (else the scene's [shear] pressure)",
     cli::fit_compaction},
    {"fabric-bounds", "envelope z_min, z_max of (z, a_c) points", cli::fit_fabric_bounds},
};

struct Declared {
  CLI::App* sub;
  Handler run;
};

void declare(CLI::App& parent, const Command& c, std::vector<Declared>& out) {
  CLI::App* sub = parent.add_subcommand(c.name, c.help);
  out.push_back({sub, c.declare(*sub)});
}

// A parse error: --help prints and gives 0; any other is bad input (2),
// told as every other message is, "cdanalysis: ...", with the commands the
// innermost one given accepts (CLI11's own text names neither the program
// nor what was wanted: "A subcommand is required").
int usage_error(CLI::App& app, const CLI::ParseError& e) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
  CLI::App* at = &app;
  std::string path = "cdanalysis";
  for (bool deeper = true; deeper;) {
    deeper = false;
    for (CLI::App* sub : at->get_subcommands())
      if (sub->parsed()) {
        at = sub;
        path += " " + sub->get_name();
        deeper = true;
        break;
      }
  }
  std::string what = e.what();
  if (const auto subs = at->get_subcommands([](const CLI::App*) { return true; });
      !subs.empty() && at->get_subcommands().empty()) {
    std::vector<std::string> names;
    for (const CLI::App* sub : subs) names.push_back(sub->get_name());
    // A misspelt command is taken for a stray word: named as what it was meant to be.
    for (const std::string& a : at->remaining(true))
      if (!a.empty() && a[0] != '-') {
        what = fmt::format("unknown command '{}'", a);
        break;
      }
    what += fmt::format(" (`{}` takes one of: {})", path, fmt::join(names, ", "));
  }
  for (std::size_t b = 0, n; b < what.size(); b = n + 1) {
    n = what.find('\n', b);
    if (n == std::string::npos) n = what.size();
    if (n > b) fmt::print(stderr, "cdanalysis: {}\n", what.substr(b, n - b));
  }
  fmt::print(stderr, "cdanalysis: see `{} --help` for the options\n", path);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdanalysis: analysis of cdsim runs (steady state, fabric, rheology fits, reports)"};
  app.require_subcommand(1);
  std::vector<Declared> handlers;
  for (std::size_t i = 0; i < std::size(kCommands); ++i) {
    if (i == kFitPosition) {
      auto* fit = app.add_subcommand("fit", "rheology fits (method.md section 11)");
      fit->require_subcommand(1);
      for (const auto& f : kFits) declare(*fit, f, handlers);
    }
    declare(app, kCommands[i], handlers);
  }
  require_finite_numbers(app);
  set_command_line(argc, argv);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return usage_error(app, e);
  }

  try {
    for (const auto& h : handlers)
      if (h.sub->parsed()) return h.run();
  } catch (const InputError& e) {
    fmt::print(stderr, "cdanalysis: bad input: {}\n", printable(e.what()));
    return 2;
  } catch (const AnalysisError& e) {
    fmt::print(stderr, "cdanalysis: refused: {}\n", printable(e.what()));
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "cdanalysis: error: {}\n", printable(e.what()));
    return 2;
  }
  return 0;
}
