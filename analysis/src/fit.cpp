#include "fit.hpp"

#include <fmt/core.h>
#include <fmt/format.h>
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

namespace cda {

void FitData::add(std::initializer_list<double> xs, double yv, double s) {
  if (xs.size() != dim)
    throw AnalysisError(fmt::format("fit data: point with {} inputs, {} expected", xs.size(), dim));
  x.insert(x.end(), xs.begin(), xs.end());
  y.push_back(yv);
  if (s > 0) sigma.push_back(s);
}

double FitResult::operator[](const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return value[i];
  throw AnalysisError(fmt::format("fit '{}' has no parameter '{}'", model, name));
}
std::vector<std::string> undetermined_params(const FitResult& r) {
  std::vector<std::string> u;
  for (std::size_t i = 0; i < r.names.size(); ++i)
    if (!(r.error[i] < std::abs(r.value[i]))) u.push_back(r.names[i]);
  return u;
}

std::string what_would_determine(const std::string& model) {
  const std::string common = "longer runs (STRAIN=) for smaller error bars, WINDOW= for runs without a detected "
                             "steady window";
  if (model == "mu_I")
    return "runs on both sides of I0, up to I = 0.3-0.5 where mu(I) bends over (INERTIAL_I=), " + common;
  if (model == "nu_I")
    return "runs over a wider range of I (INERTIAL_I=; at imposed volume, of packing fractions: VOLUME_PHI=), " +
           common;
  if (model == "void_ratio") return "runs at more pressures over a wider range (PRESSURE_P=), " + common;
  if (model == "cohesion") return "eta > 0 runs at several eta and I (COHESIVE_ETA=, COHESIVE_I=), " + common;
  if (model == "mu_alpha") return "more shapes (ANGULAR_NS=), " + common;
  return "more runs, " + common;
}

std::string undetermined_flag(const FitResult& r, const std::string& name) {
  const auto u = undetermined_params(r);
  return std::find(u.begin(), u.end(), name) != u.end() ? " (undetermined)" : "";
}

double FitResult::err(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return error[i];
  throw AnalysisError(fmt::format("fit '{}' has no parameter '{}'", model, name));
}

namespace {

struct Problem {
  const Model* model;
  const FitData* data;
};

int residuals(const gsl_vector* p, void* vp, gsl_vector* f) {
  const auto* pb = static_cast<const Problem*>(vp);
  const auto& d = *pb->data;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double m = pb->model->f(&d.x[i * d.dim], p->data);
    const double s = d.sigma.empty() ? 1.0 : d.sigma[i];
    double r = (m - d.y[i]) / s;
    // Outside the model's domain (e.g. I_c >= 1): a large finite residual
    // makes the trust region step back instead of GSL failing on a NaN.
    if (!std::isfinite(r)) r = 1e10;
    gsl_vector_set(f, i, r);
  }
  return GSL_SUCCESS;
}

struct GslOff {  // GSL's default handler aborts; report through status codes instead
  gsl_error_handler_t* old;
  GslOff() : old(gsl_set_error_handler_off()) {}
  ~GslOff() { gsl_set_error_handler(old); }
};

}  // namespace

