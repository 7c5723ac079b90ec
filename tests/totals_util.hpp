// Checkpoints as another build writes them, for the resume tests: the run
// totals' array (the last before the checksum, core/checkpoint_io.hpp)
// replaced by one of another name or length, and the checksum recomputed.
#pragma once
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "checkpoint_io.hpp"

namespace cdtest {

// The totals' array names, spelled out as the files hold them: the nine
// fields written before the accelerations' counts (format version 5 too),
// the twelve written before floor_steps, and this build's thirteen.
inline const std::string kTotals9 =
    "totals:wall:cpu:sweeps:sweeps_max:cap_steps:residual_max:residual_last:overlap_max:sessions";
inline const std::string kTotals12 = kTotals9 + ":cg_iterations:anderson_off_steps:subspace_off_steps";
inline const std::string kTotals13 = kTotals12 + ":floor_steps";

// `file`, a checkpoint this build wrote, with its totals array replaced by
// `name` holding `values`.
inline std::string with_totals(const std::string& file, const std::string& name,
                               const std::vector<double>& values) {
  // u32 name length, name, u64 count, u32 element size, 13 f64; u64 checksum
  const std::size_t tail = 4 + kTotals13.size() + 8 + 4 + 13 * sizeof(double) + 8;
  EXPECT_GT(file.size(), tail);
  if (file.size() <= tail) return file;
  EXPECT_EQ(file.substr(file.size() - tail + 4, kTotals13.size()), kTotals13)
      << "the file does not end with this build's totals";
  cd::ckpt::Writer o;
  o.buf = file.substr(0, file.size() - tail);
  o.array(name, values);
  o.put(cd::fnv1a(o.buf));
  return o.buf;
}

}  // namespace cdtest
