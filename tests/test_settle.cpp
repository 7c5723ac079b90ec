// The stop rule of a compaction at imposed pressure (shear.settle_stress,
// settle_phi, settle_time; core/settle.hpp): the window logic on rows made
// by hand, the resume that reads the rows back, the keys' refusals, and the
// 3D preparation of configs/shear3-prep.toml ending settled, checked apart
// from the rule: the sample, relaxed at a ten times tighter tolerance, holds
// p without compacting further, carries it through a mechanically stable
// contact network, and its overlaps are small.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "files.hpp"
#include "observables.hpp"
#include "run3.hpp"
#include "settle.hpp"
#include "setup3.hpp"
#include "world3.hpp"

using namespace cd;
namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kPrep3 = CDLAB_SOURCE_DIR "/configs/shear3-prep.toml";

// A compaction scene: 3D, isotropic, p = 1e5 Pa, d = 1 mm, rho = 2600
// kg/m^3 (t_p = 1.6125e-4 s); the rule at 1 %, 1e-3 over 2 t_p.
Scene rule_scene() {
  Scene s;
  s.dimension = 3;
  s.shear_mode = ShearMode::Periodic;
  s.pressure = 1e5;
  s.density = 2600;
  s.d_mean = 1e-3;
  s.isotropic = true;
  s.settle_stress = 0.01;
  s.settle_phi = 1e-3;
  s.settle_time = 2;
  return s;
}
const double kTp = 1e-3 * std::sqrt(2600 / 1e5);

using Row = std::vector<std::pair<std::string, double>>;
Row row(double t, double sxx, double syy, double szz, double phi) {
  return {{"step", 0}, {"time", t}, {"sxx", sxx}, {"syy", syy}, {"szz", szz}, {"packing_fraction", phi}};
}

// The index of the first row the rule calls settled (-1: none).
int first_settled(SettleRule r, const std::vector<Row>& rows) {
  for (std::size_t i = 0; i < rows.size(); ++i) {
    r.add(rows[i]);
    if (r.settled()) return int(i);
  }
  return -1;
}

}  // namespace

// Rows every t_p/2 (row i at (i + 1) t_p/2), so the window of 2 t_p spans
// four intervals: row n's window starts at row n - 4. Stresses 5 % off p up
// to row 5, then 0.4 %; phi rising by 0.01 a row up to row 7 (0.62), then
// 0.64 at row 8 and by 1e-4 a row. Row 9's window (rows 5-9) still holds
// row 5's 5 %; rows 10 and 11 hold it no more, but their phi range reaches
// back to rows 6 and 7 (0.03, 0.02);
// row 12's window starts at row 8: range 4e-4, every stress within 1 %:
// settled there, and not before.
TEST(Settle, StopsAtTheFirstRowThatEndsASettledWindow) {
  const double p = 1e5;
  std::vector<Row> rows;
  for (int i = 0; i < 20; ++i) {
    const double s = i <= 5 ? 1.05 * p : 1.004 * p;
    const double phi = i < 8 ? 0.55 + 0.01 * i : 0.64 + 1e-4 * (i - 8);
    rows.push_back(row((i + 1) * kTp / 2, p, s, p, phi));
  }
  EXPECT_EQ(first_settled(SettleRule(rule_scene()), rows), 12);
  // One axis 2 % off at row 10: its window must pass first (row 14).
  std::vector<Row> z = rows;
  z[10] = row(11 * kTp / 2, p, 1.004 * p, 0.98 * p, 0.6402);
  EXPECT_EQ(first_settled(SettleRule(rule_scene()), z), 14);
  // Without isotropic only sigma_yy counts: the same z settles at row 12.
  Scene y = rule_scene();
  y.isotropic = false;
  EXPECT_EQ(first_settled(SettleRule(y), z), 12);
  // A steady sample at p from the first row: settled once the window is
  // full, the row 2 t_p after the first (row 4), not earlier.
  std::vector<Row> steady;
  for (int i = 0; i < 8; ++i) steady.push_back(row((i + 1) * kTp / 2, p, p, p, 0.6));
  EXPECT_EQ(first_settled(SettleRule(rule_scene()), steady), 4);
  // Off: never.
  Scene off = rule_scene();
  off.settle_stress = 0;
  EXPECT_EQ(first_settled(SettleRule(off), steady), -1);
}

