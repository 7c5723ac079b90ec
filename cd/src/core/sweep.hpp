// The NLGS sweep (method.md section 5), written once over a "coupling": how a
// row sees the impulses of the others, and over the row type (2D rows
// today, 3D rows next). 2d/coupling.hpp couples rows through the velocities
// of the bodies they touch (the simulator's steps); 2d/problem.cpp through
// the off-diagonal blocks of W (frozen problems in matrix form). The sweep
// order, the convergence test, the boundary dofs and the residuals are this
// code for both, so a frozen problem is replayed by the production solver.
// Studies that visit rows in their own order (cd/bench/ss_pair) use the
// coupling's update, the sweep's own row update, rather than a copy, and
// solve_units, this sweep's convergence test and residuals in their order.
//
// Nothing here depends on the dimension. A coupling C provides
//   template <class L, bool Write1>
//   void update(Row& r, double& dp2, double& pabs)
//       one local solve of row r with law L; dp2 = |dp|^2, pabs = |p|.
//       Write1 = false when body 1 is driven (read, never written).
// and the row type provides, found by argument-dependent lookup,
//   double row_residual(const C& c, const Row& r)   the law residual of r
//   double impulse_norm(const Row& r)               |p| of r
//   double update_dof(Dof& d, Row* rows)            one boundary dof update
//       (returns its residual; see 2d/nlgs.hpp).
#pragma once
#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "solver.hpp"

