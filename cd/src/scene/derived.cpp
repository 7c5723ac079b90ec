#include "derived.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace cd {

namespace {

// Diameter range [a, b] with b = ratio a whose number mean is d_mean.
//   uniform:       d uniform,           mean = a (1 + r) / 2
//   uniform_area:  pdf(d) ~ 1/d^2, i.e. each size class holds the same area
//                  fraction (2D), mean = a r ln r / (r - 1)
void diameter_range(const Scene& s, double& a, double& b) {
  const double r = s.size_ratio;
  if (r == 1.0) {
    a = b = s.d_mean;
  } else if (s.size_dist == SizeDist::Uniform) {
    a = 2.0 * s.d_mean / (1.0 + r);
  } else {
    a = s.d_mean * (r - 1.0) / (r * std::log(r));
  }
  b = a * r;
}

// Quantities derived from several keys, checked before anything is built or
// written: each must be finite, and the run must take at least one step and
// no more than kMaxSteps.
constexpr double kMaxSteps = 1e9;

}  // namespace

std::vector<double> generated_diameters(const Scene& s) {
  if (!s.diameters.empty()) {
    // The given diameters, in an order shuffled by the seed (Fisher-Yates
    // with the platform-independent uniform01), so that a sorted list does
    // not place the large grains in the bottom rows.
    std::vector<double> d = s.diameters;
    std::mt19937_64 g(s.seed);
    for (std::size_t i = d.size(); i > 1; --i)
      std::swap(d[i - 1], d[static_cast<std::size_t>(uniform01(g) * i)]);
    return d;
  }
  double a, b;
  diameter_range(s, a, b);
  std::mt19937_64 g(s.seed);
  std::vector<double> d(s.n);
  for (double& x : d) {
    const double u = uniform01(g);
    x = s.size_dist == SizeDist::Uniform ? a + u * (b - a) : 1.0 / (1.0 / a - u * (1.0 / a - 1.0 / b));
  }
  return d;
}

std::pair<double, double> diameter_bounds(const Scene& s) {
  if (!s.diameters.empty())
    return {*std::min_element(s.diameters.begin(), s.diameters.end()),
            *std::max_element(s.diameters.begin(), s.diameters.end())};
  double a, b;
  diameter_range(s, a, b);
  return {a, b};
}

double mean_diameter(const Scene& s) {
  double sum = 0;
  int n = 0;
  for (const DiskSpec& d : s.disks) {
    sum += 2 * d.radius;
    ++n;
  }
  if (!s.diameters.empty()) {
    for (const double d : s.diameters) sum += d;
    n += static_cast<int>(s.diameters.size());
  } else if (s.n > 0) {
    sum += s.n * s.d_mean;
    n += s.n;
  }
  return n > 0 ? sum / n : s.d_mean;
}

double pressure_time(const Scene& s) {
  return s.pressure > 0 ? mean_diameter(s) * std::sqrt(s.density / s.pressure) : 0.0;
}

double shear_rate(const Scene& s) {
  const double tp = pressure_time(s);
  if (s.shear_control == ShearControl::Volume) return s.rate_tp > 0 ? (tp > 0 ? s.rate_tp / tp : 0.0) : s.imposed_rate;
  return tp > 0 ? s.inertial_number / tp : 0.0;
}

double pull_off_force(const Scene& s) {
  if (!(s.cohesion_number > 0)) return s.adhesion;
  const double d = mean_diameter(s);
  return s.cohesion_number * s.pressure * (s.dimension == 3 ? d * d : d);
}

double contact_stiffness(const Scene& s) {
  if (!(s.stiffness_number > 0)) return s.stiffness;
  return s.stiffness_number * s.pressure * mean_diameter(s);
}

double time_step(const Scene& s) { return s.dt_tp > 0 ? s.dt_tp * pressure_time(s) : s.dt; }

