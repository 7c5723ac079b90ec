// Steady-state statistics of a time series (method.md §10): the mean over a
// steady window with an error bar that accounts for time correlation, two
// ways, and the detection of that window.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "error.hpp"

namespace cda {

// Flyvbjerg-Petersen blocking. Level k averages pairs of level k-1 (block
// size 2^k, an odd last element dropped). At each level with n blocks,
// sem_k = sqrt(var_k/(n - 1)) (var with 1/n) and its own error
// sem_k/sqrt(2(n - 1)).
struct BlockLevel {
  std::size_t block_size = 0, blocks = 0;
  double sem = 0, sem_err = 0;
};

struct BlockAverage {
  double mean = 0;
  double sem = 0, sem_err = 0;  // at the chosen level
  std::size_t block_size = 0;   // chosen block size
  // The choice is the smallest block size B with B^3 > 2 N (sem_B/sem_1)^4
  // (Lee et al. 2011, as in pyblock): since (sem_B/sem_1)^2 -> 2 tau_int,
  // it balances the bias of short blocks (~ tau/B) against the scatter of
  // few blocks (~ sqrt(B/N)). `converged` is false when no level qualifies
  // with at least 4 blocks left; the last level with 4 or more blocks is
  // then reported and the error bar is a lower bound.
  bool converged = false;
  std::vector<BlockLevel> levels;
};

BlockAverage block_average(std::span<const double> x);

// Normalised autocorrelation rho(t), t = 0..n-1, through FFTW (zero-padded
// to 2n, so it is the direct sum (1/n) sum_i dx_i dx_{i+t}, not circular).
std::vector<double> autocorrelation(std::span<const double> x);

// Integrated autocorrelation time tau = 1/2 + sum_{t=1}^{W} rho(t), with
// Sokal's self-consistent window: the smallest W with W >= c tau(W), c = 5.
// N_eff = N/(2 tau); sem = sqrt(var 2 tau / N); the error of tau is
// tau sqrt(2(2W + 1)/N) (Madras-Sokal). `converged` is false if no such W
// exists below N/2.
struct AutoCorrTime {
  double tau = 0.5, tau_err = 0;
  std::size_t window = 0;
  double n_eff = 0;
  double sem = 0;
  bool converged = false;
};
AutoCorrTime autocorrelation_time(std::span<const double> x, double c = 5.0);

// A window [begin, end) of row indices, with the x values at its ends.
struct Window {
  std::size_t begin = 0, end = 0;
  double x_begin = 0, x_end = 0;
};

// The rows with a <= x <= b. Throws AnalysisError if fewer than 2 rows.
Window window_from_range(std::span<const double> x, double a, double b);

// Steady window detection. Candidate windows all end at the last row and
// start at the `candidates` evenly spaced rows from 0 up to (1 - min_fraction)
// of the run. The slope of a least-squares line over a window is significant
// when |slope| > t_crit se, se being the ordinary standard error inflated by
// sqrt(2 tau) (correlated noise would otherwise make every drift look
// significant). tau is the noise's, estimated once from the residuals of a
// line over the last half of the run, not per window: the residuals of a
// window that holds part of a transient are curved, their tau grows (to 22
// rows instead of 2.8 in the test series), and the transient then passes as
// noise; and the tau of the shortest window is noisy (1.1 for 2.8). t_crit = 3
// (two-sided 0.27% for one test): a false rejection of the shortest window
// declares a steady run not steady, so it must be rare (2.5 still rejected
// one of four synthetic stationary runs of 600 rows, at t = 2.8).
// A line has little power against a short transient at the start of a long
// window (the tail dominates the fit: the test series passed from x = 1.2,
// leaving a bias of 2.6 error bars in the mean), so a window must also pass
// Geweke's test: the mean of its first 10% (at least 8 rows) and that of its
// last 50% agree within t_crit combined standard errors (each
// sqrt(var 2 tau/n), tau as above).
// Going back from the shortest window, candidates are accepted while they
// pass both tests; the window is the longest accepted one: the latest part
// of the run with no detectable trend.
// Rejected (AnalysisError naming `what`) if even the shortest window drifts,
// or if the result has fewer than min_independent independent samples
// (N/(2 tau)).
struct SteadyOptions {
  double min_fraction = 0.2;
  int candidates = 20;
  double t_crit = 3.0;
  double min_independent = 10.0;
};
Window detect_steady_window(std::span<const double> x, std::span<const double> y,
                            const SteadyOptions& opt = {}, const std::string& what = "series");

struct LineFit {
  double intercept = 0, slope = 0, slope_se = 0;  // se corrected for correlation
  double tau = 0.5;                               // of the residuals
};
// Least-squares line; slope_se is inflated by sqrt(2 tau), tau that of the
// residuals, or the given noise_tau when positive.
LineFit line_fit(std::span<const double> x, std::span<const double> y, double noise_tau = -1);

// Everything reported for one quantity over a window.
struct SteadyStats {
  Window window;
  double mean = 0;
  BlockAverage blocks;
  AutoCorrTime acf;
  LineFit trend;
  // The error bar used downstream: the blocking sem if converged, else the
  // larger of the two estimates.
  double error() const;
};
// Throws AnalysisError (naming `what`) when the window holds fewer than 16
// rows, too few for either error estimate.
SteadyStats steady_stats(std::span<const double> x, std::span<const double> y, const Window& w,
                         const std::string& what = "series");

}  // namespace cda
