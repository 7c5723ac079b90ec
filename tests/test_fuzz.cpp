// Fuzzing the three tools' inputs: seeded, reproducible random
// mutations of valid inputs, each run as a user would run it. The contract:
//   cdsim:      exit 0 with every series value finite, or exit 2 (bad input)
//               or 3 (diverged) with a message, and no output folder written
//               for exit 2;
//   cdanalysis: exit 0, or 1/2 with a "cdanalysis:" message;
//   cdproblem:  exit 0/1, or 2 with a "cdproblem:" message;
// never a crash, an abort, a hang or a NaN written. A failing case prints
// its seed and input, so that it can be replayed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kBin = CDLAB_BINARY_DIR;
// Every case runs under a time limit: a hang is a failure, not a stuck suite.
const std::string kTimeout = "timeout -k 5 60 ";

// A scene as (section, key, value) lines, so that a mutation can change,
// drop or add one.
struct Line {
  std::string section, key, value;
};
using SceneLines = std::vector<Line>;

std::string text(const SceneLines& s) {
  std::string out, section;
  // Top-level keys first, then each section once, [[array]] entries as given.
  for (const Line& l : s)
    if (l.section.empty()) out += l.key + " = " + l.value + "\n";
  for (const Line& l : s) {
    if (l.section.empty()) continue;
    if (l.section.rfind("[[", 0) == 0) {
      out += l.section + "\n" + l.value + "\n";  // a whole array entry
      section.clear();
      continue;
    }
    if (l.section != section) out += "[" + (section = l.section) + "]\n";
    out += l.key + " = " + l.value + "\n";
  }
  return out;
}

// Three valid scenes: a box pile of polygons and disks, a periodic shear
// under pressure, a cohesive one.
std::vector<SceneLines> bases() {
  const SceneLines common = {{"", "name", "\"fuzz\""},
                             {"time", "dt", "1e-4"},
                             {"time", "duration", "2e-3"},
                             {"output", "series_interval", "5e-4"},
                             {"output", "snapshot_interval", "1e-3"},
                             {"output", "checkpoint_interval", "1e-3"},
                             {"contact", "mu", "0.4"},
                             {"solver", "tol", "1e-4"},
                             {"solver", "max_iter", "200"}};
  SceneLines pile = common;
  pile.insert(pile.end(), {{"gravity", "g", "[0.0, -9.81]"},
                           {"particles", "n", "40"},
                           {"particles", "d_mean", "1e-3"},
                           {"particles", "size_ratio", "1.5"},
                           {"particles", "nsides", "[0, 6]"},
                           {"box", "width", "0.012"},
                           {"box", "height", "0.02"},
                           {"[[disk]]", "", "pos = [0.006, 0.018]\nradius = 5e-4\nvel = [0.0, -0.1]"},
                           {"[[wall]]", "", "a = [0.0, 0.01]\nb = [0.004, 0.008]"}});
  SceneLines shear = common;
  shear.insert(shear.end(), {{"gravity", "g", "[0.0, 0.0]"},
                             {"particles", "n", "30"},
                             {"particles", "d_mean", "1e-3"},
                             {"particles", "size_ratio", "2.0"},
                             {"shear", "mode", "\"periodic\""},
                             {"shear", "width", "0.01"},
                             {"shear", "height", "0.01"},
                             {"shear", "pressure", "100.0"},
                             {"shear", "inertial_number", "0.05"},
                             {"shear", "dt_tp", "0.05"},
                             {"shear", "strain", "0.1"}});
  SceneLines cohesive = shear;
  cohesive.push_back({"contact", "cohesion_number", "5.0"});
  cohesive.push_back({"contact", "debond", "0.01"});
  return {pile, shear, cohesive};
}

