#include "protocol.hpp"

#include <utility>

#include <fmt/format.h>

#include "derived.hpp"

namespace cd {

double imposed_pressure(const Scene& s) {
  return s.shear_mode != ShearMode::None && s.shear_control == ShearControl::Pressure ? s.pressure : 0.0;
}

double nominal_inertial_number(const Scene& s) {
  if (s.shear_control == ShearControl::Volume)
    return s.rate_tp > 0 ? (pressure_time(s) > 0 ? s.rate_tp : 0.0) : s.imposed_rate * pressure_time(s);
  return s.inertial_number;
}

namespace {

// The rules of a scene without a protocol: no protocol key set. 2D keeps
// shear.pressure (and shear.dt_tp, contact.cohesion_number with it) as the
// scale of a scene in a box; 3D has no use for it.
void check_no_protocol(const Scene& s, bool three, const auto& fail) {
  if (three) {
    if (s.pressure != 0 || s.inertial_number != 0 || s.isotropic || s.strain != 0 || s.dt_tp != 0 ||
        !s.start.empty() || s.cell_width != 0 || s.cell_height != 0 || s.cell_depth != 0 ||
        s.cohesion_number != 0 || s.checkpoint_strain != 0 || s.series_strain != 0 || s.snapshot_strain != 0 ||
        s.imposed_rate != 0 || s.rate_tp != 0 || s.volume_fraction != 0 ||
        s.shear_control != ShearControl::Pressure)
      fail("shear.* (pressure, inertial_number, isotropic, strain, dt_tp, start, width, height, depth, control, "
           "rate, rate_tp, volume_fraction), contact.cohesion_number and output.checkpoint_strain (series_strain, "
           "snapshot_strain) need shear.mode = \"periodic\": leave them at their defaults");
    return;
  }
  if (s.inertial_number > 0 || s.isotropic || !s.start.empty() || s.strain > 0 || s.compaction_rate > 0 ||
      s.imposed_rate > 0 || s.rate_tp > 0 || s.volume_fraction > 0 || s.series_strain > 0 ||
      s.snapshot_strain > 0 || s.shear_control != ShearControl::Pressure)
    fail("shear.inertial_number, shear.isotropic, shear.strain, shear.start, shear.compaction_rate, "
         "shear.control, shear.rate, shear.rate_tp, shear.volume_fraction, output.series_strain and output.snapshot_strain need shear.mode \"periodic\" or \"walls\"");
}

// What the cell imposes besides the shear: the keys of one control that the
// other refuses.
void check_control(const Scene& s, const auto& fail) {
  if (s.shear_control == ShearControl::Pressure) {
    if (s.volume_fraction > 0)
      fail(fmt::format("shear.volume_fraction = {} sets the volume of a cell whose lengths are held fixed: it "
                       "needs shear.control = \"volume\" (at imposed pressure the volume follows p)",
                       s.volume_fraction));
    for (const auto& [key, v] : {std::pair{"shear.rate", s.imposed_rate}, std::pair{"shear.rate_tp", s.rate_tp}})
      if (v > 0)
        fail(fmt::format("{} = {} imposes the shear rate under shear.control = \"volume\"; at imposed "
                         "pressure the rate is shear.inertial_number's (I sqrt(p/rho)/d)",
                         key, v));
    return;
  }
  if (s.imposed_rate > 0 && s.rate_tp > 0)
    fail(fmt::format("shear.rate = {} and shear.rate_tp = {} both give the shear rate: give one (shear.rate in "
                     "1/s, or shear.rate_tp in units of 1/t_p, t_p = d sqrt(rho/p) at shear.pressure)",
                     s.imposed_rate, s.rate_tp));
  if (s.rate_tp > 0 && s.pressure <= 0)
    fail(fmt::format("shear.rate_tp = {} is the shear rate in units of 1/t_p, t_p = d sqrt(rho/p): it needs "
                     "shear.pressure > 0 (the pressure scale), or give shear.rate (1/s)",
                     s.rate_tp));
  if (s.shear_mode != ShearMode::Periodic)
    fail("shear.control = \"volume\" needs shear.mode = \"periodic\" (a cell whose lengths are held fixed); the "
         "walls protocol holds its top wall at shear.pressure");
  if (s.inertial_number > 0)
    fail(fmt::format("shear.inertial_number = {}: shear.control = \"volume\" imposes the shear rate "
                     "(shear.rate or shear.rate_tp) and measures I (the series' inertial_number column): leave "
                     "shear.inertial_number at 0",
                     s.inertial_number));
  if (s.volume_fraction > 0 && s.start.empty())
    fail(fmt::format("shear.volume_fraction = {} scales a sample's cell: it needs shear.start", s.volume_fraction));
  const std::pair<const char*, bool> compaction[] = {{"shear.isotropic", s.isotropic},
                                                     {"shear.compaction_rate", s.compaction_rate > 0},
                                                     {"shear.settle_stress", s.settle_stress > 0}};
  for (const auto& [key, set] : compaction)
    if (set)
      fail(fmt::format("{} acts on cell lengths at imposed pressure: under shear.control = \"volume\" they "
                       "stay fixed (a compaction needs shear.control = \"pressure\")",
                       key));
}

}  // namespace

void check_protocol(const Scene& s) {
  const bool three = s.dimension == 3;
  const auto fail = [three](const std::string& m) {
    throw SceneError(three ? m + " (dimension = 3; docs/3d.md)" : m);
  };
  const bool shear = s.shear_mode != ShearMode::None;
  const bool volume = shear && s.shear_control == ShearControl::Volume;
  // The shear rate's source: I (with p) at imposed pressure, shear.rate (or
  // shear.rate_tp) at imposed volume.
  const char* rate_key = volume ? "shear.rate or shear.rate_tp" : "shear.inertial_number";
  const bool sheared = volume ? s.imposed_rate > 0 || s.rate_tp > 0 : s.inertial_number > 0;

  if (three && s.shear_mode == ShearMode::Walls)
    fail("shear.mode = \"walls\": a 3D scene is \"none\" (the box) or \"periodic\" (a tri-periodic cell)");
  if (!shear) {
    check_no_protocol(s, three, fail);
    if (!three && s.checkpoint_strain > 0)
      fail("output.checkpoint_strain > 0 needs a shear rate (shear.mode \"periodic\" or \"walls\" "
           "and shear.inertial_number > 0); use output.checkpoint_interval or "
           "output.checkpoint_wall for other runs");
    if (!three && s.cohesion_number > 0) {
      if (s.pressure <= 0) fail("contact.cohesion_number > 0 needs shear.pressure > 0 (f_a = eta p d)");
      if (s.adhesion > 0) fail("give contact.adhesion or contact.cohesion_number, not both");
    }
    if (!three && s.dt_tp > 0 && s.pressure <= 0)
      fail("shear.dt_tp > 0 needs shear.pressure > 0 (t_p = d sqrt(rho/p))");
    return;
  }
  check_control(s, fail);

  // The pressure scale p: imposed (pressure control) or the scale of t_p
  // (volume control). What needs it, by name.
  if (s.cohesion_number > 0) {
    if (s.pressure <= 0)
      fail(three ? "contact.cohesion_number > 0 needs shear.pressure > 0 (f_a = eta p d^2, p in N/m^2); without "
                   "an imposed pressure give the pull-off force itself, contact.adhesion (N)"
                 : "contact.cohesion_number > 0 needs shear.pressure > 0 (f_a = eta p d)");
    if (s.adhesion > 0) fail("give contact.adhesion or contact.cohesion_number, not both");
  }
  if (s.pressure <= 0) {
    const std::pair<const char*, bool> need_p[] = {{"shear.inertial_number", s.inertial_number != 0},
                                                   {"shear.isotropic", s.isotropic},
                                                   {"shear.compaction_rate", s.compaction_rate != 0},
                                                   {"shear.dt_tp", s.dt_tp != 0}};
    for (const auto& [key, set] : need_p)
      if (set)
        fail(three ? fmt::format("{} needs shear.pressure > 0 (the cell's lengths at imposed stress; t_p = d "
                                 "sqrt(rho/p), shear rate I sqrt(p/rho)/d)",
                                 key)
             : key == std::string("shear.dt_tp")
                 ? std::string("shear.dt_tp > 0 needs shear.pressure > 0 (t_p = d sqrt(rho/p))")
             : key == std::string("shear.inertial_number")
                 ? std::string("shear.inertial_number > 0 needs shear.pressure > 0 (shear rate = I sqrt(p/rho)/d)")
                 : fmt::format("{} needs shear.pressure > 0", key));
  }

  // The strain counts the shear: it needs a rate.
  for (const auto& [key, set] : {std::pair{"output.series_strain", s.series_strain > 0},
                                 std::pair{"output.snapshot_strain", s.snapshot_strain > 0}})
    if (set && !sheared) fail(fmt::format("{} > 0 needs a shear rate ({} > 0)", key, rate_key));
  if (s.checkpoint_strain > 0 && !sheared)
    fail(fmt::format("output.checkpoint_strain > 0 needs a shear rate ({} > 0); use output.checkpoint_interval "
                     "or output.checkpoint_wall for other runs",
                     rate_key));
  if (s.strain > 0 && !sheared) fail(fmt::format("shear.strain > 0 needs {} > 0", rate_key));

  // A compaction: every length at p, without shear.
  if (s.isotropic && (s.shear_mode != ShearMode::Periodic || s.inertial_number > 0))
    fail(three ? "shear.isotropic (compaction: all three lengths at sigma = p) needs shear.inertial_number = 0"
               : "shear.isotropic (compaction) needs shear.mode = \"periodic\" and shear.inertial_number = 0");
  if (s.compaction_rate > 0 && s.shear_mode != ShearMode::Periodic)
    fail("shear.compaction_rate > 0 needs shear.mode = \"periodic\" and shear.pressure > 0 (it "
         "bounds the rate of the cell's pressure-controlled lengths)");
  // Lengths at imposed pressure move by at most a quarter of the alert
  // distance a step.
  if (imposed_pressure(s) > 0 && !(s.alert > 0)) {
    const bool walls = s.shear_mode == ShearMode::Walls;
    fail(three ? std::string("shear.pressure > 0 needs contact.alert > 0: the cell's lengths shrink by at most a "
                             "quarter of the alert distance a step (so that their contacts are detected before "
                             "they close), and would not move")
               : fmt::format("shear.mode = \"{}\" with shear.pressure > 0 needs contact.alert > 0: {} by at most "
                             "a quarter of the alert distance a step (so that {} contacts are detected before "
                             "they close), and would not move",
                             name_of(s.shear_mode), walls ? "the top wall falls" : "the cell's lengths shrink",
                             walls ? "its" : "their"));
  }

  // The shear protocols run in an open periodic space.
  if (three) {
    if (s.gravity.size() == 3 && (s.gravity[0] != 0 || s.gravity[1] != 0 || s.gravity[2] != 0))
      fail("gravity.g: a tri-periodic cell has no floor; use [0, 0, 0]");
    if (s.box_width != 0 || s.box_depth != 0 || s.box_height != 0)
      fail("box.width, box.depth, box.height: a periodic cell has no box; its lengths are shear.width, "
           "shear.height and shear.depth");
  } else {
    if (s.gravity[0] != 0 || s.gravity[1] != 0)
      fail("shear protocols run without gravity: set [gravity] g = [0.0, 0.0]");
    if (s.box_width > 0 || !s.walls.empty()) fail("shear protocols take no [box] and no [[wall]]");
  }
  if (!s.start.empty() && s.shear_mode != ShearMode::Periodic)
    fail("shear.start needs shear.mode = \"periodic\" (a walls run places its own grains "
         "between its walls)");
}

}  // namespace cd
