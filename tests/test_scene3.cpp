// `dimension = 3` scenes run by cdsim: the scene -> World3
// mapping (cd/src/3d/setup3), contacts in VTK (output3), 3D checkpoints
// (checkpoint3) and the shared run loop (core/run_loop) driving World3:
// resume bit-identical, 1 and 2 threads identical, the other dimension's
// checkpoint refused, bad 3D input refused naming the key.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include "checkpoint3.hpp"
#include "cli_util.hpp"
#include "config.hpp"
#include "output3.hpp"
#include "pile3d.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"
#include "totals_util.hpp"

namespace fs = std::filesystem;
using namespace cd;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kPile3d = CDLAB_SOURCE_DIR "/configs/pile3d.toml";

// Every byte of a World3's state that the next step reads.
std::uint64_t state_hash(const World3& w) {
  std::uint64_t h = fnv1a("");
  const auto add = [&](const auto& v) {
    h = fnv1a(std::string_view(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0])), h);
  };
  add(w.bodies.pos);
  add(w.bodies.orient);
  add(w.bodies.vel);
  add(w.bodies.radius);
  add(w.bodies.mass);
  add(w.warm_start().keys);
  add(w.warm_start().p);
  h = fnv1a(std::string_view(reinterpret_cast<const char*>(&w.steps), sizeof w.steps), h);
  return fnv1a(std::string_view(reinterpret_cast<const char*>(&w.time), sizeof w.time), h);
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// series.csv without the t_* (wall-clock) columns: what must be identical.
std::vector<std::string> series_without_timers(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  std::vector<bool> keep;
  std::vector<std::string> out;
  {
    std::istringstream hs(line);
    for (std::string c; std::getline(hs, c, ',');) keep.push_back(!c.starts_with("t_"));
  }
  out.push_back(line);
  while (std::getline(f, line)) {
    std::istringstream ls(line);
    std::string r;
    std::size_t i = 0;
    for (std::string c; std::getline(ls, c, ','); ++i)
      if (i < keep.size() && keep[i]) r += c + ",";
    out.push_back(r);
  }
  return out;
}

}  // namespace

// configs/pile3d.toml builds pile3d.hpp's scene: the lattice, the box fitted
// to it, radii in [0.5, 1] r_max = [2.5, 5] mm, density 2600 kg/m^3, and the
// scene's contact settings on WorldParams3.
TEST(Scene3, Pile3dSceneIsThePile3dLayout) {
  const Scene s = load_scene(kPile3d, {"particles.n=130"});
  ASSERT_EQ(s.dimension, 3);
  const World3 w = build_world3(s);
  ASSERT_EQ(w.bodies.size(), 135u);  // 5 planes, then 130 spheres
  for (int i = 0; i < 5; ++i) EXPECT_EQ(w.bodies.shape[i], Shape3::Plane);
  const double side = 6 * 0.011;  // n = ceil(130^(1/3)) = 6, pitch 1.1 x 10 mm
  EXPECT_NEAR(w.bodies.pos[2].x(), side, 1e-15);  // the x = L wall
  EXPECT_NEAR(w.bodies.pos[4].y(), side, 1e-15);  // the y = L wall
  double zmin = 1e9, rmin = 1e9, rmax = 0;
  for (std::size_t i = 5; i < w.bodies.size(); ++i) {
    const double r = w.bodies.radius[i];
    zmin = std::min(zmin, w.bodies.pos[i].z());
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
    EXPECT_NEAR(w.bodies.mass[i], 2600.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r, 1e-15);
    EXPECT_GT(w.bodies.pos[i].x() - r, 0.0);
    EXPECT_LT(w.bodies.pos[i].y() + r, side);
  }
  EXPECT_NEAR(zmin, 1.1 * 0.005, 0.05 * 0.005 + 1e-15);  // bottom layer, +- jitter
  EXPECT_GE(rmin, 0.0025);
  EXPECT_LE(rmax, 0.005);
  const WorldParams3& p = w.params();
  EXPECT_EQ(p.gravity, Vec3(0, 0, -9.81));
  EXPECT_EQ(p.mu, 0.4);
  EXPECT_EQ(p.mu_wall, 0.4);
  EXPECT_NEAR(p.alert, 0.0025, 1e-15);  // 1/3 d_mean = 0.5 r_max
  EXPECT_EQ(p.d_ref, 7.5e-3);
  EXPECT_EQ(p.dt, 1e-3);
}