// Values a mutation puts in: extreme, non-finite, wrong types.
const std::vector<std::string> kValues = {
    "0",    "-1",     "1",      "0.5",     "1e-300", "1e300",  "-1e300", "1e20",  "1e-20",
    "inf",  "-inf",   "nan",    "2147483648", "-2147483649", "3.5", "\"x\"", "\"\"", "true",
    "[]",   "[1.0]",  "[1, 2]", "[nan, 1]", "[1, 2, 3, 4]", "{ a = 1 }", "1979-05-27",
    // plausible values too, so that a fair share of the mutants run
    "0.01", "0.2", "2.0", "10", "100.0", "1e-3", "[0.0, 0.0]", "[0, 6]",
};
const std::vector<Line> kExtraKeys = {{"contact", "mu_wall", ""},  {"contact", "e_n", ""},
                                      {"contact", "adhesion", ""}, {"contact", "alert", ""},
                                      {"contact", "overlap_correction", ""},
                                      {"solver", "threads", ""},   {"shear", "cell_mass", ""},
                                      {"shear", "isotropic", ""},  {"shear", "start", ""},
                                      {"particles", "seed", ""},   {"particles", "region", ""},
                                      {"contact", "bogus", ""},    {"nosuchsection", "x", ""}};

SceneLines mutate(SceneLines s, std::mt19937_64& g, std::string& what) {
  const int n = g() % 3 == 0 ? 2 : 1;  // one mutation, or two
  for (int m = 0; m < n; ++m) {
    const auto pick = [&](std::size_t k) { return static_cast<std::size_t>(g() % k); };
    const std::size_t i = pick(s.size());
    switch (pick(4)) {
      case 0:  // drop a line
        what += "drop " + s[i].section + "." + s[i].key + "; ";
        s.erase(s.begin() + static_cast<long>(i));
        break;
      case 1: {  // add a key with a random value
        Line l = kExtraKeys[pick(kExtraKeys.size())];
        l.value = kValues[pick(kValues.size())];
        what += "add " + l.section + "." + l.key + " = " + l.value + "; ";
        s.push_back(l);
        break;
      }
      default:  // change a value (twice as likely)
        if (s[i].section.rfind("[[", 0) == 0) {
          // An array entry: replace the value of its first key.
          std::string& v = s[i].value;
          const auto eq = v.find('='), nl = v.find('\n');
          v = v.substr(0, eq + 2) + kValues[pick(kValues.size())] + v.substr(nl);
          what += "change " + s[i].section + " to " + v + "; ";
        } else {
          s[i].value = kValues[pick(kValues.size())];
          what += "set " + s[i].section + "." + s[i].key + " = " + s[i].value + "; ";
        }
    }
  }
  return s;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every data field of a CSV file is a finite number.
bool csv_finite(const fs::path& p, std::string& bad) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);  // header
  for (int row = 2; std::getline(in, line); ++row) {
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) {
      char* end = nullptr;
      const double v = std::strtod(f.c_str(), &end);
      if (*end != '\0' || !std::isfinite(v)) {
        bad = "row " + std::to_string(row) + ": '" + f + "'";
        return false;
      }
    }
  }
  return true;
}

}  // namespace

TEST(Fuzz, MutatedScenesRunCleanlyOrAreRefusedCleanly) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "scenes");
  const auto base = bases();
  const int cases = 240;
  int ran = 0, refused = 0, diverged = 0;
  for (int c = 0; c < cases; ++c) {
    std::mt19937_64 g(1000 + c);
    std::string what;
    const SceneLines s = mutate(base[c % base.size()], g, what);
    const std::string scene = text(s);
    const fs::path sc = dir / "s.toml", out = dir / "out";
    std::ofstream(sc) << scene;
    fs::remove_all(out);
    const cdtest::CmdResult r = cdtest::run_command(kTimeout + kBin + "/cd/cdsim " + sc.string() +
                                                    " --max-steps 8 -q --threads 1 --out " + out.string());
    const std::string id = "case " + std::to_string(c) + " (" + what + ")\n" + scene + "\n" + r.out;
    // summary.toml never holds inf or nan, whether the run ended or diverged.
    if (fs::exists(out / "summary.toml")) {
      const std::string sum = slurp(out / "summary.toml");
      EXPECT_EQ(sum.find(" = nan"), std::string::npos) << sum << id;
      EXPECT_EQ(sum.find("inf"), std::string::npos) << sum << id;
    }
    if (r.code == 0) {
      ++ran;
      std::string bad;
      ASSERT_TRUE(fs::exists(out / "series.csv")) << id;
      EXPECT_TRUE(csv_finite(out / "series.csv", bad)) << bad << "\n" << id;
    } else if (r.code == 2) {
      ++refused;
      EXPECT_NE(r.out.find("cdsim: "), std::string::npos) << id;
      EXPECT_FALSE(fs::exists(out)) << "a refused run wrote its folder: " << id;
    } else if (r.code == 3) {
      ++diverged;
      EXPECT_NE(r.out.find("run diverged"), std::string::npos) << id;
      if (fs::exists(out / "series.csv")) {
        std::string bad;
        EXPECT_TRUE(csv_finite(out / "series.csv", bad)) << bad << "\n" << id;
      }
    } else {
      ADD_FAILURE() << "exit " << r.code << " (crash, abort or time limit): " << id;
    }
  }
  std::printf("[ fuzz ] %d scenes: %d ran, %d refused, %d diverged\n", cases, ran, refused, diverged);
  // The mutations must exercise both paths, or the test tests nothing.
  EXPECT_GT(ran, cases / 20);
  EXPECT_GT(refused, cases / 4);
}

