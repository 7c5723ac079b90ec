// cdanalysis report CAMPAIGN: tables, fits, plots and index.html for a
// campaign (report.hpp write_report).
#include <fmt/core.h>
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/report.hpp"

namespace cda::cli {

Handler report(CLI::App& sub) {
  struct Opt {
    std::string campaign, out, window;
    int bins = 36;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("campaign", o->campaign, "campaign folder (its subfolders are runs)")->required();
  sub.add_option("--out", o->out, "report folder (default: CAMPAIGN/report)");
  sub.add_option("--bins", o->bins, "angular bins over [0, pi)")
      ->check(CLI::Range(4, 36000))
      ->capture_default_str();
  add_window_option(sub, o->window);
  return [o] {
    const std::string dir = o->out.empty() ? (std::filesystem::path(o->campaign) / "report").string() : o->out;
    const auto s = write_report(o->campaign, dir, o->bins, o->window);
    fmt::print("report in {}: {} runs, {} steady, {} with fabric{}\n", dir, s.runs, s.steady, s.fabric,
               s.plots_ok ? "" : " (some plots failed: see the .gp.log files)");
    if (s.costed)
      fmt::print("cost: {:.1f} s wall time ({:.2f} h), {:.1f} s CPU time over {} runs{}\n", s.wall_time,
                 s.wall_time / 3600, s.cpu_time, s.costed,
                 s.costed < s.runs ? fmt::format(" ({} without summary.toml: n/a)", s.runs - s.costed) : "");
    else
      fmt::print("cost: n/a (no run has a summary.toml)\n");
    fmt::print("campaign kind: {}; fits: {}\n", s.kinds.empty() ? "none" : fmt::format("{}", fmt::join(s.kinds, "; ")),
               s.fits.empty() ? "none" : fmt::format("{}", fmt::join(s.fits, ", ")));
    for (const auto& p : s.problems) fmt::print(stderr, "problem: {}\n", p);
    fmt::print("open {}/index.html\n", dir);
    if (s.left_out || !s.undetermined.empty()) {
      fmt::print(stderr, "cdanalysis report: written with reservations (exit {}): {} of {} runs left out{}\n",
                 kExitPartial, s.left_out, s.runs,
                 s.undetermined.empty() ? std::string()
                                        : fmt::format("; undetermined: {}", fmt::join(s.undetermined, "; ")));
      return kExitPartial;
    }
    return 0;
  };
}

}  // namespace cda::cli