// One sphere at rest on the floor carries exactly its weight: the floor
// row's impulse is m g dt (a single converged contact: equality to
// round-off, 1e-9), stick (no tangential force), and contacts_*.vtp says
// so; nothing else touches (the side walls stay in the alert band, open).
TEST(Scene3, SphereAtRestOnTheFloorCarriesMg) {
  const Scene s = parse_scene(
      "dimension = 3\n[gravity]\ng = [0.0, 0.0, -9.81]\n[time]\ndt = 1e-3\n"
      "[particles]\ndiameters = [0.01]\ndensity = 2600.0\n", "one.toml");
  World3 w = build_world3(s);
  ASSERT_EQ(w.bodies.size(), 6u);
  for (int k = 0; k < 300; ++k) w.step();  // falls 0.5 mm, lands, rests
  const double m = w.bodies.mass[5], g = 9.81, dt = 1e-3;
  int floor_rows = 0;
  for (const SphereRow& r : w.rows()) {
    if (r.b1 == 0) {
      ++floor_rows;
      EXPECT_NEAR(r.r[0] / dt, m * g, 1e-9 * m * g);
      EXPECT_EQ(contact_status3(r), 1);
    } else {
      EXPECT_EQ(r.r[0], 0.0) << "side wall " << r.b1;
    }
  }
  EXPECT_EQ(floor_rows, 1);
  EXPECT_LT(w.bodies.vel[5].v.norm(), 1e-12);
  const fs::path d = cdtest::scratch_dir("test_scene3", "at_rest");
  write_contacts3_vtp(w, (d / "c.vtp").string());
  vtkNew<vtkXMLPolyDataReader> rd;
  rd->SetFileName((d / "c.vtp").string().c_str());
  rd->Update();
  vtkPolyData* pd = rd->GetOutput();
  ASSERT_EQ(pd->GetNumberOfCells(), static_cast<vtkIdType>(w.rows().size()));
  vtkCellData* cd = pd->GetCellData();
  ASSERT_NE(cd->GetArray("ft"), nullptr);
  EXPECT_EQ(cd->GetArray("ft")->GetNumberOfComponents(), 3);
  for (vtkIdType k = 0; k < pd->GetNumberOfCells(); ++k) {
    if (cd->GetArray("b1")->GetTuple1(k) != 0) {
      EXPECT_EQ(cd->GetArray("status")->GetTuple1(k), 0);  // open
      continue;
    }
    EXPECT_NEAR(cd->GetArray("fn")->GetTuple1(k), m * g, 1e-9 * m * g);
    EXPECT_EQ(cd->GetArray("status")->GetTuple1(k), 1);
    const double* f = cd->GetArray("force")->GetTuple3(k);
    EXPECT_NEAR(f[2], m * g, 1e-9 * m * g);  // on the sphere, upwards
    double a[3], b[3];  // the line: from the foot on the floor to the centre
    pd->GetPoint(2 * k, a);
    pd->GetPoint(2 * k + 1, b);
    EXPECT_NEAR(a[2], 0.0, 1e-6);
    EXPECT_NEAR(b[2], 0.005, 1e-6);
  }
}