// A damaged checkpoint (bytes flipped, cut short, grown) is refused with
// exit 2 and the run's files left exactly as they were.
TEST(Fuzz, DamagedCheckpointsAreRefusedAndNothingIsLost) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "checkpoints");
  const std::string scene = text(bases()[1]);
  const fs::path sc = dir / "s.toml", out = dir / "out";
  std::ofstream(sc) << scene;
  const std::string cmd = kTimeout + kBin + "/cd/cdsim " + sc.string() + " -q --threads 1 --out " + out.string();
  ASSERT_EQ(cdtest::run_command(cmd + " --max-steps 20").code, 0);
  const std::string ckpt = slurp(out / "checkpoint.bin"), series = slurp(out / "series.csv");
  ASSERT_GT(ckpt.size(), 64u);
  int refused = 0;
  for (int c = 0; c < 60; ++c) {
    std::mt19937_64 g(2000 + c);
    std::string bad = ckpt, what;
    switch (c % 3) {
      case 0: {
        const int flips = 1 + static_cast<int>(g() % 4);
        for (int k = 0; k < flips; ++k) {
          const std::size_t at = g() % bad.size();
          bad[at] = static_cast<char>(bad[at] ^ (1 + g() % 255));
          what += "flip byte " + std::to_string(at) + "; ";
        }
        break;
      }
      case 1: {
        const std::size_t len = g() % bad.size();
        bad.resize(len);
        what = "cut to " + std::to_string(len) + " bytes";
        break;
      }
      default:
        bad += std::string(1 + g() % 64, static_cast<char>(g()));
        what = "grown";
    }
    std::ofstream(out / "checkpoint.bin", std::ios::binary) << bad;
    std::ofstream(out / "series.csv", std::ios::binary) << series;
    const cdtest::CmdResult r = cdtest::run_command(cmd + " --max-steps 1");
    const std::string id = "case " + std::to_string(c) + " (" + what + ")\n" + r.out;
    if (r.code == 2) {
      ++refused;
      EXPECT_NE(r.out.find("checkpoint"), std::string::npos) << id;
      EXPECT_EQ(slurp(out / "series.csv"), series) << "series.csv changed: " << id;
      EXPECT_EQ(slurp(out / "checkpoint.bin"), bad) << "checkpoint.bin changed: " << id;
    } else {
      // The checksum covers every byte: no damage may pass.
      ADD_FAILURE() << "exit " << r.code << ": " << id;
    }
  }
  std::printf("[ fuzz ] 60 damaged checkpoints: %d refused\n", refused);
  EXPECT_EQ(refused, 60);
}

