// Greedy colouring of a coupling graph given by adjacency lists (contacts
// that share a block of W, whatever the block size): used by the matrix-form
// NLGS of 2D and 3D frozen problems (2d/problem.cpp, 3d/problem3.cpp).
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "solver.hpp"

namespace cd {

// Greedy colouring of the contacts' coupling graph (W's block pattern), in
// index order; as colour_rows, at most 63 colours and an overflow colour.
inline Colouring colour_blocks(int nc, const std::vector<std::vector<std::int32_t>>& adj) {
  constexpr int kMax = 63;
  std::vector<int> colour(nc, -1);
  int used = 0;
  bool overflow = false;
  for (int k = 0; k < nc; ++k) {
    std::uint64_t m = 0;
    for (const std::int32_t j : adj[k])
      if (colour[j] >= 0 && colour[j] < kMax) m |= std::uint64_t{1} << colour[j];
    int c = std::countr_one(m);
    if (c >= kMax) {
      c = kMax;
      overflow = true;
    } else {
      used = std::max(used, c + 1);
    }
    colour[k] = c;
  }
  const int ncol = overflow ? used + 1 : used;
  Colouring col;
  col.overflow = overflow;
  col.start.assign(ncol + 1, 0);
  for (int k = 0; k < nc; ++k) ++col.start[(colour[k] == kMax ? used : colour[k]) + 1];
  for (int c = 0; c < ncol; ++c) col.start[c + 1] += col.start[c];
  col.split.assign(col.start.begin(), col.start.end() - 1);  // no driven bodies: all "write1"
  col.perm.resize(nc);
  std::vector<std::int32_t> pos(col.start.begin(), col.start.end() - 1);
  for (int k = 0; k < nc; ++k) col.perm[pos[colour[k] == kMax ? used : colour[k]]++] = k;
  return col;
}

}  // namespace cd
