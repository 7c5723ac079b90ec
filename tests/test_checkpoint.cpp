// Checkpoint and restart: a run stopped and continued from a checkpoint is
// bit-identical to one never stopped, in the library (state hash) and through
// cdsim killed with SIGKILL mid-run and run again (every output compared);
// damaged checkpoints and checkpoints of another scene are refused clearly.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "scene.hpp"
#include "cli_util.hpp"
#include "totals_util.hpp"
#include "world_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";

// In the build folder (cdtest::scratch_dir), not /tmp: the folders stay
// with the build instead of piling up in /tmp, one per run of the suite.
fs::path temp_dir(const std::string& name) { return cdtest::scratch_dir("test_checkpoint", name); }

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// A pile settling in a box: a few hundred disks with many contacts, so that
// the warm start matters.
cd::World pile() {
  cd::WorldParams p = cdtest::params(4e-3, 9.81, 0.4);
  p.solver.tol = 1e-4;
  p.solver.max_iter = 500;
  cd::World w(p);
  cdtest::fill_box(w, 300, 20.0, 40.0, 0.6, 1.0, 7);
  return w;
}

// ---- library ----------------------------------------------------------------

TEST(Checkpoint, RestartIsBitIdentical) {
  const int n = 125;  // 1 s in all: the lattice collapses into a pile
  cd::World a = pile();
  for (int k = 0; k < 2 * n; ++k) a.step();
  EXPECT_GT(a.last().active, 250) << "not yet a pile";

  cd::World b = pile();
  for (int k = 0; k < n; ++k) b.step();
  const fs::path f = temp_dir("lib") / "checkpoint.bin";
  cd::save_checkpoint(f.string(), b, 42);

  cd::World c = pile();  // a fresh world of the same scene
  EXPECT_EQ(cd::load_checkpoint(f.string(), c), 42u);
  EXPECT_EQ(c.steps, n);
  EXPECT_EQ(c.time, b.time);
  EXPECT_EQ(cdtest::state_hash(c), cdtest::state_hash(b));
  cd::World d = c;  // for the control below
  for (int k = 0; k < n; ++k) c.step();
  EXPECT_EQ(cdtest::state_hash(c), cdtest::state_hash(a));
  EXPECT_EQ(c.time, a.time);
  EXPECT_EQ(c.warm_start().keys, a.warm_start().keys);

  // Control: the test can see a missing piece of state (the warm start).
  d.set_warm_start({});
  for (int k = 0; k < n; ++k) d.step();
  EXPECT_NE(cdtest::state_hash(d), cdtest::state_hash(a));
}

