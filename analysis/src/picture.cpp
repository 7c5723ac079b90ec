#include "picture.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <set>

#include "plot.hpp"
#include "scene_info.hpp"
#include "snapshot.hpp"

namespace fs = std::filesystem;

namespace cda {

// Classes by fn/<fn>: weak (below the mean: the network that props the
// chains), then the strong chains by multiples of the mean.
const double kForceClassBounds[kForceClasses + 1] = {0, 1, 1.5, 2, 3, INFINITY};
const char* const kForceClassColour[kForceClasses] = {"#f4a582", "#d6604d", "#b2182b", "#8b0a26", "#4d0015"};
namespace {
const double kForceClassWidth[kForceClasses] = {1, 2, 3.5, 5, 7};

struct Bar {
  double xa, ya, xb, yb, fn;
};

// The index of the particles and contacts snapshots drawn together: the
// same number in both series (cdsim writes them at the same steps).
std::pair<std::string, std::string> snapshot_pair(const std::string& run, const char* bodies, int k) {
  const std::string p = snapshot_path(run, bodies, k);
  const std::string stem = fs::path(p).filename().string();  // particles_00012.vtp
  const std::string number = stem.substr(stem.find('_'));
  const std::string c = (fs::path(run) / ("contacts" + number)).string();
  std::error_code ec;
  if (!fs::is_regular_file(c, ec))
    throw AnalysisError(fmt::format("'{}' has no contacts snapshot beside '{}' (expected '{}')", run, p, c));
  return {p, c};
}

}  // namespace

Picture draw_snapshot(const std::string& run, const std::string& png, const PictureOptions& opt) {
  const int dim = run_dimension(run);
  Picture pic;
  const auto [pfile, cfile] = snapshot_pair(run, particles_prefix(dim), opt.snapshot);
  pic.particles = pfile;
  pic.contacts = cfile;
  ParticleSet ps = read_particles(pfile);
  // 3D polyhedra: their bodies (centres, circumradii) from the polyhedra
  // snapshot of the same number, drawn as their sections by the slice.
  const std::optional<std::string> polyfile =
      dim == 3 ? companion_snapshot(pfile, "polyhedra") : std::optional<std::string>{};
  std::set<int> polyhedra;
  if (polyfile)
    for (const auto& p : read_polyhedra(*polyfile)) {
      ps.push_back(p);
      polyhedra.insert(p.id);
    }
  if (ps.empty()) throw AnalysisError(fmt::format("'{}' holds no particle", pfile));
  std::map<int, const Particle*> by_id;
  for (const auto& p : ps) by_id[p.id] = &p;

  // 3D: the slice plane through the middle of the spheres, and its half
  // thickness for contacts, one mean radius.
  double zmid = 0, half = 0;
  if (dim == 3) {
    double zlo = INFINITY, zhi = -INFINITY, rsum = 0;
    for (const auto& p : ps) zlo = std::min(zlo, p.z), zhi = std::max(zhi, p.z), rsum += p.radius;
    zmid = (zlo + zhi) / 2;
    half = rsum / ps.size();
  }
  pic.z_mid = zmid;

  // Outlines: one closed polyline per grain, blank-line separated.
  std::string grains;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  const auto extend = [&](double x, double y) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };
  if (polyfile) {
    pic.particles += " + " + *polyfile;
    for (const auto& [body, corners] : polyhedra_sections(*polyfile, zmid)) {
      for (std::size_t k = 0; k <= corners.size(); ++k) {
        const auto& q = corners[k % corners.size()];
        grains += fmt::format("{} {}\n", toml_num(q[0]), toml_num(q[1]));
        extend(q[0], q[1]);
      }
      grains += "\n";
      ++pic.grains;
    }
  }
  for (const auto& p : ps) {
    if (polyhedra.count(p.id)) continue;  // a polyhedron: its section above
    double r = p.radius;
    if (dim == 3) {
      const double dz = p.z - zmid;
      if (std::abs(dz) >= r) continue;
      r = std::sqrt(r * r - dz * dz);
    }
    const bool polygon = dim == 2 && p.nsides >= 3;
    const int n = polygon ? p.nsides : 72;
    const double a0 = polygon ? p.angle : 0;
    for (int k = 0; k <= n; ++k) {
      const double a = a0 + 2 * std::numbers::pi * (k % n) / n;
      const double x = p.x + r * std::cos(a), y = p.y + r * std::sin(a);
      grains += fmt::format("{} {}\n", toml_num(x), toml_num(y));
      extend(x, y);
    }
    grains += "\n";
    ++pic.grains;
  }

