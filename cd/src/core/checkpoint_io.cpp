#include "checkpoint_io.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "files.hpp"

namespace cd {

namespace {

static_assert(std::endian::native == std::endian::little,
              "checkpoints store raw little-endian values");

constexpr std::string_view kMagic = "CDLABCKP";

// RunTotals' fields, in order: the name of its array, so that a build with
// other totals refuses the file by name.
constexpr const char* kTotalsNames[] = {"wall",          "cpu",           "sweeps",
                                        "sweeps_max",    "cap_steps",     "residual_max",
                                        "residual_last", "overlap_max",   "sessions",
                                        "cg_iterations", "anderson_off_steps", "subspace_off_steps",
                                        "floor_steps"};
static_assert(sizeof(RunTotals) == std::size(kTotalsNames) * sizeof(double),
              "a RunTotals field is missing from kTotalsNames (checkpoint_io.cpp)");
std::string totals_name() {
  std::string s = "totals";
  for (const char* n : kTotalsNames) s += std::string(":") + n;
  return s;
}

// The totals of earlier builds (same version 5), under the names those
// files hold, spelled out: RunTotals' first nine fields (before the
// accelerations' counts) and its first twelve (before floor_steps). Such a
// checkpoint resumes with the later fields at 0. The assertions keep each a
// prefix of kTotalsNames, in order, so that the values land in the fields
// they were.
struct OlderTotals {
  std::size_t n;
  std::string_view name;
};
constexpr OlderTotals kOlderTotals[] = {
    {9, "totals:wall:cpu:sweeps:sweeps_max:cap_steps:residual_max:residual_last:overlap_max:sessions"},
    {12, "totals:wall:cpu:sweeps:sweeps_max:cap_steps:residual_max:residual_last:overlap_max:sessions:"
         "cg_iterations:anderson_off_steps:subspace_off_steps"},
};
constexpr bool totals_begin_with(std::string_view name, std::size_t n) {
  if (!name.starts_with("totals")) return false;
  name.remove_prefix(6);
  for (std::size_t k = 0; k < n; ++k) {
    const std::string_view field = kTotalsNames[k];
    if (!name.starts_with(':') || !name.substr(1).starts_with(field)) return false;
    name.remove_prefix(1 + field.size());
  }
  return name.empty();
}
static_assert(totals_begin_with(kOlderTotals[0].name, kOlderTotals[0].n),
              "kTotalsNames must begin with the nine totals older checkpoints hold, in their order");
static_assert(totals_begin_with(kOlderTotals[1].name, kOlderTotals[1].n),
              "kTotalsNames must begin with the twelve totals older checkpoints hold, in their order");
static_assert(kOlderTotals[1].n < std::size(kTotalsNames), "an older build's totals are fewer than this one's");

// The name of the timers' array: the stage names, so that a checkpoint
// from a build with another stage table is refused by name.
std::string timers_name() {
  std::string s = "times";
  for (const char* n : kStageNames) s += std::string(":") + n;
  return s;
}

}  // namespace

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h) {
  for (const char c : bytes) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

namespace ckpt {

void begin(Writer& o, int dimension, std::uint64_t key, std::int64_t steps, double time,
           const StageTimes& times) {
  o.buf += kMagic;
  o.put(kVersion);
  o.put(static_cast<std::uint32_t>(dimension));
  o.put(key);
  o.put(steps);
  o.put(time);
  o.array(timers_name(), std::vector<double>(times.t.begin(), times.t.end()));
}

void finish(Writer& o, const RunTotals& totals, const std::string& path) {
  std::vector<double> t(std::size(kTotalsNames));
  std::memcpy(t.data(), &totals, sizeof totals);
  o.array(totals_name(), t);
  o.put(fnv1a(o.buf));
  write_file_atomic(path, o.buf);  // binary-safe: the string is written as is
}

Header open(const std::string& path, std::string& data, Reader& in, int dimension, bool resume) {
  {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      throw CheckpointError(fmt::format("checkpoint '{}' is a folder, not a checkpoint file (a run folder's is "
                                        "its checkpoint.bin)", path));
    std::ifstream f(path, std::ios::binary);
    std::ostringstream text;
    if (f) text << f.rdbuf();
    if (!f) throw CheckpointError(fmt::format("cannot read checkpoint '{}'", path));
    data = std::move(text).str();
  }
  in.rest = data;
  if (!kMagic.starts_with(in.rest.substr(0, kMagic.size()))) in.fail("is not a cdlab checkpoint");
  in.need(kMagic.size(), "the magic string");
  in.rest.remove_prefix(kMagic.size());
  Header h;
  h.version = in.get<std::uint32_t>("the version");
  if (h.version == kStartVersion && resume)
    in.fail(fmt::format("has format version {}, which holds no run totals (summary.toml); this "
                        "build resumes versions {} and {} only", h.version, kOldVersion, kVersion));
  if (h.version != kVersion && h.version != kOldVersion && h.version != kStartVersion)
    in.fail(fmt::format("has format version {}; this build reads version {}", h.version, kVersion));
  // The checksum first: a truncated or damaged file is named as such, not by
  // whichever field happens to look wrong.
  in.need(sizeof(std::uint64_t), "the header");
  std::uint64_t sum;
  std::memcpy(&sum, data.data() + data.size() - sizeof sum, sizeof sum);
  if (sum != fnv1a(std::string_view(data).substr(0, data.size() - sizeof sum)))
    in.fail("is truncated or corrupt (checksum mismatch)");
  in.rest.remove_suffix(sizeof sum);

  h.dimension = h.version >= 5 ? static_cast<int>(in.get<std::uint32_t>("the header")) : 2;
  if (h.dimension != dimension)
    in.fail(fmt::format("holds a {}D run (dimension = {}); this scene has dimension = {}",
                        h.dimension, h.dimension, dimension));
  h.key = in.get<std::uint64_t>("the header");
  h.steps = in.get<std::int64_t>("the header");
  h.time = in.get<double>("the header");
  if (h.steps < 0) in.fail(fmt::format("is corrupt: its step count 'steps' is {} (must be >= 0)", h.steps));
  if (!(std::isfinite(h.time) && h.time >= 0))
    in.fail(fmt::format("is corrupt: its 'time' is {} (must be finite and >= 0)", h.time));
  std::vector<double> t;
  in.array(timers_name(), t);
  if (t.size() != h.times.t.size())
    in.fail(fmt::format("is corrupt: 'times' holds {} stage timers, this build has {}", t.size(), h.times.t.size()));
  for (std::size_t s = 0; s < t.size(); ++s) in.non_negative("times", s, kStageNames[s], t[s]);
  std::copy(t.begin(), t.end(), h.times.t.begin());
  return h;
}

RunTotals close(Reader& in, const Header& h) {
  RunTotals tot;
  if (h.version >= 4) {
    // This build's totals, or those of an earlier build (kOlderTotals: the
    // nine written before the accelerations' counts, version 4 files too,
    // or the twelve written before floor_steps): the later fields then
    // start at 0 and cover the sessions from this resume on. Any other
    // totals are another build's: refused, as their sum could not go on.
    const std::string name = totals_name();
    const std::string_view stored = in.next_name("the run totals");
    std::size_t n = std::size(kTotalsNames);
    std::string_view read = name;
    for (const OlderTotals& o : kOlderTotals)
      if (stored == o.name) {
        n = o.n;
        read = o.name;
      }
    if (read == std::string_view(name) && stored != read && stored.starts_with("totals"))
      in.fail(fmt::format("holds run totals named '{}'; this build reads '{}' (or the first nine or twelve "
                          "of them, as written before the acceleration counts or before floor_steps): "
                          "written by another build?",
                          stored.substr(0, 300), name));
    std::vector<double> t;
    in.array(read, t);
    if (t.size() != n)
      in.fail(fmt::format("is corrupt: 'totals' holds {} run totals where its name lists {}", t.size(), n));
    for (std::size_t k = 0; k < t.size(); ++k) in.non_negative("totals", k, kTotalsNames[k], t[k]);
    std::memcpy(static_cast<void*>(&tot), t.data(), n * sizeof(double));
  }
  if (!in.rest.empty()) in.fail("has unexpected data after the last array");
  return tot;
}

}  // namespace ckpt

std::vector<std::string> truncate_series(const std::string& path, std::int64_t step) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream all;
  all << f.rdbuf();
  const std::string text = std::move(all).str();
  const auto fields = [](std::string_view l) { return std::count(l.begin(), l.end(), ',') + 1; };
  std::size_t at = text.find('\n');
  const std::string header = text.substr(0, at);
  std::string kept;
  std::int64_t last = 0;  // step of the last row kept
  // Whole rows only: a row ends in a newline and has the header's fields. A
  // row after the checkpoint, or one cut short by a kill or a full disk
  // (whose step may read small), ends what is kept: steps only grow.
  while (at != std::string::npos && at + 1 < text.size()) {
    const std::size_t end = text.find('\n', at + 1);
    if (end == std::string::npos) break;
    const std::string_view line = std::string_view(text).substr(at + 1, end - at - 1);
    std::int64_t k = -1;
    const auto [ptr, ec] = std::from_chars(line.data(), line.data() + line.size(), k);  // "step" first
    if (ec != std::errc() || *ptr != ',' || fields(line) != fields(header) || k <= last || k > step) break;
    kept.append(line).push_back('\n');
    last = k;
    at = end;
  }
  if (!header.starts_with("step,") || last != step)
    throw CheckpointError(fmt::format("'{}' does not reach the checkpoint's step {} with a whole row "
                                      "(its last whole row is step {})", path, step, last));
  std::vector<std::string> names;
  for (std::size_t a = 0, b; a <= header.size(); a = b + 1) {
    b = std::min(header.find(',', a), header.size());
    names.push_back(header.substr(a, b - a));
  }
  write_file_atomic(path, header + '\n' + kept);
  return names;
}

}  // namespace cd
