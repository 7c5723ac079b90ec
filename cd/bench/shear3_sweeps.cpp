// Where the sweeps of a 3D dense-shear step go (docs/accuracy.md): a World3
// built from a scene (typically configs/shear3-inertial.toml started from a
// sheared checkpoint) is stepped normally, and on chosen steps the same step
// is taken again from copies of the world with the sweep stopped after k
// sweeps (tol 0, max_iter k) for k on a ladder up to a reference. Each copy
// is the k-th iterate of the production NLGS on that step (the solve is
// deterministic), so the ladder is the solve's history without touching the
// solver: the law residual, the stress the user measures (mu = -(s_xy +
// s_yx)/2 / s_yy, s_yy/p), the coordination, and the distance of the
// impulses and of the body velocities to the reference iterate. The rows
// still moving when the laws are met are then sorted by what they are in
// the reference (sliding, sticking, open; weak or strong).
//
//   shear3_sweeps SCENE --set KEY=VALUE ... [--warm 20] [--samples 3]
//                 [--every 20] [--caps 1,2,5,...] [--out DIR]
// writes DIR/ladder.csv (one line a sample step and cap) and
// DIR/moving.csv (per sample step: the rows that move after the laws are
// met, by class), and prints a summary. One thread.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config.hpp"
#include "machine.hpp"
#include "run3.hpp"
#include "setup3.hpp"

using namespace cd;