namespace {

// A checkpoint's arrays (core/checkpoint_io.hpp's frame), parsed here
// independently of cdsim's reader, so that a mutation can change one field
// and recompute the checksum: the damage the checksum cannot see.
struct CkptArray {
  std::string name;
  std::size_t at;    // offset of the name length
  std::size_t data;  // offset of the first element
  std::uint64_t count;
  std::uint32_t size;
};
constexpr std::size_t kArraysAt = 40;  // magic, version, dimension, key, steps, time

template <class T>
T get_at(const std::string& b, std::size_t at) {
  T x;
  std::memcpy(&x, b.data() + at, sizeof x);
  return x;
}
template <class T>
void put_at(std::string& b, std::size_t at, T x) {
  std::memcpy(b.data() + at, &x, sizeof x);
}

std::vector<CkptArray> ckpt_arrays(const std::string& b) {
  std::vector<CkptArray> v;
  for (std::size_t at = kArraysAt; at + 8 < b.size();) {
    CkptArray a;
    a.at = at;
    const auto len = get_at<std::uint32_t>(b, at);
    a.name = b.substr(at + 4, len);
    a.count = get_at<std::uint64_t>(b, at + 4 + len);
    a.size = get_at<std::uint32_t>(b, at + 12 + len);
    a.data = at + 16 + len;
    at = a.data + a.count * a.size;
    v.push_back(a);
  }
  return v;
}

std::string with_checksum(std::string b) {
  b.resize(b.size() - 8);
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, as the file's
  for (const char c : b) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  b.append(reinterpret_cast<const char*>(&h), 8);
  return b;
}

// The field names a message must hold for a damaged element of `a`: the
// array's own name, or for the named lists ("times:predict:...",
// "totals:wall:..."), the list's name.
std::string shown_name(const CkptArray& a) { return a.name.substr(0, a.name.find(':')); }

// Which arrays hold doubles only (every 8-byte slot a number that must be
// finite); the others hold tags, counts or keys.
bool all_doubles(const std::string& name) {
  for (const char* n : {"shape", "nsides", "driven", "warm.keys"})
    if (name == n || name == std::string("3d.") + n) return false;
  for (const char* n : {"3d.poly.shapes", "3d.poly.shape_id", "3d.poly.memory.keys", "3d.poly.memory.axis",
                        "3d.poly.memory.feature", "3d.poly.vertex_count"})
    if (name == n) return false;
  return true;
}

struct Mutant {
  std::string what, bytes, field;  // field: what the message must name
};

// Systematic damage, each mutant's checksum recomputed: every array one
// element shorter and longer, emptied, a count beyond the file, another
// element size; every number of the first and last element NaN (and the
// first's +inf); negative sizes, masses and inertias; tags and sides out of
// range; the header's step count and time.
std::vector<Mutant> mutants(const std::string& good) {
  std::vector<Mutant> m;
  // The first grain (not driven): 2D lists the walls last, 3D the planes first.
  std::uint64_t grain = 0;
  for (const CkptArray& a : ckpt_arrays(good))
    if (a.name == "driven" || a.name == "3d.driven")
      while (grain + 1 < a.count && good[a.data + grain] != 0) ++grain;
  const auto add = [&](std::string what, std::string b, std::string field) {
    m.push_back({std::move(what), with_checksum(std::move(b)), std::move(field)});
  };
  bool poly = false;  // a checkpoint of polyhedra
  for (const CkptArray& a : ckpt_arrays(good)) poly |= a.name == "3d.poly.shapes";
  {
    std::string b = good;
    put_at<std::int64_t>(b, 24, -1);
    add("steps = -1", b, "steps");
    for (const double t : {std::nan(""), HUGE_VAL, -1.0}) {
      b = good;
      put_at<double>(b, 32, t);
      add("time = " + std::to_string(t), b, "time");
    }
  }
  for (const CkptArray& a : ckpt_arrays(good)) {
    const std::string f = shown_name(a);
    const std::size_t count_at = a.data - 12, size_at = a.data - 4;
    std::string b = good;
    put_at<std::uint64_t>(b, count_at, std::uint64_t(1) << 60);
    add(a.name + ": count 2^60", b, f);
    b = good;
    put_at<std::uint32_t>(b, size_at, a.size + 1);
    add(a.name + ": element size + 1", b, f);
    if (a.count > 0) {
      b = good;
      put_at<std::uint64_t>(b, count_at, a.count - 1);
      b.erase(a.data + (a.count - 1) * a.size, a.size);
      add(a.name + ": one element fewer", b, f);
      b = good;
      put_at<std::uint64_t>(b, count_at, a.count + 1);
      b.insert(a.data + a.count * a.size, good.substr(a.data + (a.count - 1) * a.size, a.size));
      add(a.name + ": last element twice", b, f);
      b = good;
      put_at<std::uint64_t>(b, count_at, 0);
      b.erase(a.data, a.count * a.size);
      add(a.name + ": emptied", b, f);
    }
    if (a.count == 0) continue;
    if (all_doubles(a.name)) {
      for (const std::uint64_t e : {std::uint64_t(0), a.count - 1})
        for (std::size_t slot = 0; slot < a.size / 8; ++slot)
          for (const double x : {std::nan(""), HUGE_VAL}) {
            if (std::isinf(x) && e != 0) continue;
            b = good;
            put_at<double>(b, a.data + e * a.size + slot * 8, x);
            add(a.name + "[" + std::to_string(e) + "] slot " + std::to_string(slot) + " = " + std::to_string(x), b, f);
          }
      // Absurd but finite: beyond a scene number's bound (1e100).
      for (std::size_t slot = 0; slot < a.size / 8; ++slot) {
        b = good;
        put_at<double>(b, a.data + slot * 8, 1e300);
        add(a.name + "[0] slot " + std::to_string(slot) + " = 1e300", b, f);
      }
    }
    const std::string base = a.name.substr(a.name.rfind('.') == 2 ? 3 : 0);  // without "3d."
    if (base == "radius") {  // every grain grown: values the rules pass, overlaps the file did not record
      b = good;
      for (std::uint64_t e = 0; e < a.count; ++e)
        put_at<double>(b, a.data + e * a.size, 1.5 * get_at<double>(good, a.data + e * a.size));
      // (a polyhedron's radius is its shape's circumradius: that check comes first)
      add(a.name + ": every radius x 1.5", b,
          poly ? a.name : a.name.substr(0, a.name.size() - base.size()) + "overlap");
    }
    if (poly && a.name == "3d.orient") {  // every body turned to the identity: valid, but not the recorded overlap
      b = good;
      for (std::uint64_t e = 0; e < a.count; ++e)
        for (int c = 0; c < 4; ++c) put_at<double>(b, a.data + e * a.size + 8 * c, c == 3 ? 1.0 : 0.0);
      add(a.name + ": every body at the identity orientation", b, "3d.overlap");
    }
    for (const std::uint64_t e : {std::uint64_t(0), a.count - 1}) {
      const std::size_t at = a.data + e * a.size;
      const std::string el = a.name + "[" + std::to_string(e) + "]";
      b = good;
      if (base == "radius" || base == "mass" || base == "inertia") {
        put_at<double>(b, at, -1.0);
        add(el + " = -1", b, f);
        if (e == 0) {  // a grain's size or mass that underflows
          b = good;
          put_at<double>(b, a.data + grain * a.size, 1e-300);
          add(a.name + "[" + std::to_string(grain) + "] = 1e-300", b, f);
        }
      } else if (base == "shape" || base == "driven") {
        b[at] = 7;
        add(el + " = 7", b, f);
      } else if (base == "nsides") {
        for (const std::int32_t n : {100000000, 2, -1}) {
          b = good;
          put_at<std::int32_t>(b, at, n);
          add(el + " = " + std::to_string(n), b, f);
        }
      } else if (base == "vel") {  // inv_m: after vx, vy, w (2D) or v, w (3D)
        put_at<double>(b, at + (a.size == 40 ? 24 : 48), -1.0);
        add(el + ".inv_m = -1", b, f);
        if (e == 0) {  // a grain's inverse mass that is not 1/mass
          b = good;
          const std::size_t inv = a.data + grain * a.size + (a.size == 40 ? 24 : 48);
          put_at<double>(b, inv, 2 * get_at<double>(good, inv));
          add(a.name + "[" + std::to_string(grain) + "].inv_m doubled", b, f);
        }
      } else if (base == "orient") {  // a quaternion of norm 2
        for (int c = 0; c < 4; ++c) put_at<double>(b, at + 8 * c, c == 3 ? 2.0 : 0.0);
        add(el + " of norm 2", b, f);
      }
    }
  }
  return m;
}

// Every file of a folder, by name, with its bytes.
std::map<std::string, std::string> folder(const fs::path& d) {
  std::map<std::string, std::string> f;
  for (const auto& e : fs::directory_iterator(d)) f[e.path().filename().string()] = slurp(e.path());
  return f;
}

void corrupt_systematically(const std::string& label, const std::string& cmd, const fs::path& out,
                            const std::vector<Mutant>& more = {}, bool systematic = true) {
  const std::string good = slurp(out / "checkpoint.bin");
  ASSERT_GT(good.size(), kArraysAt + 8);
  ASSERT_EQ(with_checksum(good), good) << "the test's parser does not know the file's frame";
  const std::vector<CkptArray> arrays = ckpt_arrays(good);
  ASSERT_GE(arrays.size(), 12u);
  // The warm start: spheres' impulses by key, or polyhedra's pair memory.
  bool warm = false;
  for (const CkptArray& a : arrays)
    warm |= (a.name.ends_with("warm.p") || a.name.ends_with("memory.p")) && a.count > 0;
  ASSERT_TRUE(warm) << "no contacts: warm start untested";
  const std::map<std::string, std::string> before = folder(out);
  std::vector<Mutant> ms = systematic ? mutants(good) : std::vector<Mutant>{};
  ms.insert(ms.end(), more.begin(), more.end());
  for (const Mutant& mu : ms) {
    std::ofstream(out / "checkpoint.bin", std::ios::binary) << mu.bytes;
    const cdtest::CmdResult r = cdtest::run_command(cmd + " --max-steps 1");
    const std::string id = label + ": " + mu.what + "\n" + r.out;
    EXPECT_EQ(r.code, 2) << id;
    EXPECT_NE(r.out.find("checkpoint"), std::string::npos) << id;
    EXPECT_NE(r.out.find(mu.field), std::string::npos) << "the field is not named: " << id;
    std::map<std::string, std::string> after = folder(out);
    EXPECT_EQ(after["checkpoint.bin"], mu.bytes) << id;
    after["checkpoint.bin"] = good;
    EXPECT_TRUE(after == before) << "a refused resume wrote into the folder: " << id;
    std::ofstream(out / "checkpoint.bin", std::ios::binary) << good;
  }
  std::printf("[ fuzz ] %s: %zu systematically damaged checkpoints (checksum recomputed), all refused\n",
              label.c_str(), ms.size());
}

}  // namespace

