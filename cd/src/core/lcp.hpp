// Lemke's complementary pivoting for a dense linear complementarity problem
// (LCP), whatever the dimension of the contact problem it came from: the 2D
// frictional contact LCP (2d/lemke.hpp, exact) and the 3D one with a
// polyhedral cone (3d/lemke3.hpp) both hand their (M, q) to it.
//
// LCP(M, q): find z >= 0 with w = M z + q >= 0 and z^T w = 0.
//
// The friction LCPs' M is neither symmetric nor positive semi-definite, but
// for W positive semi-definite Lemke's method processes it (Stewart &
// Trinkle 1996; Anitescu & Potra 1997); ray termination is reported, never
// hidden.
//
// Pivoting: covering vector of ones and artificial variable z0; the ratio test
// is lexicographic on the rows of [B^-1 q, B^-1] (ties are common: the
// friction rows have q = 0), with z0 leaving first whenever it ties. The
// dense tableau is n x (2n + 1) with n the LCP size: meant for a few hundred unknowns.
// At the end the basic variables are recomputed by one LU solve with the
// final basis, which removes the round-off the pivots accumulated.
#pragma once
#include <Eigen/Core>

namespace cd {

enum class LemkeStatus { Solved, RayTermination, IterationCap };
const char* to_string(LemkeStatus s);

struct LcpSolution {
  LemkeStatus status = LemkeStatus::Solved;
  int pivots = 0;
  Eigen::VectorXd z, w;  // on ray termination or cap: the last basic point
};

// Lemke's method on LCP(M, q); max_pivots <= 0 means 50 n + 100.
LcpSolution solve_lcp_lemke(const Eigen::MatrixXd& M, const Eigen::VectorXd& q, int max_pivots = 0);

}  // namespace cd
