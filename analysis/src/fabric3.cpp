#include "fabric3.hpp"

#include <Eigen/Eigenvalues>
#include <fmt/core.h>

#include <cmath>
#include <limits>

namespace cda {
namespace {

Eigen::Matrix3d to_eigen(const Mat3& t) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = t[i][j];
  return m;
}

Mat3 from_eigen(const Eigen::Matrix3d& m) {
  Mat3 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t[i][j] = m(i, j);
  return t;
}

// Deviator of the symmetric part.
Eigen::Matrix3d dev_sym(const Eigen::Matrix3d& m) {
  const Eigen::Matrix3d s = 0.5 * (m + m.transpose());
  return s - (s.trace() / 3) * Eigen::Matrix3d::Identity();
}

}  // namespace

Principal principal(const Mat3& t) {
  const Eigen::Matrix3d m = to_eigen(t);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (m + m.transpose()));
  Principal p;
  for (int k = 0; k < 3; ++k) {  // Eigen sorts ascending
    p.value[k] = es.eigenvalues()[2 - k];
    for (int i = 0; i < 3; ++i) p.dir[k][i] = es.eigenvectors()(i, 2 - k);
  }
  return p;
}

double spread3(const Mat3& t) {
  const auto p = principal(t);
  return (p.value[0] - p.value[2]) / 3;
}

double Stress3::p() const { return cd::obs::mean_3d(s); }
double Stress3::q() const { return spread3(s); }
double Stress3::q_over_p() const {
  const double pp = p();
  return pp != 0 ? q() / pp : std::numeric_limits<double>::quiet_NaN();
}
double Stress3::q_vm() const { return cd::obs::deviator_3d(s); }
double Stress3::mu() const {
  return s[1][1] != 0 ? -0.5 * (s[0][1] + s[1][0]) / s[1][1] : std::numeric_limits<double>::quiet_NaN();
}
double Stress3::skew() const {
  double m = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m = std::max(m, 0.5 * std::abs(s[i][j] - s[j][i]));
  return m;
}

Stress3 contact_stress3(const ContactSet3& cs, double volume) {
  if (!(volume > 0)) throw AnalysisError(fmt::format("stress: volume {} is not positive", volume));
  const auto f = as_forces(cs);
  return {cd::obs::contact_stress<3>(f, volume)};
}

double Anisotropy3::sum_2_5() const { return 0.4 * (a_c() + a_n() + a_t()); }

double Anisotropy3::sum_2_5_tensor() const {
  return 0.4 * spread3(from_eigen(to_eigen(Ac) + to_eigen(An) + to_eigen(At)));
}

double Anisotropy3::sum_2_5_on(const Stress3& s) const {
  const auto ps = principal(s.s);
  const Eigen::Matrix3d A = to_eigen(Ac) + to_eigen(An) + to_eigen(At);
  const Eigen::Vector3d e1(ps.dir[0][0], ps.dir[0][1], ps.dir[0][2]), e3(ps.dir[2][0], ps.dir[2][1], ps.dir[2][2]);
  return 0.4 * (e1.dot(A * e1) - e3.dot(A * e3)) / 3;
}

Anisotropy3 anisotropy3(const ContactSet3& cs) {
  if (cs.empty()) throw AnalysisError("anisotropy: no contacts");
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero(), chi_n = Eigen::Matrix3d::Zero(), chi_t = Eigen::Matrix3d::Zero();
  for (const auto& k : cs) {
    const Eigen::Vector3d n(k.c.n[0], k.c.n[1], k.c.n[2]), ft(k.c.ft[0], k.c.ft[1], k.c.ft[2]);
    F += n * n.transpose();
    chi_n += k.c.fn * n * n.transpose();
    chi_t += ft * n.transpose();
  }
  const double N = static_cast<double>(cs.size());
  F /= N;
  chi_n /= N;
  chi_t /= N;
  if (!(chi_n.trace() > 0))
    throw AnalysisError(fmt::format("anisotropy: mean normal force {} is not positive", chi_n.trace()));
  const Eigen::Matrix3d Ac = 7.5 * dev_sym(F);
  const Eigen::Matrix3d Dn = 7.5 * dev_sym(chi_n), Dt = 7.5 * dev_sym(chi_t);
  // First-order start, then the fixed point of the exact relations (header).
  double f = chi_n.trace();
  Eigen::Matrix3d An = Dn / f - Ac, At = Dt / f;
  Anisotropy3 a;
  bool done = false;
  for (int it = 1; it <= 200 && !done; ++it) {
    const double f_next = chi_n.trace() / (1 + (2.0 / 15) * (Ac.cwiseProduct(An)).sum());
    const Eigen::Matrix3d An_next = Dn / f_next - Ac - (2.0 / 7) * dev_sym(Ac * An + An * Ac);
    const Eigen::Matrix3d At_next = Dt / f_next - (1.0 / 7) * dev_sym(Ac * At + At * Ac);
    const double change = (An_next - An).norm() + (At_next - At).norm() + std::abs(f_next - f) / f;
    f = f_next;
    An = An_next;
    At = At_next;
    a.iterations = it;
    done = change < 1e-13 * (1 + An.norm() + At.norm());
    if (!std::isfinite(change)) break;
  }
  if (!done)
    throw AnalysisError(fmt::format("anisotropy: the harmonic forms do not fit these {} contacts (no fixed "
                                    "point; first-order a_c {:.3g})",
                                    cs.size(), spread3(from_eigen(Ac))));
  a.Ac = from_eigen(Ac);
  a.An = from_eigen(An);
  a.At = from_eigen(At);
  a.mean_f = f;
  a.contacts = cs.size();
  return a;
}

BranchAnisotropy3 branch_anisotropy3(const ContactSet3& cs) {
  ContactSet3 branch = cs;
  for (auto& k : branch) {
    const Eigen::Vector3d n(k.c.n[0], k.c.n[1], k.c.n[2]), l(k.c.l[0], k.c.l[1], k.c.l[2]);
    const double ln = l.dot(n);
    const Eigen::Vector3d lt = l - ln * n;
    k.c.fn = ln;
    for (int i = 0; i < 3; ++i) k.c.ft[i] = lt[i];
  }
  const Anisotropy3 a = anisotropy3(branch);
  return {a.An, a.At, branch_fabric3(cs), a.mean_f};
}

Mat3 branch_fabric3(const ContactSet3& cs) {
  if (cs.empty()) throw AnalysisError("branch fabric: no contacts");
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  for (const auto& k : cs) {
    const Eigen::Vector3d l(k.c.l[0], k.c.l[1], k.c.l[2]);
    const double len = l.norm();
    if (!(len > 0.0) || !std::isfinite(len))
      throw AnalysisError(fmt::format("branch fabric: a branch vector of length {} (bodies {} and {})", len,
                                      k.c.b1, k.c.b2));
    F += (l / len) * (l / len).transpose();
  }
  return from_eigen(7.5 * dev_sym(F / static_cast<double>(cs.size())));
}

}  // namespace cda