FitResult fit(const Model& model, const FitData& data, std::vector<double> p0) {
  const std::size_t n = data.size(), p = model.params.size();
  if (p0.size() != p)
    throw AnalysisError(fmt::format("fit {}: {} starting values for {} parameters", model.name,
                                    p0.size(), p));
  if (n < p)
    throw AnalysisError(fmt::format("fit {}: {} points for {} parameters", model.name, n, p));
  if (data.x.size() != n * data.dim)
    throw AnalysisError(fmt::format("fit {}: {} inputs for {} points", model.name, data.x.size(), n));
  if (!data.sigma.empty() && data.sigma.size() != n)
    throw AnalysisError(fmt::format("fit {}: {} error bars for {} points", model.name,
                                    data.sigma.size(), n));
  for (double s : data.sigma)
    if (!(s > 0)) throw AnalysisError(fmt::format("fit {}: an error bar is not positive ({})", model.name, s));
  for (std::size_t i = 0; i < n; ++i) {
    bool finite = std::isfinite(data.y[i]) && (data.sigma.empty() || std::isfinite(data.sigma[i]));
    for (std::size_t k = 0; k < data.dim; ++k) finite = finite && std::isfinite(data.x[i * data.dim + k]);
    if (!finite) throw InputError(fmt::format("fit {}: point {} is not finite", model.name, i));
  }
  // p parameters need p distinct inputs: a curve through fewer is not
  // determined, whatever the optimiser says.
  {
    std::vector<std::vector<double>> xs;
    for (std::size_t i = 0; i < n; ++i) xs.emplace_back(&data.x[i * data.dim], &data.x[(i + 1) * data.dim]);
    std::sort(xs.begin(), xs.end());
    const std::size_t distinct = std::unique(xs.begin(), xs.end()) - xs.begin();
    if (distinct < p)
      throw AnalysisError(fmt::format("fit {}: {} distinct value{} of ({}) for {} parameters: the fit "
                                      "is not determined", model.name, distinct, distinct == 1 ? "" : "s",
                                      fmt::join(model.inputs, ", "), p));
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(model.f(&data.x[i * data.dim], p0.data())))
      throw AnalysisError(fmt::format("fit {}: model not finite at the starting point (point {})",
                                      model.name, i));

  GslOff guard;
  Problem pb{&model, &data};
  gsl_multifit_nlinear_fdf fdf{};
  fdf.f = residuals;
  fdf.df = nullptr;  // finite differences
  fdf.fvv = nullptr;
  fdf.n = n;
  fdf.p = p;
  fdf.params = &pb;
  auto params = gsl_multifit_nlinear_default_parameters();
  std::unique_ptr<gsl_multifit_nlinear_workspace, void (*)(gsl_multifit_nlinear_workspace*)> w(
      gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &params, n, p),
      gsl_multifit_nlinear_free);
  gsl_vector_view x0 = gsl_vector_view_array(p0.data(), p);
  gsl_multifit_nlinear_init(&x0.vector, &fdf, w.get());
  int info = 0;
  const int status =
      gsl_multifit_nlinear_driver(500, 1e-10, 1e-10, 1e-12, nullptr, nullptr, &info, w.get());

  // A Jacobian of (numerically) lower rank than p at the optimum leaves a
  // combination of the parameters free: refused, never "converged".
  double rcond = 0;
  gsl_multifit_nlinear_rcond(&rcond, w.get());
  if (!(rcond > 1e-12))
    throw AnalysisError(fmt::format("fit {}: the Jacobian is singular at the optimum (reciprocal "
                                    "condition number {:.2g}): the data do not determine all of {}",
                                    model.name, rcond, fmt::join(model.params, ", ")));

  FitResult r;
  r.model = model.name;
  r.names = model.params;
  r.weighted = !data.sigma.empty();
  r.iterations = gsl_multifit_nlinear_niter(w.get());
  r.converged = status == GSL_SUCCESS;
  if (!r.converged) r.message = gsl_strerror(status);
  const gsl_vector* xb = gsl_multifit_nlinear_position(w.get());
  r.value.assign(xb->data, xb->data + p);
  const gsl_vector* f = gsl_multifit_nlinear_residual(w.get());
  gsl_blas_ddot(f, f, &r.chi2);
  r.dof = static_cast<int>(n) - static_cast<int>(p);
  r.chi2_dof = r.dof > 0 ? r.chi2 / r.dof : std::numeric_limits<double>::quiet_NaN();
  if (r.dof > 0)
    r.scale = r.weighted ? std::max(1.0, r.chi2_dof) : r.chi2_dof;
  else
    r.scale = 1;  // no residual degrees of freedom: error bars only
  std::unique_ptr<gsl_matrix, void (*)(gsl_matrix*)> C(gsl_matrix_alloc(p, p), gsl_matrix_free);
  gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(w.get()), 0.0, C.get());
  r.cov.resize(p * p);
  r.error.resize(p);
  for (std::size_t i = 0; i < p; ++i) {
    for (std::size_t j = 0; j < p; ++j) r.cov[i * p + j] = r.scale * gsl_matrix_get(C.get(), i, j);
    r.error[i] = std::sqrt(r.cov[i * p + i]);
    if (!std::isfinite(r.value[i]) || !std::isfinite(r.error[i]))
      throw AnalysisError(fmt::format("fit {}: parameter {} = {} +- {} is not finite", model.name,
                                      model.params[i], r.value[i], r.error[i]));
  }
  return r;
}

double predict(const Model& model, const FitResult& r, const double* x) {
  return model.f(x, r.value.data());
}

double predict_error(const Model& model, const FitResult& r, const double* x) {
  const std::size_t p = r.value.size();
  std::vector<double> g(p), q = r.value;
  for (std::size_t i = 0; i < p; ++i) {
    const double h = 1e-6 * std::max(std::abs(q[i]), 1e-6);
    q[i] = r.value[i] + h;
    const double up = model.f(x, q.data());
    q[i] = r.value[i] - h;
    const double dn = model.f(x, q.data());
    q[i] = r.value[i];
    g[i] = (up - dn) / (2 * h);
  }
  double v = 0;
  for (std::size_t i = 0; i < p; ++i)
    for (std::size_t j = 0; j < p; ++j) v += g[i] * r.cov[i * p + j] * g[j];
  return std::sqrt(std::max(v, 0.0));
}