// contact.e_n of a 3D scene reaches the engine: the lone sphere, dropped
// onto the floor, leaves it at e_n times its impact speed. The law acts on
// u+ + e_n u- with u- the velocity at the start of the impact step (before
// that step's gravity), so the ratio is exact, to round-off (1e-12).
TEST(Scene3, RestitutionOfTheSceneReachesTheEngine) {
  const Scene s = parse_scene(
      "dimension = 3\n[gravity]\ng = [0.0, 0.0, -9.81]\n[time]\ndt = 1e-4\n"
      "[contact]\ne_n = 0.5\n[particles]\ndiameters = [0.01]\ndensity = 2600.0\n", "bounce.toml");
  World3 w = build_world3(s);
  ASSERT_EQ(w.bodies.size(), 6u);
  double v_in = 0.0, v_out = 0.0;
  for (int k = 0; k < 3000 && v_out == 0.0; ++k) {
    const double v0 = w.bodies.vel[5].v.z();
    w.step();
    bool floor = false;
    for (const SphereRow& r : w.rows()) floor = floor || (r.b1 == 0 && r.r[0] > 0);
    if (floor) {
      v_in = v0;
      v_out = w.bodies.vel[5].v.z();
    }
  }
  ASSERT_LT(v_in, 0.0) << "the sphere never hit the floor";
  EXPECT_NEAR(v_out, -0.5 * v_in, 1e-12 * std::abs(v_in));
}

// contact.mu_b and contact.axis_a of a 3D scene reach the engine: a sphere
// on the floor of a wide box under gravity tilted along x (g_x = 12, g_z =
// -9.81 m/s^2), mu = 0.2 along axis_a and mu_b = 0.6 across it (the floor
// is a wall: mu_wall and mu_wall_b < 0 take mu and mu_b). Along the 0.2
// axis tan(theta) = 1.22 > 7/2 mu = 0.7: the sphere slides, its centre
// accelerating at g_x - mu |g_z| (10.04 m/s^2); along the 0.6 axis 7/2 mu =
// 2.1 > 1.22: it rolls without slipping at 5/7 g_x (8.57 m/s^2). After the
// landing (0.5 mm drop) the discrete velocity gains exactly a dt a step: to
// 1e-9 over 100 steps; no velocity across the slope (the slip is along a
// principal axis of the ellipse).
TEST(Scene3, OrthotropicFrictionOfTheSceneReachesTheEngine) {
  const auto accel = [](const std::string& axis, double& vy) {
    const Scene s = parse_scene(
        "dimension = 3\n[gravity]\ng = [12.0, 0.0, -9.81]\n[time]\ndt = 1e-3\n"
        "[contact]\nmu = 0.2\nmu_b = 0.6\naxis_a = " + axis + "\n"
        "[box]\nwidth = 1.0\ndepth = 1.0\n"
        "[particles]\ndiameters = [0.01]\ndensity = 2600.0\n", "ortho.toml");
    const WorldParams3 p = world_params3(s);
    EXPECT_TRUE(p.orthotropic);
    EXPECT_EQ(p.mu_b, 0.6);
    EXPECT_EQ(p.mu_wall_b, 0.6);
    EXPECT_NEAR(p.axis_a.norm(), 1.0, 1e-15);
    World3 w = build_world3(s);
    for (int k = 0; k < 50; ++k) w.step();  // lands within ~10 steps
    const double v0 = w.bodies.vel.back().v.x();
    for (int k = 0; k < 100; ++k) w.step();
    vy = w.bodies.vel.back().v.y();
    return (w.bodies.vel.back().v.x() - v0) / 0.1;
  };
  double vy = 1.0;
  EXPECT_NEAR(accel("[2.0, 0.0, 0.0]", vy), 12.0 - 0.2 * 9.81, 1e-9 * 12.0);  // slides
  EXPECT_NEAR(vy, 0.0, 1e-12);
  EXPECT_NEAR(accel("[0.0, 1.0, 0.0]", vy), 5.0 / 7.0 * 12.0, 1e-9 * 12.0);  // rolls
  EXPECT_NEAR(vy, 0.0, 1e-12);
  // Walls: an explicit mu_wall makes them isotropic unless mu_wall_b is given.
  const auto params = [](const std::string& extra) {
    return world_params3(parse_scene("dimension = 3\n[gravity]\ng = [0.0, 0.0, -9.81]\n[contact]\nmu = 0.2\n" +
                                     extra + "[particles]\ndiameters = [0.01]\n", "w.toml"));
  };
  EXPECT_FALSE(params("").orthotropic);
  EXPECT_EQ(params("mu_b = 0.5\nmu_wall = 0.3\n").mu_wall_b, 0.3);
  EXPECT_EQ(params("mu_b = 0.5\nmu_wall = 0.3\nmu_wall_b = 0.1\n").mu_wall_b, 0.1);
  EXPECT_EQ(params("mu_wall_b = 0.1\n").mu_b, 0.2);  // walls alone orthotropic
}

