#include "stress.hpp"

#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace cda {

double Stress::p() const { return 0.5 * (xx + yy); }
double Stress::q() const {
  const double d = 0.5 * (xx - yy), s = 0.5 * (xy + yx);
  return std::hypot(d, s);
}
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
  Stress s;
  for (const auto& c : cs) {
    const double nx = c.nx(), ny = c.ny();
    const double fx = c.fn * nx - c.ft * ny, fy = c.fn * ny + c.ft * nx;
    s.xx += fx * c.lx;
    s.xy += fx * c.ly;
    s.yx += fy * c.lx;
    s.yy += fy * c.ly;
  }
  s.xx /= volume;
  s.xy /= volume;
  s.yx /= volume;
  s.yy /= volume;
  return s;
}

PartialStress partial_stress(const ContactSet& cs, double volume) {
  return {contact_stress(of_type(cs, 0), volume), contact_stress(of_type(cs, 1), volume),
          contact_stress(of_type(cs, 2), volume)};
}

}  // namespace cda
