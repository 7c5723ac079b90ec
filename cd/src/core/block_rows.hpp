// The block rows of a frozen problem's sparse W (nc contacts, Dim x Dim
// blocks), as the matrix-form couplings read them (2d/problem.cpp,
// 3d/problem3.cpp): per contact the blocks W_ab of every b it couples to,
// the contacts' adjacency (for the colouring), and the block rows in colour
// order as CSR arrays. The block type B is the caller's (an array, a small
// Eigen matrix); `add(block, i, j, value)` accumulates one entry.
#pragma once
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace cd {

template <class B>
using BlockRowList = std::vector<std::vector<std::pair<std::int32_t, B>>>;

// W column-major (Eigen::SparseMatrix): entry (i, j) goes to block (i/Dim, j/Dim).
template <int Dim, class B, class Sparse, class Add>
BlockRowList<B> block_rows(const Sparse& W, int nc, const B& zero, Add&& add) {
  BlockRowList<B> brow(nc);
  for (int j = 0; j < Dim * nc; ++j)
    for (typename Sparse::InnerIterator it(W, j); it; ++it) {
      const int a = static_cast<int>(it.row()) / Dim, b = j / Dim;
      auto& v = brow[a];
      auto f = std::find_if(v.begin(), v.end(), [&](const auto& e) { return e.first == b; });
      if (f == v.end()) {
        v.push_back({b, zero});
        f = v.end() - 1;
      }
      add(f->second, static_cast<int>(it.row()) % Dim, j % Dim, it.value());
    }
  return brow;
}

// Contacts coupled by an off-diagonal block (both ways).
template <class B>
std::vector<std::vector<std::int32_t>> block_adjacency(const BlockRowList<B>& brow) {
  const int nc = static_cast<int>(brow.size());
  std::vector<std::vector<std::int32_t>> adj(nc);
  for (int a = 0; a < nc; ++a)
    for (const auto& e : brow[a])
      if (e.first != a) {
        adj[a].push_back(e.first);
        adj[e.first].push_back(a);
      }
  return adj;
}

// old index -> new index of a permutation given as new -> old.
inline std::vector<std::int32_t> inverse_permutation(const std::vector<std::int32_t>& perm) {
  std::vector<std::int32_t> inv(perm.size());
  for (std::size_t i = 0; i < perm.size(); ++i) inv[perm[i]] = static_cast<std::int32_t>(i);
  return inv;
}

// The block rows in colour order (perm: new index -> old; inv: old -> new),
// each sorted by the new column index: row i is [start[i], start[i+1]) of
// col (new indices) and blk. Sorts brow's rows in place.
template <class B>
void colour_ordered_rows(BlockRowList<B>& brow, const std::vector<std::int32_t>& perm,
                         const std::vector<std::int32_t>& inv, std::vector<std::int32_t>& start,
                         std::vector<std::int32_t>& col, std::vector<B>& blk) {
  const int nc = static_cast<int>(brow.size());
  start.assign(nc + 1, 0);
  for (int i = 0; i < nc; ++i) start[i + 1] = start[i] + static_cast<int>(brow[perm[i]].size());
  col.resize(start[nc]);
  blk.resize(start[nc]);
  for (int i = 0; i < nc; ++i) {
    auto& v = brow[perm[i]];
    std::sort(v.begin(), v.end(), [&](const auto& x, const auto& y) { return inv[x.first] < inv[y.first]; });
    for (std::size_t m = 0; m < v.size(); ++m) {
      col[start[i] + m] = inv[v[m].first];
      blk[start[i] + m] = v[m].second;
    }
  }
}

}  // namespace cd
