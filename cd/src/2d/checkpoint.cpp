#include "checkpoint.hpp"

#include <bit>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <tuple>
#include <type_traits>

#include <fmt/format.h>

#include "config.hpp"
#include "output.hpp"

namespace cd {

namespace {

static_assert(std::endian::native == std::endian::little,
              "checkpoints store raw little-endian values");

constexpr std::string_view kMagic = "CDLABCKP";
// 2: the periodic cell; 3: the stage timers as a named array (world.hpp's
// stage table). A version 2 file is refused: its run's series.csv has the
// old timer columns, which the resumed rows could not continue. 4: the
// run's totals (RunTotals, for summary.toml). A version 3 file is refused for
// a resume (its run's cost would be lost), read as a start sample.
constexpr std::uint32_t kVersion = 4;
constexpr std::uint32_t kStartVersion = 3;  // the oldest read as a start sample

// RunTotals' fields, in order: the name of its array, so that a build with
// other totals refuses the file by name.
constexpr const char* kTotalsNames[] = {"wall",         "cpu",           "sweeps",
                                        "sweeps_max",   "cap_steps",     "residual_max",
                                        "residual_last", "overlap_max",  "sessions"};
static_assert(sizeof(RunTotals) == std::size(kTotalsNames) * sizeof(double),
              "a RunTotals field is missing from kTotalsNames (checkpoint.cpp)");
std::string totals_name() {
  std::string s = "totals";
  for (const char* n : kTotalsNames) s += std::string(":") + n;
  return s;
}

// The name of the timers' array: the stage names, so that a checkpoint
// from a build with another stage table is refused by name.
std::string timers_name() {
  std::string s = "times";
  for (const char* n : kStageNames) s += std::string(":") + n;
  return s;
}

// Every Bodies array, listed once: the writer and the reader both walk this
// list, so a new Bodies member is one line here.
constexpr std::tuple kBodiesArrays{
    std::pair{"vel", &Bodies::vel},
    std::pair{"pos", &Bodies::pos},
    std::pair{"angle", &Bodies::angle},
    std::pair{"shape", &Bodies::shape},
    std::pair{"radius", &Bodies::radius},
    std::pair{"nsides", &Bodies::nsides},
    std::pair{"mass", &Bodies::mass},
    std::pair{"inertia", &Bodies::inertia},
    std::pair{"driven", &Bodies::driven},
    std::pair{"force", &Bodies::force},
};
// Bodies holds only vectors, so a member left out of the list shows here.
static_assert(sizeof(Bodies) ==
                  std::tuple_size_v<decltype(kBodiesArrays)> * sizeof(std::vector<char>),
              "a Bodies member is missing from kBodiesArrays (checkpoint.cpp)");

template <class B, class F>
void for_each_array(B& b, F&& f) {
  std::apply([&](const auto&... a) { (f(a.first, b.*(a.second)), ...); }, kBodiesArrays);
}

// Elements are stored as their bytes. Vec2 and pair<double, double> are two
// plain doubles whose copy operations are user-declared (so not "trivially
// copyable") but equivalent to a byte copy.
template <class T>
constexpr bool kRaw = std::is_trivially_copyable_v<T> || std::is_same_v<T, Vec2> ||
                      std::is_same_v<T, std::pair<double, double>>;

struct Writer {
  std::string buf;

