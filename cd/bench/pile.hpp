// Benchmark scenes: a dense, disordered pile of N disks in a box, built
// geometrically so that even N = 1e5 costs well under a second to prepare.
//
// Sequential deposition (Visscher & Bolsterli, Nature 239, 1972): each disk
// falls at a random abscissa, then rolls down on the disks it meets until it
// rests on two of them, on the floor, or against a side wall. The result is
// a gravitationally stable random packing (packing fraction ~0.8) whose
// contacts touch exactly, so the contact dynamics only has to build the
// force network: no settling run. Rejected: settling a loose lattice under
// gravity with the simulator itself, which takes minutes at N = 1e4 and
// hours at 1e5, and a monodisperse hexagonal crystal, whose uniform,
// hyperstatic force network is not representative of granular piles.
#pragma once
#include <vector>

#include "scene.hpp"
#include "world.hpp"

namespace cdbench {

struct Pile {
  double width = 0, height = 0;  // box width; top of the highest disk
  std::vector<cd::Vec2> x;
  std::vector<double> r;
};

// Deposits disks of the given diameters (in that order) in a box of the given
// width, abscissae drawn from the seed. Deterministic.
Pile deposit(const std::vector<double>& diameters, double width, unsigned seed);

// The default scene's settings (cd::Scene defaults: d = 1 mm, size ratio 2,
// mu = 0.4, dt = 1e-4 s, eps_f = 1e-4, g = 9.81) with n generated disks.
cd::Scene pile_scene(int n, unsigned seed = 1);

// A deposited pile of the scene's disks in a box (floor and two side walls)
// about `aspect` times as wide as deep, with the scene's parameters. No step
// has been taken.
cd::World pile_world(const cd::Scene& s, double aspect = 1.0);

// Settles a pile built by pile_world. The deposit is stable disk by disk but
// not under the weight of the disks above: a few percent of the disks give
// way and the pile creeps for ~0.1 s. A quick densification at coarse
// settings (dt = 5e-4 s, eps_f = 1e-3, 600 steps: ~6 s for N = 1000) lets it
// collapse to a static state (kinetic energy down by 3 decades, overlaps
// about 1 % of d; dt = 1e-3 s left 10 %), then 50 steps at the scene's own
// settings rebuild its force network. A few rattlers may still creep.
void settle(cd::World& w);

// Width of the box (the floor spans [0, width]).
double box_width(const cd::World& w);

// A settled pile of n regular polygons of `sides` sides (circumscribed
// diameters drawn as pile_scene's disk diameters), about as wide as deep.
// Deposition does not generalise to polygons, so the scene's lattice
// (build_world: jittered square lattice of pitch 1.02 d_max, random
// orientations) collapses in a box under gravity, at the coarse settings of
// settle() (dt = 5e-4 s, eps_f = 1e-3) plus an overlap correction
// (beta = 0.2: the impacts overlap 25 % d otherwise) for `coarse_steps`
// steps, then 50 steps at the scene's own settings rebuild the force network
// (max overlap ~0.3 % d). The lattice is filled row by row, so the numbering
// stays close to spatial order. ~10 s for n = 1000 on one core.
cd::World polygon_pile(int n, int sides, int coarse_steps = 300, unsigned seed = 1);

// Side by side copies of a settled pile in one box, every other copy
// mirrored, so that a disk that leaned on a side wall now faces its mirror
// image across the joint: the packing and the normal forces stay balanced,
// only the wall friction is lost at the joints. Copies are spaced by the
// extent of the disks, so that overlaps with the old walls do not become
// overlaps between copies. Velocities are zeroed and the warm start is lost:
// take a few steps before timing. Polygons are copied as polygons (mirrored
// copies with the mirrored orientation).
cd::World tile(const cd::World& base, int copies);

// Vertical force of the walls on the particles over the last step
// (sum of wall-row impulses / dt).
double wall_force_y(const cd::World& w);

// Total weight of the dynamic bodies, |m g|.
double total_weight(const cd::World& w);

}  // namespace cdbench
