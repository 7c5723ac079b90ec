// Contact and particle snapshots as plain data, read from the simulator's
// contacts_NNNNN.vtp / particles_NNNNN.vtp (format in cd/src/2d/output.hpp).
//
// Frame convention (method.md §1): n points from body 1 to body 2 and
// t = n rotated by +90 degrees; f = fn n + ft t is the force exerted by body 1
// on body 2 (fn > 0 repulsive); the branch vector l points from the centre of
// body 1 to the centre of body 2 (periodic image included).
#pragma once
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cd/src/core/observables.hpp"
#include "error.hpp"

namespace cda {

struct Contact {
  double theta = 0;       // angle of n, in (-pi, pi]
  double lx = 0, ly = 0;  // branch vector, body 1 -> body 2
  double fn = 0, ft = 0;  // force components in (n, t)
  int status = 0;         // 0 open, 1 stick, 2 slide
  int type = 0;           // 0 disk, 1 side-vertex, 2 side-side
  int b1 = 0, b2 = 0;     // body ids

  double nx() const;
  double ny() const;
  double ln() const;  // l.n
  double lt() const;  // l.t
};

using ContactSet = std::vector<Contact>;

struct Particle {
  int id = 0;
  double x = 0, y = 0, z = 0;  // z: 3D (spheres) snapshots; 0 in 2D
  double radius = 0;
  double vx = 0, vy = 0, vz = 0, omega = 0, angle = 0, mass = 0;  // omega: 2D only (0 in 3D)
  int nsides = -1;  // 0 disk, n polygon; -1: the snapshot has no nsides array
};

using ParticleSet = std::vector<Particle>;

// Contacts of one type (0 disk, 1 sv, 2 ss).
ContactSet of_type(const ContactSet& cs, int type);

// The points of a side-side contact (same bodies, type 2) merged into one
// physical contact: forces summed (method.md §7), normal and branch of the
// first point. Other contacts are copied as they are. Fabric statistics use
// physical contacts; stress may use either (the sum is the same).
ContactSet merge_side_side(const ContactSet& cs);

// The contacts as observables.hpp takes them (same order): the stress,
// force-bearing and coordination definitions shared with cdsim.
std::vector<cd::obs::Contact<2>> as_forces(const ContactSet& cs);

// A contact row of a 3D snapshot (cd/src/3d/output3.cpp, docs/outputs.md):
// the shared observables' contact (bodies, unit normal n from body 1 to
// body 2, fn, the tangential force vector ft on body 2, the branch vector l),
// the status flag (0 open, 1 stick, 2 slide) and the kind (the `kind`
// array, 0 when absent). A sphere pair is one row; a polyhedra pair is one
// row per contact point (1 to 4), the points sharing the pair's normal and
// branch. A wall contact's branch runs from the wall to the grain's centre.
struct Contact3 {
  cd::obs::Contact<3> c;
  int status = 0;
  int kind = 0;
};
using ContactSet3 = std::vector<Contact3>;

// The kinds of the `kind` array: a sphere's row, then a polyhedron's
// contact by the features that touch (1 + cd's PolyContactKind); a sphere
// on a polyhedron's face is a VertexFace, on its edge or vertex the last two.
enum class Kind3 { Sphere = 0, VertexFace = 1, EdgeFace = 2, FaceFace = 3, EdgeEdge = 4, SphereEdge = 5, SphereVertex = 6 };
inline constexpr int kKinds3 = 7;
const char* kind3_name(int kind);  // "sphere", "vertex-face", ...; "unknown" out of range

// The points of a polyhedra pair (same bodies, kind > 0) merged into one
// physical contact: forces summed, normal, branch and kind of the first
// point, sliding if any point slides (2D's merge_side_side in 3D). Sphere
// rows are copied as they are. The order is the first points' order.
ContactSet3 merge_points3(const ContactSet3& cs);
std::vector<cd::obs::Contact<3>> as_forces(const ContactSet3& cs);

// Readers. Throw AnalysisError naming the file when it is missing, unreadable,
// or lacks a required array. The branch vector comes from the cell array
// `branch` when present (periodic runs), else from the line's two points.
// read_contacts refuses a 3D snapshot (a 3-component ft, or a normal
// with a z component) by name, and read_contacts3 a 2D one: neither reads
// the other's data as its own.
ContactSet read_contacts(const std::string& vtp_path);
ContactSet3 read_contacts3(const std::string& vtp_path);
ParticleSet read_particles(const std::string& vtp_path);
// The snapshot `stem`_NNNNN.vtp beside a snapshot <any>_NNNNN.vtp (the
// same number: cdsim writes a step's files together), if it exists.
std::optional<std::string> companion_snapshot(const std::string& snapshot, const std::string& stem);
// The bodies of a 3D polyhedra snapshot (polyhedra_NNNNN.vtp: one cell per
// face), one per body in the order of their first face: id, centre (the
// `centre` array), circumradius, velocity.
ParticleSet read_polyhedra(const std::string& vtp_path);
// The sections of those bodies by the plane z = z0: per body id that the
// plane cuts, the corners of its section (a convex polygon: the crossings
// of its faces' edges), in counter-clockwise order about their mean.
std::map<int, std::vector<std::array<double, 2>>> polyhedra_sections(const std::string& vtp_path, double z0);

// Writers of the same format, for synthetic fixtures (tests, examples).
// Contact lines start at the centre of body b1 (from `centres`, the origin
// if absent) and end at that centre plus the branch vector; with_branch
// also writes the `branch` cell array of periodic runs.
void write_contacts(const std::string& vtp_path, const ContactSet& cs,
                    const ParticleSet& centres, bool with_branch = true);
void write_particles(const std::string& vtp_path, const ParticleSet& ps);
// cdsim's 3D format: lines from x2 - l to x2 (x2 = body 2's centre in
// `centres`, the origin if absent), no `branch` array, as output3.cpp.
void write_contacts3(const std::string& vtp_path, const ContactSet3& cs, const ParticleSet& centres);

// The area of a 2D particle between the heights lo and hi (lo <= hi): a
// disk's (nsides 0, or -1: no nsides array) by its circular segments, a
// regular polygon's (circumradius `radius`, vertex k at angle + 2 pi k / n,
// cdsim's convention) by clipping it to the band. The area in a band
// counted this way sums to the grains' area over any tiling of the heights,
// where counting whole grains by their centre is off by the grains cut by
// the band's edges.
double area_in_band(const Particle& p, double lo, double hi);

// The prefix of the particle snapshots: "particles" in 2D, "spheres" in 3D.
inline const char* particles_prefix(int dimension) { return dimension == 3 ? "spheres" : "particles"; }

// Snapshot files of a run folder, sorted by their number:
// prefix "contacts" lists contacts_NNNNN.vtp. Throws if the folder is missing.
std::vector<std::string> list_snapshots(const std::string& run_dir, const std::string& prefix);
// The k-th snapshot (k < 0 counts from the end: -1 is the last). Throws with
// the folder name when there is none or k is out of range.
std::string snapshot_path(const std::string& run_dir, const std::string& prefix, int k);

}  // namespace cda