  template <class T>
  void put(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    buf.append(reinterpret_cast<const char*>(&x), sizeof(T));
  }
  template <class T>
  void array(std::string_view name, const std::vector<T>& v) {
    static_assert(kRaw<T>);
    put(static_cast<std::uint32_t>(name.size()));
    buf += name;
    put(static_cast<std::uint64_t>(v.size()));
    put(static_cast<std::uint32_t>(sizeof(T)));
    buf.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

struct Reader {
  const std::string& path;
  std::string_view rest;

  [[noreturn]] void fail(const std::string& why) const {
    throw CheckpointError(fmt::format("checkpoint '{}' {}", path, why));
  }
  void need(std::size_t n, std::string_view what) const {
    if (rest.size() < n) fail(fmt::format("is truncated (it ends inside {})", what));
  }
  template <class T>
  T get(std::string_view what) {
    need(sizeof(T), what);
    T x;
    std::memcpy(&x, rest.data(), sizeof(T));
    rest.remove_prefix(sizeof(T));
    return x;
  }
  template <class T>
  void array(std::string_view name, std::vector<T>& v) {
    static_assert(kRaw<T>);
    const auto len = get<std::uint32_t>(name);
    need(len, name);
    if (rest.substr(0, len) != name)
      fail(fmt::format("holds array '{}' where '{}' was expected (written by another build?)",
                       rest.substr(0, std::min<std::size_t>(len, 40)), name));
    rest.remove_prefix(len);
    const auto n = get<std::uint64_t>(name);
    const auto size = get<std::uint32_t>(name);
    if (size != sizeof(T))
      fail(fmt::format("stores '{}' with {}-byte elements, this build uses {} (written by "
                       "another build?)", name, size, sizeof(T)));
    if (n > rest.size() / sizeof(T)) fail(fmt::format("is truncated (it ends inside {})", name));
    v.resize(n);
    std::memcpy(static_cast<void*>(v.data()), rest.data(), n * sizeof(T));
    rest.remove_prefix(n * sizeof(T));
  }
};

}  // namespace

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h) {
  for (const char c : bytes) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

void save_checkpoint(const std::string& path, const World& w, std::uint64_t scene_key,
                     const RunTotals& totals) {
  Writer o;
  o.buf += kMagic;
  o.put(kVersion);
  o.put(scene_key);
  o.put(static_cast<std::int64_t>(w.steps));
  o.put(w.time);
  o.array(timers_name(), std::vector<double>(w.times.t.begin(), w.times.t.end()));
  for_each_array(w.bodies, [&](std::string_view name, const auto& v) { o.array(name, v); });
  o.array("warm.keys", w.warm_start().keys);
  o.array("warm.p", w.warm_start().p);
  o.array("cell", std::vector<CellState>{w.cell});
  std::vector<double> t(std::size(kTotalsNames));
  std::memcpy(t.data(), &totals, sizeof totals);
  o.array(totals_name(), t);
  o.put(fnv1a(o.buf));
  write_file_atomic(path, o.buf);  // binary-safe: the string is written as is
}

std::uint64_t load_checkpoint(const std::string& path, World& w, RunTotals* totals) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream text;
  if (f) text << f.rdbuf();
  if (!f) throw CheckpointError(fmt::format("cannot read checkpoint '{}'", path));
  const std::string data = std::move(text).str();

  Reader in{path, data};
  if (!kMagic.starts_with(in.rest.substr(0, kMagic.size()))) in.fail("is not a cdlab checkpoint");
  in.need(kMagic.size(), "the magic string");
  in.rest.remove_prefix(kMagic.size());
  const auto version = in.get<std::uint32_t>("the version");
  if (version == kStartVersion && totals)
    in.fail(fmt::format("has format version {}, which holds no run totals (summary.toml); this "
                        "build resumes version {} only", version, kVersion));
  if (version != kVersion && version != kStartVersion)
    in.fail(fmt::format("has format version {}; this build reads version {}", version, kVersion));
  // The checksum first: a truncated or damaged file is named as such, not by
  // whichever field happens to look wrong.
  in.need(sizeof(std::uint64_t), "the header");
  std::uint64_t sum;
  std::memcpy(&sum, data.data() + data.size() - sizeof sum, sizeof sum);
  if (sum != fnv1a(std::string_view(data).substr(0, data.size() - sizeof sum)))
    in.fail("is truncated or corrupt (checksum mismatch)");
  in.rest.remove_suffix(sizeof sum);

  const auto key = in.get<std::uint64_t>("the header");
  const auto steps = in.get<std::int64_t>("the header");
  const auto time = in.get<double>("the header");
  StageTimes times;
  {
    std::vector<double> t;
    in.array(timers_name(), t);
    if (t.size() != times.t.size()) in.fail("is corrupt (stage timers)");
    std::copy(t.begin(), t.end(), times.t.begin());
  }
  Bodies b;
  for_each_array(b, [&](std::string_view name, auto& v) { in.array(name, v); });
  World::WarmStart warm;
  in.array("warm.keys", warm.keys);
  in.array("warm.p", warm.p);
  if (warm.keys.size() != warm.p.size()) in.fail("is corrupt (warm-start sizes differ)");
  std::vector<CellState> cell;
  in.array("cell", cell);
  if (cell.size() != 1) in.fail("is corrupt (cell state)");
  RunTotals tot;
  if (version >= 4) {
    std::vector<double> t;
    in.array(totals_name(), t);
    if (t.size() != std::size(kTotalsNames)) in.fail("is corrupt (run totals)");
    std::memcpy(static_cast<void*>(&tot), t.data(), sizeof tot);
  }
  if (!in.rest.empty()) in.fail("has unexpected data after the last array");

  w.bodies = std::move(b);
  w.steps = steps;
  w.time = time;
  w.times = times;
  w.set_warm_start(std::move(warm));
  w.cell = cell[0];
  if (totals) *totals = tot;
  return key;
}

// ---------------------------------------------------------------------------
// Restarting a run

std::uint64_t scene_key(const Scene& scene) {
  Scene s = scene;
  s.source.clear();
  s.threads = 0;
  s.quiet = false;
  s.checkpoint_interval = 0;
  s.checkpoint_strain = 0;
  s.checkpoint_wall = 0;
  return fnv1a(resolved_toml(s));
}

std::vector<std::string> truncate_series(const std::string& path, std::int64_t step) {
  std::ifstream f(path, std::ios::binary);
  std::string header, line, kept;
  std::getline(f, header);
  std::int64_t last = 0;  // step of the last row kept
  while (std::getline(f, line)) {
    std::int64_t k = -1;
    std::from_chars(line.data(), line.data() + line.size(), k);  // "step" is the first column
    // Rows after the checkpoint, including one cut short by the kill (whose
    // step may read small): steps only grow.
    if (k <= last || k > step) break;
    kept += line + '\n';
    last = k;
  }
  if (!header.starts_with("step,") || last != step)
    throw CheckpointError(fmt::format("'{}' does not reach the checkpoint's step {}", path, step));
  std::vector<std::string> names;
  for (std::size_t a = 0, b; a <= header.size(); a = b + 1) {
    b = std::min(header.find(',', a), header.size());
    names.push_back(header.substr(a, b - a));
  }
  write_file_atomic(path, header + '\n' + kept);
  return names;
}

}  // namespace cd