// A checkpoint whose checksum matches is still input: every array length,
// every number, every tag is checked before the state is used.
TEST(Fuzz, CheckpointsWithAValidChecksumAreStillValidated2D) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "systematic2d");
  SceneLines pile = bases()[0];
  for (Line& l : pile) {
    if (l.key == "g") l.value = "[0.0, -2000.0]";  // so that grains touch within 20 steps
    if (l.key == "n") l.value = "16\nregion = [0.0, 0.0, 0.012, 0.004]";
  }
  std::ofstream(dir / "s.toml") << text(pile);
  const std::string cmd = kTimeout + kBin + "/cd/cdsim " + (dir / "s.toml").string() + " -q --threads 1 --out " +
                          (dir / "out").string();
  ASSERT_EQ(cdtest::run_command(cmd + " --max-steps 20").code, 0);
  corrupt_systematically("2D pile", cmd, dir / "out");
}

// 50 g, so that grains touch within 20 steps (11 contacts bear force at
// step 20) with overlaps of 10^-4 d; at 200 g they fall 8 d a step by step 4
// and sink 0.66 d into each other, a diverged run (exit 3).
TEST(Fuzz, CheckpointsWithAValidChecksumAreStillValidated3D) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "systematic3d");
  const std::string cmd = kTimeout + kBin + "/cd/cdsim " + CDLAB_SOURCE_DIR "/configs/pile3d.toml" +
                          " -q --threads 1 --set particles.n=8 --set time.duration=0.04 --set gravity.g=[0,0,-500]"
                          " --set output.series_interval=0.002 --set output.checkpoint_interval=0.01 --out " +
                          (dir / "out").string();
  ASSERT_EQ(cdtest::run_command(cmd + " --max-steps 20").code, 0);
  corrupt_systematically("3D pile", cmd, dir / "out");
}