double run_duration(const Scene& s) {
  return s.strain > 0 && shear_rate(s) > 0 ? s.strain / shear_rate(s) : s.duration;
}

// Every grain's mass and moment of inertia, and their inverses, must be
// normal doubles: a radius or density of 1e-300 gives a mass that
// underflows to 0 and an infinite inverse mass (a grain that cannot be
// pushed). Checked for the extreme generated sizes and every [[disk]], with
// the shape's own formulas (2D: a regular n-gon's, Bodies::add_polygon; 3D:
// a sphere's, Bodies3::add_sphere).
static void check_grain_masses(const Scene& s) {
  const auto check = [&](const std::string& what, double d, double rho, int sides) {
    const double r = 0.5 * d;
    double m, I;
    if (s.dimension == 3) {
      m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
      I = 0.4 * m * r * r;
    } else if (sides > 0) {
      const double a = 2.0 * std::numbers::pi / sides;
      m = rho * 0.5 * sides * r * r * std::sin(a);
      I = m * r * r * (2.0 + std::cos(a)) / 6.0;
    } else {
      m = rho * std::numbers::pi * r * r;
      I = 0.5 * m * r * r;
    }
    const auto normal = [](double x) { return std::isnormal(x) && x > 0 && std::isnormal(1.0 / x); };
    if (!normal(m) || !normal(I))
      throw SceneError(fmt::format("{} of diameter {} m and density {} has mass {} and moment of inertia {}: both "
                                   "and their inverses must be finite and > 0 (a grain of zero mass cannot be "
                                   "pushed, one of infinite mass cannot be moved)", what, d, rho, m, I));
  };
  const char* grain = s.dimension == 3 ? "a sphere" : "a grain";
  if (s.n > 0 || !s.diameters.empty()) {
    const auto [d_min, d_max] = diameter_bounds(s);
    for (const double d : {d_min, d_max})
      for (const double n : s.dimension == 3 ? std::vector<double>{0.0} : s.nsides)
        check(fmt::format("{} (particles.d_mean, size_ratio, diameters, density{})", grain,
                          s.dimension == 3 ? "" : ", nsides"),
              d, s.density, static_cast<int>(n));
  }
  for (std::size_t i = 0; i < s.disks.size(); ++i) {
    const DiskSpec& d = s.disks[i];
    check(fmt::format("disk[{}]", i), 2 * d.radius, d.density > 0 ? d.density : s.density, d.nsides);
  }
}

