// Weighted nonlinear least squares (GSL gsl_multifit_nlinear, trust region
// with Levenberg-Marquardt steps, finite-difference Jacobian) and the
// rheology models of method.md §11.
//
// Residuals are (model - y)/sigma. Covariance: C = (J^T J)^-1 of the weighted
// Jacobian at the optimum, i.e. the error bars of the data propagated, then
// scaled by s:
//   - data with error bars: s = max(1, chi2/dof). The error bars come from
//     block averaging and are trusted; if the model does not fit within them
//     (chi2/dof > 1) the parameter errors are inflated accordingly, but never
//     shrunk below what the error bars give (a lucky small chi2 with few
//     points must not claim a precision the data do not have).
//   - data without error bars (sigma all 1): s = chi2/dof, the usual
//     estimate of the noise variance from the residuals.
// Parameter errors are sqrt(s C_ii); chi2/dof is reported in both cases.
#pragma once
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "error.hpp"

namespace cda {

struct Model {
  std::string name;
  std::string formula;               // for reports
  std::vector<std::string> params;
  std::vector<std::string> inputs;   // names of the independent variables
  std::function<double(const double* x, const double* p)> f;
};

struct FitData {
  std::size_t dim = 1;          // independent variables per point
  std::vector<double> x;        // size() * dim, point-major
  std::vector<double> y;
  std::vector<double> sigma;    // empty: unweighted
  std::size_t size() const { return y.size(); }
  void add(std::initializer_list<double> xs, double yv, double s = -1);
};

struct FitResult {
  std::string model;
  std::vector<std::string> names;
  std::vector<double> value, error;
  std::vector<double> cov;      // p x p, row-major, scaled as above
  double chi2 = 0, chi2_dof = 0, scale = 1;
  int dof = 0;
  bool weighted = false;
  std::size_t iterations = 0;
  bool converged = false;
  std::string message;          // GSL's reason when not converged
  double operator[](const std::string& name) const;
  double err(const std::string& name) const;
};

// The parameters the data do not determine: an error at least as large as
// the value (a curve drawn through them says nothing of them), in order.
std::vector<std::string> undetermined_params(const FitResult& r);
// What would determine a fit of `model` (its name), for the messages that
// flag an undetermined fit: which data are missing and how to get them.
std::string what_would_determine(const std::string& model);
// " (undetermined)" for such a parameter of r, else "": for legends and pages.
std::string undetermined_flag(const FitResult& r, const std::string& name);

// Fits `model` to `data` from the starting point p0. Throws AnalysisError if
// there are fewer points than parameters, a sigma is not positive, or the
// model is not finite at the start.
FitResult fit(const Model& model, const FitData& data, std::vector<double> p0);

// Model value and its 1-sigma uncertainty at x, propagated from the
// covariance with a finite-difference gradient (for fit bands in plots).
double predict(const Model& model, const FitResult& r, const double* x);
double predict_error(const Model& model, const FitResult& r, const double* x);

// The models (method.md §11).
Model mu_of_I();          // mu = mu1 + (mu2 - mu1)/(1 + I0/I)             x: I
Model nu_of_I();          // nu = nu_max - a I                              x: I
// The same law at imposed volume, where nu is exact and I is measured: fitted
// as I = (nu_max - nu)/a, weighted by I's error bars. Same name and
// parameters as nu_of_I (compare-fits compares the two campaigns' nu_I).
Model nu_of_I_volume();   // I = (nu_max - nu)/a                            x: nu
Model void_ratio(double p0);  // e = e0 - lambda ln(p/p0), p0 fixed         x: p
Model cohesion();         // c/p = k0 eta/(1 - beta ln(1 - I_c)),
                          // I_c = I/(1 + alpha eta)^(1/2)                 x: eta, I
Model dilatancy();        // sin phi = sin phi_c + sin psi (slope 1)        x: sin psi
Model dilatancy_free();   // sin phi = sin phi_c + b sin psi (checks b = 1) x: sin psi
Model mu_of_alpha();      // mu = mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)) x: alpha
Model nu_of_alpha();      // nu = nu0 + (nu1 - nu0)(1 - exp(-alpha/alpha_c)) x: alpha

// Fits with starting points guessed from the data. sigma may be empty.
FitResult fit_mu_I(std::span<const double> I, std::span<const double> mu,
                   std::span<const double> sigma);
FitResult fit_nu_I(std::span<const double> I, std::span<const double> nu,
                   std::span<const double> sigma);
// nu(I) at imposed volume (nu_of_I_volume): nu exact, sigma the error bars of I.
FitResult fit_nu_I_volume(std::span<const double> nu, std::span<const double> I,
                          std::span<const double> sigma_I);
FitResult fit_void_ratio(std::span<const double> p, std::span<const double> e,
                         std::span<const double> sigma, double p0);
FitResult fit_cohesion(std::span<const double> eta, std::span<const double> I,
                       std::span<const double> c_over_p, std::span<const double> sigma);
FitResult fit_dilatancy(std::span<const double> sin_psi, std::span<const double> sin_phi,
                        std::span<const double> sigma, bool free_slope = false);
FitResult fit_mu_alpha(std::span<const double> alpha, std::span<const double> mu,
                       std::span<const double> sigma);
// mu_of_alpha or nu_of_alpha (m) through (alpha, y): starts at y0, y1 = y at
// the smallest and largest alpha, alpha_c = 0.3 max alpha.
FitResult fit_of_alpha(const Model& m, std::span<const double> alpha, std::span<const double> y,
                       std::span<const double> sigma);

}  // namespace cda