// A resumed run reads its series back: the rule decides on the values as
// written (10 digits), so that, for rows whose values sit anywhere near the
// bounds, the rule fed the rows in memory and the one fed the file agree
// after every row.
TEST(Settle, ResumeReadsTheRowsBackAndDecidesAsTheRunDid) {
  const fs::path dir = cdtest::scratch_dir("test_settle", "resume");
  const std::string path = (dir / "series.csv").string();
  const double p = 1e5;
  SettleRule live(rule_scene());
  int agreed = 0, settled = 0;
  {
    Series series(path);
    for (int i = 0; i < 60; ++i) {
      // Stresses within 0.99-1.01 p and a phi range near 1e-3, with digits
      // beyond the tenth: decisions near the bounds either way.
      const double e = 0.01 * std::sin(1.3 * i + 0.2) * (1 + 1e-13 * i);
      const double phi = 0.6 + 0.5e-3 * std::sin(0.7 * i) + 1e-14 * i;
      const Row r = row((i + 1) * kTp / 3 + 1e-17, p * (1 + e), p * (1 - 0.5 * e), p * (1 + 0.999999999999 * e), phi);
      series.row(r);
      series.flush();
      live.add(r);
      SettleRule back(rule_scene());
      back.resume(path);
      agreed += back.settled() == live.settled();
      settled += live.settled();
    }
  }
  EXPECT_EQ(agreed, 60);
  EXPECT_GT(settled, 0);   // the sequence crosses the bounds both ways
  EXPECT_LT(settled, 55);
}