// A setting that cannot act under the scene's law, shape or protocol is
// refused by name, not ignored: a reader of the scene would believe it
// does something. (Others live beside the rule they belong to: the
// subspace correction under the orthotropic cone, check_scene3; the
// compaction keys under volume control, check_protocol; stiffness_ratio,
// below.) Keys at their defaults pass, whatever the scene.
static void check_settings_act(const Scene& s) {
  const auto fail = [](const std::string& m) { throw SceneError(m); };
  const Scene d;
  const bool walls = !(s.shear_mode == ShearMode::Periodic);  // a periodic cell has none
  if (!walls && s.mu_wall >= 0)
    fail(fmt::format("contact.mu_wall = {}: a periodic cell (shear.mode = \"periodic\") has no walls; leave "
                     "it at -1 (contact.mu acts on every contact)",
                     s.mu_wall));
  if (!walls && s.mu_wall_b >= 0)
    fail(fmt::format("contact.mu_wall_b = {}: a periodic cell (shear.mode = \"periodic\") has no walls; give "
                     "the orthotropic cone of the grains, contact.mu_b",
                     s.mu_wall_b));
  if (s.dimension == 3 && !s.orthotropic() && s.axis_a != d.axis_a)
    fail(fmt::format("contact.axis_a = [{}, {}, {}]: the direction of the orthotropic cone acts only with contact.mu_b "
                     "or contact.mu_wall_b >= 0 (the round cone has no direction)",
                     s.axis_a[0], s.axis_a[1], s.axis_a[2]));
  const bool friction = s.mu > 0 || s.mu_w() > 0 || (s.orthotropic() && (s.mu_b > 0 || s.mu_wall_b > 0));
  if (!friction && s.e_t > 0)
    fail(fmt::format("contact.e_t = {}: without friction (contact.mu = 0{}) no contact carries a tangential "
                     "impulse, so a tangential restitution cannot act; leave it at 0",
                     s.e_t, walls ? ", and on walls" : ""));
  if (!(s.adhesion > 0 || s.cohesion_number > 0) && s.debond != d.debond)
    fail(fmt::format("contact.debond = {}: the debonding distance acts only on adhesive contacts "
                     "(contact.adhesion or contact.cohesion_number > 0)",
                     s.debond));
  const bool stretched = has_shape(s, Shape3d::Cuboid) || has_shape(s, Shape3d::Irregular);
  if (!stretched && s.aspect != d.aspect)
    fail(fmt::format("particles.aspect = [{}]: the ratios act only on particles.shape = \"cuboid\" or "
                     "\"irregular\" (here {}); leave it out",
                     fmt::join(s.aspect, ", "), shape_text(s.shape)));
  if (!has_shape(s, Shape3d::Irregular) && s.vertices != d.vertices)
    fail(fmt::format("particles.vertices = {}: the number of points acts only on particles.shape = \"irregular\" "
                     "(here {}); leave it out",
                     s.vertices, shape_text(s.shape)));
  if (s.shear_mode != ShearMode::None && s.shear_control == ShearControl::Volume && s.cell_mass != d.cell_mass)
    fail(fmt::format("shear.cell_mass = {}: under shear.control = \"volume\" the cell's lengths are held "
                     "fixed, so they have no mass; leave it out",
                     s.cell_mass));
}

