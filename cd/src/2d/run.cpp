#include "run.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "output.hpp"
#include "problem.hpp"
#include "setup.hpp"

namespace cd {

namespace {

// The watchdog: the first non-finite quantity of the state a step left, or
// "". O(bodies + contacts), a few per cent of a step's detection.
std::string non_finite(const World& w) {
  const Bodies& b = w.bodies;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (!std::isfinite(b.pos[i].x()) || !std::isfinite(b.pos[i].y()) || !std::isfinite(b.angle[i]))
      return fmt::format("body {}: position ({}, {}), angle {}", i, b.pos[i].x(), b.pos[i].y(), b.angle[i]);
    if (!std::isfinite(b.vel[i].vx) || !std::isfinite(b.vel[i].vy) || !std::isfinite(b.vel[i].w))
      return fmt::format("body {}: velocity ({}, {}), angular velocity {}", i, b.vel[i].vx,
                         b.vel[i].vy, b.vel[i].w);
  }
  const auto& rows = w.rows();
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (!std::isfinite(rows[k].pn) || !std::isfinite(rows[k].pt))
      return fmt::format("contact {} (bodies {} and {}): impulses p_n = {}, p_t = {}", k,
                         rows[k].b1, rows[k].b2, rows[k].pn, rows[k].pt);
  const CellState& c = w.cell;
  for (const double x : {c.width, c.height, c.offset, c.hdot, c.wdot, c.strain})
    if (!std::isfinite(x))
      return fmt::format("cell: width {}, height {}, offset {}, rates ({}, {}), strain {}", c.width,
                         c.height, c.offset, c.wdot, c.hdot, c.strain);
  return "";
}

// Coordination of the last step's contacts, by obs::coordination (the
// definitions are in observables.hpp): the particles are the dynamic bodies.
obs::Coordination coordination(const World& w) {
  std::vector<std::int32_t> particles;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) particles.push_back(static_cast<std::int32_t>(i));
  return obs::coordination<2>(w.contact_forces(), particles);
}

// Packing fraction, obs::packing_fraction: the particles' areas and half of
// each wall grain's (its centre is on the cell's edge), over the cell area V.
double packing_fraction(const Bodies& b, double V) {
  std::vector<double> area, weight;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.shape[i] == Shape::Segment) continue;
    area.push_back(obs::particle_area(b.radius[i], b.nsides[i]));
    weight.push_back(b.is_dynamic(i) ? 1.0 : 0.5);
  }
  return obs::packing_fraction(area, weight, V);
}

// The walls protocol's bulk: the central half of the gap between the
// walls' grain centres, [H/4, 3H/4], away from the layering the walls
// impose on the first grains.
struct Band {
  double lo, hi;
  explicit Band(const World& w) : lo(0.25 * w.cell.height), hi(0.75 * w.cell.height) {}
  double area(const World& w) const { return w.cell.width * (hi - lo); }
  bool holds(double y) const { return y >= lo && y < hi; }
  // The share of a branch vector from height y to y + ly inside the band
  // (a contact's share of the band's stress: the stress of a sub-volume by
  // the cut branch vectors, whose average over the heights is the cell's).
  double share(double y, double ly) const {
    if (std::abs(ly) <= 1e-12 * (hi - lo)) return holds(y) ? 1.0 : 0.0;
    const double a = std::min(y, y + ly), b = std::max(y, y + ly);
    return std::max(0.0, std::min(b, hi) - std::max(a, lo)) / (b - a);
  }
};

// What the walls protocol measures besides the cell's stress, on one step:
// the force the sample exerts on the top wall's grains, and the band's
// contact stress (Love-Weber over the band's share of each branch vector).
struct WallsStep {
  Vec2 top_force = Vec2::Zero();
  Eigen::Matrix2d bulk = Eigen::Matrix2d::Zero();
};
WallsStep walls_step(const World& w) {
  std::vector<char> top(w.bodies.size(), 0);
  for (const std::int32_t i : w.top_wall) top[static_cast<std::size_t>(i)] = 1;
  const Band band(w);
  WallsStep m;
  std::vector<obs::Contact<2>> cs = w.contact_forces();
  for (obs::Contact<2>& c : cs) {
    const obs::Vec<2> f = c.force();  // on body 2
    if (top[static_cast<std::size_t>(c.b2)]) m.top_force += Vec2(f[0], f[1]);
    if (top[static_cast<std::size_t>(c.b1)]) m.top_force -= Vec2(f[0], f[1]);
    const double k = band.share(w.bodies.pos[c.b1].y(), c.l[1]);
    c.fn *= k;
    for (double& x : c.ft) x *= k;
  }
  const auto S = obs::contact_stress<2>(cs, band.area(w));
  m.bulk << S[0][0], S[0][1], S[1][0], S[1][1];
  return m;
}

