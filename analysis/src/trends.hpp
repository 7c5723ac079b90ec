// Campaign trends: the steady state of each run of a campaign as a point,
// and the fits across runs that a campaign supports (method.md §11):
//   angularity   mu*(alpha) = mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)),
//                with nu*, z, anisotropies, sliding and side-side shares and
//                partial strengths against alpha = 2 pi/n_s (disks 0);
//   nu(I)        nu = nu_max - b I over steady shear runs;
//   compaction   e = e0 - lambda ln(p/p0), e = 1/nu - 1, over runs at several p.
//
// Error bars.
//   - Series quantities (q/p, packing_fraction, z, p) are steady means over
//     the window detected on q_over_p (packing_fraction for runs without
//     it), with block-averaging errors (steady.hpp).
//   - Snapshot quantities (anisotropies, sliding and side-side shares,
//     partial strengths, the stress check) are the mean over the last K
//     contact snapshots (default 5) with the standard error sd/sqrt(K):
//     this treats snapshots as independent, which holds when they are
//     farther apart than the fabric's correlation strain (campaign
//     snapshots are 0.2 apart in strain; the fabric decorrelates over
//     ~0.1 in dense flow). With one snapshot the error is nan.
//
// Sliding test. A force-bearing physical contact slides when
//   |f_t| >= mu f_n (1 - tol),  tol = the run's [solver] tol (1e-4 by default),
// mu the run's [contact] mu. The local solver projects a sliding contact
// exactly onto the cone (cdsim's own status flag tests 1e-9), but the
// global iteration stops when the impulses change by tol relative over a
// sweep: a contact within tol of the cone is, at that accuracy, not
// distinguishable from a sliding one. Side-side contacts are tested on
// their summed force (both points slide the same way when the pair slides).
// The status-flag share (sliding_flag) is reported beside it; the two
// differ by the contacts within tol of the cone.
// Cohesive runs (adhesion shifts the cone) are outside this test.
//
// Partial strengths: q_sv/p and q_ss/p, the deviator of the partial stress
// of the side-vertex (side-side) contacts over the mean pressure of all
// contacts. Disks have neither (nan).
#pragma once
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fit.hpp"
#include "table.hpp"

namespace cda {

struct Val {
  double v = std::numeric_limits<double>::quiet_NaN();
  double err = std::numeric_limits<double>::quiet_NaN();
};

// Mean and standard error sd/sqrt(n) of per-snapshot values, nan values
// skipped (sd with n - 1); err nan with one value, both nan with none.
Val mean_sem(const std::vector<double>& x);

struct AngularityOptions {
  int snapshots = 5;  // last K contact snapshots for the fabric
  int bins = 36;
  std::string window;  // as fit mu-i's --window (run.hpp resolve_window); "": detected
};

struct AngularityPoint {
  std::string run;
  int nsides = 0;
  double alpha = 0;
  std::string alpha_source;  // "particles snapshot" or "scene.toml"
  Val mu, nu, z, p;          // steady series means
  std::size_t snapshots = 0;
  Val a_c, a_ln, a_lt, a_fn, a_ft;           // FFT estimates
  Val q_over_p_snap, sum_half_fft, sum_half_tensor;
  Val sliding, sliding_flag, ss_share, q_sv, q_ss;
  double friction = 0, sliding_tol = 1e-4;
};

// One run. alpha from the nsides array of the run's last particles snapshot
// (the shapes that were sheared: a run started from a checkpoint keeps its
// shapes whatever its scene says), else from scene.toml [particles] nsides.
// Throws AnalysisError naming the run when it has no steady window, mixed
// shapes, no contact snapshot, or no nsides anywhere.
AngularityPoint angularity_point(const std::string& run_dir, const AngularityOptions& opt = {});

// The columns of angularity.csv, one row per point (run = index).
Table angularity_table(const std::vector<AngularityPoint>& pts);

// mu*(alpha) over the points (steady error bars as weights). Refused
// (AnalysisError) with fewer than 3 distinct alpha, or a singular fit.
FitResult fit_angularity(const std::vector<AngularityPoint>& pts);
// nu*(alpha) of the same form (nu_of_alpha), refused likewise.
FitResult fit_angularity_nu(const std::vector<AngularityPoint>& pts);

// The plots against alpha into dir: angularity_{mu,nu,z,anisotropy,sliding,
// partial}.{png,svg,gp} with angularity.csv and angularity_mu_fit.csv
// (fit may be null: points only). `command` goes into each script's header.
// Returns false when gnuplot failed on one of them.
bool plot_angularity(const std::string& dir, const std::vector<AngularityPoint>& pts,
                     const FitResult* fit, const std::string& command);
extern const std::vector<std::string> kAngularityPlots;

// A steady state for the nu(I) and compaction fits.
struct StatePoint {
  std::string run;
  Val I;                 // measured inertial number (nan without the column)
  Val nu;                // packing_fraction
  Val p;                 // measured p of the series, else scene [shear] pressure (err nan)
  bool p_from_scene = false;
  double I_imposed = std::numeric_limits<double>::quiet_NaN();
  bool volume = false;   // imposed volume: nu exact, I measured (fit nu(I) in I)
  double e() const { return 1 / nu.v - 1; }
  double e_err() const { return nu.err / (nu.v * nu.v); }
};
// window: as fit mu-i's --window (run.hpp resolve_window); "": detected.
StatePoint state_point(const std::string& run_dir, const std::string& window = "");

// nu(I) and its plot nu_I.{png,svg} (data nu_I_data.csv, nu_I_fit.csv).
// Runs at imposed volume are fitted in I (fit_nu_I_volume, weighted by I's
// errors), the others in nu; a mixture of the two is refused. weighted:
// by the error bars (all finite and positive), else unweighted.
FitResult fit_nu_I_points(const std::vector<StatePoint>& pts, bool weighted = true);
// Whether the points are at imposed volume (all; a mixture: AnalysisError
// naming a run of each), and the model that fit_nu_I_points fits to them.
bool volume_points(const std::vector<StatePoint>& pts);
Model nu_model(const std::vector<StatePoint>& pts);
bool plot_nu_I(const std::string& dir, const std::vector<StatePoint>& pts, const FitResult& r,
               const std::string& command);
// e(p) with p0 given (p0 <= 0: the geometric mean of the p's, which makes
// e0 and lambda nearly uncorrelated), and its plot compaction.{png,svg}.
double default_p0(const std::vector<StatePoint>& pts);
FitResult fit_compaction_points(const std::vector<StatePoint>& pts, double p0);
bool plot_compaction(const std::string& dir, const std::vector<StatePoint>& pts, const FitResult& r,
                     double p0, const std::string& command);

}  // namespace cda
