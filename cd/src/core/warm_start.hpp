// The warm-start memory of a simulator's step (2d/world, 3d/world3): the
// last step's impulses by contact key, sorted, so that the next step finds
// a contact's impulse by bisection. P is the engine's stored impulse (2D:
// (p_n, p_t) in the contact frame; 3D: a world-frame vector, re-projected
// on the new frame). Part of the state a bit-identical restart restores
// (the checkpoints hold keys and p).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace cd {

template <class P>
struct WarmStart {
  std::vector<std::uint64_t> keys;  // strictly increasing
  std::vector<P> p;

  // The impulse remembered for `key`, or null.
  const P* find(std::uint64_t key) const {
    const auto it = std::lower_bound(keys.begin(), keys.end(), key);
    return it != keys.end() && *it == key ? &p[static_cast<std::size_t>(it - keys.begin())] : nullptr;
  }

  // Remembers the n rows of a step: row k's contact key key(k) and impulse
  // impulse(k), sorted by key (keys are unique within a step).
  template <class Key, class Impulse>
  void keep(std::size_t n, Key&& key, Impulse&& impulse) {
    std::vector<std::size_t> idx(n);
    std::iota(idx.begin(), idx.end(), 0);
    std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
    keys.resize(n);
    p.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      keys[k] = key(idx[k]);
      p[k] = impulse(idx[k]);
    }
  }
};

}  // namespace cd
