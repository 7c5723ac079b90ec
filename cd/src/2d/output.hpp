// VTK snapshots of a 2D run (particles, contacts, walls, shapes) with one
// .pvd collection each; the folder checks, atomic writes and series.csv are
// core/files.hpp. Every file is written to a temporary name and renamed into
// place, so a reader (or a killed run) never sees a half-written file.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "files.hpp"
#include "world.hpp"

namespace cd {

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
