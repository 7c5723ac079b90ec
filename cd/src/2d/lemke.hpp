// Reference solver: the 2D frictional contact problem as a linear
// complementarity problem (LCP), solved by Lemke's complementary pivoting
// (method.md section 12: in 2D the Coulomb cone is already polyhedral, so the
// problem is exactly an LCP; no cone is faceted).
//
// LCP(M, q): find z >= 0 with w = M z + q >= 0 and z^T w = 0.
//
// Formulation (Stewart & Trinkle 1996; Anitescu & Potra 1997), per contact k
// with u = W r + q the law's velocity, four unknowns and four slacks:
//   z_k = (r_n, r_t+, r_t-, lambda),   r_t = r_t+ - r_t-
//   w_k = (u_n, lambda + u_t, lambda - u_t, mu r_n - r_t+ - r_t-)
// and z_k _|_ w_k componentwise. lambda >= 0 is the sliding speed |u_t|.
// Why this is the Signorini-Coulomb law:
//   - (u_n, r_n): Signorini as is.
//   - |u_t| <= lambda from the two middle slacks.
//   - lambda > 0 forces r_t+ + r_t- = mu r_n (cone boundary); if r_n > 0 one
//     of r_t+/- is positive, say r_t+: then u_t = -lambda < 0, the third slack
//     is 2 lambda > 0 so r_t- = 0, and r_t = +mu r_n = -mu r_n sign(u_t):
//     sliding. If r_n = 0, r_t = 0 and any u_t is allowed (open contact,
//     lambda = |u_t|).
//   - lambda = 0 forces u_t = 0 and r_t+ + r_t- <= mu r_n: sticking, with
//     |r_t| <= mu r_n.
// Conversely any solution of the law gives one of the LCP (lambda = |u_t|,
// r_t+/- the positive/negative parts of r_t). In blocks, with W_ab the block
// of W coupling the a-rows of contact k with the b-columns of contact j:
//                  r_n      r_t+     r_t-     lambda      q
//   u_n       [  W_nn     W_nt    -W_nt      0    ]   [  q_n ]
//   l + u_t   [  W_tn     W_tt    -W_tt    I(k=j) ]   [  q_t ]
//   l - u_t   [ -W_tn    -W_tt     W_tt    I(k=j) ]   [ -q_t ]
//   friction  [ mu I     -I       -I        0    ]   [   0  ]
// M is not symmetric nor positive semi-definite, but for W positive
// semi-definite Lemke's method processes it (the references above); ray
// termination is reported, never hidden.
//
// Pivoting: core/lcp.hpp (shared with the 3D polyhedral-cone LCP).
#pragma once
#include <Eigen/Core>

#include "lcp.hpp"
#include "problem.hpp"

namespace cd {

// The LCP above for a 2D problem (unknowns ordered per contact).
void friction_lcp(const Problem& p, Eigen::MatrixXd& M, Eigen::VectorXd& q);

struct LemkeResult {
  LemkeStatus status = LemkeStatus::Solved;
  int pivots = 0;
  Eigen::VectorXd r;  // 2nc impulses (r_n, r_t) per contact
  double time = 0;    // wall-clock seconds, LCP assembly included
};
LemkeResult solve_lemke(const Problem& p, int max_pivots = 0);

}  // namespace cd