namespace cd::sweep {

constexpr int kBlock = 128;  // rows per reduction block (fixed: see nlgs.hpp)
constexpr int kResidualEvery = 10;  // sweeps between checks of SolverParams::residual_tol

struct RowBlock {
  std::int32_t begin, end;
  bool write1;
};

struct BlockStats {
  double dp2sum = 0, psum = 0, rmax = 0, rsum = 0;
};

// Splits [begin, end) into fixed blocks.
inline void push_blocks(std::vector<RowBlock>& out, int begin, int end, bool write1) {
  for (int b = begin; b < end; b += kBlock) out.push_back({b, std::min(end, b + kBlock), write1});
}

template <class L, class Row, class C>
void run_block(const RowBlock& k, Row* rows, C& c, BlockStats& s) {
  double dsum = 0, psum = 0;
  if (k.write1) {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      c.template update<L, true>(rows[i], dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
  } else {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      c.template update<L, false>(rows[i], dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
  }
  s.dp2sum = dsum;
  s.psum = psum;
}

// Law residual of every row (normalised by mean |p|), read-only.
template <class Row, class C>
void residuals(const std::vector<Row>& rows, const C& c, int min_parallel, SolveStats& st) {
  const int n = static_cast<int>(rows.size());
  if (n == 0) {
    st.residual_max = st.residual_mean = 0;
    return;
  }
  std::vector<RowBlock> blocks;
  push_blocks(blocks, 0, n, true);
  std::vector<BlockStats> bs(blocks.size());
  const int nb = static_cast<int>(blocks.size());
#pragma omp parallel for schedule(static) if (n >= min_parallel)
  for (int b = 0; b < nb; ++b) {
    double rmax = 0, rsum = 0;
    for (int i = blocks[b].begin; i < blocks[b].end; ++i) {
      const double e = row_residual(c, rows[i]);
      rmax = std::max(rmax, e);
      rsum += e;
    }
    bs[b].rmax = rmax;
    bs[b].rsum = rsum;
  }
  double rmax = 0, rsum = 0, psum = 0;
  for (const BlockStats& s : bs) {
    rmax = std::max(rmax, s.rmax);
    rsum += s.rsum;
  }
  for (const Row& r : rows) psum += impulse_norm(r);
  st.p_mean = psum / n;
  const double scale = st.p_mean > 0 ? st.p_mean : 1.0;
  st.residual_max = rmax / scale;
  st.residual_mean = rsum / n / scale;
}

// A problem without rows: the dofs keep their free velocity, nothing to solve.
template <class Dof>
SolveStats no_rows(std::vector<Dof>* dofs) {
  if (dofs)
    for (Dof& d : *dofs) d.v = d.v0;
  return {};
}

// The end of a sweep: the convergence test on the sweep's sums (dsum of
// |dp|^2, psum of |p| over the n rows), the dofs' update, the observer.
// Returns true when the solve stops (dp_rel < tol and every dof converged,
// or max_iter sweeps).
template <class Row, class Dof>
bool end_sweep(int it, double dsum, double psum, int n, Row* R, std::vector<Dof>* dofs,
               const SolverParams& prm, const SweepObserver& observer, SolveStats& st) {
  st.p_mean = psum / n;
  const double scale = st.p_mean > 0 ? st.p_mean : 1.0;
  st.dp_rel = std::sqrt(dsum / n) / scale;
  st.iterations = it;
  st.dof_rel = 0.0;
  if (dofs)
    for (Dof& d : *dofs) st.dof_rel = std::max(st.dof_rel, update_dof(d, R));
  if (observer) observer(it, st.dp_rel);
  return it >= prm.max_iter || (st.dp_rel < prm.tol && st.dof_rel < prm.tol);
}

template <class L, class Row, class C, class Dof>
SolveStats solve(std::vector<Row>& rows, const Colouring& col, C& c, const SolverParams& prm,
                 std::vector<Dof>* dofs, const SweepObserver& observer) {
  if (rows.empty()) return no_rows(dofs);
  SolveStats st;
  const int n = static_cast<int>(rows.size());

  const int ncol = static_cast<int>(col.start.size()) - 1;
  std::vector<RowBlock> blocks;
  std::vector<int> cb(ncol + 1, 0);  // blocks of colour c: [cb[c], cb[c+1])
  for (int k = 0; k < ncol; ++k) {
    cb[k] = static_cast<int>(blocks.size());
    push_blocks(blocks, col.start[k], col.split[k], false);
    push_blocks(blocks, col.split[k], col.start[k + 1], true);
  }
  cb[ncol] = static_cast<int>(blocks.size());
  const int nb = cb[ncol];
  std::vector<BlockStats> bs(nb);
  Row* R = rows.data();
  const bool parallel = n >= prm.min_parallel;
  bool done = false;
  int it = 0;

#pragma omp parallel if (parallel)
  {
    while (!done) {
      // Symmetric Gauss-Seidel: colours forward on odd sweeps, backward on
      // even ones, so that forces travel both ways along a chain (a pile's
      // weight down, the floor's reaction up) within two sweeps. Inside a
      // colour the order does not matter. The overflow colour stays last.
      const bool backward = (it % 2) == 1;
      const int nreg = col.overflow ? ncol - 1 : ncol;
      for (int cc = 0; cc < ncol; ++cc) {
        const int k = (cc < nreg && backward) ? nreg - 1 - cc : cc;
        if (col.overflow && k == ncol - 1) {
#pragma omp single
          for (int b = cb[k]; b < cb[k + 1]; ++b) run_block<L>(blocks[b], R, c, bs[b]);
        } else {
#pragma omp for schedule(static)
          for (int b = cb[k]; b < cb[k + 1]; ++b) run_block<L>(blocks[b], R, c, bs[b]);
        }
      }
#pragma omp single
      {
        double dsum = 0, psum = 0;
        for (int b = 0; b < nb; ++b) {
          dsum += bs[b].dp2sum;
          psum += bs[b].psum;
        }
        done = end_sweep(++it, dsum, psum, n, R, dofs, prm, observer, st);
        // The optional second criterion: the law residual itself, checked
        // every kResidualEvery sweeps (a read-only pass over the rows, on
        // this thread). Off (residual_tol = 0) it costs nothing.
        if (!done && prm.residual_tol > 0 && it % kResidualEvery == 0) {
          SolveStats r;
          residuals(rows, c, INT_MAX, r);
          st.residual_met = r.residual_max < prm.residual_tol && st.dof_rel < prm.tol;
          done = st.residual_met;
        }
      }
      // implicit barrier: every thread sees the same 'done'
    }
  }

  residuals(rows, c, prm.min_parallel, st);
  st.cap_hit = not_converged(st, prm);
  return st;
}

// Sequential symmetric Gauss-Seidel over `units` groups of rows in the
// caller's order, for studies that visit rows in their own order
// (cd/bench/ss_pair: a side-side pair as one block): update(k, backward,
// dp2, pabs) updates unit k (dp2 and pabs summed over its rows, as a row
// update gives them); units go forward on odd sweeps, backward on even ones,
// and dp2, pabs are summed in visiting order. The convergence test, the
// dofs, the observer and the residuals are solve's. One thread.
template <class Row, class C, class Dof, class Update>
SolveStats solve_units(std::vector<Row>& rows, int units, const C& c, const SolverParams& prm,
                       std::vector<Dof>* dofs, const SweepObserver& observer, Update&& update) {
  if (rows.empty()) return no_rows(dofs);
  SolveStats st;
  const int n = static_cast<int>(rows.size());
  for (int it = 0;;) {
    const bool backward = (it % 2) == 1;
    double dsum = 0, psum = 0;
    for (int kk = 0; kk < units; ++kk) {
      double dp2, pabs;
      update(backward ? units - 1 - kk : kk, backward, dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
    if (end_sweep(++it, dsum, psum, n, rows.data(), dofs, prm, observer, st)) break;
  }
  residuals(rows, c, prm.min_parallel, st);
  st.cap_hit = not_converged(st, prm);
  return st;
}

}  // namespace cd::sweep