// pile3d at N = 300 through cdsim: the pile comes to rest (kinetic energy
// below 1e-4 m_total g d_mean at 0.6 s, after the ~0.12 s fall; a settled
// run measured 6e-8 J against m g d = 0.014 J) with overlaps bounded by
// 1e-3 of the smaller diameter (the gap term keeps them at the solver's
// tolerance; measured 1.3e-4; cdsim warns above 1e-2). The outputs are
// there: series columns as 2D's, sphere and contact snapshots with .pvd.
TEST(Scene3, Pile300ReachesRestWithBoundedOverlap) {
  const fs::path d = cdtest::scratch_dir("test_scene3", "pile300");
  const auto r = cdtest::run_command(kCdsim + " " + kPile3d + " --quiet --threads 1 --out " + d.string() +
                                     " --set particles.n=300 --set time.duration=0.6");
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream f(d / "series.csv");
  std::string header, line, last;
  std::getline(f, header);
  for (const char* c : {"step,time,contacts,active,iterations", "residual", "max_overlap",
                        "max_overlap_small", "kinetic_energy"})
    EXPECT_NE(header.find(c), std::string::npos) << c;
  {
    // The stage timings: timings.csv, not the series.
    std::ifstream t(d / "timings.csv");
    std::string th;
    std::getline(t, th);
    for (const char* c : {"step,time,t_predict", "t_detect", "t_solve", "t_output"})
      EXPECT_NE(th.find(c), std::string::npos) << c;
    EXPECT_EQ(header.find("t_"), std::string::npos) << header;
  }
  std::vector<std::string> names;
  for (std::istringstream hs(header); std::getline(hs, line, ',');) names.push_back(line);
  const auto col = [&](const std::string& row, const std::string& name) {
    std::istringstream ls(row);
    std::string c;
    for (const std::string& n : names) {
      std::getline(ls, c, ',');
      if (n == name) return std::stod(c);
    }
    return std::nan("");
  };
  double ov_small = 0;
  int rows = 0;
  while (std::getline(f, line)) {
    ++rows;
    ov_small = std::max(ov_small, col(line, "max_overlap_small"));
    last = line;
  }
  EXPECT_EQ(rows, 60);
  const World3 w0 = build_world3(load_scene(kPile3d, {"particles.n=300"}));
  double m = 0;
  for (std::size_t i = 5; i < w0.bodies.size(); ++i) m += w0.bodies.mass[i];
  EXPECT_LT(col(last, "kinetic_energy"), 1e-4 * m * 9.81 * 7.5e-3) << last;
  EXPECT_GT(col(last, "active"), 300);  // every sphere carried
  EXPECT_LT(ov_small, 1e-3);
  EXPECT_GT(ov_small, 0.0);
  for (const char* file : {"spheres.pvd", "contacts.pvd", "spheres_00012.vtp", "contacts_00012.vtp",
                           "summary.toml", "scene.toml"})
    EXPECT_TRUE(fs::exists(d / file)) << file;
  EXPECT_FALSE(fs::exists(d / "spheres_00013.vtp"));
  EXPECT_NE(slurp(d / "scene.toml").find("dimension = 3"), std::string::npos);
}