// Polyhedra add their arrays (shape ids, moments, pair memory, the shapes'
// vertices) and an overlap measured through the narrow phase: 8 cubes
// resting in the pile's box.
TEST(Fuzz, CheckpointsWithAValidChecksumAreStillValidatedPolyhedra) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "systematic_poly");
  const std::string cmd = kTimeout + kBin + "/cd/cdsim " + CDLAB_SOURCE_DIR "/configs/pile-polyhedra.toml" +
                          " -q --threads 1 --set particles.n=8 --set time.duration=0.04 --set gravity.g=[0,0,-500]"
                          " --set output.series_interval=0.002 --set output.checkpoint_interval=0.01 --out " +
                          (dir / "out").string();
  ASSERT_EQ(cdtest::run_command(cmd + " --max-steps 20").code, 0);
  corrupt_systematically("3D polyhedra pile", cmd, dir / "out");
}

// A periodic cell's state against its grains: lengths the detection cannot
// grid, a Lees-Edwards offset outside the width (1e20 ran into a crash in
// the 3D detection), a grain outside the periodic lengths. Each is a state
// no run leaves; refused by name, nothing written.
std::vector<Mutant> cell_mutants(const std::string& good, const std::string& cell, std::size_t x_at,
                                 std::size_t offset_at, const std::string& pos, const std::string& cell_field) {
  std::vector<Mutant> m;
  CkptArray c{}, p{};
  for (const CkptArray& a : ckpt_arrays(good)) {
    if (a.name == cell) c = a;
    if (a.name == pos) p = a;
  }
  if (c.name.empty() || p.name.empty()) return m;
  const double L = get_at<double>(good, c.data + x_at);
  const auto add = [&](std::string what, std::size_t at, double v, std::string field) {
    std::string b = good;
    put_at<double>(b, at, v);
    m.push_back({std::move(what), with_checksum(std::move(b)), std::move(field)});
  };
  add("cell width 0", c.data + x_at, 0.0, cell_field);
  add("cell width 1e-6 of itself", c.data + x_at, 1e-6 * L, cell_field);
  add("offset 1e20", c.data + offset_at, 1e20, "offset");
  add("offset -1", c.data + offset_at, -1.0, "offset");
  add("offset 2 L_x", c.data + offset_at, 2 * L, "offset");
  add("a grain at x = 3 L_x", p.data, 3 * L, pos);
  return m;
}

