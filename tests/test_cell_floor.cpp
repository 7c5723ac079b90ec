// The approach floor of a pressure-driven length, reported (core/cell_dof.hpp,
// held_at_approach_floor; docs/outputs.md, floor_steps). A length shrinks by
// at most a quarter of the alert distance a step; when the load asks for
// more on every step, the length's free velocity is the floor's, not dt p
// A / M below its start, and the imposed pressure is not applied. These
// tests run cdsim as a user would, on a small sample compacted by cdsim
// from the shipped preparation scene, then sheared by the shipped shear
// scene at imposed pressure, with the alert distance as shipped and tiny:
//   - tiny: summary.toml's floor_steps is (nearly) every step, the measured
//     normal stress sigma_yy + K_yy is far below p and is what the floor
//     lets through, M (<v> + alert / (4 dt)) / (dt A) (the momentum balance
//     of the length held at its floor), and cdsim says so on stdout and, as
//     a warning, on stderr;
//   - as shipped: floor_steps = 0, sigma_yy + K_yy is p within the
//     cell-control tests' tolerance (test_cell_control), and nothing said.
// And floor_steps adds up over sessions through the checkpoint.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "analysis/src/table.hpp"
#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "setup.hpp"
#include "setup3.hpp"
#include "totals_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kConfigs = CDLAB_SOURCE_DIR "/configs/";
constexpr const char* kWarning =
    "cdsim: warning: the cell's compaction was held at its floor on ";
constexpr const char* kWarningTail =
    "% of the steps (a length may shrink by at most a quarter of contact.alert a step): the imposed "
    "pressure was not fully applied on them; raise contact.alert or shear.cell_mass";

struct CdsimRun {
  int code = 0;
  std::string out, err;                         // stdout, stderr
  std::map<std::string, std::string> summary;  // summary.toml's key = value
};

// cdsim `args` into `dir`, stdout and stderr apart.
CdsimRun cdsim(const std::string& args, const fs::path& dir) {
  const fs::path err = dir.string() + ".stderr";
  const auto r = cdtest::run_command("(" + kCdsim + " " + args + " --quiet --threads 1 --out " + dir.string() +
                                     " 2>" + err.string() + ")");
  CdsimRun run{r.code, r.out, cdtest::slurp(err), {}};
  if (fs::exists(dir / "summary.toml")) run.summary = cdtest::summary_fields(dir / "summary.toml");
  return run;
}

// Mean of x over rows [from, rows) and the standard error of the means of
// nb consecutive blocks (as test_cell_control's block_mean).
std::pair<double, double> block_mean(const std::vector<double>& x, std::size_t from, int nb) {
  const std::size_t len = (x.size() - from) / nb;
  std::vector<double> m(nb, 0.0);
  for (int b = 0; b < nb; ++b) {
    for (std::size_t k = 0; k < len; ++k) m[b] += x[from + b * len + k];
    m[b] /= double(len);
  }
  double mean = 0, var = 0;
  for (double v : m) mean += v / nb;
  for (double v : m) var += (v - mean) * (v - mean) / (nb - 1);
  return {mean, std::sqrt(var / nb)};
}

// What a shear run measured over its last two thirds (of strain): the whole
// normal stress (sigma_yy + K_yy) / p, its block error, the same in Pa
// (N/m in 2D), the mean face A the pressure acts on (3D: L_x L_z; 2D: L_x)
// and the height's mean rate dL_y/dt over the window.
struct Measured {
  double load = 0, se = 0, stress = 0, face = 0, rate = 0;
};
Measured measure(const fs::path& dir, double p, int dimension) {
  const cda::Table t = cda::Table::read_csv((dir / "series.csv").string());
  const auto& strain = t.column("strain");
  const auto& syy = t.column("syy");
  const auto& kyy = t.column("kyy");
  const auto& w = t.column("cell_width");
  const auto& h = t.column("cell_height");
  const auto& time = t.column("time");
  std::size_t from = 1;
  while (from < t.rows() && strain[from] < strain.back() / 3) ++from;
  std::vector<double> load(t.rows());
  for (std::size_t k = 0; k < t.rows(); ++k) load[k] = (syy[k] + kyy[k]) / p;
  Measured m;
  std::tie(m.load, m.se) = block_mean(load, from, 5);
  // Each row averages the steps since the row before: the window starts at
  // row from - 1.
  const double n = double(t.rows() - from);
  for (std::size_t k = from; k < t.rows(); ++k) {
    m.stress += (syy[k] + kyy[k]) / n;
    m.face += (dimension == 3 ? w[k] * t.column("cell_depth")[k] : w[k]) / n;
  }
  m.rate = (h.back() - h[from - 1]) / (time.back() - time[from - 1]);
  return m;
}

