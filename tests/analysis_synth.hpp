// Synthetic shear runs with a known answer, for the analysis tests and the
// committed reference campaign (tests/gen_analysis_campaign.cpp). Portable
// on purpose: the normal deviates come from mt19937_64 (fixed by the
// standard) through Box-Muller, not std::normal_distribution (whose
// algorithm is left to the library), so a regenerated campaign is the same
// file on every platform.
//
// A run, row i = 0..rows-1 at strain gamma = strain_step i, shear rate g:
//   sin psi(gamma) = psi0 exp(-gamma/gamma0)                 (dense: psi0 > 0)
//   volume_strain_rate = g sin psi/sqrt(1 - sin^2 psi) + g noise_v e_v
//   q_over_p = mu + c_over_p cos phi + sin psi + noise_mu e_mu
//   inertial_number = I (1 + noise_I e_I)
// with sin phi = mu the cohesionless friction at I (so q/p - sin phi =
// c/p cos phi: method.md §11), and e_* independent AR(1) series of unit
// variance, e_k = a e_{k-1} + sqrt(1 - a^2) n_k. The AR(1) coefficient a
// gives tau_int = (1 + a)/(2(1 - a)) rows.
#pragma once
#include <fmt/core.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

namespace synth {

class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double operator()() {
    if (have_) {
      have_ = false;
      return spare_;
    }
    const double u1 = uniform(), u2 = uniform();
    const double r = std::sqrt(-2 * std::log(u1));
    spare_ = r * std::sin(2 * std::numbers::pi * u2);
    have_ = true;
    return r * std::cos(2 * std::numbers::pi * u2);
  }

 private:
  double uniform() { return (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53; }  // (0, 1)
  std::mt19937_64 rng_;
  double spare_ = 0;
  bool have_ = false;
};

struct RunSpec {
  double mu = 0.3;          // steady sin phi of the cohesionless material at I
  double I = 0.01;
  double eta = 0;           // cohesion number written to scene.toml
  double c_over_p = 0;      // cohesion's contribution (model value at eta, I)
  double psi0 = 0.2, gamma0 = 0.2;
  double noise_mu = 0.02, noise_v = 0.05, noise_I = 0.02, ar = 0.5;
  double shear_rate = 1.0, strain_step = 0.01;
  int rows = 300;
  std::uint64_t seed = 1;
};

inline double mu_of_I(double mu1, double mu2, double I0, double I) { return mu1 + (mu2 - mu1) / (1 + I0 / I); }

inline double cohesion_model(double k0, double beta, double alpha, double eta, double I) {
  return k0 * eta / (1 - beta * std::log(1 - I / std::sqrt(1 + alpha * eta)));
}

// series.csv (6 significant digits: the noise is at the 2nd) and scene.toml.
inline void write_run(const std::filesystem::path& dir, const RunSpec& s) {
  std::filesystem::create_directories(dir);
  Normal G(s.seed);
  const double a = s.ar, b = std::sqrt(1 - s.ar * s.ar);
  double em = G(), ev = G(), ei = G();
  const double cos_phi = std::sqrt(1 - s.mu * s.mu);
  std::ofstream csv(dir / "series.csv");
  csv << "step,time,strain,shear_rate,q_over_p,inertial_number,volume_strain_rate\n";
  for (int i = 0; i < s.rows; ++i) {
    const double gamma = s.strain_step * i;
    const double sp = s.psi0 * std::exp(-gamma / s.gamma0);
    csv << fmt::format("{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", i, gamma / s.shear_rate, gamma,
                       s.shear_rate, s.mu + s.c_over_p * cos_phi + sp + s.noise_mu * em,
                       s.I * (1 + s.noise_I * ei),
                       s.shear_rate * (sp / std::sqrt(1 - sp * sp) + s.noise_v * ev));
    em = a * em + b * G();
    ev = a * ev + b * G();
    ei = a * ei + b * G();
  }
  std::ofstream(dir / "scene.toml") << fmt::format(
      "# Synthetic run (tests/analysis_synth.hpp), not a cdsim run: only the keys the analysis reads.\n"
      "[contact]\ncohesion_number = {:.17g}\n\n[shear]\npressure = 1000.0\ninertial_number = {:.17g}\n",
      s.eta, s.I);
}

}  // namespace synth
