// Cohesion from shear runs (method.md §11): q/p = sin phi + (c/p) cos phi,
// so c/p = (q/p - sin phi)/cos phi, where sin phi is the friction of the
// cohesionless material at the same inertial number, taken from the
// eta = 0 runs given alongside (the reference).
//
// 3D runs (dimension = 3; docs/analysis.md "3D runs"): the Coulomb law on
// the shear plane, tau = mu0(I) sigma_yy + c, with mu = -(sigma_xy +
// sigma_yx)/(2 sigma_yy) the series' shear_stress_ratio (the mu of the 3D
// steady analysis and mu(I) fit) and mu0(I) that of the eta = 0 runs: c/p =
// mu - mu0(I), p = sigma_yy the imposed normal stress, error
// hypot(mu_err, mu0_err); eta = f_a/(p d^2) is the scene's cohesion_number.
// The model and I_c = I/(1 + alpha eta)^(1/2) are 2D's. A fit mixes no
// dimensions.
//
// Error bars. q/p and I are steady means with block-averaging errors
// (steady.hpp). sin phi(I) carries the reference's error (the mu(I) fit's
// covariance, or the two bracketing runs' errors) and that of I through the
// slope of sin phi(I). Then, with m = q/p and s = sin phi,
//   dc/dm = 1/cos phi,   dc/ds = (m s - 1)/cos^3 phi,
// and the two add in quadrature (different runs: independent). The
// reference error is shared by cohesive runs at nearby I, so their c/p
// errors are correlated; the model fit treats them as independent, which
// makes its parameter errors somewhat optimistic when the reference
// dominates (it is small next to the q/p errors when the reference runs are
// as long as the cohesive ones).
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "fit.hpp"

namespace cda {

// One run's steady point: q/p and the measured I averaged over the steady
// window of q_over_p, eta and the imposed I from scene.toml.
struct SteadyPoint {
  std::string run;
  int dim = 2;               // the run's dimension (scene.toml)
  double eta = 0;
  double I_imposed = 0;      // nan when scene.toml has no [shear] inertial_number
  double I = 0, I_err = 0;   // measured inertial_number
  double mu = 0, mu_err = 0; // q_over_p (2D), shear_stress_ratio (3D)
  // Is the flow homogeneous? shear_profile's rate_min over the same window
  // with 5 layers (run.hpp window_rate_min), nan when the run has no
  // particle snapshots to measure it; banded: rate_min < kBandedRateMin.
  double rate_min = std::numeric_limits<double>::quiet_NaN(), rate_min_err = rate_min;
  bool banded() const;
};
// The friction column of a run of dimension dim, and the names of the
// reference friction and of the cohesion formula, for messages and tables.
const char* cohesion_mu_column(int dim);
const char* cohesion_ref_name(int dim);      // "sin phi" (2D), "mu0" (3D)
const char* cohesion_formula(int dim);       // "c/p = (q/p - sin phi)/cos phi", "c/p = mu - mu0(I)"
// Throws AnalysisError naming the run when series.csv or scene.toml is
// missing, [contact] cohesion_number is absent or negative, or the run has
// no steady window (not when the shear profile cannot be measured).
// window: as fit mu-i's --window (run.hpp resolve_window); "": detected.
SteadyPoint steady_point(const std::string& run_dir, const std::string& window = "");

// sin phi(I) of the cohesionless reference.
//   mu-i:   the mu(I) fit of the reference runs (needs 4: 3 parameters and
//           a residual degree of freedom); error from its covariance.
//   interp: linear interpolation in ln I between the two bracketing runs
//           (runs at the same I are averaged first), linear extrapolation
//           from the end pair outside, a constant with one run.
//   auto:   mu-i with 4 or more reference runs when that fit converges,
//           else interp.
class SinPhiReference {
 public:
  enum class Mode { Auto, MuI, Interp };
  // Throws AnalysisError when `points` is empty or mode MuI has fewer than 4.
  SinPhiReference(std::vector<SteadyPoint> points, Mode mode);
  struct Value {
    double sin_phi = 0, err = 0;
    bool extrapolated = false;  // I outside the reference runs' range
  };
  Value at(double I, double I_err) const;
  bool uses_fit() const { return use_fit_; }
  const FitResult& fit() const { return fit_; }
  const std::vector<SteadyPoint>& points() const { return points_; }
  int dim() const { return dim_; }

 private:
  std::pair<double, double> raw(double I) const;  // value, error at I exactly
  std::vector<SteadyPoint> points_;               // sorted by I, distinct I
  bool use_fit_ = false;
  FitResult fit_;
  int dim_ = 2;
};

struct CohesionPoint {
  SteadyPoint run;
  SinPhiReference::Value ref;
  double c_over_p = 0, c_over_p_err = 0;
};
// Throws AnalysisError when p and the reference differ in dimension.
CohesionPoint cohesion_point(const SteadyPoint& p, const SinPhiReference& ref);

// c/p against I per eta with the model curves: <dir>/cohesion.{png,svg,gp}
// and cohesion_data.csv (2D: q_over_p, sin_phi columns; 3D: mu, mu0),
// cohesion_fit.csv. r null: the points alone (the model fit was refused).
bool plot_cohesion(const std::string& dir, const std::vector<CohesionPoint>& pts, const FitResult* r);

}  // namespace cda
