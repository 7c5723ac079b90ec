// What the 2D and 3D checkpoints share (2d/checkpoint.hpp, 3d/checkpoint3.hpp):
// the file's frame, its named arrays, the run's totals, the checksum, and the
// series cut back on a restart.
//
// File format (version 5), little-endian, no padding:
//   "CDLABCKP"                      8-byte magic
//   u32 version
//   u32 dimension                   2 or 3 (version 5; a version 3 or 4 file is 2D)
//   u64 scene key                   opaque to this file (run loop: hash of the scene)
//   i64 steps, f64 time
//   arrays, each: u32 name length, name, u64 count, u32 element size, raw elements
//     first the stage timers, one f64 per stage of core/stages.hpp, in an
//     array named "times:" + the stage names joined by ':' (a build with
//     other stages refuses the file); then the engine's arrays (its bodies,
//     warm start, ...); then the run's totals (one f64 per RunTotals field,
//     in an array named "totals:" + the field names joined by ':'; a file
//     whose totals hold the first nine fields only (written before the
//     accelerations' counts) or the first twelve (before floor_steps) is
//     read with the others at 0)
//   u64 FNV-1a of every byte before it
// A reader checks every size against the file and the checksum, and names the
// file in any error.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "stages.hpp"

namespace cd {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The cost of a run so far, carried by its checkpoint so that a resumed run's
// summary.toml (run loop) covers every session. Wall and CPU time count what
// was spent up to the checkpoint: the work a kill loses after it is not
// counted (the session that redoes it counts it).
struct RunTotals {
  double wall = 0;           // s of wall-clock time in the run loop, summed over sessions
  double cpu = 0;            // s of CPU time of the process (user + system) in the run loop
  double sweeps = 0;         // NLGS sweeps summed over the steps (exact below 2^53)
  double sweeps_max = 0;     // most sweeps of one step
  double cap_steps = 0;      // steps that stopped at solver.max_iter
  double residual_max = 0;   // largest law residual of any step
  double residual_last = 0;  // the last step's law residual
  double overlap_max = 0;    // largest overlap, in mean diameters
  double sessions = 0;       // cdsim calls that took steps of this run
  // The accelerations' cost and stalls (solver.subspace, solver.anderson;
  // 0 when off). A checkpoint written before they were counted holds the
  // nine fields above only: it resumes with these at 0, and they then count
  // the sessions since (checkpoint_io.cpp, ckpt::close).
  double cg_iterations = 0;       // conjugate-gradient iterations of the subspace corrections, all steps
  double anderson_off_steps = 0;  // steps whose Anderson mixing stalled and went off
  double subspace_off_steps = 0;  // steps whose subspace corrections stalled and stopped
  // Steps on which a pressure-driven length was held at its approach floor
  // by a load past it (StepStats::floor_held): the imposed pressure was not
  // fully applied on them. A checkpoint written before it was counted (the nine or the twelve
  // fields above) resumes with it at 0.
  double floor_steps = 0;
};

// 64-bit FNV-1a (the checksum; also used for the scene key).
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 1469598103934665603ull);

namespace ckpt {

inline constexpr std::uint32_t kVersion = 5;       // written, and resumed
inline constexpr std::uint32_t kOldVersion = 4;    // 2D without the dimension tag: resumed as 2D
inline constexpr std::uint32_t kStartVersion = 3;  // 2D: the oldest read as a start sample

// Elements are stored as their bytes; T must be a plain aggregate of
// numbers (Eigen's fixed vectors and quaternions are, though not "trivially
// copyable" by the standard's letter: their copies are byte copies).
struct Writer {
  std::string buf;

  template <class T>
  void put(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    buf.append(reinterpret_cast<const char*>(&x), sizeof(T));
  }
  template <class T>
  void array(std::string_view name, const std::vector<T>& v) {
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
    // An empty array: v.data() may be null, which memcpy may not be given
    // even for 0 bytes (UBSan, make test-sanitize).
    if (n > 0) std::memcpy(static_cast<void*>(v.data()), rest.data(), n * sizeof(T));
    rest.remove_prefix(n * sizeof(T));
  }
  // The name of the next array, left unread: for an array whose name
  // differs between builds that both read it (the run totals).
  std::string_view next_name(std::string_view what) const {
    Reader r = *this;
    const auto len = r.get<std::uint32_t>(what);
    r.need(len, what);
    return r.rest.substr(0, len);
  }

