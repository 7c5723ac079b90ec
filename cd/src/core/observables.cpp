#include "observables.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>
#include <string>

#include "cd/src/scene/derived.hpp"  // grain_area

namespace cd::obs {

template <int D>
Tensor<D> contact_stress(std::span<const Contact<D>> cs, double volume) {
  if (!(volume > 0))
    throw std::invalid_argument("contact stress: volume " + std::to_string(volume) +
                                " is not positive");
  Tensor<D> s{};
  for (const auto& c : cs) {
    const Vec<D> f = c.force();
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) s[i][j] += f[i] * c.l[j];
  }
  for (auto& row : s)
    for (double& v : row) v /= volume;
  return s;
}

template <int D>
double force_threshold(std::span<const Contact<D>> cs, double rel) {
  if (cs.empty()) return 0.0;
  double sum_abs = 0;
  for (const auto& c : cs) sum_abs += std::abs(c.fn);
  return rel * sum_abs / static_cast<double>(cs.size());
}

namespace {

Link link_of(std::int32_t a, std::int32_t b) { return {std::min(a, b), std::max(a, b)}; }

// (pair, index) of the bearing points, sorted by pair then index.
template <int D>
std::vector<std::pair<Link, std::size_t>> bearing(std::span<const Contact<D>> cs, double f_eps) {
  if (f_eps < 0) f_eps = force_threshold(cs);
  std::vector<std::pair<Link, std::size_t>> v;
  for (std::size_t k = 0; k < cs.size(); ++k)
    if (bears_force(cs[k], f_eps)) v.emplace_back(link_of(cs[k].b1, cs[k].b2), k);
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

template <int D>
std::vector<Link> force_bearing_links(std::span<const Contact<D>> cs, double f_eps) {
  std::vector<Link> links;
  for (const auto& [l, k] : bearing(cs, f_eps))
    if (links.empty() || links.back() != l) links.push_back(l);
  return links;
}

template <int D>
std::vector<std::size_t> force_bearing_points(std::span<const Contact<D>> cs, double f_eps) {
  std::vector<std::size_t> first;
  const auto v = bearing(cs, f_eps);
  for (std::size_t i = 0; i < v.size(); ++i)
    if (i == 0 || v[i].first != v[i - 1].first) first.push_back(v[i].second);
  std::sort(first.begin(), first.end());
  return first;
}

Coordination coordination(std::span<const Link> links, std::span<const std::int32_t> particles,
                          int min_contacts) {
  Coordination r;
  r.particles = particles.size();
  r.force_bearing = links.size();
  // Dense index of body id -> particle index (-1: not a particle).
  std::int32_t max_id = -1;
  for (std::int32_t id : particles) max_id = std::max(max_id, id);
  for (const Link& l : links) {
    if (l.b1 < 0 || l.b1 > l.b2)
      throw std::invalid_argument("coordination: a link is not a pair b1 <= b2 of ids >= 0");
    max_id = std::max(max_id, l.b2);
  }
  for (std::int32_t id : particles)
    if (id < 0) throw std::invalid_argument("coordination: negative particle id " + std::to_string(id));
  std::vector<long> index(static_cast<std::size_t>(max_id + 1), -1);
  for (std::size_t i = 0; i < particles.size(); ++i)
    index[static_cast<std::size_t>(particles[i])] = static_cast<long>(i);

  // Adjacency of particles over the links, in CSR; -1: a body that is not a
  // particle (never removed). Each pair is visited twice, each particle
  // removed once: O(N + C).
  const std::size_t np = particles.size();
  std::vector<int> deg(np, 0), start(np + 1, 0);
  for (const Link& l : links) {
    for (std::int32_t b : {l.b1, l.b2})
      if (const long i = index[static_cast<std::size_t>(b)]; i >= 0) ++deg[static_cast<std::size_t>(i)];
  }
  for (std::size_t i = 0; i < np; ++i) start[i + 1] = start[i] + deg[i];
  std::vector<long> adj(static_cast<std::size_t>(start[np]));
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (const Link& l : links) {
      const long a = index[static_cast<std::size_t>(l.b1)], b = index[static_cast<std::size_t>(l.b2)];
      if (a >= 0) adj[static_cast<std::size_t>(fill[static_cast<std::size_t>(a)]++)] = b;
      if (b >= 0) adj[static_cast<std::size_t>(fill[static_cast<std::size_t>(b)]++)] = a;
    }
  }
  for (int c : deg) {
    if (static_cast<std::size_t>(c) >= r.P.size()) r.P.resize(static_cast<std::size_t>(c) + 1, 0.0);
    r.P[static_cast<std::size_t>(c)] += 1.0;
  }
  for (double& p : r.P) p /= static_cast<double>(np);

  r.is_rattler.assign(np, false);
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < np; ++i)
    if (deg[i] < min_contacts) {
      r.is_rattler[i] = true;
      todo.push_back(i);
    }
  while (!todo.empty()) {
    const std::size_t i = todo.back();
    todo.pop_back();
    for (int k = start[i]; k < start[i + 1]; ++k) {
      const long o = adj[static_cast<std::size_t>(k)];
      if (o < 0) continue;
      const auto u = static_cast<std::size_t>(o);
      if (r.is_rattler[u]) continue;
      if (--deg[u] < min_contacts) {
        r.is_rattler[u] = true;
        todo.push_back(u);
      }
    }
  }
  long ends = 0;
  std::size_t active = 0;
  for (std::size_t i = 0; i < np; ++i) {
    if (r.is_rattler[i]) continue;
    ++active;
    ends += deg[i];
  }
  r.rattlers = np - active;
  r.z = active ? static_cast<double>(ends) / static_cast<double>(active) : 0.0;
  r.non_rattler = np ? static_cast<double>(active) / static_cast<double>(np) : 0.0;
  return r;
}

