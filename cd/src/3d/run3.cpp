#include "run3.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "checkpoint.hpp"
#include "checkpoint3.hpp"
#include "output3.hpp"
#include "run.hpp"

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

namespace {

class Engine3 final : public RunEngine {
 public:
  explicit Engine3(World3& w) : w_(w) {}
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

 private:
  World3& w_;
  StepStats last_;
  Snapshots3 snaps_;
};

}  // namespace

RunSummary run3(World3& w, const Scene& s, const RunOptions& opt) {
  Engine3 e(w);
  return run_loop(e, plan_of(s, w.params().dt), opt);
}

}  // namespace cd
