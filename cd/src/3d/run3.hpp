// A 3D run: World3 in the shared run loop (core/run_loop.hpp), with its
// checkpoints (checkpoint3.hpp), snapshots (output3.hpp) and watchdog. The
// plan (series rows, snapshots, checkpoints, scene key) is core/run_plan.hpp's,
// as 2D's.
#pragma once
#include "run_loop.hpp"
#include "scene.hpp"
#include "world3.hpp"

namespace cd {

// The watchdog: the first non-finite position, orientation, velocity or
// impulse of w, or "".
std::string non_finite3(const World3& w);

// Largest overlap of the last step's contacts over the smaller grain's
// diameter (a wall contact: the sphere's), as 2D's max_overlap_small.
double max_overlap_small3(const World3& w);

// The series columns of a tri-periodic cell (docs/3d.md, "Periodic cell
// columns"; definitions in core/observables.hpp): shear_rate; the contact
// stress S (the caller's interval mean; compression positive) as sxx, sxy,
// sxz, syx, ..., szz; p = tr S/3; q = sqrt(3/2 s:s) of its symmetric part;
// q_over_p; shear_stress_ratio mu = -(S_xy + S_yx)/2 / S_yy (> 0 for shear
// along +x with gradient y); inertial_number gd d sqrt(rho/(S_yy + K_yy));
// packing_fraction; z and non_rattler (rattlers: fewer than 2 force-bearing
// contacts, removed recursively, as in 2D); cell_width, cell_height,
// cell_depth (L_x, L_y, L_z); kxx, kxy, kxz, kyy, kyz, kzz (kinetic stress
// at the row's step).
Columns cell_columns3(const World3& w, const Eigen::Matrix3d& S, double density, double d_mean);

// The coordination of the last step's contacts, the particles being the dynamic bodies.
obs::Coordination coordination3(const World3& w);

// As 2D's run (run.hpp): resumes from out/checkpoint.bin if there is one.
RunSummary run3(World3& w, const Scene& s, const RunOptions& opt);

}  // namespace cd