  // A checkpoint is input like a scene: a matching checksum only says the
  // file is as written, not that what was written is a state. The engines'
  // readers check every element with these, naming the array, the element
  // and the field, before the state is used.
  [[noreturn]] void bad(std::string_view array, std::size_t i, std::string_view field,
                        const std::string& why) const {
    fail(fmt::format("is corrupt: '{}' element {}{}{} {}", array, i, field.empty() ? "" : " ", field, why));
  }
  // Finite and at most kMaxMagnitude in magnitude, a scene number's bound
  // (docs/errors.md): a state the scene rules would refuse is refused from
  // a checkpoint too (an offset or a speed of 1e300 runs into overflow).
  static constexpr double kMaxMagnitude = 1e100, kMinPositive = 1e-100;
  void finite(std::string_view array, std::size_t i, std::string_view field, double x) const {
    if (!std::isfinite(x)) bad(array, i, field, fmt::format("is {} (must be finite)", x));
    if (!(std::abs(x) <= kMaxMagnitude))
      bad(array, i, field, fmt::format("is {:.17g} (at most 1e+100 in magnitude, as a scene's numbers)", x));
  }
  // Finite and >= 0 (if `positive`, at least kMinPositive: a size, mass or
  // inertia that small makes a grain of zero mass or infinite inverse).
  void non_negative(std::string_view array, std::size_t i, std::string_view field, double x,
                    bool positive = false) const {
    finite(array, i, field, x);
    if (positive ? !(x >= kMinPositive) : !(x >= 0))
      bad(array, i, field, fmt::format("is {:.6g} (must be {})", x, positive ? ">= 1e-100" : ">= 0"));
  }
  // A dynamic body's inverse mass (inertia) is 1 / its mass (inertia), as
  // the bodies are made: to round-off.
  void inverse(std::string_view array, std::size_t i, std::string_view field, double inv, double x,
               std::string_view of) const {
    if (!(std::abs(inv * x - 1.0) <= 1e-9))
      bad(array, i, field, fmt::format("is {:.17g}, but 1/{} is {:.17g} (it must be the inverse)", inv, of, 1.0 / x));
  }
};

struct Header {
  std::uint32_t version = kVersion;
  int dimension = 2;
  std::uint64_t key = 0;
  std::int64_t steps = 0;
  double time = 0;
  StageTimes times;
};

// The frame's start: magic, version, dimension, key, steps, time, timers.
void begin(Writer& o, int dimension, std::uint64_t key, std::int64_t steps, double time,
           const StageTimes& times);
// The frame's end: the totals, the checksum; then the file, written
// atomically (temporary file, then rename).
void finish(Writer& o, const RunTotals& totals, const std::string& path);

// Reads the whole file into `data` and its header, checking the magic, the
// version, the checksum and the dimension (a checkpoint of the other
// dimension is refused by name). `resume`: the file must hold run totals.
// Leaves `in` (over `data`) at the engine's arrays, without the checksum.
Header open(const std::string& path, std::string& data, Reader& in, int dimension, bool resume);
// After the engine's arrays: the run's totals (none in a version 3 file),
// then the end of the data.
RunTotals close(Reader& in, const Header& h);

// Calls f(name, b.*member) for every (name, member pointer) pair of the
// tuple `table`: the one list of a body container's arrays that the writer
// and the reader both walk (2d/checkpoint.cpp, 3d/checkpoint3.cpp), so a new
// member is one line there.
template <class Table, class B, class F>
void for_each_array(const Table& table, B& b, F&& f) {
  std::apply([&](const auto&... a) { (f(a.first, b.*(a.second)), ...); }, table);
}

// Every array of the table holds as many elements as the first. Returns the count.
template <class Table, class B>
std::size_t same_lengths(const Table& table, const B& b, const Reader& in) {
  const auto& first = std::get<0>(table);
  const std::size_t n = (b.*(first.second)).size();
  for_each_array(table, b, [&](std::string_view name, const auto& v) {
    if (v.size() != n)
      in.fail(fmt::format("is corrupt: '{}' holds {} elements, '{}' {}", name, v.size(), first.first, n));
  });
  return n;
}

// A resume reads into the world built from the scene (`expected` > 0 bodies):
// the file must hold as many. Checked last, after the checks that say more.
inline void check_count(const Reader& in, std::size_t n, std::size_t expected) {
  if (expected > 0 && n != expected)
    in.fail(fmt::format("holds {} bodies; this scene has {} (a damaged file, or another scene's)", n, expected));
}

// The warm-start memory: keys strictly increasing (it is searched by
// bisection), as many impulses as keys, every impulse component finite.
template <class P>
void check_warm(const Reader& in, std::string_view keys_name, const std::vector<std::uint64_t>& keys,
                std::string_view p_name, const std::vector<P>& p) {
  if (keys.size() != p.size())
    in.fail(fmt::format("is corrupt: '{}' holds {} elements, '{}' {}", p_name, p.size(), keys_name, keys.size()));
  for (std::size_t k = 1; k < keys.size(); ++k)
    if (!(keys[k - 1] < keys[k])) in.bad(keys_name, k, "", "is not greater than the one before (keys must increase)");
  static_assert(sizeof(P) % sizeof(double) == 0);
  for (std::size_t k = 0; k < p.size(); ++k)
    for (std::size_t c = 0; c < sizeof(P) / sizeof(double); ++c) {
      double x;
      std::memcpy(&x, reinterpret_cast<const char*>(&p[k]) + c * sizeof(double), sizeof x);
      in.finite(p_name, k, fmt::format("component {}", c), x);
    }
}

}  // namespace ckpt

// Cuts series.csv back to its header and the rows up to `step` (a killed run
// may have written rows after its last checkpoint) and returns the column
// names. Throws CheckpointError if the file does not reach `step`.
std::vector<std::string> truncate_series(const std::string& path, std::int64_t step);

}  // namespace cd