Model mu_of_I() {
  return {"mu_I", "mu = mu1 + (mu2 - mu1)/(1 + I0/I)", {"mu1", "mu2", "I0"}, {"I"},
          [](const double* x, const double* p) { return p[0] + (p[1] - p[0]) / (1 + p[2] / x[0]); }};
}
Model nu_of_I() {
  return {"nu_I", "nu = nu_max - a I", {"nu_max", "a"}, {"I"},
          [](const double* x, const double* p) { return p[0] - p[1] * x[0]; }};
}
Model nu_of_I_volume() {
  return {"nu_I", "nu = nu_max - a I, fitted as I = (nu_max - nu)/a (nu imposed)", {"nu_max", "a"}, {"nu"},
          [](const double* x, const double* p) { return (p[0] - x[0]) / p[1]; }};
}
Model void_ratio(double p0) {
  return {"void_ratio", fmt::format("e = e0 - lambda ln(p/p0), p0 = {}", p0), {"e0", "lambda"}, {"p"},
          [p0](const double* x, const double* p) { return p[0] - p[1] * std::log(x[0] / p0); }};
}
Model cohesion() {
  return {"cohesion", "c/p = k0 eta/(1 - beta ln(1 - I/(1 + alpha eta)^(1/2)))",
          {"k0", "beta", "alpha"}, {"eta", "I"},
          [](const double* x, const double* p) {
            const double Ic = x[1] / std::sqrt(1 + p[2] * x[0]);
            return p[0] * x[0] / (1 - p[1] * std::log(1 - Ic));
          }};
}
Model dilatancy() {
  return {"dilatancy", "sin phi = sin phi_c + sin psi", {"sin_phi_c"}, {"sin_psi"},
          [](const double* x, const double* p) { return p[0] + x[0]; }};
}
Model dilatancy_free() {
  return {"dilatancy_free", "sin phi = sin phi_c + b sin psi", {"sin_phi_c", "b"}, {"sin_psi"},
          [](const double* x, const double* p) { return p[0] + p[1] * x[0]; }};
}
// y = y0 + (y1 - y0)(1 - exp(-alpha/alpha_c)): the angularity study's law,
// for mu* and for nu* alike.
namespace {
Model saturation_in_alpha(const std::string& y) {
  return {y + "_alpha", fmt::format("{0} = {0}0 + ({0}1 - {0}0)(1 - exp(-alpha/alpha_c))", y),
          {y + "0", y + "1", "alpha_c"},
          {"alpha"},
          [](const double* x, const double* p) {
            return p[0] + (p[1] - p[0]) * (1 - std::exp(-x[0] / p[2]));
          }};
}
}  // namespace
Model mu_of_alpha() { return saturation_in_alpha("mu"); }
Model nu_of_alpha() { return saturation_in_alpha("nu"); }

