// Checkpoint and restart: a run stopped and continued from a checkpoint is
// bit-identical to one never stopped, in the library (state hash) and through
// cdsim killed with SIGKILL mid-run and run again (every output compared);
// damaged checkpoints and checkpoints of another scene are refused clearly.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
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

#include "checkpoint.hpp"
#include "cli_util.hpp"
#include "world_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("cdlab_ckpt_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

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
  v2[8] = 9;  // version field (this build reads 2)
  expect_error(v2, "version 9");
  EXPECT_THROW(cd::load_checkpoint((d / "missing.bin").string(), x), cd::CheckpointError);
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
  std::vector<std::string> args = {kCdsim, scene.string(), "--quiet", "--out", out_b};
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid;
  ASSERT_EQ(posix_spawn(&pid, kCdsim.c_str(), &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
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
  const Result b = cdsim(scene.string() + " --quiet --out " + out_b);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("resumed from"), std::string::npos) << b.out;
  expect_same_outputs(d / "A", B);

  // The final checkpoints hold the same state; B's stage timers went on
  // across the restart, and its series rows add up to them.
  cd::World wa{cd::WorldParams{}}, wb{cd::WorldParams{}};
  EXPECT_EQ(cd::load_checkpoint((d / "A" / "checkpoint.bin").string(), wa),
            cd::load_checkpoint((B / "checkpoint.bin").string(), wb));
  EXPECT_EQ(cdtest::state_hash(wa), cdtest::state_hash(wb));
  EXPECT_EQ(wa.warm_start().p, wb.warm_start().p);
  std::array<double, cd::kStages> sum{};
  for (const auto& row : series_cells(B / "series.csv"))
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
