#include "stress.hpp"

#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace cda {

double Stress::p() const { return cd::obs::mean_2d({{{xx, xy}, {yx, yy}}}); }
double Stress::q() const { return cd::obs::deviator_2d({{{xx, xy}, {yx, yy}}}); }
double Stress::q_over_p() const {
  const double pp = p();
  return pp != 0 ? q() / pp : std::numeric_limits<double>::quiet_NaN();
}
double Stress::theta() const {
  double t = 0.5 * std::atan2(xy + yx, xx - yy);
  if (t < 0) t += std::numbers::pi;
  return t;
}
double Stress::skew() const { return 0.5 * (xy - yx); }

Stress contact_stress(const ContactSet& cs, double volume) {
  if (!(volume > 0)) throw AnalysisError(fmt::format("stress: volume {} is not positive", volume));
  const auto t = cd::obs::contact_stress<2>(as_forces(cs), volume);
  Stress s;
  s.xx = t[0][0];
  s.xy = t[0][1];
  s.yx = t[1][0];
  s.yy = t[1][1];
  return s;
}

PartialStress partial_stress(const ContactSet& cs, double volume) {
  return {contact_stress(of_type(cs, 0), volume), contact_stress(of_type(cs, 1), volume),
          contact_stress(of_type(cs, 2), volume)};
}

}  // namespace cda
