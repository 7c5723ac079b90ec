// The machine's load, and what it does to OpenMP runs. The coloured NLGS
// sweep meets a barrier after every colour (tens per sweep, thousands of
// sweeps per step). libgomp's waiting threads spin; when other processes hold
// the cores, a spinning thread burns the time slice its partner needs, and a
// run slows down many-fold: measured here, two 3000-disk shear runs started
// together with 2 threads each on 2 cores took 28x the wall time of the same
// two runs with 1 thread each (19 s against 0.68 s a step, load 8). cdsim
// warns at start when its threads do not fit in the cores the load leaves.
#pragma once
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace cd {

// The 1, 5 and 15 minute load averages; empty when /proc/loadavg is unreadable.
inline std::vector<double> load_average() {
  std::ifstream f("/proc/loadavg");
  double a, b, c;
  if (f >> a >> b >> c) return {a, b, c};
  return {};
}

// "" when `threads` fit beside the load on `cores`; otherwise what to do.
// The margin of half a core tolerates the load's own lag and noise. Not
// called for runs too small to open a parallel region (parallel.hpp), nor
// when waiting threads sleep (OMP_WAIT_POLICY=passive).
inline std::string oversubscription_warning(int threads, double load1, int cores) {
  if (threads <= 1 || load1 + threads <= cores + 0.5) return {};
  return fmt::format(
      "the machine is loaded (1-min load average {:.2f} on {} cores) and this run uses {} "
      "threads: threads spinning at the solver's barriers can slow it many-fold. Use "
      "--threads 1 (or OMP_NUM_THREADS=1), or OMP_WAIT_POLICY=passive (docs/accuracy.md, \"Performance of a step\")",
      load1, cores, threads);
}

}  // namespace cd
