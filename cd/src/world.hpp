// World: bodies, per-scene settings, and the time step as a list of named,
// timed stages (method.md section 6, midpoint scheme):
//   predict    r_m = r + dt/2 U-
//   detect     contacts at the midpoint configuration
//   build      W blocks, law offsets (gap, restitution), warm start
//   external   U_free = U- + dt M^-1 F_ext   (only if the scene has gravity)
//   solve      NLGS on the coloured rows
//   integrate  r+ = r_m + dt/2 U+
// Stages a scene does not need are not run; the law is fixed once per scene.
#pragma once
#include <cstdint>
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"
#include "detect.hpp"
#include "nlgs.hpp"

namespace cd {

struct WorldParams {
  double dt = 1e-4;
  Vec2 gravity{0.0, 0.0};
  double mu = 0.0, mu_wall = 0.0;
  double e_n = 0.0, e_t = 0.0;
  double alert = 0.0;     // absolute alert distance
  // Overlap correction beta: an overlapping contact must separate at
  // beta |g|/dt (0: pure CD, overlaps are never pushed apart). The velocity
  // it gives persists, so it injects energy; its work p_n beta |g|/dt, an
  // upper bound of that energy, is reported in StepStats::correction_work.
  double overlap_correction = 0.0;
  // Adhesion-shifted Signorini law (method.md section 2): pull-off force f_a
  // on every contact whose midpoint gap is <= debond (absolute); 0: none.
  double adhesion = 0.0, debond = 0.0;
  double d_ref = 1.0;     // length scale for overlaps (mean diameter)
  SolverParams solver;
};

struct StageTimes {  // wall-clock seconds, accumulated
  double detect = 0, solve = 0, integrate = 0, output = 0;
};

struct StepStats {
  SolveStats solve;
  int contacts = 0;        // rows handed to the solver
  int active = 0;          // rows carrying a force (p_n + a > 0)
  double max_overlap = 0;  // max over contacts of -gap / d_ref (midpoint configuration)
  double mean_overlap = 0; // mean of -gap / d_ref over overlapping contacts
  double correction_work = 0;  // sum of p_n x bias velocity of the overlap correction (J)
};

class World {
 public:
  explicit World(const WorldParams& p) : prm_(p) { configure(); }

  Bodies bodies;
  double time = 0.0;
  std::int64_t steps = 0;
  StageTimes times;

  const WorldParams& params() const { return prm_; }
  // Re-reads the parameters (call after changing them).
  void set_params(const WorldParams& p) {
    prm_ = p;
    configure();
  }

  void step();
  const StepStats& last() const { return last_; }
  const std::vector<ContactRow>& rows() const { return rows_; }
  const std::vector<ContactInfo>& infos() const { return info_; }

  double kinetic_energy() const;
  double potential_energy() const;  // -m g.r summed over dynamic bodies

  // Status of a solved row: open, stick or slide.
  ContactStatus status(std::size_t k) const;

  // Warm-start memory: the previous step's impulses by contact key (sorted).
  // Part of the state a bit-identical restart must restore.
  struct WarmStart {
    std::vector<std::uint64_t> keys;
    std::vector<std::pair<double, double>> p;
  };
  const WarmStart& warm_start() const { return warm_; }
  void set_warm_start(WarmStart w) { warm_ = std::move(w); }

 private:
  void configure();
  void predict();
  void detect_stage();
  void build();
  void external();
  void solve();
  void integrate();

  WorldParams prm_;
  bool gravity_on_ = false, restitution_on_ = false, adhesion_on_ = false;
  bool forces_on_ = false, prepared_ = false;  // forces_on_: some body has an applied force
  double alert_ = 0.0;
  StepStats last_;
  std::vector<Vec2> xm_;
  std::vector<double> thm_;
  std::vector<ContactRow> rows_;
  std::vector<ContactInfo> info_;
  CellGrid grid_;
  Colouring col_;
  WarmStart warm_;
};

}  // namespace cd