TEST(Checkpoint, DamagedFilesAreNamedAndLeaveTheWorldUnchanged) {
  cd::World w = pile();
  for (int k = 0; k < 5; ++k) w.step();
  const fs::path d = temp_dir("damaged");
  const fs::path f = d / "checkpoint.bin";
  cd::save_checkpoint(f.string(), w, 1);
  const std::string good = slurp(f);

  cd::World x = pile();
  const std::uint64_t h = cdtest::state_hash(x);
  auto expect_error = [&](const std::string& bytes, const std::string& what) {
    spit(f, bytes);
    try {
      cd::load_checkpoint(f.string(), x);
      ADD_FAILURE() << "no error for: " << what;
    } catch (const cd::CheckpointError& e) {
      EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
    EXPECT_EQ(cdtest::state_hash(x), h);
    EXPECT_EQ(x.steps, 0);
  };
  expect_error(good.substr(0, good.size() / 2), "truncated");
  expect_error(good.substr(0, 5), "truncated");
  std::string flipped = good;
  flipped[good.size() / 2] ^= 1;
  expect_error(flipped, "corrupt");
  expect_error("not a checkpoint at all", "not a cdlab checkpoint");
  std::string v2 = good;
  v2[8] = 9;  // version field (this build reads 4)
  expect_error(v2, "version 9");
  // Version 3 (no run totals): refused for a resume, with a clear message.
  std::string v3 = good;
  v3[8] = 3;
  cd::RunTotals t;
  t.sessions = 7;
  spit(f, v3);
  try {
    cd::load_checkpoint(f.string(), x, &t);
    ADD_FAILURE() << "a version 3 checkpoint was resumed";
  } catch (const cd::CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("format version 3, which holds no run totals"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(t.sessions, 7.0);
  EXPECT_EQ(x.steps, 0);

  // The totals round-trip.
  cd::RunTotals in{1.5, 2.5, 300, 40, 5, 1e-3, 2e-4, 3e-3, 2, 700, 8, 9, 10};
  cd::save_checkpoint(f.string(), w, 1, in);
  cd::RunTotals out;
  cd::load_checkpoint(f.string(), x, &out);
  EXPECT_EQ(std::memcmp(&in, &out, sizeof in), 0);
  EXPECT_THROW(cd::load_checkpoint((d / "missing.bin").string(), x), cd::CheckpointError);
}

// A checkpoint of an earlier build holds its totals under their own name
// (same format version 5): nine before the accelerations' counts, twelve
// before floor_steps. It resumes: the state and the stored totals as they
// were, the later ones at 0 (from then on they count the sessions since the
// resume).
void resumes_with_the_later_totals_at_zero(const std::string& name, const std::string& totals) {
  cd::World w = pile();
  for (int k = 0; k < 5; ++k) w.step();
  const fs::path f = temp_dir(name) / "checkpoint.bin";
  const std::vector<double> all{1.5, 2.5, 300, 40, 5, 1e-3, 2e-4, 3e-3, 2, 700, 8, 9, 10};
  cd::save_checkpoint(f.string(), w, 1, cd::RunTotals{1.5, 2.5, 300, 40, 5, 1e-3, 2e-4, 3e-3, 2, 700, 8, 9, 10});
  const std::size_t stored = std::count(totals.begin(), totals.end(), ':');
  spit(f, cdtest::with_totals(slurp(f), totals, std::vector<double>(all.begin(), all.begin() + stored)));
  cd::World x = pile();
  cd::RunTotals t{0, 0, 0, 0, 0, 0, 0, 0, 0, 11, 12, 13, 14};
  EXPECT_EQ(cd::load_checkpoint(f.string(), x, &t), 1u) << name;
  EXPECT_EQ(x.steps, 5) << name;
  EXPECT_EQ(cdtest::state_hash(x), cdtest::state_hash(w)) << name;
  std::vector<double> want(all.begin(), all.begin() + stored);
  want.resize(all.size(), 0.0);
  ASSERT_EQ(sizeof t, want.size() * sizeof(double));
  EXPECT_EQ(std::memcmp(&t, want.data(), sizeof t), 0)
      << name << ": " << t.wall << " " << t.sessions << " " << t.cg_iterations << " " << t.anderson_off_steps << " "
      << t.subspace_off_steps << " " << t.floor_steps;
}

TEST(Checkpoint, TotalsOfTheEarlierBuildsResumeWithTheLaterOnesAtZero) {
  resumes_with_the_later_totals_at_zero("nine", cdtest::kTotals9);
  resumes_with_the_later_totals_at_zero("twelve", cdtest::kTotals12);
}

// Totals under any other name (another build's fields, or one more) are
// refused naming the file, the world and the caller's totals untouched; so
// are a name over another count of values (the nine-field name over twelve,
// ...), and a totals array missing.
TEST(Checkpoint, OtherTotalsAreRefusedNamingTheFile) {
  cd::World w = pile();
  for (int k = 0; k < 5; ++k) w.step();
  const fs::path f = temp_dir("other_totals") / "checkpoint.bin";
  cd::save_checkpoint(f.string(), w, 1);
  const std::string good = slurp(f);
  const std::vector<double> nine(9, 1.0), twelve(12, 1.0), thirteen(13, 1.0);
  std::string renamed = cdtest::kTotals13;
  renamed.replace(renamed.find("cg_iterations"), 13, "cg_iters");
  const struct {
    std::string name;
    std::vector<double> values;
    std::string what;
  } cases[] = {
      {renamed, thirteen, "holds run totals named '" + renamed + "'; this build reads '" + cdtest::kTotals13 + "'"},
      {cdtest::kTotals13 + ":sweeps_cg", std::vector<double>(14, 1.0), "holds run totals named"},
      {cdtest::kTotals12 + ":floor", thirteen, "holds run totals named"},
      {"totals:wall:cpu", {1.0, 1.0}, "holds run totals named 'totals:wall:cpu'"},
      {cdtest::kTotals9, twelve, "is corrupt: 'totals' holds 12 run totals where its name lists 9"},
      {cdtest::kTotals12, thirteen, "is corrupt: 'totals' holds 13 run totals where its name lists 12"},
      {cdtest::kTotals13, twelve, "is corrupt: 'totals' holds 12 run totals where its name lists 13"},
      {"cell", thirteen, "where 'totals:wall:cpu:sweeps:sweeps_max"},
  };
  cd::World x = pile();
  const std::uint64_t h = cdtest::state_hash(x);
  for (const auto& c : cases) {
    spit(f, cdtest::with_totals(good, c.name, c.values));
    cd::RunTotals t;
    t.sessions = 7;
    try {
      cd::load_checkpoint(f.string(), x, &t);
      ADD_FAILURE() << "totals named " << c.name << " were read";
    } catch (const cd::CheckpointError& e) {
      EXPECT_NE(std::string(e.what()).find("checkpoint '" + f.string() + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
    }
    EXPECT_EQ(t.sessions, 7.0);
    EXPECT_EQ(cdtest::state_hash(x), h);
  }
}

// ---- cdsim --------------------------------------------------------------------

using Result = cdtest::CmdResult;
Result cdsim(const std::string& args) { return cdtest::run_command(kCdsim + " " + args); }

// Steps of a series.csv's rows.
std::vector<long> row_steps(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  std::vector<long> steps;
  while (std::getline(in, line)) steps.push_back(std::atol(line.c_str()));
  return steps;
}

// series.csv rows as column -> text.
std::vector<std::map<std::string, std::string>> series_cells(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::vector<std::string> names;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
    if (names.empty()) {
      names = cells;
      continue;
    }
    EXPECT_EQ(cells.size(), names.size()) << p << ": " << line;
    rows.emplace_back();
    for (std::size_t i = 0; i < cells.size() && i < names.size(); ++i) rows.back()[names[i]] = cells[i];
  }
  return rows;
}

// The same, without the wall-clock columns t_*.
std::vector<std::map<std::string, std::string>> series_without_timing(const fs::path& p) {
  auto rows = series_cells(p);
  for (auto& r : rows) std::erase_if(r, [](const auto& c) { return c.first.starts_with("t_"); });
  return rows;
}

// Every point and array of two .vtp files, compared exactly.
void expect_same_vtp(const fs::path& a, const fs::path& b) {
  auto read = [](const fs::path& p) {
    vtkNew<vtkXMLPolyDataReader> r;
    r->SetFileName(p.c_str());
    r->Update();
    vtkSmartPointer<vtkPolyData> pd = r->GetOutput();
    return pd;
  };
  const auto A = read(a), B = read(b);
  ASSERT_EQ(A->GetNumberOfPoints(), B->GetNumberOfPoints()) << a;
  ASSERT_EQ(A->GetNumberOfCells(), B->GetNumberOfCells()) << a;
  for (vtkIdType i = 0; i < A->GetNumberOfPoints(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(A->GetPoint(i)[c], B->GetPoint(i)[c]) << a;
  for (auto [fa, fb] : {std::pair<vtkFieldData*, vtkFieldData*>{A->GetPointData(), B->GetPointData()},
                        {A->GetCellData(), B->GetCellData()}}) {
    ASSERT_EQ(fa->GetNumberOfArrays(), fb->GetNumberOfArrays()) << a;
    for (int k = 0; k < fa->GetNumberOfArrays(); ++k) {
      vtkDataArray* x = fa->GetArray(k);
      vtkDataArray* y = fb->GetArray(x->GetName());
      ASSERT_TRUE(y) << a << ": " << x->GetName();
      ASSERT_EQ(x->GetNumberOfValues(), y->GetNumberOfValues()) << a << ": " << x->GetName();
      for (vtkIdType v = 0; v < x->GetNumberOfValues(); ++v)
        ASSERT_EQ(x->GetComponent(v / x->GetNumberOfComponents(), v % x->GetNumberOfComponents()),
                  y->GetComponent(v / y->GetNumberOfComponents(), v % y->GetNumberOfComponents()))
            << a << ": " << x->GetName() << "[" << v << "]";
    }
  }
}

// The outputs of two runs: the same files, the same series (timing columns
// aside), identical collections and snapshot arrays. (A kill during a write
// may leave a *.tmp.<pid> file behind: not an output.)
void expect_same_outputs(const fs::path& a, const fs::path& b) {
  auto names = [](const fs::path& d) {
    std::vector<std::string> n;
    for (const auto& e : fs::directory_iterator(d))
      if (e.path().filename().string().find(".tmp.") == std::string::npos)
        n.push_back(e.path().filename().string());
    std::sort(n.begin(), n.end());
    return n;
  };
  ASSERT_EQ(names(a), names(b));
  EXPECT_EQ(series_without_timing(a / "series.csv"), series_without_timing(b / "series.csv"));
  for (const char* pvd : {"particles.pvd", "contacts.pvd", "walls.pvd"})
    EXPECT_EQ(slurp(a / pvd), slurp(b / pvd)) << pvd;
  for (const std::string& f : names(a))
    if (f.ends_with(".vtp")) expect_same_vtp(a / f, b / f);
}

// ~1000 steps of a 300-disk pile: a few seconds, so that a kill lands mid-run.
const std::string kPile = R"(name = "restart"
[time]
dt = 2e-4
duration = 0.2
[contact]
mu = 0.4
alert = 0.4
[solver]
tol = 1e-3
max_iter = 500
[particles]
n = 300
seed = 3
[box]
width = 0.025
height = 0.05
[output]
series_interval = 0.005
snapshot_interval = 0.025
checkpoint_interval = 0.05
)";

TEST(CdsimRestart, KilledRunResumesBitIdentical) {
  const fs::path d = temp_dir("kill");
  const fs::path scene = d / "s.toml";
  spit(scene, kPile);

  const Result a = cdsim(scene.string() + " --quiet --out " + (d / "A").string());
  ASSERT_EQ(a.code, 0) << a.out;

  // Run B, killed (SIGKILL) once a checkpoint exists and the series has gone
  // past it, so that the restart must also drop rows written after it.
  const fs::path B = d / "B";
  const std::string out_b = B.string();
  const pid_t pid = cdtest::spawn({kCdsim, scene.string(), "--quiet", "--out", out_b});
  ASSERT_GT(pid, 0);
  const long first_ckpt = 250;  // checkpoint_interval / dt
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  bool exited = false;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120)) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    if (fs::exists(B / "checkpoint.bin")) {
      const auto steps = row_steps(B / "series.csv");
      if (!steps.empty() && steps.back() > first_ckpt) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (!exited) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the run ended before it could be killed: make the scene bigger";
  const long killed_at = row_steps(B / "series.csv").back();
  EXPECT_LT(killed_at, 1000);

  // The same command again resumes and finishes.
  // With progress lines every millisecond: the run's lines while it steps.
  const Result b = cdsim(scene.string() + " --quiet --progress 0.001 --out " + out_b);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("resumed from"), std::string::npos) << b.out;
  // Said when the run resumes, before its first progress line (so a log has
  // it even if the resumed run is killed), not after the run returns.
  ASSERT_NE(b.out.find("% (step "), std::string::npos) << b.out;
  EXPECT_LT(b.out.find("resumed from"), b.out.find("% (step ")) << b.out;
  expect_same_outputs(d / "A", B);

  // The final checkpoints hold the same state; B's stage timers went on
  // across the restart, and its timings.csv rows add up to them.
  cd::World wa{cd::WorldParams{}}, wb{cd::WorldParams{}};
  EXPECT_EQ(cd::load_checkpoint((d / "A" / "checkpoint.bin").string(), wa),
            cd::load_checkpoint((B / "checkpoint.bin").string(), wb));
  EXPECT_EQ(cdtest::state_hash(wa), cdtest::state_hash(wb));
  EXPECT_EQ(wa.warm_start().p, wb.warm_start().p);
  std::array<double, cd::kStages> sum{};
  for (const auto& row : series_cells(B / "timings.csv"))
    for (int s = 0; s < cd::kStages; ++s)
      sum[s] += std::stod(row.at(std::string("t_") + cd::kStageNames[s]));
  // Every stage of the step (output is also timed after the last row: the
  // final snapshot and checkpoint are written after it).
  for (int s = 0; s < cd::kStages; ++s) {
    if (cd::Stage(s) != cd::Stage::Output) {
      EXPECT_NEAR(sum[s], wb.times.t[s], 1e-6 * wb.times.t[s]) << cd::kStageNames[s];
    }
  }
  std::cout << "killed after step " << killed_at << "; " << b.out;
  if (!HasFailure()) fs::remove_all(d);
}

// ---- a campaign run killed at half its length ---------------------------------

// Spawns `args` and sends it `sig` as soon as `ready()` holds; returns its
// wait status, or -1 if it ended first.
int run_and_signal_when(std::vector<std::string> args, const std::function<bool()>& ready, int sig) {
  const pid_t pid = cdtest::spawn(std::move(args));
  if (pid < 0) return -1;
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(300)) {
    if (waitpid(pid, &status, WNOHANG) == pid) return -1;
    if (ready()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  kill(pid, sig);
  waitpid(pid, &status, 0);
  return status;
}

// Spawns `args` and kills it with SIGKILL as soon as `ready()` holds.
// Returns false if the run ended first.
bool run_and_kill_when(std::vector<std::string> args, const std::function<bool()>& ready) {
  const int status = run_and_signal_when(std::move(args), ready, SIGKILL);
  return status != -1 && WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
}

using cdtest::summary_fields;  // summary.toml as key -> value text

// The run's cost in summary.toml against its series: steps are the last
// row's step, the mean sweeps the step-weighted mean of the iterations
// column (10 significant digits), the cap steps the sum of cap_hit, the
// largest residual and overlap the columns' maxima.
void expect_summary_matches_series(const fs::path& run) {
  const auto f = summary_fields(run / "summary.toml");
  const auto rows = series_cells(run / "series.csv");
  ASSERT_FALSE(rows.empty());
  double prev = 0, sweeps = 0, cap = 0, res = 0, ov = 0, it_max = 0;
  for (const auto& r : rows) {
    const double step = std::stod(r.at("step"));
    sweeps += std::stod(r.at("iterations")) * (step - prev);
    prev = step;
    cap += std::stod(r.at("cap_hit"));
    res = std::max(res, std::stod(r.at("residual")));
    ov = std::max(ov, std::stod(r.at("max_overlap")));
    it_max = std::max(it_max, std::stod(r.at("iterations_max")));
  }
  EXPECT_EQ(std::stod(f.at("steps")), prev) << run;
  EXPECT_NEAR(std::stod(f.at("sweeps_mean")), sweeps / prev, 1e-9 * sweeps / prev) << run;
  EXPECT_EQ(std::stod(f.at("sweeps_max")), it_max) << run;
  EXPECT_EQ(std::stod(f.at("cap_steps")), cap) << run;
  EXPECT_DOUBLE_EQ(std::stod(f.at("cap_share")), cap / prev) << run;
  EXPECT_NEAR(std::stod(f.at("residual_max")), res, 1e-9 * res) << run;
  EXPECT_NEAR(std::stod(f.at("overlap_max")), ov, 1e-9 * ov + 1e-300) << run;
  EXPECT_GT(std::stod(f.at("wall_time")), 0.0) << run;
  EXPECT_GT(std::stod(f.at("cpu_time")), 0.0) << run;
  EXPECT_GE(std::stod(f.at("threads")), 1.0) << run;
  EXPECT_EQ(f.at("status"), "\"done\"") << run;
  EXPECT_TRUE(f.count("cdlab_version") && f.at("cdlab_version").size() > 2) << run;
  EXPECT_EQ(f.at("load_start").front(), '[') << run;
}

// A campaign's shear run, small: configs/shear-inertial.toml with 80 grains
// (generated loose in the cell, so no preparation is needed), sheared to
// gamma = 1 at I = 0.01 (2000 steps, a series row every 0.01 of strain as in
// the campaigns), with the campaign's checkpoint keys (Makefile,
// CAMPAIGN_SET: every 0.1 of strain, and every 300 s of wall clock), at the
// cohesive campaigns' tolerance 1e-3 to keep it to about a second.
std::vector<std::string> campaign_run(const fs::path& out, const std::string& ckpt) {
  std::vector<std::string> a = {kCdsim, std::string(CDLAB_SOURCE_DIR) + "/configs/shear-inertial.toml",
                                "--quiet", "--out", out.string(), "--threads", "1"};
  for (const char* set : {"particles.n=80", "shear.start=\"\"", "shear.width=0.0135",
                          "shear.height=0.0135", "shear.strain=1", "solver.tol=1e-3",
                          "output.series_interval=1.612452e-4",  // 0.01 strain: 20 steps
                          "output.snapshot_interval=1.612452e-3"})  // 0.1 strain
    a.insert(a.end(), {"--set", set});
  std::stringstream s(ckpt);
  for (std::string set; s >> set;) a.insert(a.end(), {"--set", set});
  return a;
}

std::string joined(const std::vector<std::string>& a) {
  std::string s;
  for (std::size_t i = 0; i < a.size(); ++i)
    s += (i ? " '" : "'") + a[i] + "'";
  return s;
}

// The README's promise, tested: a campaign run killed (SIGKILL) at about
// half its length resumes from a checkpoint written after at least 40 % of
// it and ends bit-identical to a run never stopped (series but the t_*
// columns, snapshots). Once with strain checkpoints, once with wall-clock
// ones at every series row (a wall-clock trigger changes no result), and the
// summaries of the resumed runs cover both sessions.
TEST(CdsimRestart, CampaignRunKilledAtHalfResumesBitIdentical) {
  const fs::path d = temp_dir("half");
  const std::string strain = "output.checkpoint_strain=0.1 output.checkpoint_wall=300";
  const Result a = cdtest::run_command(joined(campaign_run(d / "A", strain)));
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_EQ(a.out.find("warning: output.checkpoint"), std::string::npos) << a.out;
  const auto steps_a = row_steps(d / "A" / "series.csv");
  ASSERT_EQ(steps_a.size(), 100u);
  const long n = steps_a.back();
  ASSERT_EQ(n, 2000);
  expect_summary_matches_series(d / "A");

  for (const auto& [name, ckpt] : {std::pair<std::string, std::string>{"B", strain},
                                   {"C", "output.checkpoint_wall=1e-9"}}) {
    SCOPED_TRACE(name + ": " + ckpt);
    const fs::path run = d / name;
    // Killed once the series shows more than 45 % of its rows.
    ASSERT_TRUE(run_and_kill_when(campaign_run(run, ckpt), [&] {
      std::ifstream f(run / "series.csv");
      return std::count(std::istreambuf_iterator<char>(f), {}, '\n') > 1 + 45;
    })) << "the run ended before it could be killed";
    ASSERT_TRUE(fs::exists(run / "checkpoint.bin"));
    cd::World w{cd::WorldParams{}};
    cd::RunTotals t;
    cd::load_checkpoint((run / "checkpoint.bin").string(), w, &t);
    EXPECT_GE(w.steps, 0.4 * n) << "the last checkpoint before the kill";
    EXPECT_LT(w.steps, n);
    EXPECT_EQ(t.sessions, 1.0);
    EXPECT_GT(t.wall, 0.0);
    EXPECT_EQ(w.steps % 20, 0) << "checkpoints fall on series rows";
    std::cout << name << ": killed with " << row_steps(run / "series.csv").back()
              << " steps in series.csv, checkpoint at step " << w.steps << " of " << n << "\n";

    const Result r = cdtest::run_command(joined(campaign_run(run, ckpt)));
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
    expect_same_outputs(d / "A", run);
    expect_summary_matches_series(run);
    const auto fa = summary_fields(d / "A" / "summary.toml"), fr = summary_fields(run / "summary.toml");
    EXPECT_EQ(fr.at("sessions"), "2");
    for (const char* k : {"steps", "sweeps_mean", "sweeps_max", "cap_steps", "residual_final",
                          "residual_max", "overlap_max"})
      EXPECT_EQ(fa.at(k), fr.at(k)) << k;
  }
  if (!HasFailure()) fs::remove_all(d);
}

// A small scene for the refusal cases.
const std::string kTiny = R"(name = "tiny"
[time]
dt = 1e-3
duration = 0.02
[[disk]]
pos = [0.0, 0.5]
radius = 0.5
[[disk]]
pos = [1.0, 0.5]
radius = 0.5
[[wall]]
a = [-5.0, 0.0]
b = [5.0, 0.0]
[output]
series_interval = 1e-3
snapshot_interval = 5e-3
checkpoint_interval = 5e-3
)";

TEST(CdsimRestart, DamagedOrForeignCheckpointIsRefusedUnlessFresh) {
  const fs::path d = temp_dir("refuse");
  const fs::path scene = d / "s.toml";
  spit(scene, kTiny);
  const std::string out = " --quiet --out " + (d / "out").string();
  const fs::path ckpt = d / "out" / "checkpoint.bin";
  ASSERT_EQ(cdsim(scene.string() + out).code, 0);
  ASSERT_TRUE(fs::exists(ckpt));
  const std::string series = slurp(d / "out" / "series.csv");
  fs::copy_file(d / "out" / "series.csv", d / "series0.csv");

  // A finished run resumes at its end: nothing to do, nothing changed. The
  // thread count and quiet are not part of the scene's identity.
  Result r = cdsim(scene.string() + out + " --threads 1");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("at step 20 of 20"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(d / "out" / "series.csv"), series);

  // Another scene: refused, exit 2, nothing touched; --fresh starts over.
  r = cdsim(scene.string() + out + " --set contact.mu=0.3");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("different scene"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(ckpt.string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--fresh"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(d / "out" / "series.csv"), series);
  r = cdsim(scene.string() + out + " --set contact.mu=0.3 --fresh");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("resumed"), std::string::npos) << r.out;
  ASSERT_EQ(cdsim(scene.string() + out + " --fresh").code, 0);
  EXPECT_EQ(series_without_timing(d / "out" / "series.csv"), series_without_timing(d / "series0.csv"));

  // Truncated, corrupt: a clear error naming the file, exit 2.
  const std::string good = slurp(ckpt);
  spit(ckpt, good.substr(0, good.size() - 10));
  r = cdsim(scene.string() + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(ckpt.string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("truncated or corrupt"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--fresh"), std::string::npos) << r.out;
  spit(ckpt, "garbage");
  r = cdsim(scene.string() + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("not a cdlab checkpoint"), std::string::npos) << r.out;
  EXPECT_EQ(cdsim(scene.string() + out + " --fresh").code, 0);
  EXPECT_NE(slurp(ckpt), "garbage");
  if (!HasFailure()) fs::remove_all(d);
}

TEST(CdsimRestart, CheckpointKeysAreCheckedAndLongIntervalsWarned) {
  const fs::path d = temp_dir("keys");
  const fs::path scene = d / "s.toml";
  spit(scene, kTiny);
  const std::string out = " --quiet --out " + (d / "out").string();
  // An interval as long as the run: a warning, and the checkpoint at the end.
  Result r = cdsim(scene.string() + out + " --set output.checkpoint_interval=0.05");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("warning: output.checkpoint_interval = 0.05 s is 20 steps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no checkpoint before the end"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(d / "out" / "checkpoint.bin"));
  r = cdsim(scene.string() + out + " --fresh");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  // A strain interval needs a shear rate: refused, nothing written.
  r = cdsim(scene.string() + " --quiet --out " + (d / "strain").string() +
            " --set output.checkpoint_strain=0.1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("output.checkpoint_strain > 0 needs a shear rate"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "strain"));
  // The wall-clock key alone turns checkpoints on (one at the end at least);
  // a run resumed with other checkpoint keys is the same scene.
  r = cdsim(scene.string() + " --quiet --out " + (d / "wall").string() + " --set output.checkpoint_interval=0"
            " --set output.checkpoint_wall=3600");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(d / "wall" / "checkpoint.bin"));
  r = cdsim(scene.string() + " --quiet --out " + (d / "wall").string() + " --set output.checkpoint_wall=1");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  if (!HasFailure()) fs::remove_all(d);
}

TEST(CdsimSummary, CapShareIsShownAndWarnedAbove1Percent) {
  const fs::path d = temp_dir("cap");
  const fs::path scene = d / "s.toml";
  spit(scene, kTiny);
  // One sweep a step cannot converge a contact problem: every step with
  // contacts stops at the cap.
  Result r = cdsim(scene.string() + " --quiet --out " + (d / "out").string() +
                   " --set solver.max_iter=1 --set solver.tol=1e-12");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto f = summary_fields(d / "out" / "summary.toml");
  const double share = std::stod(f.at("cap_share"));
  EXPECT_GT(share, 0.01);
  EXPECT_NE(r.out.find(fmt::format("({:.1f} % of steps)", 100 * share)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("warning: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stopped at the sweep cap (solver.max_iter = 1)"), std::string::npos) << r.out;
  expect_summary_matches_series(d / "out");
  // The default solver converges: no warning, share 0.
  r = cdsim(scene.string() + " --quiet --fresh --out " + (d / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("(0.0 % of steps)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  EXPECT_EQ(summary_fields(d / "out" / "summary.toml").at("cap_share"), "0.0");
  expect_summary_matches_series(d / "out");
  if (!HasFailure()) fs::remove_all(d);
}

TEST(CdsimRestart, ZeroIntervalWritesNoCheckpoint) {
  EXPECT_EQ(cd::Scene{}.checkpoint_interval, 0.0);  // off unless asked for
  const fs::path d = temp_dir("zero");
  const fs::path scene = d / "s.toml";
  spit(scene, kTiny);
  ASSERT_EQ(cdsim(scene.string() + " --quiet --set output.checkpoint_interval=0 --out " +
                  (d / "out").string()).code, 0);
  EXPECT_FALSE(fs::exists(d / "out" / "checkpoint.bin"));
  fs::remove_all(d);
}

}  // namespace

// ---- signals, one writer, write failures ------------------------------------

// What summary.toml says of the run's physics (not of its sessions' cost).
std::map<std::string, std::string> summary_physics(const fs::path& run) {
  auto f = summary_fields(run / "summary.toml");
  std::map<std::string, std::string> p;
  for (const char* k : {"status", "steps", "total_steps", "sweeps_mean", "sweeps_max", "cap_steps", "cap_share",
                        "residual_final", "residual_max", "overlap_max"})
    p[k] = f[k];
  return p;
}

// Every data row of series.csv ends in a newline and has the header's fields.
void expect_whole_rows(const fs::path& series) {
  const std::string text = slurp(series);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n') << series << ": the last row is cut";
  series_cells(series);  // checks each row's field count
}

// A run stopped mid-interval by SIGINT, SIGTERM or SIGHUP stops at its next
// series row with a checkpoint there (exit 128 + signal), and SIGKILL stops
// it anywhere; the same command then ends with the files of a run never
// stopped: the same series (timers aside), snapshots, collections and
// summary physics. (Rows come every 25 steps: a signal lands between rows
// 24 times in 25.)
TEST(CdsimRestart, AnySignalThenResumeGivesTheUninterruptedRun) {
  const fs::path d = temp_dir("signals");
  const fs::path scene = d / "s.toml";
  spit(scene, kPile);
  const Result a = cdsim(scene.string() + " --quiet --threads 1 --out " + (d / "A").string());
  ASSERT_EQ(a.code, 0) << a.out;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGKILL}) {
    const fs::path B = d / fmt::format("sig{}", sig);
    const std::vector<std::string> args = {kCdsim, scene.string(), "--quiet", "--threads", "1", "--out", B.string()};
    const int status = run_and_signal_when(args, [&] {
      const auto steps = row_steps(B / "series.csv");
      return !steps.empty() && steps.back() > 300;  // past the first checkpoint (250)
    }, sig);
    ASSERT_NE(status, -1) << "the run ended before signal " << sig << ": make the scene bigger";
    if (sig == SIGKILL) {
      EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    } else {
      ASSERT_TRUE(WIFEXITED(status)) << sig;
      EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
      const long last = row_steps(B / "series.csv").back();
      EXPECT_EQ(last % 25, 0) << "signal " << sig << ": a row that is not a whole interval";
      cd::World w{cd::WorldParams{}};
      cd::load_checkpoint((B / "checkpoint.bin").string(), w);
      EXPECT_EQ(w.steps, last) << "signal " << sig << ": the checkpoint is not at the last row";
      EXPECT_EQ(summary_fields(B / "summary.toml").at("status"), "\"stopped\"");
    }
    expect_whole_rows(B / "series.csv");
    const long stopped_at = row_steps(B / "series.csv").back();
    const Result b = cdsim(scene.string() + " --quiet --threads 1 --out " + B.string());
    ASSERT_EQ(b.code, 0) << "signal " << sig << ": " << b.out;
    EXPECT_NE(b.out.find("resumed from"), std::string::npos) << b.out;
    expect_same_outputs(d / "A", B);
    EXPECT_EQ(summary_physics(d / "A"), summary_physics(B)) << "signal " << sig;
    std::cout << "signal " << sig << ": the series stopped at step " << stopped_at << "\n";
  }
  if (!HasFailure()) fs::remove_all(d);
}

// One writer per output folder: a second cdsim on a folder that a running
// one holds is refused (exit 6), naming the folder and the other's pid,
// and writes nothing, even once the lock file is removed under the run; once the first is killed with SIGKILL the lock is gone
// with it, and the same command resumes.
TEST(CdsimRestart, ASecondCdsimOnAHeldFolderIsRefused) {
  const fs::path d = temp_dir("lock");
  const fs::path scene = d / "s.toml", B = d / "B";
  spit(scene, kPile);
  const pid_t pid = cdtest::spawn({kCdsim, scene.string(), "--quiet", "--threads", "1", "--out", B.string()});
  ASSERT_GT(pid, 0);
  const auto t0 = std::chrono::steady_clock::now();
  while (row_steps(B / "series.csv").size() < 2 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const Result second = cdsim(scene.string() + " --quiet --threads 1 --out " + B.string());
  const Result fresh = cdsim(scene.string() + " --quiet --threads 1 --fresh --out " + B.string());
  // The lock file removed under the run: the folder's own lock still holds.
  fs::remove(B / ".cdsim.lock");
  const Result unlocked = cdsim(scene.string() + " --quiet --threads 1 --out " + B.string());
  int status = 0;
  const bool running = waitpid(pid, &status, WNOHANG) == 0;
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  ASSERT_TRUE(running) << "the first run ended before the second started: make the scene bigger";
  for (const Result& r : {second, fresh}) {
    EXPECT_EQ(r.code, 6) << r.out;
    EXPECT_NE(r.out.find("output folder '" + B.string() + "' is being written by another cdsim (pid " +
                         std::to_string(pid) + ")"), std::string::npos) << r.out;
  }
  EXPECT_EQ(unlocked.code, 6) << unlocked.out;
  EXPECT_NE(unlocked.out.find("holds the folder's lock (its lock file"), std::string::npos) << unlocked.out;
  expect_whole_rows(B / "series.csv");
  EXPECT_EQ(slurp(B / "series.csv").find("step,", 1), std::string::npos) << "a second header";
  // No stale lock after a kill -9.
  const Result after = cdsim(scene.string() + " --quiet --threads 1 --out " + B.string());
  EXPECT_EQ(after.code, 0) << after.out;
  if (!HasFailure()) fs::remove_all(d);
}

// Two started together: one runs, the other is refused; the series has one
// header and no step twice.
TEST(CdsimRestart, TwoCdsimStartedTogetherOneRuns) {
  const fs::path d = temp_dir("lock2");
  const fs::path scene = d / "s.toml", B = d / "B";
  spit(scene, kPile);
  const std::vector<std::string> args = {kCdsim, scene.string(), "--quiet", "--threads", "1", "--set",
                                         "time.duration=0.05", "--out", B.string()};
  const pid_t p1 = cdtest::spawn(args), p2 = cdtest::spawn(args);
  ASSERT_GT(p1, 0);
  ASSERT_GT(p2, 0);
  int s1 = 0, s2 = 0;
  waitpid(p1, &s1, 0);
  waitpid(p2, &s2, 0);
  ASSERT_TRUE(WIFEXITED(s1) && WIFEXITED(s2));
  std::vector<int> codes = {WEXITSTATUS(s1), WEXITSTATUS(s2)};
  std::sort(codes.begin(), codes.end());
  EXPECT_EQ(codes, (std::vector<int>{0, 6}));
  const auto steps = row_steps(B / "series.csv");
  EXPECT_TRUE(std::is_sorted(steps.begin(), steps.end()) &&
              std::adjacent_find(steps.begin(), steps.end()) == steps.end());
  EXPECT_EQ(slurp(B / "series.csv").find("step,", 1), std::string::npos) << "a second header";
  if (!HasFailure()) fs::remove_all(d);
}

// A write that fails mid-run (here: series.csv over a file size limit, the
// way a full disk fails a write) stops the run with exit 4 and "could not
// write", not "bad input"; series.csv holds whole rows, the last checkpoint
// is intact, and once the file can be written the same command resumes to
// the files of a run never stopped. A snapshot that cannot be put in place
// (a folder in its way) is the same failure.
TEST(CdsimRestart, AWriteFailureMidRunIsExitFourAndResumable) {
  const fs::path d = temp_dir("full");
  const fs::path scene = d / "s.toml", B = d / "B";
  // A row every step (1000 rows, about 300 kB of series), no snapshots: the
  // series outgrows a 100 kB limit after the checkpoint of step 250 (about
  // 60 kB) was written.
  std::string text = kPile;
  text.replace(text.find("series_interval = 0.005"), 23, "series_interval = 2e-4");
  text.replace(text.find("snapshot_interval = 0.025"), 25, "snapshot_interval = 0.0");
  spit(scene, text);
  const std::string args = scene.string() + " --quiet --threads 1 --out ";
  ASSERT_EQ(cdsim(args + (d / "A").string()).code, 0);
  const Result full = cdtest::run_command("prlimit --fsize=100000 " + kCdsim + " " + args + B.string());
  EXPECT_EQ(full.code, 4) << full.out;
  EXPECT_NE(full.out.find("could not write '" + (B / "series.csv").string() + "'"), std::string::npos) << full.out;
  EXPECT_EQ(full.out.find("bad input"), std::string::npos) << full.out;
  EXPECT_LE(fs::file_size(B / "series.csv"), 100000u);
  expect_whole_rows(B / "series.csv");
  cd::World w{cd::WorldParams{}};
  cd::load_checkpoint((B / "checkpoint.bin").string(), w);
  EXPECT_GE(w.steps, 250);
  EXPECT_LT(w.steps, row_steps(B / "series.csv").back());
  const Result b = cdsim(args + B.string());
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("resumed from"), std::string::npos) << b.out;
  expect_same_outputs(d / "A", B);
  EXPECT_EQ(summary_physics(d / "A"), summary_physics(B));

  // A snapshot's place taken by a folder: exit 4, one message (after the
  // line saying the run resumed, said when it did), no VTK log.
  const fs::path C = d / "C";
  ASSERT_EQ(cdsim(scene.string() + " --quiet --threads 1 --set output.snapshot_interval=0.025"
                  " --max-steps 130 --out " + C.string()).code, 0);
  fs::create_directories(C / "particles_00002.vtp" / "x");
  const Result snap = cdsim(scene.string() + " --quiet --threads 1 --set output.snapshot_interval=0.025 --out " + C.string());
  EXPECT_EQ(snap.code, 4) << snap.out;
  EXPECT_NE(snap.out.find("could not write '" + (C / "particles_00002.vtp").string() + "'"), std::string::npos) << snap.out;
  EXPECT_EQ(snap.out.rfind("cdsim: resumed from ", 0), 0u) << snap.out;
  EXPECT_EQ(std::count(snap.out.begin(), snap.out.end(), '\n'), 2) << snap.out;
  expect_whole_rows(C / "series.csv");
  if (!HasFailure()) fs::remove_all(d);
}
