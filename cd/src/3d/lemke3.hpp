// Reference solver for 3D problems: the cone replaced by a polyhedral one,
// so that the frictional contact problem becomes a linear complementarity
// problem (method.md section 13), solved by Lemke's method (core/lcp.hpp,
// the same pivoting as the 2D reference).
//
// Polyhedral cone with e >= 2 pairs of faces, face normals alpha_i = i pi/e
// in the tangent plane: |(r_a/mu_a) cos alpha_i + (r_b/mu_b) sin alpha_i|
// <= r_n, i = 0..e-1. It circumscribes the elliptic (round) cone; its 2e
// edges are the generators
//     G_j = D (cos th_j, sin th_j) / cos(pi/2e),  th_j = (2j+1) pi/(2e),
// D = diag(mu_a, mu_b), so the tangential impulse is r_t = sum_j beta_j G_j,
// beta >= 0, sum beta <= r_n. e = 2 gives G = D(+-1, +-1): the rectangle
// law |r_a| <= mu_a r_n, |r_b| <= mu_b r_n.
//
// Per contact k (Stewart & Trinkle 1996, with the edges as generators), the
// unknowns and slacks, 2e + 2 pairs:
//   z_k = (r_n, beta_0 .. beta_{2e-1}, lambda)
//   w_k = (u_n, lambda + G_0.u_t, .., lambda + G_{2e-1}.u_t, r_n - sum beta)
// with u = W r + q. Why this is the polyhedral Coulomb law with maximal
// dissipation: lambda >= max_j (-G_j.u_t); lambda > 0 forces sum beta = r_n
// (on the boundary) and beta_j > 0 only on the generators that maximise
// -G_j.u_t, i.e. r_t maximises the dissipation -r_t.u_t over the polygon;
// lambda = 0 forces G_j.u_t >= 0 for all j, and since the G_j span the plane
// with positive combinations, u_t = 0 (stick), r_t anywhere in the polygon.
#pragma once
#include <Eigen/Core>

#include "lcp.hpp"
#include "problem3.hpp"

namespace cd {

// The generators G_j (2 x 2e) of contact cone c with e face pairs.
Eigen::Matrix2Xd polyhedral_generators(const Cone3& c, int e);

// The LCP (M, q) above; unknowns ordered per contact, 2e + 2 each.
void polyhedral_lcp(const Problem3& p, int e, Eigen::MatrixXd& M, Eigen::VectorXd& q);

struct Lemke3Result {
  LemkeStatus status = LemkeStatus::Solved;
  int pivots = 0;
  Eigen::VectorXd r;     // 3nc impulses (r_n, r_t1, r_t2) per contact
  double lcp_error = 0;  // max_i |min(z_i, w_i)| / max(1, max |q|) of the LCP solution
  double time = 0;       // wall-clock seconds, LCP assembly included
};
Lemke3Result solve_lemke(const Problem3& p, int e, int max_pivots = 0);

}  // namespace cd
