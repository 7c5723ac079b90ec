// Stress-dilatancy from the time series of shear runs (method.md §11):
// sin phi = sin phi_c + sin psi, fitted over the whole run, transient and
// steady state: the transient spreads sin psi, the steady state pins
// sin phi_c at sin psi = 0.
//
// Columns. sin phi = q/p (2D). sin psi = -eps_v_dot/eps_q_dot with
// compression positive; see sin_psi() for the derivation from
// volume_strain_rate and shear_rate.
//
// Error bars. The rows of a series are correlated in time (tau rows), and
// volume_strain_rate is noisy, so rows are never treated as independent:
//  1. tau = the larger integrated autocorrelation time of sin phi and of
//     sin psi, from the residuals of a line over the last half of the rows
//     (the least transient part; as steady.hpp does for window detection).
//  2. The rows are averaged in consecutive blocks of B = ceil(4 tau) rows.
//     Block means that far apart are nearly independent (for AR(1) noise the
//     correlation of neighbouring block means is about 1/8 at B = 4 tau;
//     B = 2 tau leaves ~1/3, which would understate the error bars by ~25%).
//  3. Consecutive blocks are grouped into bins of blocks_per_bin blocks: a
//     bin is a stretch of strain (>= 16 tau rows), its point the mean
//     sin psi and mean sin phi of its rows. Because the model is linear,
//     averaging over a stretch is exact whatever sin psi does inside it.
//  4. The error bar of a run's bins is the scatter, over that run's bins,
//     of sin phi - b sin psi (b = 1 for the fixed slope): under the model it
//     is constant, so its scatter is the noise of a bin mean, both
//     coordinates and their correlation included (the effective variance of
//     a line with errors in x and y), and bins of >= 16 tau rows are close
//     to independent. One error bar per run, with (bins - 1) degrees of
//     freedom: stable weights, where per-bin scatters of 4 blocks (3 dof)
//     gave erratic ones and pulls with an rms of 1.9 instead of 1. A misfit
//     of the model shows up as a larger scatter: conservative.
//  5. The free-slope fit minimises the effective-variance (Deming/York)
//     objective sum_j (y_j - a - b x_j)^2/(Syy - 2b Sxy + b^2 Sxx), S the
//     noise covariance of a bin's (sin psi, sin phi), estimated per run
//     from its bins in the last half of the run (steady: their scatter is
//     noise). With b inside the denominator the slope is not attenuated by
//     the noise of sin psi; ordinary least squares with these error bars
//     was (pulls of b with an rms of 1.9, b biased low by 1 - R).
// Rejected: bins of sin psi. Selecting rows by the noisy sin psi biases the
// free slope towards 0 (regression dilution): on the synthetic runs of
// test_analysis_runs the pulls of b had an rms of 3.1 instead of 1. Bins of
// strain select on a noiseless variable; what remains is the attenuation by
// the noise of the bins' mean sin psi, reported per run as the reliability
// R = 1 - var(noise of a bin's sin psi)/var(bins' sin psi), the noise
// variance from the bins of the last half of the run (1: no attenuation).
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fit.hpp"
#include "table.hpp"

namespace cda {

// sin psi in 2D from the series columns, compression positive.
double sin_psi(double volume_strain_rate, double shear_rate);

struct DilatancyOptions {
  std::size_t blocks_per_bin = 4;
  std::optional<std::pair<double, double>> strain;   // rows with a <= strain <= b; default all
};

struct DilatancyBin {
  double sin_psi = 0, sin_phi = 0;
  double sin_psi_err = 0, sin_phi_err = 0;  // standard errors of the bin means (for plots)
  double strain_begin = 0, strain_end = 0;  // of its rows (row index when there is no strain column)
  std::size_t blocks = 0;
};

struct RunDilatancy {
  std::string run;
  std::size_t rows = 0, skipped = 0;        // rows used; rows without a shear rate or out of range
  double tau = 0.5;                         // rows
  std::size_t block_rows = 1;
  double reliability = 1;                   // of the bin sin psi (see above)
  double sxx = 0, sxy = 0, syy = 0;         // noise covariance of a bin's (sin psi, sin phi)
  std::vector<double> row_sin_psi, row_sin_phi;
  std::vector<DilatancyBin> bins;
  // Error bar of each bin's sin phi - b sin psi: the scatter over the bins.
  double sigma(double b) const;
};

// One run's binned points. Throws AnalysisError naming the file for missing
// columns (q_over_p, volume_strain_rate, shear_rate), too few rows, or too
// few blocks for two bins.
RunDilatancy run_dilatancy(const std::string& run_dir, const Table& series, const DilatancyOptions& opt = {});

struct DilatancyFit {
  std::vector<RunDilatancy> runs;
  FitResult fixed;   // dilatancy(): slope 1
  FitResult free;    // dilatancy_free(): slope b, the check b = 1
};
DilatancyFit fit_dilatancy_runs(std::vector<RunDilatancy> runs);

// sin phi against sin psi: rows (grey), binned points per run with error
// bars, the slope-1 fit with its 1-sigma band and the free-slope fit;
// <dir>/dilatancy.{png,svg,gp} and the CSV files it reads.
bool plot_dilatancy(const std::string& dir, const DilatancyFit& f);

}  // namespace cda