// The two shear runs of one sample, the alert distance as shipped and
// `tiny`, and what each reports. `shear`: the shear scene and its settings.
void check_floor(int dimension, const std::string& name, const std::vector<std::string>& shear, double tiny,
                 double min_share) {
  std::string sets;
  for (const std::string& s : shear) sets += " --set " + s;
  const double p = dimension == 3 ? 1e5 : 100.0;
  const std::string scene = kConfigs + (dimension == 3 ? "shear3-inertial.toml" : "shear-inertial.toml");
  Measured m[2];
  CdsimRun r[2];
  for (int tiny_alert = 0; tiny_alert < 2; ++tiny_alert) {
    const std::string alert = tiny_alert ? fmt::format(" --set contact.alert={}", tiny) : "";
    const fs::path d = cdtest::scratch_dir("test_cell_floor", name + (tiny_alert ? "_tiny" : "_shipped"));
    r[tiny_alert] = cdsim(scene + sets + alert, d);
    ASSERT_EQ(r[tiny_alert].code, 0) << r[tiny_alert].out << r[tiny_alert].err;
    m[tiny_alert] = measure(d, p, dimension);
  }
  const auto steps = [&](const CdsimRun& x) { return std::stod(x.summary.at("steps")); };
  const auto floor = [&](const CdsimRun& x) { return std::stod(x.summary.at("floor_steps")); };
  std::printf("[ %s ] shipped alert: floor_steps %.0f of %.0f, (sigma_yy + K_yy)/p = %.3f +- %.3f; alert %g: "
              "floor_steps %.0f of %.0f, (sigma_yy + K_yy)/p = %.3f +- %.3f\n",
              name.c_str(), floor(r[0]), steps(r[0]), m[0].load, m[0].se, tiny, floor(r[1]), steps(r[1]),
              m[1].load, m[1].se);

  // As shipped: the floor never binds, the pressure is held, nothing said.
  EXPECT_EQ(floor(r[0]), 0.0);
  EXPECT_NEAR(m[0].load, 1.0, 3 * m[0].se + 0.05);
  EXPECT_EQ(r[0].err.find("held at its floor"), std::string::npos) << r[0].err;
  EXPECT_EQ(r[0].out.find("held at its floor"), std::string::npos) << r[0].out;

  // Tiny: held on (nearly) every step, the pressure far from applied, and
  // the session says so, on stdout and as a warning on stderr.
  EXPECT_GE(floor(r[1]), min_share * steps(r[1]));
  EXPECT_LT(m[1].load, 0.5);
  EXPECT_LT(m[1].load + 3 * m[1].se, m[0].load - 3 * m[0].se);
  const std::string share = fmt::format("{:.1f} ", 100.0 * floor(r[1]) / steps(r[1]));
  EXPECT_NE(r[1].err.find(kWarning + share + kWarningTail), std::string::npos) << r[1].err;
  EXPECT_NE(r[1].out.find(fmt::format("cdsim: the cell's compaction was held at its floor on {:.0f} steps",
                                      floor(r[1]))),
            std::string::npos)
      << r[1].out;
  EXPECT_EQ(r[1].out.find(kWarning), std::string::npos) << "the warning goes to stderr only";

  // Held at the floor, the height's free velocity is v_floor = -alert / (4
  // dt), whatever p: a step's contact impulse across the face is M (v -
  // v_floor), v the height's velocity after it. Over the window, where the
  // floor holds on every step, the time mean of sigma_yy + K_yy (the force
  // across the face per area) is then M (<v> + alert / (4 dt)) / (dt A),
  // <v> the height's mean rate: the floor sets the stress, not p.
  std::vector<std::string> all = shear;
  all.push_back(fmt::format("contact.alert={}", tiny));
  const cd::Scene sc = cd::load_scene(scene, all);
  double dt, M, alert;
  if (dimension == 3) {
    const cd::World3 w = cd::build_world3(sc);
    dt = w.params().dt, M = w.params().cell_mass, alert = w.params().alert;
  } else {
    const cd::World w = cd::build_world(sc);
    dt = w.params().dt, M = w.params().cell.mass, alert = w.params().alert;
  }
  const double held = M * (m[1].rate + alert / (4 * dt)) / (dt * m[1].face);
  std::printf("[ %s ] sigma_yy + K_yy = %.4g, M (<v> + alert / (4 dt)) / (dt A) = %.4g (<v> dt = %.3g alert)\n",
              name.c_str(), m[1].stress, held, m[1].rate * dt / alert);
  EXPECT_NEAR(m[1].stress / held, 1.0, 0.1);
}