// Protocol columns: stress averaged over the steps of the interval (and,
// between walls, the top wall's traction and the bulk's stress).
struct ShearInterval {
  int steps = 0;
  Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  WallsStep walls;
  void add(const World& w, bool between_walls) {
    ++steps;
    sigma += w.contact_stress();
    if (!between_walls) return;
    const WallsStep m = walls_step(w);
    walls.top_force += m.top_force;
    walls.bulk += m.bulk;
  }
};

// The 2D world as the run loop sees it: checkpoints, snapshots, the
// --dump-problem files and the shear protocols' columns.
class Engine2 final : public RunEngine {
 public:
  Engine2(World& w, const Scene& s, const RunOptions& opt)
      : w_(w), s_(s), dir_(opt.out), dump_(opt.dump_steps), shear_(s.shear_mode != ShearMode::None),
        walls_(s.shear_mode == ShearMode::Walls),
        d_mean_(w.params().d_ref) {
    // --dump-problem: the hook sees the problem of the step being taken
    // (w.steps + 1) just before its solve. Each file is written whole under
    // a temporary name and renamed (a failure is a WriteError naming it).
    if (!dump_.empty())
      w_.set_problem_hook([this](const ContactProblem& p, const SolverParams& prm) {
        const std::int64_t k = w_.steps + 1;
        if (!dumped(k)) return;
        const std::string stem = (dir_ / fmt::format("problem_{}", k)).string();
        std::ostringstream cdp;
        write_contact_problem(p, prm, cdp);
        write_file_atomic(stem + ".cdp", cdp.str());
        const bool cohesive = std::any_of(p.rows.begin(), p.rows.end(),
                                          [](const ContactRow& r) { return r.adh != 0.0; });
        if (cohesive) return;
        std::ostringstream dat;
        write_problem(to_matrix(p), dat);
        write_file_atomic(stem + ".dat", dat.str());
      });
  }

  void step() override { w_.step(); }
  const StepStats& last() const override { return w_.last(); }
  std::int64_t steps() const override { return w_.steps; }
  double time() const override { return w_.time; }
  StageTimes& times() override { return w_.times; }
  double kinetic_energy() const override { return w_.kinetic_energy(); }
  std::string non_finite() const override { return cd::non_finite(w_); }
  void save(const std::string& path, std::uint64_t key, const RunTotals& t) const override {
    save_checkpoint(path, w_, key, t);
  }
  std::uint64_t load(const std::string& path, RunTotals* t) override {
    return load_checkpoint(path, w_, t);
  }
  void open_snapshots(const std::string& dir, Frames frames) override {
    snaps_ = frames.empty() ? Snapshots(dir) : Snapshots(dir, std::move(frames));
  }
  void write_snapshot() override { snaps_.write(w_); }

