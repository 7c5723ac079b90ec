// cdanalysis draw RUN: a PNG of one snapshot, grains and force chains,
// without ParaView (picture.hpp).
#include <fmt/core.h>

#include <filesystem>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/picture.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {

Handler draw(CLI::App& sub) {
  struct Opt {
    std::string run, out;
    PictureOptions pic;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("run", o->run, "run folder (particles or spheres and contacts snapshots)")->required();
  sub.add_option("--snapshot", o->pic.snapshot, "snapshot index (negative: from the end)")->capture_default_str();
  sub.add_option("--width", o->pic.width, "image width in pixels (the height follows the drawn region)")
      ->check(CLI::Range(100, 20000))
      ->capture_default_str();
  sub.add_option("--out", o->out, "PNG file (default: RUN/picture_NNNNN.png, NNNNN the snapshot's number)")
      ->check(writable_file());
  return [o] {
    std::string out = o->out;
    if (out.empty()) {
      const std::string p = snapshot_path(o->run, particles_prefix(run_dimension(o->run)), o->pic.snapshot);
      const std::string stem = std::filesystem::path(p).stem().string();
      out = (std::filesystem::path(o->run) / ("picture" + stem.substr(stem.find('_')) + ".png")).string();
    }
    const Picture p = draw_snapshot(o->run, out, o->pic);
    fmt::print("{} grains{}, {} force-bearing contacts as bars (width and colour by normal force) from {} and {}\n",
               p.grains, p.z_mid != 0 || run_dimension(o->run) == 3 ? fmt::format(" cut by z = {:.4g}", p.z_mid) : "",
               p.bars, p.particles, p.contacts);
    if (!p.gnuplot_ok) throw AnalysisError(fmt::format("gnuplot failed on {} (see {}.log)", p.script, p.script));
    fmt::print("picture: {}\n", p.png);
    return 0;
  };
}

}  // namespace cda::cli