TEST(Fuzz, CheckpointedCellsAreCheckedAgainstTheirGrains) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "cells");
  // A short Lees-Edwards run's checkpoint, then each cell mutant of it.
  const auto check = [&](const std::string& name, const std::string& scene, const std::string& pressure,
                         const std::string& cell, std::size_t offset_at, const std::string& pos,
                         const std::string& width_field) {
    std::ofstream(dir / (name + ".toml")) << scene << "[particles]\nn = 30\n[shear]\nmode = \"periodic\"\npressure = "
                                         << pressure << "\ninertial_number = 0.1\nstrain = 0.5\ndt_tp = 0.05\n"
                                         << "[output]\ncheckpoint_interval = 1e-4\n";
    const std::string cmd = kTimeout + kBin + "/cd/cdsim " + (dir / (name + ".toml")).string() +
                            " -q --threads 1 --out " + (dir / name).string();
    ASSERT_EQ(cdtest::run_command(cmd + " --max-steps 20").code, 0);
    const std::vector<Mutant> more = cell_mutants(slurp(dir / name / "checkpoint.bin"), cell, 0, offset_at, pos,
                                                  width_field);
    ASSERT_EQ(more.size(), 6u);
    corrupt_systematically(name, cmd, dir / name, more, false);
  };
  // 2D: CellState {width, height, offset, ...}; 3D: "3d.cell" {L_x, L_y, L_z, offset, ...}.
  check("le2d", "name = \"s\"\n[gravity]\ng = [0.0, 0.0]\n", "100.0", "cell", 16, "pos", "width");
  check("le3d", "name = \"s\"\ndimension = 3\n[gravity]\ng = [0.0, 0.0, 0.0]\n", "1e5", "3d.cell", 24, "3d.pos", "3d.cell");
}