// 150 spheres compacted by configs/shear3-prep.toml into `dir` (its
// checkpoint the sample).
fs::path prep3(const std::string& name) {
  const fs::path prep = cdtest::scratch_dir("test_cell_floor", name);
  const CdsimRun r = cdsim(kConfigs + "shear3-prep.toml --set particles.n=150 --set output.checkpoint_interval=0.004",
                           prep);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  // The compaction's brake (shear.compaction_rate) is the scene's choice,
  // not the approach floor: not counted.
  EXPECT_EQ(r.summary.at("floor_steps"), "0");
  return prep / "checkpoint.bin";
}

}  // namespace

// 150 spheres compacted by configs/shear3-prep.toml, sheared by
// configs/shear3-inertial.toml at I = 0.1 to strain 1 (200 steps; its
// settings by I: dt = 0.05 t_p, shear.cell_mass 0.1). The load asks the
// height to shrink by about dt_tp^2 d / (cell_mass phi L_y / d) ~ 0.008 d a
// step; at contact.alert = 0.005 the floor allows 0.00125 d. Measured:
// shipped, floor_steps 0, (sigma_yy + K_yy)/p 1.00; alert 0.005, floor_steps
// 200 of 200, 0.26; the momentum balance at the floor within 2 %.
TEST(CellFloor, HeldAtTheFloorTheRunSaysSoAndThePressureIsNotApplied3D) {
  const fs::path start = prep3("prep3");
  check_floor(3, "shear3",
              {"shear.start=" + start.string(), "shear.inertial_number=0.1", "shear.strain=1",
               "output.checkpoint_strain=0", "output.series_interval=5e-5"},
              0.005, 1.0);
}

// 100 disks compacted by configs/shear-prep.toml, sheared by
// configs/shear-inertial.toml at I = 0.03 to strain 1 (667 steps, dt = 0.05
// t_p, cell_mass 0.1). At contact.alert = 5e-4 the floor holds on all but
// a few steps (measured 658 of 667, none of the first 30: on the others the
// height's velocity at the step's start, the sample dilating, is high
// enough that the load does not bring it below the floor). Measured:
// shipped, floor_steps 0, (sigma_yy + K_yy)/p 1.01; alert 5e-4, 0.23; the
// momentum balance at the floor within 0.2 %.
TEST(CellFloor, HeldAtTheFloorTheRunSaysSoAndThePressureIsNotApplied2D) {
  const fs::path prep = cdtest::scratch_dir("test_cell_floor", "prep2");
  const CdsimRun r = cdsim(kConfigs + "shear-prep.toml --set particles.n=100 --set shear.width=0.015 "
                      "--set shear.height=0.015 --set output.snapshot_interval=0 "
                      "--set output.checkpoint_interval=0.01",
                      prep);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(r.summary.at("floor_steps"), "0");
  check_floor(2, "shear2",
              {"shear.start=" + (prep / "checkpoint.bin").string(), "shear.inertial_number=0.03",
               "shear.strain=1", "output.snapshot_interval=0", "output.series_interval=2e-4"},
              5e-4, 0.95);
}

