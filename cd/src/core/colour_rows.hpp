// Greedy colouring of rows coupled through bodies (the simulators' steps,
// 2D and 3D): no two rows of a colour share a dynamic body, and inside a
// colour the rows whose body 1 is driven (read, never written) come first.
// Written once over the row type: b1(i), b2(i) give row i's bodies and
// dynamic(b) whether body b is written by the solver.
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "solver.hpp"

namespace cd {

inline constexpr int kMaxColours = 63;  // colour 63 of the mask is the overflow colour

// Rows in index order take the lowest colour free at both their bodies (a
// driven body 1 takes no colour); at most kMaxColours colours, the rest go
// to an overflow colour solved on one thread, last. Deterministic: a stable
// counting sort by (colour, body 1 dynamic).
template <class B1, class B2, class Dyn>
Colouring colour_by_bodies(int n, std::size_t nbodies, B1&& b1, B2&& b2, Dyn&& dynamic) {
  std::vector<std::uint64_t> mask(nbodies, 0);
  std::vector<std::uint8_t> colour(n);
  int used = 0;
  bool overflow = false;
  for (int i = 0; i < n; ++i) {
    const auto i1 = b1(i), i2 = b2(i);
    const bool dyn1 = dynamic(i1);
    std::uint64_t m = mask[i2] | (dyn1 ? mask[i1] : 0);
    int c = std::countr_one(m);
    if (c >= kMaxColours) {
      c = kMaxColours;  // overflow: solved in sequence, after all colours
      overflow = true;
    } else {
      mask[i2] |= std::uint64_t{1} << c;
      if (dyn1) mask[i1] |= std::uint64_t{1} << c;
      used = std::max(used, c + 1);
    }
    colour[i] = static_cast<std::uint8_t>(c);
  }
  const int ncol = overflow ? used + 1 : used;
  // Counting sort by (colour, body 1 dynamic): stable, so deterministic.
  auto slot = [&](int i) {
    const int c = colour[i] == kMaxColours ? used : colour[i];
    return 2 * c + (dynamic(b1(i)) ? 1 : 0);
  };
  std::vector<std::int32_t> count(2 * ncol + 1, 0);
  for (int i = 0; i < n; ++i) ++count[slot(i) + 1];
  for (int s = 0; s < 2 * ncol; ++s) count[s + 1] += count[s];
  Colouring col;
  col.overflow = overflow;
  col.start.resize(ncol + 1);
  col.split.resize(ncol);
  for (int c = 0; c < ncol; ++c) {
    col.start[c] = count[2 * c];
    col.split[c] = count[2 * c + 1];
  }
  col.start[ncol] = n;
  col.perm.resize(n);
  std::vector<std::int32_t> pos(count.begin(), count.end() - 1);
  for (int i = 0; i < n; ++i) col.perm[pos[slot(i)]++] = i;
  return col;
}

}  // namespace cd
