// A picture of one snapshot of a run without ParaView: the
// grains with their true outlines (disks as circles, polygons with their
// sides at their orientation) and the force chains, every force-bearing
// contact a bar between the two centres (to the touched periodic image, or
// from the contact point on a wall), thicker and darker for a larger normal
// force, drawn by gnuplot into a PNG. A 2D wall contact (the wall is not a
// grain) is a bar from the grain's centre to its edge along the normal. A 3D run is drawn as a slice: the
// spheres cut by the plane z = z_mid (circles of radius sqrt(r^2 - dz^2))
// and the contacts whose two ends lie within one mean radius of the plane,
// projected on it.
#pragma once
#include <string>

namespace cda {

struct PictureOptions {
  int snapshot = -1;      // index of the particles/contacts pair (negative: from the end)
  int width = 1000;       // pixels; the height follows the drawn region's aspect
};

struct Picture {
  std::string png, script;        // written files
  std::string particles, contacts;  // the snapshots drawn
  int width = 0, height = 0;      // pixels
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // the region drawn (data units): pixel (0, 0) is (x0, y1)
  double z_mid = 0;               // 3D: the plane of the slice
  std::size_t grains = 0, bars = 0;
  bool gnuplot_ok = false;
};

// Number of force classes and, for each, its bar width (px) and colour:
// class k holds the contacts with fn / <fn> in [kForceClassBounds[k],
// kForceClassBounds[k + 1]) (<fn> the mean over force-bearing contacts).
inline constexpr int kForceClasses = 5;
extern const double kForceClassBounds[kForceClasses + 1];
extern const char* const kForceClassColour[kForceClasses];  // "#rrggbb"

// Draws snapshot opt.snapshot of run_dir into png_path (and png_path with
// .gp for the script, .dat files beside it). Throws AnalysisError naming the
// run when it has no particles/spheres or contacts snapshot.
Picture draw_snapshot(const std::string& run_dir, const std::string& png_path, const PictureOptions& opt = {});

}  // namespace cda