void check_derived(const Scene& s) {
  auto fail = [](const std::string& m) { throw SceneError(m); };
  check_grain_masses(s);
  check_settings_act(s);
  const double dt = time_step(s);
  const char* dt_from = s.dt_tp > 0 ? "shear.dt_tp x t_p" : "time.dt";
  if (!std::isfinite(dt) || dt <= 0) fail(fmt::format("the time step ({}) is {}: must be finite and > 0", dt_from, dt));
  if (s.shear_mode != ShearMode::None && s.pressure > 0) {
    const double tp = pressure_time(s), gd = shear_rate(s);
    if (!std::isfinite(tp) || !std::isfinite(gd))
      fail(fmt::format("t_p = d sqrt(rho/p) = {} s and the shear rate {} 1/s must be finite "
                       "(particles.d_mean, particles.density, shear.pressure, shear.inertial_number)",
                       tp, gd));
  }
  // The stop rule settles a compaction (core/settle.hpp): a periodic cell
  // at imposed pressure, not sheared.
  if (s.settle_stress > 0 && (s.shear_mode != ShearMode::Periodic || s.pressure <= 0 || s.inertial_number != 0))
    fail(fmt::format("shear.settle_stress = {}: the stop rule settles a compaction: it needs shear.mode = "
                     "\"periodic\", shear.pressure > 0 and shear.inertial_number = 0 (here shear.pressure = {}, "
                     "shear.inertial_number = {}{})", s.settle_stress, s.pressure, s.inertial_number,
                     s.shear_mode == ShearMode::Periodic ? "" : ", another shear.mode"));
  if (s.adhesion > 0 || s.cohesion_number > 0) {
    const double fa = pull_off_force(s);
    if (!std::isfinite(fa))
      fail(fmt::format("the pull-off force f_a = {} N must be finite ({})", fa,
                       s.cohesion_number > 0 ? (s.dimension == 3 ? "contact.cohesion_number x shear.pressure x d^2"
                                                                 : "contact.cohesion_number x shear.pressure x d")
                                             : "contact.adhesion"));
  }
  if (s.stiffness_ratio != 1.0 && !(s.stiffness > 0 || s.stiffness_number > 0))
    fail(fmt::format("contact.stiffness_ratio = {} without compliant contacts (contact.stiffness or "
                     "contact.stiffness_number > 0): rigid contacts have no stiffness to divide",
                     s.stiffness_ratio));
  if (s.stiffness > 0 || s.stiffness_number > 0) {
    const char* key = s.stiffness_number > 0 ? "contact.stiffness_number" : "contact.stiffness";
    if (s.dimension != 3)
      fail(fmt::format("{} > 0: compliant contacts are 3D only (2D contacts are rigid)", key));
    if (s.stiffness > 0 && s.stiffness_number > 0)
      fail("give contact.stiffness or contact.stiffness_number, not both");
    if (!(s.stiffness_ratio <= 1e3))
      fail(fmt::format("contact.stiffness_ratio = {} (k_t / k): at most 1e3", s.stiffness_ratio));
    if (s.stiffness_number > 0 && !(s.pressure > 0))
      fail("contact.stiffness_number > 0 needs shear.pressure > 0 (k = kappa p d, p in N/m^2); without an "
           "imposed pressure give the stiffness itself, contact.stiffness (N/m)");
    if (s.e_n > 0 || s.e_t > 0)
      fail(fmt::format("{} > 0 with restitution (contact.e_n, contact.e_t): a compliant contact has its own "
                       "rebound; choose one", key));
    const double k = contact_stiffness(s), rho = 1.0 / (k * dt * dt);
    if (!std::isfinite(k) || !std::isnormal(rho))
      fail(fmt::format("the contact stiffness k = {} N/m with the time step {} s gives 1/(k dt^2) = {}: both "
                       "must be finite and > 0 ({})", k, dt, rho, key));
    // A compliant bond stretches by f/k as it pulls (method.md section 15)
    // and breaks at the debonding distance: f_a must be reached before it.
    if (s.adhesion > 0 || s.cohesion_number > 0) {
      const double d = mean_diameter(s), fa = pull_off_force(s), reach = k * s.debond * d;
      if (!(fa <= reach))
        fail(fmt::format("{} with {}: a bond pulling f_a = {:.4g} N stretches by f_a/k = {:.3g} d, beyond "
                         "contact.debond = {:.3g} d, so it would break at a pull of k delta_a = {:.4g} N, "
                         "never at f_a; make f_a/k at most contact.debond ({}), or raise contact.debond "
                         "(docs/method.md section 15)",
                         s.cohesion_number > 0 ? "contact.cohesion_number" : "contact.adhesion", key, fa,
                         fa / (k * d), s.debond, reach,
                         s.cohesion_number > 0 && s.stiffness_number > 0
                             ? fmt::format("cohesion_number <= stiffness_number x debond = {:.4g}",
                                           s.stiffness_number * s.debond)
                             : fmt::format("adhesion <= {:.4g} N", reach)));
    }
  }
  const double T = run_duration(s);
  const char* T_from = s.strain > 0 ? "shear.strain / shear rate" : "time.duration";
  const double steps = T / dt;
  // The run plan's count (run_plan.cpp: the nearest integer), the limit
  // included; printed whole, so that a count just past it does not read as
  // the limit itself.
  if (!std::isfinite(steps) || std::round(steps) > kMaxSteps)
    fail(fmt::format("the run would take {} steps ({} = {:.4g} s, time step {:.4g} s), more "
                     "than the limit of {:.0f}: shorten the run or lengthen the step",
                     std::isfinite(steps) && steps < 1e15 ? fmt::format("{:.0f}", std::round(steps))
                                                          : fmt::format("{:.3g}", steps),
                     T_from, T, dt, kMaxSteps));
  if (!(steps >= 1 - 1e-9))
    fail(fmt::format("the run would take less than one step: its duration ({} = {:.4g} s) is "
                     "shorter than the time step ({} = {:.4g} s)", T_from, T, dt_from, dt));
}

}  // namespace cd
