#include "coordination.hpp"

#include <cmath>
#include <map>
#include <unordered_map>

namespace cda {

Connectivity connectivity(const ContactSet& cs, const ParticleSet& ps, double f_eps,
                          int min_contacts) {
  Connectivity r;
  r.particles = ps.size();
  std::unordered_map<int, std::size_t> index;  // particle id -> index
  for (std::size_t i = 0; i < ps.size(); ++i) index[ps[i].id] = i;

  std::map<std::pair<int, int>, std::pair<double, double>> pairs;  // summed (fn, ft)
  double sum_abs = 0;
  for (const auto& c : cs) {
    auto& f = pairs[{std::min(c.b1, c.b2), std::max(c.b1, c.b2)}];
    f.first += c.fn;
    f.second += c.ft;
    sum_abs += std::abs(c.fn);
  }
  if (f_eps < 0) f_eps = cs.empty() ? 0 : 1e-9 * sum_abs / static_cast<double>(cs.size());

  // Adjacency over force-bearing pairs; -1 marks a boundary body.
  std::vector<std::vector<long>> adj(ps.size());
  for (const auto& [key, f] : pairs) {
    if (std::abs(f.first) + std::abs(f.second) <= f_eps) continue;
    ++r.force_bearing;
    const auto i1 = index.find(key.first), i2 = index.find(key.second);
    const long a = i1 == index.end() ? -1 : static_cast<long>(i1->second);
    const long b = i2 == index.end() ? -1 : static_cast<long>(i2->second);
    if (a >= 0) adj[static_cast<std::size_t>(a)].push_back(b);
    if (b >= 0) adj[static_cast<std::size_t>(b)].push_back(a);
  }

  std::vector<int> count(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) count[i] = static_cast<int>(adj[i].size());
  for (int c : count) {
    if (static_cast<std::size_t>(c) >= r.P.size()) r.P.resize(static_cast<std::size_t>(c) + 1, 0.0);
    r.P[static_cast<std::size_t>(c)] += 1.0;
  }
  for (auto& v : r.P) v /= static_cast<double>(ps.size());

  // Iterative removal: a work list of particles whose count dropped below the
  // threshold; each removal decrements its still-active neighbours.
  r.is_rattler.assign(ps.size(), false);
  std::vector<std::size_t> work;
  for (std::size_t i = 0; i < ps.size(); ++i)
    if (count[i] < min_contacts) work.push_back(i);
  while (!work.empty()) {
    const std::size_t i = work.back();
    work.pop_back();
    if (r.is_rattler[i]) continue;
    r.is_rattler[i] = true;
    ++r.rattlers;
    for (long j : adj[i]) {
      if (j < 0) continue;
      const auto u = static_cast<std::size_t>(j);
      if (r.is_rattler[u]) continue;
      if (--count[u] < min_contacts) work.push_back(u);
    }
  }
  double links = 0;
  std::size_t active = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (r.is_rattler[i]) continue;
    ++active;
    links += count[i];
  }
  r.z = active ? links / static_cast<double>(active) : 0.0;
  r.non_floating = ps.empty() ? 0.0 : static_cast<double>(active) / static_cast<double>(ps.size());
  return r;
}

}  // namespace cda