// The three keys together, and only on a compaction.
TEST(Settle, KeysNeedEachOtherAndACompaction) {
  const auto refused = [](const std::vector<std::string>& set, const std::string& want) {
    try {
      load_scene(kPrep3, set);
      ADD_FAILURE() << "accepted: " << set.front();
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  };
  refused({"shear.settle_phi=0"}, "the stop rule needs all three > 0");
  refused({"shear.settle_stress=0"}, "the stop rule needs all three > 0");
  refused({"shear.settle_stress=1.5"}, "shear.settle_stress = 1.5: must be in [0, 1]");
  EXPECT_NO_THROW(load_scene(kPrep3, {"shear.settle_stress=0", "shear.settle_phi=0", "shear.settle_time=0"}));
  // A shear run (2D and 3D), refused before anything is written.
  for (const std::string scene : {"shear-inertial", "shear3-inertial"}) {
    const fs::path dir = cdtest::scratch_dir("test_settle", "refused_" + scene);
    const auto r = cdtest::run_command(kCdsim + " " + CDLAB_SOURCE_DIR + "/configs/" + scene +
                                       ".toml --set shear.settle_stress=0.01 --set shear.settle_phi=1e-3 --set "
                                       "shear.settle_time=2 --quiet --out " + (dir / "out").string());
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("the stop rule settles a compaction"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << scene;
  }
}

namespace {

// configs/shear3-prep.toml at n spheres through cdsim, one thread, into dir.
cdtest::CmdResult prep3(const fs::path& dir, int n, const std::string& more = "") {
  return cdtest::run_command(kCdsim + " " + kPrep3 + " --quiet --threads 1 --set particles.n=" + std::to_string(n) +
                             " " + more + " --out " + dir.string());
}

std::string summary_value(const fs::path& dir, const std::string& key) {
  const std::string s = cdtest::slurp(dir / "summary.toml");
  const auto at = s.find("\n" + key + " = ");
  if (at == std::string::npos) return "";
  const auto b = at + key.size() + 4, e = s.find_first_of(" \n", b);
  return s.substr(b, e - b);
}

}  // namespace

// The 3D preparation (configs/shear3-prep.toml) of 150 spheres ends
// settled, well before time.duration, with its checkpoint. Checked apart
// from the rule: the sample relaxed for 3 t_p more at tol 1e-4 (ten times
// tighter; the rule's own stress is not reused) holds sigma_aa + K_aa = p
// on each axis within 1 %, carried by the contacts (K < 0.1 % p); it does
// not compact further (phi within 2e-3: the jammed sample only creeps, by
// ~1e-4 per t_p at 1000 spheres); its contact network is mechanically
// stable (rattlers removed, z > 4 = d + 1, the fewest contacts a packing of
// frictional spheres needs to carry a load; measured 4.3-4.4 at 1000
// spheres); the largest overlap is below 0.005 of the smaller diameter.
TEST(Settle3, PreparationSettlesJammedAtThePressure) {
  const fs::path dir = cdtest::scratch_dir("test_settle", "prep3");
  const auto r = prep3(dir, 150);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("settled at step"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("checkpoint written"), std::string::npos) << r.out;
  EXPECT_EQ(summary_value(dir, "status"), "\"settled\"");
  const long steps = std::stol(summary_value(dir, "steps")), total = std::stol(summary_value(dir, "total_steps"));
  EXPECT_LT(steps, total / 2) << "the rule stopped late, or the run ended at time.duration";

  Scene s = load_scene(kPrep3, {"particles.n=0", "shear.start=\"" + (dir / "checkpoint.bin").string() + "\"",
                                "solver.tol=1e-4", "shear.settle_stress=0", "shear.settle_phi=0",
                                "shear.settle_time=0"});
  World3 w = build_world3(s);
  const auto phi_of = [&] {
    double v = 0;
    for (std::size_t i = 0; i < w.bodies.size(); ++i) v += obs::sphere_volume(w.bodies.radius[i]);
    return v / w.cell_volume();
  };
  const double phi0 = phi_of();
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero(), K = Eigen::Matrix3d::Zero();
  double phi_lo = phi0, phi_hi = phi0, overlap = 0;
  const int n = 60;  // 3 t_p at dt = 0.05 t_p
  for (int k = 0; k < n; ++k) {
    w.step();
    S += w.contact_stress() / n;
    K += w.kinetic_stress() / n;
    phi_lo = std::min(phi_lo, phi_of());
    phi_hi = std::max(phi_hi, phi_of());
    overlap = std::max(overlap, max_overlap_small3(w));
  }
  const obs::Coordination z = coordination3(w);
  std::printf("settled at step %ld of %ld; relaxed: (sigma + K)/p = %.4f %.4f %.4f, K_max/p %.2g, phi %.4f [%.4f, %.4f], "
              "z %.3f (non-rattlers %.2f), overlap %.2g d_small\n",
              steps, total, (S + K)(0, 0) / s.pressure, (S + K)(1, 1) / s.pressure, (S + K)(2, 2) / s.pressure,
              K.diagonal().maxCoeff() / s.pressure, phi0, phi_lo, phi_hi, z.z, z.non_rattler, overlap);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR((S + K)(a, a) / s.pressure, 1.0, 0.01) << a;
    EXPECT_LT(K(a, a) / s.pressure, 1e-3) << a;
  }
  EXPECT_LT(phi_hi - phi_lo, 2e-3);
  EXPECT_GT(phi0, 0.55);  // a frictional random packing (random loose 0.55 - close 0.64)
  EXPECT_LT(phi0, 0.64);
  EXPECT_GT(z.z, 4.0);
  EXPECT_LT(overlap, 5e-3);
}

// Stopped before it settles (--max-steps, on a series row) and resumed, the
// preparation settles at the same step with the same series as the run
// never stopped; run again, a settled run takes no more steps.
TEST(Settle3, ResumedPreparationSettlesWhereTheStraightOneDid) {
  const fs::path a = cdtest::scratch_dir("test_settle", "straight");
  const fs::path b = cdtest::scratch_dir("test_settle", "resumed");
  ASSERT_EQ(prep3(a, 100).code, 0);
  const std::string straight = cdtest::slurp(a / "series.csv");
  auto r = prep3(b, 100, "--max-steps 96");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(summary_value(b, "status"), "\"max-steps\"");
  r = prep3(b, 100);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  EXPECT_EQ(summary_value(b, "status"), "\"settled\"");
  EXPECT_EQ(summary_value(a, "steps"), summary_value(b, "steps"));
  EXPECT_EQ(cdtest::slurp(b / "series.csv"), straight);
  r = prep3(b, 100);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("cdsim: 0 steps"), std::string::npos) << r.out;
  EXPECT_EQ(summary_value(b, "status"), "\"settled\"");
  EXPECT_EQ(cdtest::slurp(b / "series.csv"), straight);
}
