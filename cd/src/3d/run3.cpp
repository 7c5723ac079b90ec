#include "run3.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "checkpoint3.hpp"
#include "dump3.hpp"
#include "output3.hpp"

namespace cd {

std::string non_finite3(const World3& w) {
  const Bodies3& b = w.bodies;
  const auto finite = [](const auto& v) { return v.allFinite(); };
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (!finite(b.pos[i]) || !finite(b.orient[i].coeffs()))
      return fmt::format("body {}: position ({}, {}, {}), orientation ({}, {}, {}, {})", i, b.pos[i].x(),
                         b.pos[i].y(), b.pos[i].z(), b.orient[i].w(), b.orient[i].x(), b.orient[i].y(),
                         b.orient[i].z());
    const BodyVel3& v = b.vel[i];
    if (!finite(v.v) || !finite(v.w))
      return fmt::format("body {}: velocity ({}, {}, {}), angular velocity ({}, {}, {})", i, v.v.x(), v.v.y(),
                         v.v.z(), v.w.x(), v.w.y(), v.w.z());
  }
  const auto& rows = w.rows();
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (!finite(rows[k].r))
      return fmt::format("contact {} (bodies {} and {}): impulse ({}, {}, {})", k, rows[k].b1, rows[k].b2,
                         rows[k].r[0], rows[k].r[1], rows[k].r[2]);
  return "";
}

double max_overlap_small3(const World3& w) {
  const Bodies3& b = w.bodies;
  double m = 0;
  const auto& rows = w.rows();
  const auto& info = w.infos();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (info[k].gap >= 0) continue;
    const double r1 = b.shape[rows[k].b1] == Shape3::Sphere ? b.radius[rows[k].b1] : b.radius[rows[k].b2];
    const double d = 2.0 * std::min(r1, b.radius[rows[k].b2]);
    m = std::max(m, -info[k].gap / d);
  }
  return m;
}

obs::Coordination coordination3(const World3& w) {
  std::vector<std::int32_t> particles;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    if (w.bodies.is_dynamic(i)) particles.push_back(static_cast<std::int32_t>(i));
  return obs::coordination<3>(w.contact_forces(), particles);
}

double packing_fraction3(const Bodies3& b, double V) {
  std::vector<double> vol;
  for (std::size_t i = 0; i < b.size(); ++i)
    if (b.shape[i] != Shape3::Plane) vol.push_back(b.volume(i));
  return obs::packing_fraction(vol, {}, V);
}

Columns cell_columns3(const World3& w, const Eigen::Matrix3d& S, double density, double d_mean) {
  const double V = w.cell_volume();
  obs::Tensor<3> St;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) St[i][j] = S(i, j);
  const double p = obs::mean_3d(St), q = obs::deviator_3d(St);
  const double gd = w.shear_rate();
  const Eigen::Matrix3d K = w.kinetic_stress();
  const obs::Coordination zc = coordination3(w);
  const Vec3 L = w.cell().size;
  const double syy = S(1, 1), sxy_sym = 0.5 * (S(0, 1) + S(1, 0));
  const char* name[3] = {"x", "y", "z"};
  Columns c{{"strain", w.cell().strain}, {"shear_rate", gd}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.emplace_back(fmt::format("s{}{}", name[i], name[j]), S(i, j));
  c.insert(c.end(), {{"p", p},
                     {"q", q},
                     {"q_over_p", p > 0 ? q / p : 0.0},
                     // tau / sigma_n, positive in the imposed sense: the
                     // images above move +x, so sigma_xy < 0 compression-positive
                     {"shear_stress_ratio", syy > 0 ? -sxy_sym / syy : 0.0},
                     // with the whole normal stress sigma_yy + K_yy, as in 2D
                     {"inertial_number",
                      syy + K(1, 1) > 0 ? gd * d_mean * std::sqrt(density / (syy + K(1, 1))) : 0.0},
                     {"packing_fraction", packing_fraction3(w.bodies, V)},
                     {"z", zc.z},
                     {"non_rattler", zc.non_rattler},
                     {"cell_width", L.x()},
                     {"cell_height", L.y()},
                     {"cell_depth", L.z()}});
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) c.emplace_back(fmt::format("k{}{}", name[i], name[j]), K(i, j));
  return c;
}

namespace {

class Engine3 final : public RunEngine {
 public:
  Engine3(World3& w, const Scene& s, const RunOptions& opt)
      : w_(w), dump_(w, opt.out, opt.dump_steps), cell_(w.cell_volume() > 0.0), density_(s.density),
        d_mean_(w.params().d_ref) {}
  void step() override {
    w_.step();
    last_ = w_.last();
    last_.max_overlap_small = max_overlap_small3(w_);
  }
  const StepStats& last() const override { return last_; }
  std::int64_t steps() const override { return w_.steps; }
  double time() const override { return w_.time; }
  StageTimes& times() override { return w_.times; }
  double kinetic_energy() const override { return w_.kinetic_energy(); }
  std::string non_finite() const override { return non_finite3(w_); }
  void save(const std::string& path, std::uint64_t key, const RunTotals& t) const override {
    save_checkpoint3(path, w_, key, t);
  }
  std::uint64_t load(const std::string& path, RunTotals* t) override { return load_checkpoint3(path, w_, t); }
  void open_snapshots(const std::string& dir, Frames frames) override { snaps_ = Snapshots3(dir, std::move(frames)); }
  void write_snapshot() override { snaps_.write(w_); }

  // A tri-periodic cell: its columns (cell_columns3), the contact stress
  // averaged over the interval's steps.
  void after_step(std::int64_t k) override {
    dump_.after_step(k);
    if (!cell_) return;
    sigma_ += w_.contact_stress();
    ++nsig_;
  }
  void add_columns(Columns& cols) override {
    if (!cell_) return;
    const Columns c = cell_columns3(w_, nsig_ ? Eigen::Matrix3d(sigma_ / nsig_) : w_.contact_stress(), density_,
                                    d_mean_);
    cols.insert(cols.end(), c.begin(), c.end());
    sigma_.setZero();
    nsig_ = 0;
  }

 private:
  World3& w_;
  ProblemDump3 dump_;
  bool cell_;
  double density_, d_mean_;
  Eigen::Matrix3d sigma_ = Eigen::Matrix3d::Zero();
  int nsig_ = 0;
  StepStats last_;
  Snapshots3 snaps_;
};

}  // namespace

RunSummary run3(World3& w, const Scene& s, const RunOptions& opt) {
  Engine3 e(w, s, opt);
  return run_loop(e, plan_of(s, w.params().dt), opt);
}

}  // namespace cd