  // Force-bearing contacts as bars.
  std::vector<Bar> bars;
  const auto add_bar = [&](int b1, int b2, double lx, double ly, double fn, double za, double zb) {
    if (!(fn > 0)) return;
    const auto i1 = by_id.find(b1), i2 = by_id.find(b2);
    double xa, ya;
    if (i1 != by_id.end()) xa = i1->second->x, ya = i1->second->y;
    else if (i2 != by_id.end()) xa = i2->second->x - lx, ya = i2->second->y - ly;
    else return;
    if (dim == 3 && !(std::abs(za - zmid) < half && std::abs(zb - zmid) < half)) return;
    bars.push_back({xa, ya, xa + lx, ya + ly, fn});
  };
  if (dim == 3) {
    // A polyhedra pair's points as one contact (their forces summed).
    for (const auto& c : merge_points3(read_contacts3(cfile))) {
      const auto i2 = by_id.find(c.c.b2);
      if (i2 == by_id.end()) continue;
      const double zb = i2->second->z, za = zb - c.c.l[2];
      add_bar(c.c.b1, c.c.b2, c.c.l[0], c.c.l[1], c.c.fn, za, zb);
    }
  } else {
    // Side-side pairs as one contact: their forces summed (the chain's load).
    // A 2D wall contact's branch runs to the wall segment's middle, not to
    // the contact: its bar is drawn from the grain's centre to its edge
    // along n instead (the radius; a polygon's circumradius).
    for (const auto& c : merge_side_side(read_contacts(cfile))) {
      const bool w1 = !by_id.count(c.b1), w2 = !by_id.count(c.b2);
      if (w1 == w2) {
        add_bar(c.b1, c.b2, c.lx, c.ly, c.fn, 0, 0);
      } else {
        const Particle& g = *by_id.at(w1 ? c.b2 : c.b1);
        const double s = w1 ? -g.radius : g.radius;  // n points from b1 to b2
        if (c.fn > 0) bars.push_back({g.x, g.y, g.x + s * c.nx(), g.y + s * c.ny(), c.fn});
      }
    }
  }
  double mean = 0;
  for (const auto& b : bars) mean += b.fn;
  if (!bars.empty()) mean /= bars.size();
  pic.bars = bars.size();
  std::string classes[kForceClasses];
  for (const auto& b : bars) {
    extend(b.xa, b.ya), extend(b.xb, b.yb);
    int k = 0;
    while (k + 1 < kForceClasses && b.fn / mean >= kForceClassBounds[k + 1]) ++k;
    classes[k] += fmt::format("{} {} {} {}\n", toml_num(b.xa), toml_num(b.ya), toml_num(b.xb - b.xa),
                              toml_num(b.yb - b.ya));
  }
  if (!std::isfinite(x0)) throw AnalysisError(fmt::format("'{}': nothing to draw in {}", run, pfile));
  // A margin of 2 % around what is drawn; pixels square.
  const double m = 0.02 * std::max(x1 - x0, y1 - y0);
  pic.x0 = x0 - m, pic.x1 = x1 + m, pic.y0 = y0 - m, pic.y1 = y1 + m;
  pic.width = opt.width;
  pic.height = std::max(1, static_cast<int>(std::lround(opt.width * (pic.y1 - pic.y0) / (pic.x1 - pic.x0))));

  const fs::path abs = fs::absolute(png);
  fs::create_directories(abs.parent_path());
  const fs::path base = fs::path(abs).replace_extension();
  write_text(base.string() + "_grains.dat", grains);
  std::string plot = fmt::format("plot '{}_grains.dat' with lines lw 1 lc rgb '#404040'",
                                 base.filename().string());
  for (int k = 0; k < kForceClasses; ++k) {
    if (classes[k].empty()) continue;
    const std::string f = fmt::format("{}_forces{}.dat", base.string(), k);
    write_text(f, classes[k]);
    plot += fmt::format(", \\\n     '{}' with vectors nohead lw {} lc rgb '{}'", fs::path(f).filename().string(),
                        kForceClassWidth[k], kForceClassColour[k]);
  }
  pic.png = png;
  pic.script = base.string() + ".gp";
  const std::string script = fmt::format(
      "# cdanalysis draw: {} and {}{}\n"
      "# grains as drawn (outlines), force-bearing contacts as bars centre to centre, width and colour by\n"
      "# fn/<fn> in [0,1) [1,1.5) [1.5,2) [2,3) [3,inf), <fn> = {} over {} contacts. Rerun: gnuplot {}\n"
      "cd '{}'\nset terminal pngcairo size {},{} background '#ffffff'\nset output '{}'\n"
      "set lmargin at screen 0\nset rmargin at screen 1\nset bmargin at screen 0\nset tmargin at screen 1\n"
      "unset border\nunset tics\nunset key\nset xrange [{}:{}]\nset yrange [{}:{}]\n{}\nunset output\n",
      pfile, cfile, dim == 3 ? fmt::format(" (slice z = {:.6g}, contacts within {:.3g} of it)", zmid, half) : "",
      toml_num(mean), bars.size(), fs::path(pic.script).filename().string(), abs.parent_path().string(),
      pic.width, pic.height, abs.filename().string(), toml_num(pic.x0), toml_num(pic.x1), toml_num(pic.y0),
      toml_num(pic.y1), plot);
  write_text(pic.script, script);
  pic.gnuplot_ok = run_gnuplot(pic.script);
  return pic;
}

}  // namespace cda