namespace {

struct Iterate {
  int cap = 0, sweeps = 0;
  double residual_max = 0, residual_mean = 0, dp_rel = 0;
  double mu = 0, syy = 0, z = 0;
  World3 w;
};

Iterate take_step(const World3& w0, int cap, double tol, double residual_tol, int anderson) {
  Iterate it{cap, 0, 0, 0, 0, 0, 0, 0, w0};
  WorldParams3 p = it.w.params();
  p.solver.tol = tol;
  p.solver.max_iter = cap;
  p.solver.residual_tol = residual_tol;
  p.solver.anderson = anderson;
  p.solver.min_parallel = 1 << 30;
  it.w.set_params(p);
  it.w.step();
  const SolveStats& s = it.w.last().solve;
  it.sweeps = s.iterations;
  it.residual_max = s.residual_max;
  it.residual_mean = s.residual_mean;
  it.dp_rel = s.dp_rel;
  const Eigen::Matrix3d S = it.w.contact_stress();
  it.mu = -0.5 * (S(0, 1) + S(1, 0)) / S(1, 1);
  it.syy = S(1, 1) / p.pressure;
  it.z = coordination3(it.w).z;
  return it;
}

// rms |r_a - r_b| over rows / mean |r_b| (rows index-aligned: the same step from the same state).
double impulse_distance(const World3& a, const World3& b) {
  const auto& ra = a.rows();
  const auto& rb = b.rows();
  double d2 = 0, pn = 0;
  for (std::size_t k = 0; k < rb.size(); ++k) {
    d2 += (ra[k].r - rb[k].r).squaredNorm();
    pn += rb[k].r.norm();
  }
  const double n = static_cast<double>(rb.size());
  return n > 0 && pn > 0 ? std::sqrt(d2 / n) / (pn / n) : 0.0;
}

// rms |v_a - v_b| over dynamic bodies / scale.
double velocity_distance(const World3& a, const World3& b, double scale) {
  double d2 = 0;
  int n = 0;
  for (std::size_t i = 0; i < b.bodies.size(); ++i) {
    if (!b.bodies.is_dynamic(i)) continue;
    d2 += (a.bodies.vel[i].v - b.bodies.vel[i].v).squaredNorm();
    ++n;
  }
  return n ? std::sqrt(d2 / n) / scale : 0.0;
}

enum RowClass { Open, Stick, Slide };
const char* kClass[] = {"open", "stick", "slide"};

RowClass classify(const SphereRow& r) {
  if (r.r[0] <= 0.0) return Open;
  const double t = std::hypot(r.r[1], r.r[2]);
  return t >= (1.0 - 1e-6) * r.mu * r.r[0] ? Slide : Stick;
}

std::vector<int> parse_caps(const std::string& s) {
  std::vector<int> caps;
  std::stringstream in(s);
  std::string tok;
  while (std::getline(in, tok, ',')) caps.push_back(std::stoi(tok));
  std::sort(caps.begin(), caps.end());
  return caps;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Where the sweeps of a 3D dense-shear step go"};
  std::string scene_path, out = "outputs/shear3-sweeps", caps_s = "1,2,5,10,20,50,100,200,300,500,700,1000,1500,2000,3000,5000,10000";
  std::vector<std::string> sets;
  int warm = 20, samples = 3, every = 20, anderson = 0;
  double met = 3e-3;  // "the laws are met": the largest law residual below this
  app.add_option("scene", scene_path, "scene file")->required();
  app.add_option("--set", sets, "scene overrides KEY=VALUE");
  app.add_option("--warm", warm, "production steps before the first sample");
  app.add_option("--samples", samples, "sample steps");
  app.add_option("--every", every, "production steps between samples");
  app.add_option("--caps", caps_s, "sweep caps, ascending; the last is the reference");
  app.add_option("--met", met, "law residual at which the laws count as met");
  app.add_option("--out", out, "output folder");
  app.add_option("--anderson", anderson, "Anderson memory of the ladder's and the production solves (0: plain NLGS)");
  CLI11_PARSE(app, argc, argv);
  try {
    const Scene s = load_scene(scene_path, sets);
    World3 w = build_world3(s);
    const std::vector<int> caps = parse_caps(caps_s);
    const double tol = w.params().solver.tol, rtol = w.params().solver.residual_tol;
    const int cap_prod = w.params().solver.max_iter;
    const double tp = s.d_mean * std::sqrt(s.density / s.pressure);
    const double vscale = s.inertial_number / tp * s.d_mean;  // gamma-dot d
    std::filesystem::create_directories(out);
    std::ofstream lad(out + "/ladder.csv"), mov(out + "/moving.csv");
    lad << "sample,step,cap,sweeps,residual_max,residual_mean,dp_rel,mu,syy_over_p,z,dr_rel,dv_rel\n";
    mov << "sample,met_at,class,rows,share_of_rows,moving,share_moving,mean_p_over_mean,mean_dr_over_mean\n";
    fmt::print("scene {}, {} bodies; production tol {} residual_tol {} cap {}; load {}\n", scene_path,
               w.bodies.size(), tol, rtol, cap_prod, cdbench::load_average());
    for (int k = 0; k < warm; ++k) w.step();
    for (int smp = 0; smp < samples; ++smp) {
      if (smp) for (int k = 0; k < every; ++k) w.step();
      std::vector<Iterate> its;
      for (int c : caps) its.push_back(take_step(w, c, 0.0, 0.0, anderson));
      const Iterate& ref = its.back();
      const Iterate prod = take_step(w, cap_prod, tol, rtol, anderson);
      fmt::print("\nsample {} (step {}): {} rows; production: {} sweeps, residual {:.2e}, mu {:.4f}; reference "
                 "({} sweeps): residual {:.2e}, mu {:.4f}, syy/p {:.4f}, z {:.3f}\n",
                 smp, w.steps, ref.w.rows().size(), prod.sweeps, prod.residual_max, prod.mu, ref.sweeps,
                 ref.residual_max, ref.mu, ref.syy, ref.z);
      fmt::print("{:>6} {:>10} {:>10} {:>10} {:>8} {:>8} {:>7} {:>9} {:>9}\n", "cap", "res_max", "res_mean",
                 "dp_rel", "mu", "syy/p", "z", "dr_rel", "dv_rel");
      int met_at = -1;
      for (const Iterate& it : its) {
        const double dr = impulse_distance(it.w, ref.w), dv = velocity_distance(it.w, ref.w, vscale);
        if (met_at < 0 && it.residual_max < met) met_at = static_cast<int>(&it - its.data());
        fmt::print("{:>6} {:>10.3e} {:>10.3e} {:>10.3e} {:>8.4f} {:>8.4f} {:>7.3f} {:>9.3e} {:>9.3e}\n", it.cap,
                   it.residual_max, it.residual_mean, it.dp_rel, it.mu, it.syy, it.z, dr, dv);
        lad << fmt::format("{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6f},{:.6f},{:.4f},{:.6e},{:.6e}\n", smp, w.steps,
                           it.cap, it.sweeps, it.residual_max, it.residual_mean, it.dp_rel, it.mu, it.syy, it.z,
                           dr, dv);
      }
      lad << fmt::format("{},{},prod,{},{:.6e},{:.6e},{:.6e},{:.6f},{:.6f},{:.4f},{:.6e},{:.6e}\n", smp, w.steps,
                         prod.sweeps, prod.residual_max, prod.residual_mean, prod.dp_rel, prod.mu, prod.syy,
                         prod.z, impulse_distance(prod.w, ref.w), velocity_distance(prod.w, ref.w, vscale));
      if (met_at < 0 || met_at + 1 >= static_cast<int>(its.size())) continue;
      // Rows still moving once the laws are met: |r_met - r_ref| > 0.1 mean |r_ref|.
      const auto& rm = its[met_at].w.rows();
      const auto& rr = ref.w.rows();
      double pmean = 0;
      for (const auto& r : rr) pmean += r.r.norm();
      pmean /= static_cast<double>(rr.size());
      int n[3] = {}, nm[3] = {}, total_m = 0;
      double psum[3] = {}, dsum[3] = {};
      for (std::size_t k = 0; k < rr.size(); ++k) {
        const RowClass c = classify(rr[k]);
        ++n[c];
        psum[c] += rr[k].r.norm();
        const double d = (rm[k].r - rr[k].r).norm();
        dsum[c] += d;
        if (d > 0.1 * pmean) {
          ++nm[c];
          ++total_m;
        }
      }
      fmt::print("laws met (residual < {:.0e}) at cap {}: {} of {} rows still move by > 0.1 mean |r|\n", met,
                 its[met_at].cap, total_m, rr.size());
      for (int c = 0; c < 3; ++c) {
        fmt::print("  {:<6} {:>5} rows ({:4.1f} %), {:>5} moving ({:4.1f} % of movers), mean |r| {:.2f}, mean "
                   "|dr| {:.3f} (of mean |r|)\n",
                   kClass[c], n[c], 100.0 * n[c] / rr.size(), nm[c], total_m ? 100.0 * nm[c] / total_m : 0.0,
                   n[c] ? psum[c] / n[c] / pmean : 0.0, n[c] ? dsum[c] / n[c] / pmean : 0.0);
        mov << fmt::format("{},{},{},{},{:.4f},{},{:.4f},{:.4f},{:.4f}\n", smp, its[met_at].cap, kClass[c], n[c],
                           double(n[c]) / rr.size(), nm[c], total_m ? double(nm[c]) / total_m : 0.0,
                           n[c] ? psum[c] / n[c] / pmean : 0.0, n[c] ? dsum[c] / n[c] / pmean : 0.0);
      }
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "shear3_sweeps: {}\n", e.what());
    return 2;
  }
  return 0;
}