namespace {

FitData data1(std::span<const double> x, std::span<const double> y, std::span<const double> s,
              const char* what) {
  if (x.size() != y.size() || (!s.empty() && s.size() != y.size()))
    throw AnalysisError(fmt::format("fit {}: columns differ in length", what));
  FitData d;
  d.x.assign(x.begin(), x.end());
  d.y.assign(y.begin(), y.end());
  d.sigma.assign(s.begin(), s.end());
  return d;
}

std::size_t argmin(std::span<const double> v) {
  return static_cast<std::size_t>(std::min_element(v.begin(), v.end()) - v.begin());
}
std::size_t argmax(std::span<const double> v) {
  return static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

}  // namespace

FitResult fit_mu_I(std::span<const double> I, std::span<const double> mu,
                   std::span<const double> sigma) {
  auto d = data1(I, mu, sigma, "mu(I)");
  if (I.empty()) throw AnalysisError("fit mu(I): no data");
  for (double v : I)
    if (!(v > 0)) throw AnalysisError(fmt::format("fit mu(I): inertial number {} is not positive", v));
  // mu1 from the slowest point, mu2 above the fastest one, I0 at the
  // geometric middle of the range: the curve's midpoint is at I = I0.
  const double lo = mu[argmin(I)], hi = mu[argmax(I)];
  double lg = 0;
  for (double v : I) lg += std::log(v);
  const double I0 = std::exp(lg / static_cast<double>(I.size()));
  return fit(mu_of_I(), d, {lo, hi + 0.5 * std::abs(hi - lo) + 0.01, I0});
}

FitResult fit_nu_I(std::span<const double> I, std::span<const double> nu,
                   std::span<const double> sigma) {
  auto d = data1(I, nu, sigma, "nu(I)");
  if (I.empty()) throw AnalysisError("fit nu(I): no data");
  return fit(nu_of_I(), d, {nu[argmin(I)], 0.0});
}

FitResult fit_nu_I_volume(std::span<const double> nu, std::span<const double> I,
                          std::span<const double> sigma_I) {
  auto d = data1(nu, I, sigma_I, "nu(I) at imposed volume");
  if (nu.empty()) throw AnalysisError("fit nu(I): no data");
  // The start: the least-squares line nu = c - s I (a = s, nu_max = c), a
  // kept away from 0 where the model is undefined.
  const double n = static_cast<double>(nu.size());
  const double mI = std::accumulate(I.begin(), I.end(), 0.0) / n, mn = std::accumulate(nu.begin(), nu.end(), 0.0) / n;
  double sII = 0, sIn = 0;
  for (std::size_t i = 0; i < nu.size(); ++i) sII += (I[i] - mI) * (I[i] - mI), sIn += (I[i] - mI) * (nu[i] - mn);
  double a = sII > 0 ? -sIn / sII : 0.0;
  if (!(std::abs(a) > 1e-6)) a = 0.1;
  return fit(nu_of_I_volume(), d, {mn + a * mI, a});
}

FitResult fit_void_ratio(std::span<const double> p, std::span<const double> e,
                         std::span<const double> sigma, double p0) {
  auto d = data1(p, e, sigma, "void ratio");
  if (p.empty()) throw AnalysisError("fit void ratio: no data");
  for (double v : p)
    if (!(v > 0)) throw AnalysisError(fmt::format("fit void ratio: pressure {} is not positive", v));
  return fit(void_ratio(p0), d, {e[0], 0.0});
}

FitResult fit_cohesion(std::span<const double> eta, std::span<const double> I,
                       std::span<const double> c_over_p, std::span<const double> sigma) {
  if (eta.size() != I.size() || I.size() != c_over_p.size() ||
      (!sigma.empty() && sigma.size() != I.size()))
    throw AnalysisError("fit cohesion: columns differ in length");
  if (I.empty()) throw AnalysisError("fit cohesion: no data");
  FitData d;
  d.dim = 2;
  for (std::size_t i = 0; i < I.size(); ++i) {
    if (!(I[i] >= 0 && I[i] < 1))
      throw AnalysisError(fmt::format("fit cohesion: inertial number {} outside [0, 1)", I[i]));
    d.x.push_back(eta[i]);
    d.x.push_back(I[i]);
    d.y.push_back(c_over_p[i]);
  }
  d.sigma.assign(sigma.begin(), sigma.end());
  // k0 from the slowest points, where the denominator is ~1.
  double k0 = 0, wsum = 0;
  for (std::size_t i = 0; i < I.size(); ++i) {
    if (eta[i] <= 0) continue;
    const double w = 1 / (1 + 100 * I[i]);
    k0 += w * c_over_p[i] / eta[i];
    wsum += w;
  }
  k0 = wsum > 0 ? k0 / wsum : 0.1;
  return fit(cohesion(), d, {k0, 1.0, 0.1});
}

FitResult fit_dilatancy(std::span<const double> sin_psi, std::span<const double> sin_phi,
                        std::span<const double> sigma, bool free_slope) {
  auto d = data1(sin_psi, sin_phi, sigma, "dilatancy");
  if (sin_psi.empty()) throw AnalysisError("fit dilatancy: no data");
  double m = 0;
  for (std::size_t i = 0; i < sin_psi.size(); ++i) m += sin_phi[i] - sin_psi[i];
  m /= static_cast<double>(sin_psi.size());
  return free_slope ? fit(dilatancy_free(), d, {m, 1.0}) : fit(dilatancy(), d, {m});
}

FitResult fit_of_alpha(const Model& m, std::span<const double> alpha, std::span<const double> y,
                       std::span<const double> sigma) {
  auto d = data1(alpha, y, sigma, m.name.c_str());
  if (alpha.empty()) throw AnalysisError(fmt::format("fit {}: no data", m.name));
  const double amax = alpha[argmax(alpha)];
  return fit(m, d, {y[argmin(alpha)], y[argmax(alpha)], 0.3 * (amax > 0 ? amax : 1)});
}
FitResult fit_mu_alpha(std::span<const double> alpha, std::span<const double> mu,
                       std::span<const double> sigma) {
  return fit_of_alpha(mu_of_alpha(), alpha, mu, sigma);
}

}  // namespace cda