double particle_area(double r, int nsides) { return grain_area(r, nsides); }

double sphere_volume(double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r; }

double packing_fraction(std::span<const double> volumes, std::span<const double> weights,
                        double volume) {
  if (!(volume > 0))
    throw std::invalid_argument("packing fraction: volume " + std::to_string(volume) +
                                " is not positive");
  if (!weights.empty() && weights.size() != volumes.size())
    throw std::invalid_argument("packing fraction: " + std::to_string(weights.size()) +
                                " weights for " + std::to_string(volumes.size()) + " volumes");
  double s = 0;
  for (std::size_t i = 0; i < volumes.size(); ++i)
    s += (weights.empty() ? 1.0 : weights[i]) * volumes[i];
  return s / volume;
}

template <int D>
Tensor<D> fabric_tensor(std::span<const Contact<D>> cs, double f_eps) {
  Tensor<D> F{};
  const auto pts = force_bearing_points(cs, f_eps);
  for (std::size_t k : pts)
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) F[i][j] += cs[k].n[i] * cs[k].n[j];
  if (!pts.empty())
    for (auto& row : F)
      for (double& v : row) v /= static_cast<double>(pts.size());
  return F;
}

double mean_2d(const Tensor<2>& t) { return 0.5 * (t[0][0] + t[1][1]); }
double deviator_2d(const Tensor<2>& t) {
  const double d = 0.5 * (t[0][0] - t[1][1]), s = 0.5 * (t[0][1] + t[1][0]);
  return std::hypot(d, s);
}
double mean_3d(const Tensor<3>& t) { return (t[0][0] + t[1][1] + t[2][2]) / 3.0; }
double deviator_3d(const Tensor<3>& t) {
  const double p = mean_3d(t);
  double ss = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double s = 0.5 * (t[i][j] + t[j][i]) - (i == j ? p : 0.0);
      ss += s * s;
    }
  return std::sqrt(1.5 * ss);
}

#define CD_OBS_INSTANTIATE(D)                                                                    \
  template Tensor<D> contact_stress<D>(std::span<const Contact<D>>, double);                    \
  template double force_threshold<D>(std::span<const Contact<D>>, double);                      \
  template std::vector<Link> force_bearing_links<D>(std::span<const Contact<D>>, double);       \
  template std::vector<std::size_t> force_bearing_points<D>(std::span<const Contact<D>>, double); \
  template Tensor<D> fabric_tensor<D>(std::span<const Contact<D>>, double);
CD_OBS_INSTANTIATE(2)
CD_OBS_INSTANTIATE(3)
#undef CD_OBS_INSTANTIATE

}  // namespace cd::obs
