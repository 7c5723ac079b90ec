// cdanalysis on polyhedra runs (docs/analysis.md, "3D runs"): a polyhedra
// pair is one contact of 1 to 4 rows (its points) that share the pair's
// normal and branch, so
// - the fabric counts each pair once with its whole force: contacts drawn
//   from the harmonic forms, each split into the points of its kind with
//   random shares of its force, give the anisotropies of the unsplit set
//   to round-off (the rows taken one by one would not), and the kinds'
//   shares and the face-face part of q/p summed here by hand;
// - on a real run of cubes compacted in the tri-periodic cell, each
//   snapshot's stress, p and z are the series' of that step, the physical
//   contacts are the bearing pairs counted here by hand, and face-face
//   contacts are there.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <set>

#include "analysis/src/fabric3.hpp"
#include "analysis/src/run.hpp"
#include "analysis/src/snapshot.hpp"
#include "cli_util.hpp"
#include "run3.hpp"
#include "setup3.hpp"
#include "shear3_util.hpp"
#include "world3.hpp"

namespace fs = std::filesystem;
using namespace cda;

namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// Contacts from the forms P(n) ~ 1 + a_c (3 cos^2 - 1), f_n = 1 + a_n (3
// cos^2 - 1) times a random factor, f_t = a_t sin 2 theta towards the axis
// plus noise, about the axis (1, 1, 0)/sqrt 2: a sheared-like fabric. A
// pair is face-face (3) with probability cos^2 theta, else its kind cycles
// through 2, 1, 4: the kinds' directions differ, as in a sheared packing.
ContactSet3 pairs(std::size_t N, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> G(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  const V3 e = V3(1, 1, 0).normalized();
  const double ac = 0.2, an = 0.3, at = 0.1;
  ContactSet3 cs;
  while (cs.size() < N) {
    V3 n(G(g), G(g), G(g));
    n.normalize();
    const double c = n.dot(e);
    if (U(g) * (1 + 2 * ac) > 1 + ac * (3 * c * c - 1)) continue;
    V3 ft = at * 2 * c * (e - c * n);  // |.| = a_t sin 2 theta, towards e
    V3 r(G(g), G(g), G(g));
    ft += 0.05 * (r - r.dot(n) * n);
    Contact3 k;
    k.c.b1 = static_cast<int>(2 * cs.size());
    k.c.b2 = k.c.b1 + 1;
    k.c.fn = (1 + an * (3 * c * c - 1)) * (0.5 + U(g));
    for (int a = 0; a < 3; ++a) {
      k.c.n[a] = n[a];
      k.c.ft[a] = ft[a];
      k.c.l[a] = 1e-3 * (1 + 0.2 * U(g)) * n[a] + 2e-4 * r[a];  // not along n: a polyhedron's branch
    }
    k.status = U(g) < 0.3 ? 2 : 1;
    static constexpr int cycle[3] = {2, 1, 4};
    k.kind = U(g) < c * c ? 3 : cycle[cs.size() % 3];
    cs.push_back(k);
  }
  return cs;
}

// Each contact as the rows of its kind's points (4 face-face, 2 edge-face,
// 1 otherwise), each with a random positive share of the force; only the
// first point carries the status flag of a sliding contact.
ContactSet3 split(const ContactSet3& cs, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.1, 1);
  ContactSet3 rows;
  for (const auto& k : cs) {
    const int m = k.kind == 3 ? 4 : k.kind == 2 ? 2 : 1;
    std::vector<double> w(static_cast<std::size_t>(m));
    double sum = 0;
    for (auto& x : w) sum += x = U(g);
    for (int j = 0; j < m; ++j) {
      Contact3 p = k;
      const double s = w[static_cast<std::size_t>(j)] / sum;
      p.c.fn = k.c.fn * s;
      for (int a = 0; a < 3; ++a) p.c.ft[a] = k.c.ft[a] * s;
      if (j > 0) p.status = 1;
      rows.push_back(p);
    }
  }
  return rows;
}

void write_run(const fs::path& dir, const ContactSet3& rows) {
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << "dimension = 3\n";
  ParticleSet none;
  write_contacts3((dir / "contacts_00000.vtp").string(), rows, none);
}

}  // namespace