// cdanalysis on damaged series and snapshots; cdproblem on damaged problems.
TEST(Fuzz, DamagedAnalysisInputsAndProblemsAreRefusedCleanly) {
  const fs::path dir = cdtest::scratch_dir("fuzz", "analysis");
  // A pile with a series row every step (300 rows), and a dumped shear step.
  SceneLines pile = bases()[0];
  for (Line& l : pile) {
    if (l.key == "duration") l.value = "0.03";
    if (l.key == "series_interval") l.value = "1e-4";
  }
  std::ofstream(dir / "pile.toml") << text(pile);
  std::ofstream(dir / "shear.toml") << text(bases()[1]);
  const fs::path run = dir / "run";
  const std::string cdsim = kTimeout + kBin + "/cd/cdsim ";
  ASSERT_EQ(cdtest::run_command(cdsim + (dir / "pile.toml").string() + " -q --threads 1 --out " + run.string()).code, 0);
  ASSERT_EQ(cdtest::run_command(cdsim + (dir / "shear.toml").string() + " -q --threads 1 --out " +
                                (dir / "shear").string() + " --dump-problem 3 --max-steps 5")
                .code,
            0);
  const std::string series = slurp(run / "series.csv"), cdp = slurp(dir / "shear" / "problem_3.cdp");
  ASSERT_FALSE(series.empty());
  ASSERT_FALSE(cdp.empty());
  // The undamaged series is analysed.
  ASSERT_EQ(cdtest::run_command(kBin + "/analysis/cdanalysis steady " + run.string() +
                                " --column kinetic_energy --window 0.01:0.03").code, 0);
  // Tokens a mutation writes over a field or a token.
  const std::vector<std::string> junk = {"nan", "inf", "-inf", "x", "", "1e999", "-1", "0", "1e300", "0x1p-1074"};
  const auto mutate_text = [&](std::string t, std::mt19937_64& g, const std::string& seps) {
    // Replace one token (between separators) with junk, or cut the text.
    if (g() % 4 == 0) return t.substr(0, g() % t.size());
    std::vector<std::size_t> starts = {0};
    for (std::size_t k = 0; k < t.size(); ++k)
      if (seps.find(t[k]) != std::string::npos) starts.push_back(k + 1);
    const std::size_t b = starts[g() % starts.size()];
    std::size_t e = b;
    while (e < t.size() && seps.find(t[e]) == std::string::npos) ++e;
    return t.substr(0, b) + junk[g() % junk.size()] + t.substr(e);
  };
  int analysed = 0, problems = 0;
  for (int c = 0; c < 60; ++c) {
    std::mt19937_64 g(3000 + c);
    const std::string bad = mutate_text(series, g, ",\n");
    std::ofstream(run / "series.csv", std::ios::binary) << bad;
    const cdtest::CmdResult r = cdtest::run_command(kTimeout + kBin + "/analysis/cdanalysis steady " +
                                                    run.string() + " --column kinetic_energy --window 0.01:0.03");
    const std::string id = "series case " + std::to_string(c) + "\n" + r.out;
    if (r.code == 0) {
      ++analysed;
      EXPECT_EQ(r.out.find("nan"), std::string::npos) << id;
    } else if (r.code == 1 || r.code == 2) {
      EXPECT_NE(r.out.find("cdanalysis: "), std::string::npos) << id;
    } else {
      ADD_FAILURE() << "exit " << r.code << ": " << id;
    }
  }
  for (int c = 0; c < 60; ++c) {
    std::mt19937_64 g(4000 + c);
    std::ofstream(dir / "p.cdp", std::ios::binary) << mutate_text(cdp, g, " \n");
    const cdtest::CmdResult r =
        cdtest::run_command(kTimeout + kBin + "/cd/cdproblem solve " + (dir / "p.cdp").string());
    const std::string id = "problem case " + std::to_string(c) + "\n" + r.out;
    if (r.code == 0 || r.code == 1) {
      ++problems;
      EXPECT_EQ(r.out.find("nan"), std::string::npos) << id;
    } else if (r.code == 2) {
      EXPECT_NE(r.out.find("cdproblem: "), std::string::npos) << id;
    } else {
      ADD_FAILURE() << "exit " << r.code << ": " << id;
    }
  }
  std::printf("[ fuzz ] 60 damaged series (%d analysed), 60 damaged problems (%d solved)\n", analysed,
              problems);
}