// A 3D checkpoint continues a run bit-identically, and threads do not
// change it: a 300-sphere pile with every loop parallel (min_parallel = 1)
// run 150 steps on 1 thread, against 60 on 1 thread, a checkpoint, a fresh
// world loaded from it and 90 more on 2 threads.
TEST(Scene3, CheckpointResumesBitIdenticallyOnOneOrTwoThreads) {
  const Scene s = load_scene(kPile3d, {"particles.n=300"});
  const auto make = [&] { return cdtest::parallel_world3(s); };
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  World3 a = make();
  for (int k = 0; k < 150; ++k) a.step();
  World3 b = make();
  for (int k = 0; k < 60; ++k) b.step();
  const fs::path d = cdtest::scratch_dir("test_scene3", "ckpt");
  const std::string f = (d / "checkpoint.bin").string();
  RunTotals t;
  t.sessions = 3;
  save_checkpoint3(f, b, 77, t);
  World3 c = make();
  RunTotals t2;
  EXPECT_EQ(load_checkpoint3(f, c, &t2), 77u);
  EXPECT_EQ(t2.sessions, 3.0);
  EXPECT_EQ(state_hash(c), state_hash(b));
  omp_set_num_threads(2);
  for (int k = 0; k < 90; ++k) c.step();
  omp_set_num_threads(saved);
  ASSERT_GT(a.rows().size(), 300u);  // the pile has landed: contacts and warm starts matter
  EXPECT_EQ(state_hash(c), state_hash(a));
  EXPECT_EQ(c.time, a.time);
  // Control: the hash sees the warm start (a resume without it differs).
  World3 e = make();
  load_checkpoint3(f, e);
  e.set_warm_start({});
  for (int k = 0; k < 90; ++k) e.step();
  EXPECT_NE(state_hash(e), state_hash(a));
}

