#include "coordination.hpp"

#include <stdexcept>

namespace cda {

namespace {

template <int D, class Set>
Connectivity connectivity_of(const Set& cs, const ParticleSet& ps, double f_eps, int min_contacts) {
  std::vector<std::int32_t> ids;
  ids.reserve(ps.size());
  for (const auto& p : ps) ids.push_back(p.id);
  cd::obs::Coordination c;
  try {
    c = cd::obs::coordination<D>(as_forces(cs), ids, f_eps, min_contacts);
  } catch (const std::invalid_argument& e) {
    throw AnalysisError(e.what());
  }
  Connectivity r;
  r.particles = c.particles;
  r.rattlers = c.rattlers;
  r.force_bearing = c.force_bearing;
  r.z = c.z;
  r.non_floating = c.non_rattler;
  r.P = std::move(c.P);
  r.is_rattler = std::move(c.is_rattler);
  return r;
}

}  // namespace

Connectivity connectivity(const ContactSet& cs, const ParticleSet& ps, double f_eps, int min_contacts) {
  return connectivity_of<2>(cs, ps, f_eps, min_contacts);
}

Connectivity connectivity(const ContactSet3& cs, const ParticleSet& ps, double f_eps, int min_contacts) {
  return connectivity_of<3>(cs, ps, f_eps, min_contacts);
}

}  // namespace cda
