// The few scene parameters the analysis needs, read from a run's resolved
// scene.toml (written by cdsim next to series.csv). Read through toml11, the
// simulator's own parser, so the two never disagree on the syntax.
#pragma once
#include <optional>
#include <string>

#include "error.hpp"

namespace cda {

struct SceneInfo {
  std::string file;
  // The top-level `dimension` (2 or 3; absent: 2, cdsim's default). Every
  // command reads it before it interprets series columns or snapshots.
  int dimension = 2;
  std::optional<double> cohesion_number;   // [contact] cohesion_number (eta; 0: cohesionless)
  // [shear] inertial_number (imposed I); empty under volume control, where
  // no I is imposed (the series' inertial_number is the measured one).
  std::optional<double> inertial_number;
  std::optional<double> pressure;          // [shear] pressure
  // [particles] nsides: sides of the polygons (0: disks). Set when the array
  // holds one value (or is a plain integer); a mixture of shapes leaves it
  // empty and sets nsides_mixed.
  std::optional<int> nsides;
  bool nsides_mixed = false;
  std::optional<double> friction;          // [contact] mu (interparticle friction)
  std::optional<double> solver_tol;        // [solver] tol (NLGS convergence)
  std::optional<std::string> shear_mode;   // [shear] mode (none, periodic, walls)
  // [shear] control = "volume": the cell's lengths held (the packing
  // fraction imposed, exact), the shear rate imposed, p and I measured.
  bool volume_control = false;
  std::optional<double> volume_fraction;   // [shear] volume_fraction (0: the sample's as it was)
};

// The angularity of a shape with n sides, alpha = 2 pi/n (disks, n = 0: 0).
double angularity_of(int nsides);

// Throws AnalysisError naming the folder when scene.toml is missing, or the
// file when it does not parse or a key has a non-numeric value. Absent keys
// are left empty: the caller says which ones it needs (require()).
SceneInfo read_scene_info(const std::string& run_dir);

// The dimension of a run: its scene.toml's `dimension` (2 when the key is
// absent), or 2 when the folder has no scene.toml (synthetic 2D series).
// Throws InputError when the scene does not parse or the key is not 2 or 3.
int run_dimension(const std::string& run_dir);

// AnalysisError "<what> is 2D only: '<run>' is a 3D run (dimension = 3 in its
// scene.toml)" when the run is 3D: the commands whose definitions have no
// 3D form yet call it before reading anything.
void refuse_3d(const std::string& run_dir, const std::string& what);

// The value of an optional field, or an AnalysisError naming the file and
// the key ("[contact] cohesion_number").
double require(const SceneInfo& s, const std::optional<double>& v, const std::string& key);

}  // namespace cda
