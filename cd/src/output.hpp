// Run outputs in one folder: the resolved scene, the time series, and VTK
// snapshots (particles, contacts, walls) with one .pvd collection each.
// Every file is written to a temporary name and renamed into place, so a
// reader (or a killed run) never sees a half-written file.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "world.hpp"

namespace cd {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws OutputError naming the folder if it cannot be created or written.
// Creates nothing: it checks the nearest existing ancestor.
void check_output_dir(const std::string& dir);

// Writes `text` to `path` atomically (temporary file, then rename).
void write_file_atomic(const std::string& path, const std::string& text);

// series.csv: one row per output interval, columns named by the first row.
class Series {
 public:
  explicit Series(const std::string& path);
  // Continues a file that already holds the header `names` and earlier rows
  // (a restart): nothing is truncated and no header is written again.
  Series(const std::string& path, std::vector<std::string> names)
      : path_(path), names_(std::move(names)) {}
  void row(const std::vector<std::pair<std::string, double>>& cols);
  void flush();

 private:
  std::string path_;
  std::vector<std::string> names_;
  std::string buf_;
};

// VTK snapshots through VTK's XML writers (binary, zlib-compressed):
//   particles_NNNNN.vtp  points, one per particle: id, radius, velocity, omega, angle,
//                        mass, nsides (0 for disks)
//   contacts_NNNNN.vtp   lines from centre to centre (to the touched periodic
//                        image across a boundary): fn, ft, force vector, normal,
//                        status (0 open, 1 stick, 2 slide), type, gap, b1, b2,
//                        branch (centre of b1 to the touched image of b2)
//   walls_NNNNN.vtp      wall segments as lines
//   shapes_NNNNN.vtp     true outlines: one polygon cell per particle (disks
//                        as 36-gons): id, nsides, velocity, omega
// and particles.pvd, contacts.pvd, walls.pvd, shapes.pvd (rewritten
// atomically after each snapshot, so they list only complete files).
class Snapshots {
 public:
  explicit Snapshots(const std::string& dir);
  // Continues after a restart: `frames` (time, number) are already written;
  // the collections list them again from the next snapshot on.
  Snapshots(const std::string& dir, std::vector<std::pair<double, std::string>> frames)
      : dir_(dir), n_(static_cast<int>(frames.size())), frames_(std::move(frames)) {}
  void write(const World& w);
  int count() const { return n_; }

 private:
  std::string dir_;
  int n_ = 0;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace cd