TEST(AnalysisPolyhedra, PointsOfAPairAreOneContactWithTheWholeForce) {
  const ContactSet3 whole = pairs(40000, 5);
  const ContactSet3 rows = split(whole, 6);
  ASSERT_GT(rows.size(), 1.8 * whole.size());
  const auto dir = cdtest::scratch_dir("test_analysis_polyhedra", "split");
  write_run(dir, rows);
  const double V = 2.0;
  const RunFabric3 f = run_fabric3(dir.string(), 0, V, 0.4, 1e-4);

  EXPECT_EQ(f.contacts, rows.size());
  EXPECT_EQ(f.physical_contacts, whole.size());
  ASSERT_TRUE(f.polyhedra);
  std::array<std::size_t, kKinds3> count{};
  for (const auto& k : whole) ++count[static_cast<std::size_t>(k.kind)];
  for (const Kind3 k : {Kind3::FaceFace, Kind3::EdgeFace, Kind3::VertexFace, Kind3::EdgeEdge})
    EXPECT_EQ(f.kind_share(k), static_cast<double>(count[static_cast<std::size_t>(k)]) / 40000.0)
        << kind3_name(static_cast<int>(k));
  EXPECT_EQ(f.by_kind[0], 0u);

  // The anisotropies are the unsplit contacts', to round-off; the rows one
  // by one give others (the test's power: a_n moves by far more than 1e-9).
  ASSERT_TRUE(f.aniso);
  const Anisotropy3 ref = anisotropy3(whole), by_rows = anisotropy3(rows);
  for (const auto& [got, want, rowwise, what] :
       {std::tuple{f.aniso->a_c(), ref.a_c(), by_rows.a_c(), "a_c"}, {f.aniso->a_n(), ref.a_n(), by_rows.a_n(), "a_n"},
        {f.aniso->a_t(), ref.a_t(), by_rows.a_t(), "a_t"}}) {
    EXPECT_NEAR(got, want, 1e-9) << what;
    std::printf("%s: pairs %.4f, rows one by one %.4f\n", what, want, rowwise);
  }
  EXPECT_GT(by_rows.a_c() - ref.a_c(), 0.05);  // the face-face directions counted 4 times
  // The forms' own values, to sampling error (40000 contacts: ~0.01).
  EXPECT_NEAR(f.aniso->a_c(), 0.2, 0.03);
  EXPECT_NEAR(f.aniso->a_n(), 0.3, 0.03);

  // Sliding: a pair slides when one of its points does (the unsplit flags).
  std::size_t slide = 0;
  for (const auto& k : whole) slide += k.status == 2;
  EXPECT_EQ(f.sliding, static_cast<double>(slide) / static_cast<double>(whole.size()));

  // Stress: (1/V) sum f (x) l over the unsplit contacts, by hand, and its
  // face-face part projected on the whole stress's principal axes.
  M3 s = M3::Zero(), s_ff = M3::Zero();
  for (const auto& k : whole) {
    const V3 n(k.c.n[0], k.c.n[1], k.c.n[2]), ft(k.c.ft[0], k.c.ft[1], k.c.ft[2]), l(k.c.l[0], k.c.l[1], k.c.l[2]);
    const M3 d = (k.c.fn * n + ft) * l.transpose() / V;
    s += d;
    if (k.kind == 3) s_ff += d;
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(f.stress.s[i][j], s(i, j), 1e-12 * s.norm());
      EXPECT_NEAR(f.stress_face_face.s[i][j] + f.stress_other.s[i][j], s(i, j), 1e-12 * s.norm());
    }
  const Eigen::SelfAdjointEigenSolver<M3> es(0.5 * (s + s.transpose()));
  const V3 e1 = es.eigenvectors().col(2), e3 = es.eigenvectors().col(0);
  const double p = s.trace() / 3;
  const double qp_ff = (e1.dot(s_ff * e1) - e3.dot(s_ff * e3)) / 3 / p;
  EXPECT_NEAR(f.q_over_p_face_face(), qp_ff, 1e-9);
  EXPECT_GT(f.q_over_p_face_face(), 0.3 * f.stress.q_over_p());  // not vanishing: the check has power

  // The face-face contacts' anisotropies are those of the unsplit ones.
  ContactSet3 ff;
  for (const auto& k : whole)
    if (k.kind == 3) ff.push_back(k);
  ASSERT_TRUE(f.aniso_face_face);
  EXPECT_NEAR(f.aniso_face_face->a_n(), anisotropy3(ff).a_n(), 1e-9);
  ASSERT_TRUE(f.aniso_other);
}

