#include "anisotropy.hpp"

#include <fftw3.h>
#include <fmt/core.h>

#include <cmath>
#include <numbers>

namespace cda {

using cplx = std::complex<double>;
constexpr double pi = std::numbers::pi;

double Harmonic::theta() const {
  if (A == cplx(0, 0)) return 0;
  double t = 0.5 * std::arg(A);
  if (t < 0) t += pi;
  return t;
}

double Anisotropy::sum_half() const {
  return 0.5 * (c.a() + ln.a() + lt.a() + fn.a() + ft.a());
}
double Anisotropy::sum_half_vector() const {
  return 0.5 * std::abs(c.A + ln.A + lt.A + fn.A + ft.A);
}

namespace {

double fold(double theta) {  // -> [0, pi)
  double t = std::fmod(theta, pi);
  if (t < 0) t += pi;
  if (t >= pi) t = 0;
  return t;
}

void fill_empty(std::vector<double>& v, const std::vector<std::size_t>& count) {
  const std::size_t m = v.size();
  for (std::size_t k = 0; k < m; ++k) {
    if (count[k]) continue;
    std::size_t lo = 1, hi = 1;
    while (lo < m && !count[(k + m - lo) % m]) ++lo;
    while (hi < m && !count[(k + hi) % m]) ++hi;
    if (lo >= m) return;  // no data at all
    const double a = v[(k + m - lo) % m], b = v[(k + hi) % m];
    v[k] = a + (b - a) * static_cast<double>(lo) / static_cast<double>(lo + hi);
  }
}

// Coefficient of exp(-2 i theta) of a profile sampled at the bin centres,
// from FFTW's r2c (which phases bin k at k d, hence the shift by d/2), divided
// by the bin-averaging factor sinc(d).
struct Harmonics {
  double c0;   // sum of the samples
  cplx c1;     // sum v_k exp(-2 i theta_k), theta_k the bin centres
};

Harmonics second_harmonic(const std::vector<double>& v) {
  const int m = static_cast<int>(v.size());
  std::vector<double> in(v);
  std::vector<fftw_complex> out(static_cast<std::size_t>(m / 2 + 1));
  fftw_plan plan = fftw_plan_dft_r2c_1d(m, in.data(), out.data(), FFTW_ESTIMATE);
  fftw_execute(plan);
  fftw_destroy_plan(plan);
  const double d = pi / m;
  const cplx raw(out[1][0], out[1][1]);
  return {out[0][0], raw * std::polar(1.0, -d) / (std::sin(d) / d)};
}

// D(T) for T = sum w x n: (T11 - T22) + i(T12 + T21) and the trace.
struct Dev {
  cplx dev;
  double tr = 0;
  cplx D() const { return tr != 0 ? 2.0 * dev / tr : cplx(0, 0); }
  void add(double vx, double vy, double nx, double ny) {  // T += v n^T
    dev += cplx(vx * nx - vy * ny, vx * ny + vy * nx);
    tr += vx * nx + vy * ny;
  }
};

// Solves A_c + A_x = r X, r = 1 + Re(A_c conj(A_x))/2; returns A_x and r.
std::pair<cplx, double> invert(cplx Ac, cplx X) {
  cplx Ax = X - Ac;
  double r = 1;
  for (int it = 0; it < 100; ++it) {
    r = 1 + 0.5 * std::real(Ac * std::conj(Ax));
    const cplx next = r * X - Ac;
    const bool done = std::abs(next - Ax) < 1e-15 * (1 + std::abs(Ax));
    Ax = next;
    if (done) break;
  }
  return {Ax, r};
}

}  // namespace

AngularProfile angular_profile(const ContactSet& cs, int bins) {
  if (bins < 4) throw AnalysisError(fmt::format("angular profile: {} bins, at least 4 needed", bins));
  const auto m = static_cast<std::size_t>(bins);
  const double d = pi / bins;
  AngularProfile p;
  p.theta.resize(m);
  p.count.assign(m, 0);
  p.P.assign(m, 0);
  p.ln.assign(m, 0);
  p.lt.assign(m, 0);
  p.fn.assign(m, 0);
  p.ft.assign(m, 0);
  for (std::size_t k = 0; k < m; ++k) p.theta[k] = (static_cast<double>(k) + 0.5) * d;
  for (const auto& c : cs) {
    auto k = static_cast<std::size_t>(fold(c.theta) / d);
    if (k >= m) k = m - 1;
    ++p.count[k];
    p.ln[k] += c.ln();
    p.lt[k] += c.lt();
    p.fn[k] += c.fn;
    p.ft[k] += c.ft;
  }
  const double n = static_cast<double>(cs.size());
  for (std::size_t k = 0; k < m; ++k) {
    p.P[k] = n > 0 ? static_cast<double>(p.count[k]) / (2 * n * d) : 0;
    if (p.count[k]) {
      const double w = 1.0 / static_cast<double>(p.count[k]);
      p.ln[k] *= w;
      p.lt[k] *= w;
      p.fn[k] *= w;
      p.ft[k] *= w;
    } else {
      ++p.empty_bins;
    }
  }
  for (auto* v : {&p.ln, &p.lt, &p.fn, &p.ft}) fill_empty(*v, p.count);
  return p;
}

Anisotropy anisotropy_fft(const ContactSet& cs, int bins) {
  if (cs.empty()) throw AnalysisError("anisotropy: no contacts");
  const auto p = angular_profile(cs, bins);
  const double m = bins;
  std::vector<double> counts(p.count.begin(), p.count.end());
  const auto hc = second_harmonic(counts);
  const auto hln = second_harmonic(p.ln), hlt = second_harmonic(p.lt);
  const auto hfn = second_harmonic(p.fn), hft = second_harmonic(p.ft);
  Anisotropy a;
  a.contacts = cs.size();
  a.mean_ln = hln.c0 / m;
  a.mean_fn = hfn.c0 / m;
  // <v>(1 + a cos 2(theta - t)) sampled at M centres gives
  // c1 = (M/2) <v> a exp(-2 i t), c0 = M <v>: conj(2 c1/c0) = a exp(2 i t).
  const cplx i(0, 1);
  a.c.A = std::conj(2.0 * hc.c1 / hc.c0);
  a.ln.A = std::conj(2.0 * hln.c1 / hln.c0);
  a.fn.A = std::conj(2.0 * hfn.c1 / hfn.c0);
  // -<v> a sin 2(theta - t) = <v> a Re(i exp(2i(theta - t))): the sum is
  // (M/2) <v> a i exp(-2 i t).
  a.lt.A = hln.c0 != 0 ? std::conj(-i * 2.0 * hlt.c1 / hln.c0) : cplx(0, 0);
  a.ft.A = hfn.c0 != 0 ? std::conj(-i * 2.0 * hft.c1 / hfn.c0) : cplx(0, 0);
  return a;
}

Anisotropy anisotropy_tensor(const ContactSet& cs) {
  if (cs.empty()) throw AnalysisError("anisotropy: no contacts");
  Dev chi_c, chi_ln, chi_l, chi_fn, chi_f;
  double sum_ln = 0, sum_fn = 0;
  for (const auto& c : cs) {
    const double nx = c.nx(), ny = c.ny(), ln = c.ln();
    const double fx = c.fn * nx - c.ft * ny, fy = c.fn * ny + c.ft * nx;
    chi_c.add(nx, ny, nx, ny);
    chi_ln.add(ln * nx, ln * ny, nx, ny);
    chi_l.add(c.lx, c.ly, nx, ny);
    chi_fn.add(c.fn * nx, c.fn * ny, nx, ny);
    chi_f.add(fx, fy, nx, ny);
    sum_ln += ln;
    sum_fn += c.fn;
  }
  Anisotropy a;
  a.contacts = cs.size();
  a.c.A = chi_c.D();
  const auto [Aln, rl] = invert(a.c.A, chi_ln.D());
  a.ln.A = Aln;
  a.lt.A = rl * (chi_l.D() - chi_ln.D());
  const auto [Afn, rf] = invert(a.c.A, chi_fn.D());
  a.fn.A = Afn;
  a.ft.A = rf * (chi_f.D() - chi_fn.D());
  const double n = static_cast<double>(cs.size());
  a.mean_ln = sum_ln / n / rl;
  a.mean_fn = sum_fn / n / rf;
  return a;
}

double sliding_share(const ContactSet& cs, double mu, double tol, double f_eps) {
  const auto forces = as_forces(cs);
  if (f_eps < 0) f_eps = cd::obs::force_threshold<2>(forces);
  std::size_t bearing = 0, sliding = 0;
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const auto& c = cs[k];
    if (!cd::obs::bears_force(forces[k], f_eps)) continue;
    ++bearing;
    const bool slides = mu > 0 ? std::abs(c.ft) >= mu * c.fn * (1 - tol) : c.status == 2;
    if (slides) ++sliding;
  }
  return bearing ? static_cast<double>(sliding) / static_cast<double>(bearing) : 0.0;
}

}  // namespace cda
