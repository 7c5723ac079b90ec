#include "run_loop.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "run_session.hpp"
#include "version.hpp"

namespace cd {

namespace {

// A TOML float: shortest text that reads back exactly, with a '.' or exponent.
std::string toml_float(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::string t = fmt::format("{}", x);
  if (t.find_first_of(".e") == std::string::npos) t += ".0";
  return t;
}

}  // namespace

std::string summary_toml(const RunSummary& s) {
  const RunTotals& t = s.totals;
  const auto load = [](const std::vector<double>& l) {
    std::string o = "[";
    for (std::size_t i = 0; i < l.size(); ++i) o += (i ? ", " : "") + toml_float(l[i]);
    return o + "]";
  };
  const auto line = [](const std::string& kv, const char* doc) {
    return fmt::format("{:<32} # {}\n", kv, doc);
  };
  std::string o =
      "# The cost of this run, over every session (cdsim call) that ran it: docs/outputs.md\n";
  o += line(fmt::format("cdlab_version = \"{}\"", version()), "git describe of the build; \"unknown\" outside a clone");
  o += line(fmt::format("status = \"{}\"", s.status), "done, settled (shear.settle_*), stopped (signal), max-steps, diverged");
  o += line(fmt::format("steps = {}", s.last_step), "the last step taken (series.csv's last row)");
  o += line(fmt::format("total_steps = {}", s.total_steps), "the scene's steps");
  o += line(fmt::format("sessions = {}", std::llround(t.sessions)), "cdsim calls that took steps (1 + resumes)");
  o += line("wall_time = " + toml_float(t.wall), "s, in the run loop, summed over sessions up to the last checkpoint or the end");
  o += line("cpu_time = " + toml_float(t.cpu), "s, user + system of every thread, likewise");
  o += line(fmt::format("threads = {}", s.threads), "OpenMP threads of the last session");
  o += line("load_start = " + load(s.load_start), "/proc/loadavg (1, 5, 15 min) when the last session started");
  o += line("load_end = " + load(s.load_end), "and when it ended");
  o += line("sweeps_mean = " + toml_float(s.last_step ? t.sweeps / double(s.last_step) : 0.0), "NLGS sweeps per step, mean over the steps");
  o += line(fmt::format("sweeps_max = {}", std::llround(t.sweeps_max)), "most sweeps of one step");
  // The accelerations' cost (0 when off). A CG iteration of the subspace
  // correction is one product W p through the bodies of the closed rows,
  // about half a sweep's cost (docs/accuracy.md): sweeps_mean leaves it out.
  o += line(fmt::format("cg_iterations = {}", std::llround(t.cg_iterations)),
            "CG iterations of the subspace corrections (solver.subspace), all steps");
  o += line("cg_iterations_mean = " + toml_float(s.last_step ? t.cg_iterations / double(s.last_step) : 0.0),
            "per step, mean over the steps; one costs about half a sweep");
  o += line(fmt::format("anderson_off_steps = {}", std::llround(t.anderson_off_steps)),
            "steps whose Anderson mixing (solver.anderson) stalled and went off");
  o += line(fmt::format("subspace_off_steps = {}", std::llround(t.subspace_off_steps)),
            "steps whose subspace corrections stalled and stopped");
  o += line(fmt::format("cap_steps = {}", std::llround(t.cap_steps)), "steps stopped at solver.max_iter");
  o += line("cap_share = " + toml_float(s.cap_share()), "cap_steps / steps");
  o += line("residual_final = " + toml_float(t.residual_last), "law residual of the last step");
  o += line("residual_max = " + toml_float(t.residual_max), "largest law residual of any step");
  o += line("overlap_max = " + toml_float(t.overlap_max), "largest overlap, in mean diameters");
  o += line(fmt::format("floor_steps = {}", std::llround(t.floor_steps)),
            "steps on which the cell's compaction was held at its floor (a quarter of contact.alert a "
            "step): the imposed pressure was not fully applied on them");
  return o;
}

RunSummary run_loop(RunEngine& e, const RunPlan& plan, const RunOptions& opt) {
  return RunSession(e, plan, opt).run();
}

}  // namespace cd