// Killed and resumed through cdsim: --max-steps 35, then the same command
// finishes the run from its checkpoint (the second session on 2 threads);
// the final state and every series value but the wall-clock timers equal a
// run never stopped. (35 is on a series row: a stop between rows adds a row
// there, and the next row then covers the rest of its interval only; the
// state is identical either way, as the test above shows at step 60.)
TEST(Scene3, CdsimMaxStepsThenResumeIsBitIdentical) {
  const fs::path A = cdtest::scratch_dir("test_scene3", "straight");
  const fs::path B = cdtest::scratch_dir("test_scene3", "resumed");
  const std::string base = kCdsim + " " + kPile3d +
                           " --quiet --set particles.n=64 --set time.duration=0.1 --set "
                           "output.series_interval=0.005 --set output.snapshot_interval=0.02 "
                           "--set output.checkpoint_interval=0.02";
  auto r = cdtest::run_command(base + " --threads 1 --out " + A.string());
  ASSERT_EQ(r.code, 0) << r.out;
  r = cdtest::run_command(base + " --threads 1 --max-steps 35 --out " + B.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("stopped after --max-steps 35"), std::string::npos) << r.out;
  r = cdtest::run_command(base + " --threads 2 --out " + B.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  World3 wa = build_world3(load_scene(kPile3d, {"particles.n=64"}));
  World3 wb = wa;
  RunTotals ta, tb;
  EXPECT_EQ(load_checkpoint3((A / "checkpoint.bin").string(), wa, &ta),
            load_checkpoint3((B / "checkpoint.bin").string(), wb, &tb));
  EXPECT_EQ(wa.steps, 100);
  EXPECT_EQ(state_hash(wa), state_hash(wb));
  EXPECT_EQ(ta.sessions, 1.0);
  EXPECT_EQ(tb.sessions, 2.0);
  EXPECT_EQ(series_without_timers(A / "series.csv"), series_without_timers(B / "series.csv"));
  EXPECT_EQ(slurp(A / "spheres.pvd"), slurp(B / "spheres.pvd"));
  EXPECT_EQ(slurp(A / "spheres_00005.vtp"), slurp(B / "spheres_00005.vtp"));
}

// summary.toml counts the accelerations over every session. A pile with the
// subspace corrections and Anderson's mixing both on (both stall on some of
// its steps at its tol 1e-4): the CG iterations and the stalled steps that
// summary.toml reports are those of the same steps taken in the library, and
// the run split by --max-steps into two sessions reports them as the run in
// one. A resume from a checkpoint whose totals are the earlier build's nine
// (rewritten into the first session's checkpoint) counts them from the
// resume on: the whole run's minus the first session's.
TEST(Scene3, SummaryCountsTheAccelerationsOverSessions) {
  const std::vector<std::string> sets = {"particles.n=64", "time.duration=0.1", "solver.subspace=10",
                                         "solver.anderson=5"};
  std::string base = kCdsim + " " + kPile3d + " --quiet --threads 1 --set output.series_interval=0.005 "
                     "--set output.snapshot_interval=0 --set output.checkpoint_interval=0.02";
  for (const std::string& s : sets) base += " --set " + s;
  double cg = 0, anderson_off = 0, subspace_off = 0;
  World3 w = build_world3(load_scene(kPile3d, sets));
  for (int k = 0; k < 100; ++k) {
    w.step();
    cg += w.last().solve.subspace_iterations;
    anderson_off += w.last().solve.anderson_off > 0;
    subspace_off += w.last().solve.subspace_off > 0;
  }
  ASSERT_GT(cg, 0);
  ASSERT_GT(anderson_off, 0) << "no stall: the test sees no stall count";
  ASSERT_GT(subspace_off, 0) << "no stall: the test sees no stall count";

  const fs::path A = cdtest::scratch_dir("test_scene3", "accel_one");
  const fs::path B = cdtest::scratch_dir("test_scene3", "accel_two");
  const fs::path C = cdtest::scratch_dir("test_scene3", "accel_nine");
  auto r = cdtest::run_command(base + " --out " + A.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto a = cdtest::summary_fields(A / "summary.toml");
  EXPECT_EQ(std::stod(a.at("cg_iterations")), cg);
  EXPECT_DOUBLE_EQ(std::stod(a.at("cg_iterations_mean")), cg / 100);
  EXPECT_EQ(std::stod(a.at("anderson_off_steps")), anderson_off);
  EXPECT_EQ(std::stod(a.at("subspace_off_steps")), subspace_off);

  for (const fs::path& d : {B, C}) {
    r = cdtest::run_command(base + " --max-steps 40 --out " + d.string());
    ASSERT_EQ(r.code, 0) << r.out;
  }
  const auto c1 = cdtest::summary_fields(C / "summary.toml");
  const std::string ckpt = (C / "checkpoint.bin").string();
  RunTotals t;
  World3 x = build_world3(load_scene(kPile3d, sets));
  load_checkpoint3(ckpt, x, &t);
  const std::string nine = cdtest::with_totals(slurp(ckpt), cdtest::kTotals9,
                                               {t.wall, t.cpu, t.sweeps, t.sweeps_max, t.cap_steps,
                                                t.residual_max, t.residual_last, t.overlap_max, t.sessions});
  std::ofstream(ckpt, std::ios::binary) << nine;
  for (const fs::path& d : {B, C}) {
    r = cdtest::run_command(base + " --out " + d.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("resumed from"), std::string::npos) << r.out;
  }
  const auto b = cdtest::summary_fields(B / "summary.toml"), c = cdtest::summary_fields(C / "summary.toml");
  EXPECT_EQ(b.at("sessions"), "2");
  for (const char* k : {"steps", "sweeps_mean", "sweeps_max", "cg_iterations", "cg_iterations_mean",
                        "anderson_off_steps", "subspace_off_steps"})
    EXPECT_EQ(b.at(k), a.at(k)) << k;
  // The earlier build's totals carried on, the counts from the resume on.
  EXPECT_EQ(c.at("sessions"), "2");
  for (const char* k : {"steps", "sweeps_mean", "sweeps_max"}) EXPECT_EQ(c.at(k), a.at(k)) << k;
  for (const char* k : {"cg_iterations", "anderson_off_steps", "subspace_off_steps"})
    EXPECT_EQ(std::stod(c.at(k)), std::stod(a.at(k)) - std::stod(c1.at(k))) << k;
  EXPECT_GT(std::stod(c1.at("cg_iterations")), 0.0);
}

// A checkpoint of the other dimension is refused, naming both, before
// anything is written (exit 2; the folder's files are untouched).
TEST(Scene3, OtherDimensionsCheckpointIsRefused) {
  const fs::path d2 = cdtest::scratch_dir("test_scene3", "dim2");
  const std::string two = kCdsim + " " + CDLAB_SOURCE_DIR "/configs/default.toml --quiet --set particles.n=20 "
                          "--set time.duration=0.002 --set output.checkpoint_interval=0.001";
  const std::string three = kCdsim + " " + kPile3d + " --quiet --set particles.n=8 --set time.duration=0.002 "
                            "--set output.checkpoint_interval=0.001";
  auto r = cdtest::run_command(two + " --out " + d2.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string series = slurp(d2 / "series.csv");
  r = cdtest::run_command(three + " --out " + d2.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("holds a 2D run (dimension = 2); this scene has dimension = 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--fresh"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(d2 / "series.csv"), series);
  EXPECT_FALSE(fs::exists(d2 / "spheres.pvd"));

  const fs::path d3 = cdtest::scratch_dir("test_scene3", "dim3");
  r = cdtest::run_command(three + " --out " + d3.string());
  ASSERT_EQ(r.code, 0) << r.out;
  r = cdtest::run_command(two + " --out " + d3.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("holds a 3D run (dimension = 3); this scene has dimension = 2"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d3 / "particles.pvd"));
  // --fresh discards it.
  r = cdtest::run_command(two + " --fresh --out " + d3.string());
  EXPECT_EQ(r.code, 0) << r.out;
}

// Bad 3D input: exit 2, one message naming the key, nothing written.
TEST(Scene3, BadInputIsRefusedNamingTheKey) {
  const fs::path root = cdtest::scratch_dir("test_scene3", "bad");
  int i = 0;
  const auto refused = [&](const std::string& args, std::vector<std::string> words) {
    const fs::path out = root / std::to_string(i++);
    const auto r = cdtest::run_command(kCdsim + " " + kPile3d + " --quiet --out " + out.string() + " " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    for (const std::string& w : words) EXPECT_NE(r.out.find(w), std::string::npos) << args << "\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << args;
  };
  refused("--set 'gravity.g=[0,0,nan]'", {"gravity.g", "finite"});
  refused("--set 'gravity.g=[0,-9.81]'", {"gravity.g", "dimension = 3", "3 components"});
  refused("--set 'gravity.g=[0,0,0,1]'", {"gravity.g", "2 or 3 numbers"});
  refused("--set dimension=4", {"dimension = 4", "in [2, 3]"});
  refused("--set particles.d_mean=inf", {"particles.d_mean", "finite"});
  refused("--set particles.d_mean=-1", {"particles.d_mean", "> 0"});
  refused("--set particles.d_mean=1e200", {"particles.d_mean", "between 1e-100 and 1e+100"});
  refused("--set particles.density=0", {"particles.density", "> 0"});
  refused("--set contact.mu=-0.1", {"contact.mu"});
  refused("--set contact.alert=nan", {"contact.alert"});
  refused("--set time.dt=1e300", {"time.dt"});
  refused("--set time.duration=1e90", {"time.duration", "limit of 1000000000"});
  refused("--set contact.e_n=1.5", {"contact.e_n"});
  refused("--set contact.rotation=false", {"contact.rotation"});
  refused("--set box.height=0.1", {"box.height", "open at the top"});
  refused("--set box.width=0.1", {"box.width", "box.depth", "both 0"});
  refused("--set box.width=0.05 --set box.depth=0.2", {"box.width = 0.05", "needs >= 0.11"});
  refused("--set 'particles.nsides=[0,6]'", {"particles.nsides", "spheres"});
  refused("--set 'particles.region=[0,0,1,1]'", {"particles.region"});
  refused("--set shear.mode=\\\"periodic\\\"", {"gravity.g", "no floor"});
  refused("--set shear.mode=\\\"walls\\\"", {"shear.mode", "tri-periodic"});
  refused("--set particles.n=0", {"particles.n"});
  refused("--set 'contact.axis_a=[0,0,0]'", {"contact.axis_a", "non-zero"});
  refused("--set 'contact.axis_a=[1,0]'", {"contact.axis_a"});
  refused("--set 'contact.axis_a=[1,0,inf]'", {"contact.axis_a", "finite"});
}
