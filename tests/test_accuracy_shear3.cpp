// cd/bench/accuracy_shear3.py, the table of `make accuracy-shear3`, on
// synthetic run folders whose answers are worked out here by hand: window
// means (rows before the window left out), the mean over samples +- the
// standard error, the difference to the reference in combined errors, CPU
// per unit strain, and the refusals (no finished run; a run without rows in
// the window).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kScript = std::string(CDLAB_SOURCE_DIR) + "/cd/bench/accuracy_shear3.py";

// A finished run: rows at strain 0.05 (outside a 0.1 window: values that
// would spoil every mean) and at 0.2, 0.4 with mu = tau / p, phi, z; the run
// ends at strain 0.4 with cpu_time seconds.
void write_run(const fs::path& d, double mu, double phi, double z, double cpu) {
  fs::create_directories(d);
  std::ofstream s(d / "series.csv");
  s << "step,strain,sxy,syx,syy,packing_fraction,z\n";
  s << "1,0.05,-900,-900,1000,0.9,9\n";  // before the window
  // The two rows average to mu, phi, z: mu +- 0.01, phi +- 0.001, z +- 0.05.
  s << "2,0.2," << -(mu + 0.01) * 1000 << "," << -(mu + 0.01) * 1000 << ",1000," << phi + 0.001 << ","
    << z + 0.05 << "\n";
  s << "3,0.4," << -(mu - 0.01) * 1000 << "," << -(mu - 0.01) * 1000 << ",1000," << phi - 0.001 << ","
    << z - 0.05 << "\n";
  std::ofstream t(d / "summary.toml");
  t << "status = \"done\"  # a comment\ncpu_time = " << cpu << "\nsweeps_mean = 100\ncap_share = 0.02\n"
    << "overlap_max = 0.001\nresidual_max = 0.03\n";
  std::ofstream(d / ".done").close();
}

}  // namespace

TEST(AccuracyShear3, TableAgainstHandComputedStatistics) {
  const fs::path top = cdtest::scratch_dir("test_accuracy_shear3", "table");
  // Reference mu over three samples 0.36, 0.38, 0.37: mean 0.37, sample
  // standard deviation 0.01, standard error 0.01/sqrt(3) = 0.005774.
  // Setting "b": 0.39, 0.41, 0.40: mean 0.40, the same error; its difference
  // 0.03 / sqrt(2 * 0.005774^2) = 3.674 sigma. z: ref 4.1, 4.1, 4.1 (error 0);
  // b 4.2, 4.3, 4.4: mean 4.3, error 0.1/sqrt(3) = 0.0577, +3.5 sigma.
  const double mu_ref[] = {0.36, 0.38, 0.37}, mu_b[] = {0.39, 0.41, 0.40};
  const double z_b[] = {4.2, 4.3, 4.4};
  for (int s = 0; s < 3; ++s) {
    write_run(top / ("s" + std::to_string(s + 1)) / "ref", mu_ref[s], 0.6, 4.1, 40.0);
    write_run(top / ("s" + std::to_string(s + 1)) / "b", mu_b[s], 0.6, z_b[s], 8.0);
  }
  const auto r = cdtest::run_command("/usr/bin/python3 " + kScript + " " + top.string() + " 0.1 ref b");
  ASSERT_EQ(r.code, 0) << r.out;
  // CPU per unit strain: 40 / 0.4 = 100, 8 / 0.4 = 20.
  EXPECT_NE(r.out.find("| ref | 3 | 100.0 | 100 | 2.0 % | 0.3700 ± 0.0058 | 0.6000 ± 0.0000 | 4.100 ± 0.000 |"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("| b | 3 | 20.0 | 100 | 2.0 % | 0.4000 ± 0.0058 (+3.7σ) | 0.6000 ± 0.0000 | "
                       "4.300 ± 0.058 (+3.5σ) | 1.0e-03 | 0.03 |"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(cdtest::slurp(top / "table.md").empty(), false);
}

TEST(AccuracyShear3, RefusesWhatItCannotAverage) {
  const fs::path top = cdtest::scratch_dir("test_accuracy_shear3", "refuse");
  fs::create_directories(top / "s1" / "ref");  // started, not finished: no .done
  auto r = cdtest::run_command("/usr/bin/python3 " + kScript + " " + top.string() + " 0.1 ref");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("no finished run"), std::string::npos) << r.out;
  write_run(top / "s1" / "ref", 0.37, 0.6, 4.1, 40.0);
  r = cdtest::run_command("/usr/bin/python3 " + kScript + " " + top.string() + " 0.5 ref");  // window past the end
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("no series row at strain >= 0.5"), std::string::npos) << r.out;
}