// The floor's purpose is not counted: 150 spheres compacted from a loose
// lattice by configs/shear3-prep.toml without its brake
// (shear.compaction_rate = 0) collapse at the approach floor, each length
// shrinking by a quarter of the alert distance a step (measured: 0.240 to
// 0.250 of it a step over the first 80 steps, the contacts already formed
// pushing back a little; asserted within 8 %), held there by the speed they
// gathered, each step's load asking less than the floor (dt (p - K) A / M
// about 0.4 alert / 4). That is the speed limit the floor is for, not a
// pressure left unapplied: the sample then jams at p (the stop rule, contact
// stress within 1 % of p), floor_steps is 0, and nothing is said.
TEST(CellFloor, ACollapseHeldAtTheFloorBySpeedItGatheredIsNotCounted) {
  const fs::path d = cdtest::scratch_dir("test_cell_floor", "collapse");
  const CdsimRun r = cdsim(kConfigs + "shear3-prep.toml --set particles.n=150 --set shear.compaction_rate=0 "
                           "--set output.checkpoint_wall=0 --set output.series_interval=2e-5",
                           d);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("cdsim: settled at step"), std::string::npos) << r.out;
  EXPECT_EQ(r.summary.at("floor_steps"), "0");
  EXPECT_EQ(r.err.find("held at its floor"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("held at its floor"), std::string::npos) << r.out;
  const cda::Table t = cda::Table::read_csv((d / "series.csv").string());
  const auto& step = t.column("step");
  const auto& h = t.column("cell_height");
  const double alert = 0.1 * 1e-3;  // contact.alert 0.1 d, d = 1 mm
  double fastest = 0, slowest = 1;  // over the first 80 steps, in alert distances a step
  for (std::size_t k = 1; k < t.rows() && step[k] <= 80; ++k) {
    const double rate = (h[k - 1] - h[k]) / (step[k] - step[k - 1]) / alert;
    fastest = std::max(fastest, rate);
    slowest = std::min(slowest, rate);
  }
  std::printf("[ collapse ] the height shrank by %.3f to %.3f alert a step over the first 80 steps\n", slowest,
              fastest);
  EXPECT_LE(fastest, 0.25 * (1 + 1e-9));
  EXPECT_GE(slowest, 0.23);
}

// floor_steps covers every session, through the checkpoint's totals: the
// 3D run held at its floor on all 200 steps (as above) counts 200 in one
// session and in two (--max-steps 80, then the resume, whose session line
// counts its own 120); resumed from a checkpoint of the build before
// floor_steps (its totals the twelve of that build), it counts the steps
// from the resume on, the other totals carried over.
TEST(CellFloor, FloorStepsAddUpOverSessions) {
  const fs::path start = prep3("prep3_sessions");
  const std::string run = kConfigs + "shear3-inertial.toml --set shear.start=" + start.string() +
                          " --set shear.inertial_number=0.1 --set shear.strain=1 --set contact.alert=0.005"
                          " --set output.checkpoint_strain=0 --set output.checkpoint_interval=4e-4";
  const fs::path A = cdtest::scratch_dir("test_cell_floor", "one_session");
  const fs::path B = cdtest::scratch_dir("test_cell_floor", "two_sessions");
  const fs::path C = cdtest::scratch_dir("test_cell_floor", "from_twelve");
  CdsimRun a = cdsim(run, A);
  ASSERT_EQ(a.code, 0) << a.out << a.err;
  EXPECT_EQ(a.summary.at("steps"), "200");
  EXPECT_EQ(a.summary.at("floor_steps"), "200");
  for (const fs::path& d : {B, C}) {
    const CdsimRun r = cdsim(run + " --max-steps 80", d);
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_EQ(r.summary.at("floor_steps"), "80");
  }
  const std::string ckpt = (C / "checkpoint.bin").string();
  cd::RunTotals t;
  cd::World3 x = cd::build_world3(cd::load_scene(kConfigs + "shear3-inertial.toml",
                                                 {"shear.start=" + start.string(), "contact.alert=0.005"}));
  cd::load_checkpoint3(ckpt, x, &t);
  EXPECT_EQ(t.floor_steps, 80.0);
  const std::string twelve = cdtest::with_totals(
      cdtest::slurp(ckpt), cdtest::kTotals12,
      {t.wall, t.cpu, t.sweeps, t.sweeps_max, t.cap_steps, t.residual_max, t.residual_last, t.overlap_max,
       t.sessions, t.cg_iterations, t.anderson_off_steps, t.subspace_off_steps});
  std::ofstream(ckpt, std::ios::binary) << twelve;
  CdsimRun b = cdsim(run, B), c = cdsim(run, C);
  for (const CdsimRun* r : {&b, &c}) {
    ASSERT_EQ(r->code, 0) << r->out << r->err;
    EXPECT_NE(r->out.find("resumed from"), std::string::npos) << r->out;
    EXPECT_NE(r->out.find("held at its floor on 120 steps (100.0 % of steps)"), std::string::npos) << r->out;
    EXPECT_EQ(r->summary.at("sessions"), "2");
    for (const char* k : {"steps", "sweeps_mean", "sweeps_max", "cg_iterations"})
      EXPECT_EQ(r->summary.at(k), a.summary.at(k)) << k;
  }
  EXPECT_EQ(b.summary.at("floor_steps"), "200");
  EXPECT_EQ(c.summary.at("floor_steps"), "120");
}