TEST(AnalysisPolyhedra, SpheresAreNotMergedAndHaveNoKinds) {
  ContactSet3 whole = pairs(2000, 7);
  for (auto& k : whole) k.kind = 0;
  const auto dir = cdtest::scratch_dir("test_analysis_polyhedra", "spheres");
  write_run(dir, whole);
  const RunFabric3 f = run_fabric3(dir.string(), 0, 1.0);
  EXPECT_EQ(f.physical_contacts, whole.size());
  EXPECT_FALSE(f.polyhedra);
  EXPECT_TRUE(std::isnan(f.kind_share(Kind3::FaceFace)));
  EXPECT_TRUE(std::isnan(f.q_over_p_face_face()));
  EXPECT_EQ(f.aniso->a_n(), anisotropy3(whole).a_n());
}

TEST(AnalysisPolyhedra, AKindOutOfRangeIsRefusedByName) {
  ContactSet3 rows = pairs(10, 8);
  rows[3].kind = 7;
  const auto dir = cdtest::scratch_dir("test_analysis_polyhedra", "badkind");
  write_run(dir, rows);
  try {
    read_contacts3((dir / "contacts_00000.vtp").string());
    ADD_FAILURE() << "kind 7 was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contact cell 3 has kind 7"), std::string::npos) << e.what();
  }
}

// 80 cubes compacted isotropically in the tri-periodic cell (the campaign's
// preparation), snapshots every 10 steps: each snapshot with force-bearing
// contacts against the series row of its step.
TEST(AnalysisPolyhedra, SnapshotMatchesTheSeriesOfARealRunOfCubes) {
  cd::Scene sc = cdtest::shear3_prep_scene(80);
  sc.shape = {cd::Shape3d::Cube};
  cd::World3 w = cd::build_world3(sc);
  const double dt = w.params().dt;
  sc.duration = 200 * dt;
  sc.series_interval = dt;
  sc.snapshot_interval = 10 * dt;
  const auto dir = cdtest::scratch_dir("test_analysis_polyhedra", "cubes");
  cd::RunOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  opt.fresh = true;
  cd::run3(w, sc, opt);
  std::ofstream(dir / "scene.toml") << "dimension = 3\n";
  const auto series = read_series(dir.string());
  const auto& time = series.column("time");
  const auto st = snapshot_times(dir.string(), "contacts");
  std::size_t snaps = 0, face_face = 0, merged_rows = 0;
  for (std::size_t k = 0; k < st.size(); ++k) {
    ASSERT_TRUE(st[k]);
    const auto rows = read_contacts3(snapshot_path(dir.string(), "contacts", static_cast<int>(k)));
    const auto forces = as_forces(rows);
    const double f_eps = cd::obs::force_threshold<3>(forces);
    std::set<std::pair<int, int>> bearing;  // by hand: pairs with a bearing row
    for (const auto& c : forces)
      if (std::abs(c.fn) + c.ft_norm() > f_eps) bearing.insert({std::min(c.b1, c.b2), std::max(c.b1, c.b2)});
    if (bearing.empty()) continue;
    std::size_t row = time.size();
    for (std::size_t r = 0; r < time.size(); ++r)
      if (std::abs(time[r] - *st[k]) < 0.5 * dt) row = r;
    ASSERT_LT(row, time.size());
    const double V = series.column("cell_width")[row] * series.column("cell_height")[row] *
                     series.column("cell_depth")[row];
    const RunFabric3 f = run_fabric3(dir.string(), static_cast<int>(k), V);
    EXPECT_EQ(f.physical_contacts, bearing.size());
    const double scale = std::abs(series.column("p")[row]);
    EXPECT_NEAR(f.stress.p(), series.column("p")[row], 1e-6 * scale);
    EXPECT_NEAR(f.stress.q_vm(), series.column("q")[row], 1e-6 * scale);
    ASSERT_TRUE(f.connectivity);
    EXPECT_NEAR(f.connectivity->z, series.column("z")[row], 1e-6);
    face_face += f.by_kind[static_cast<std::size_t>(Kind3::FaceFace)];
    merged_rows += f.contacts - f.physical_contacts;
    ++snaps;
  }
  std::printf("%zu snapshots, %zu face-face contacts, %zu rows merged into their pairs\n", snaps, face_face,
              merged_rows);
  EXPECT_GE(snaps, 5u);
  EXPECT_GT(face_face, 0u) << "no face-face contact: the test checks no merging";
  EXPECT_GT(merged_rows, 0u);
}