  void start() override {
    v_prev_ = w_.cell.width * w_.cell.height;
    t_prev_ = w_.time;
  }
  void after_step(std::int64_t k) override {
    if (dumped(k)) {
      std::string text;
      for (const ContactRow& r : w_.rows()) text += fmt::format("{:a} {:a}\n", r.pn, r.pt);
      write_file_atomic((dir_ / fmt::format("problem_{}.impulses", k)).string(), text);
    }
    if (shear_) sh_.add(w_, walls_);
  }
  void add_columns(Columns& cols) override {
    if (!shear_) return;
    // Contact stress (mean over the interval's steps), compression
    // positive; p = (s1 + s2)/2, q = (s1 - s2)/2 from the symmetric part.
    const Eigen::Matrix2d S = sh_.sigma / sh_.steps;
    const double sxx = S(0, 0), syy = S(1, 1), sxy = 0.5 * (S(0, 1) + S(1, 0));
    const obs::Tensor<2> St = {{{S(0, 0), S(0, 1)}, {S(1, 0), S(1, 1)}}};
    const double p = obs::mean_2d(St), q = obs::deviator_2d(St);
    const double V = w_.cell.width * w_.cell.height;
    const double gd = w_.shear_rate();
    const obs::Coordination zc = coordination(w_);
    const Eigen::Matrix2d K = w_.kinetic_stress();  // at the row's step
    cols.insert(cols.end(), {{"strain", w_.cell.strain},
                {"shear_rate", gd},
                {"sxx", sxx},
                {"sxy", S(0, 1)},
                {"syx", S(1, 0)},
                {"syy", syy},
                {"p", p},
                {"q", q},
                {"q_over_p", p > 0 ? q / p : 0.0},
                // tau / sigma_n, positive in the imposed sense (the
                // top moves +x, so sigma_xy < 0 compression-positive)
                {"shear_stress_ratio", syy > 0 ? -sxy / syy : 0.0},
                // with the whole normal stress, the one the control imposes
                {"inertial_number", syy + K(1, 1) > 0
                                        ? gd * d_mean_ * std::sqrt(s_.density / (syy + K(1, 1)))
                                        : 0.0},
                {"packing_fraction", V > 0 ? packing_fraction(w_.bodies, V) : 0.0},
                {"z", zc.z},
                {"non_rattler", zc.non_rattler},
                {"cell_width", w_.cell.width},
                {"cell_height", w_.cell.height},
                {"volume_strain_rate",
                 w_.time > t_prev_ ? std::log(V / v_prev_) / (w_.time - t_prev_) : 0.0},
                {"kxx", K(0, 0)},
                {"kxy", K(0, 1)},
                {"kyy", K(1, 1)}});
    if (walls_) add_walls_columns(cols);
    v_prev_ = V;
    t_prev_ = w_.time;
    sh_ = ShearInterval{};
  }

 private:
  // The walls protocol (shear.mode = "walls", docs/shear.md): the traction
  // the sample exerts on the top wall, per length, compression positive
  // (wall_sigma = F_y / W, which the wall's control holds at p on average)
  // and in the sense of the shear (wall_tau = -F_x / W: the sample drags the
  // wall back), both means over the interval's steps; and the bulk, the
  // central half of the gap: its contact stress (interval mean), and at the
  // row's step its packing fraction (grains whose centre is in it) and z
  // (their force-bearing contacts, rattlers out).
  void add_walls_columns(Columns& cols) const {
    const double W = w_.cell.width, n = sh_.steps;
    const Vec2 F = sh_.walls.top_force / n;
    const Eigen::Matrix2d B = sh_.walls.bulk / n;
    const double tau = -F.x() / W, sigma = F.y() / W;
    const double bxy = 0.5 * (B(0, 1) + B(1, 0));
    const obs::Tensor<2> Bt = {{{B(0, 0), B(0, 1)}, {B(1, 0), B(1, 1)}}};
    const double bp = obs::mean_2d(Bt), bq = obs::deviator_2d(Bt);
    const Band band(w_);
    std::vector<std::int32_t> inside;
    double area = 0.0;
    for (std::size_t i = 0; i < w_.bodies.size(); ++i)
      if (w_.bodies.is_dynamic(i) && band.holds(w_.bodies.pos[i].y())) {
        inside.push_back(static_cast<std::int32_t>(i));
        area += obs::particle_area(w_.bodies.radius[i], w_.bodies.nsides[i]);
      }
    const obs::Coordination zc = obs::coordination<2>(w_.contact_forces(), inside);
    cols.insert(cols.end(), {{"wall_tau", tau},
                             {"wall_sigma", sigma},
                             {"wall_mu", sigma > 0 ? tau / sigma : 0.0},
                             {"bulk_sxx", B(0, 0)},
                             {"bulk_sxy", bxy},
                             {"bulk_syy", B(1, 1)},
                             {"bulk_q_over_p", bp > 0 ? bq / bp : 0.0},
                             {"bulk_mu", B(1, 1) > 0 ? -bxy / B(1, 1) : 0.0},
                             {"bulk_packing_fraction", area / band.area(w_)},
                             {"bulk_z", zc.z}});
  }

  bool dumped(std::int64_t k) const { return std::find(dump_.begin(), dump_.end(), k) != dump_.end(); }

  World& w_;
  const Scene& s_;
  std::filesystem::path dir_;
  std::vector<std::int64_t> dump_;
  bool shear_, walls_;
  double d_mean_;
  Snapshots snaps_{""};
  ShearInterval sh_;
  double v_prev_ = 0, t_prev_ = 0;
};

}  // namespace

RunSummary run(World& w, const Scene& s, const RunOptions& opt) {
  Engine2 e(w, s, opt);
  return run_loop(e, plan_of(s, w.params().dt), opt);
}

}  // namespace cd
