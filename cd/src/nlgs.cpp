#include "nlgs.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "law.hpp"

namespace cd {

namespace {

constexpr int kMaxColours = 63;  // colour 63 of the mask is the overflow colour
constexpr int kBlock = 128;      // rows per reduction block (fixed: see header)

// One row update. Write1 = false when body 1 is driven (a wall): it is read,
// never written, so rows of one colour may share a wall without a data race.
template <class L, bool Rot, bool Write1>
inline void update_row(ContactRow& r, BodyVel* vel, double& dp2, double& pabs) {
  BodyVel& A = vel[r.b1];
  BodyVel& B = vel[r.b2];
  const double dx = B.vx - A.vx, dy = B.vy - A.vy;
  double un = r.nx * dx + r.ny * dy + r.bn;
  if constexpr (Rot) un += -B.w * r.c2t + A.w * r.c1t;
  const double a = L::adhesion ? r.adh : 0.0;
  const Block W{r.wnn, r.wnt, r.wtt};
  double dpn, dpt = 0.0;
  if constexpr (L::friction) {
    double ut = -r.ny * dx + r.nx * dy + r.bt;
    if constexpr (Rot) ut += B.w * r.c2n - A.w * r.c1n;
    const double bn = un - (r.wnn * r.pn + r.wnt * r.pt);
    const double bt = ut - (r.wnt * r.pn + r.wtt * r.pt);
    double pn, pt;
    solve_coulomb(bn, bt, W, r.mu, a, pn, pt);
    dpn = pn - r.pn;
    dpt = pt - r.pt;
    r.pn = pn;
    r.pt = pt;
    pabs = std::sqrt(pn * pn + pt * pt);
  } else {
    double pn;
    solve_frictionless(un - r.wnn * r.pn, W, a, pn);
    dpn = pn - r.pn;
    r.pn = pn;
    pabs = std::abs(pn);
  }
  dp2 = dpn * dpn + dpt * dpt;
  const double px = r.nx * dpn - r.ny * dpt, py = r.ny * dpn + r.nx * dpt;
  B.vx += B.inv_m * px;
  B.vy += B.inv_m * py;
  if constexpr (Rot) B.w += B.inv_I * (r.c2n * dpt - r.c2t * dpn);
  if constexpr (Write1) {
    A.vx -= A.inv_m * px;
    A.vy -= A.inv_m * py;
    if constexpr (Rot) A.w -= A.inv_I * (r.c1n * dpt - r.c1t * dpn);
  }
}

struct RowBlock {
  std::int32_t begin, end;
  bool write1;
};

struct BlockStats {
  double dp2sum = 0, psum = 0, rmax = 0, rsum = 0;
};

template <class L, bool Rot>
void run_block(const RowBlock& k, ContactRow* rows, BodyVel* vel, BlockStats& s) {
  double dsum = 0, psum = 0;
  if (k.write1) {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      update_row<L, Rot, true>(rows[i], vel, dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
  } else {
    for (int i = k.begin; i < k.end; ++i) {
      double dp2, pabs;
      update_row<L, Rot, false>(rows[i], vel, dp2, pabs);
      dsum += dp2;
      psum += pabs;
    }
  }
  s.dp2sum = dsum;
  s.psum = psum;
}

void residual_block(const RowBlock& k, const ContactRow* rows, const std::vector<BodyVel>& vel,
                    bool rot, BlockStats& s) {
  double rmax = 0, rsum = 0;
  for (int i = k.begin; i < k.end; ++i) {
    const ContactRow& r = rows[i];
    double un, ut;
    row_velocity(r, vel, rot, un, ut);
    const double e = law_residual(un + r.bn, ut + r.bt, r.pn, r.pt, r.mu, r.adh, 1.0 / r.wnn);
    rmax = std::max(rmax, e);
    rsum += e;
  }
  s.rmax = rmax;
  s.rsum = rsum;
}

// Splits [begin, end) into fixed blocks.
void push_blocks(std::vector<RowBlock>& out, int begin, int end, bool write1) {
  for (int b = begin; b < end; b += kBlock) out.push_back({b, std::min(end, b + kBlock), write1});
}

template <class L, bool Rot>
SolveStats nlgs_impl(std::vector<ContactRow>& rows, const Colouring& col,
                     std::vector<BodyVel>& vel, const SolverParams& prm,
                     std::vector<BoundaryDof>* dofs) {
  SolveStats st;
  const int n = static_cast<int>(rows.size());
  if (n == 0) {
    if (dofs)
      for (BoundaryDof& d : *dofs) d.v = d.v0;
    return st;
  }

  const int ncol = static_cast<int>(col.start.size()) - 1;
  std::vector<RowBlock> blocks;
  std::vector<int> cb(ncol + 1, 0);  // blocks of colour c: [cb[c], cb[c+1])
  for (int c = 0; c < ncol; ++c) {
    cb[c] = static_cast<int>(blocks.size());
    push_blocks(blocks, col.start[c], col.split[c], false);
    push_blocks(blocks, col.split[c], col.start[c + 1], true);
  }
  cb[ncol] = static_cast<int>(blocks.size());
  const int nb = cb[ncol];
  std::vector<BlockStats> bs(nb);
  ContactRow* R = rows.data();
  BodyVel* V = vel.data();
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
        const int c = (cc < nreg && backward) ? nreg - 1 - cc : cc;
        if (col.overflow && c == ncol - 1) {
#pragma omp single
          for (int b = cb[c]; b < cb[c + 1]; ++b) run_block<L, Rot>(blocks[b], R, V, bs[b]);
        } else {
#pragma omp for schedule(static)
          for (int b = cb[c]; b < cb[c + 1]; ++b) run_block<L, Rot>(blocks[b], R, V, bs[b]);
        }
      }
#pragma omp single
      {
        ++it;
        double dsum = 0, psum = 0;
        for (int b = 0; b < nb; ++b) {
          dsum += bs[b].dp2sum;
          psum += bs[b].psum;
        }
        st.p_mean = psum / n;
        const double scale = st.p_mean > 0 ? st.p_mean : 1.0;
        st.dp_rel = std::sqrt(dsum / n) / scale;
        st.iterations = it;
        st.dof_rel = 0.0;
        if (dofs)
          for (BoundaryDof& d : *dofs) st.dof_rel = std::max(st.dof_rel, update_dof(d, R));
        if (it >= prm.max_iter) done = true;
        if (st.dp_rel < prm.tol && st.dof_rel < prm.tol) done = true;
      }
      // implicit barrier: every thread sees the same 'done'
    }
  }

  law_residuals(rows, vel, prm, st);
  st.cap_hit = st.dp_rel >= prm.tol || st.dof_rel >= prm.tol;
  return st;
}

}  // namespace

Colouring colour_rows(const std::vector<ContactRow>& rows, const Bodies& bodies) {
  const int n = static_cast<int>(rows.size());
  std::vector<std::uint64_t> mask(bodies.size(), 0);
  std::vector<std::uint8_t> colour(n);
  int used = 0;
  bool overflow = false;
  for (int i = 0; i < n; ++i) {
    const ContactRow& r = rows[i];
    const bool dyn1 = bodies.is_dynamic(r.b1);
    std::uint64_t m = mask[r.b2] | (dyn1 ? mask[r.b1] : 0);
    int c = std::countr_one(m);
    if (c >= kMaxColours) {
      c = kMaxColours;  // overflow: solved in sequence, after all colours
      overflow = true;
    } else {
      mask[r.b2] |= std::uint64_t{1} << c;
      if (dyn1) mask[r.b1] |= std::uint64_t{1} << c;
      used = std::max(used, c + 1);
    }
    colour[i] = static_cast<std::uint8_t>(c);
  }
  const int ncol = overflow ? used + 1 : used;
  // Counting sort by (colour, body 1 dynamic): stable, so deterministic.
  auto slot = [&](int i) {
    const int c = colour[i] == kMaxColours ? used : colour[i];
    return 2 * c + (bodies.is_dynamic(rows[i].b1) ? 1 : 0);
  };
  std::vector<std::int32_t> count(2 * ncol + 1, 0);
  for (int i = 0; i < n; ++i) ++count[slot(i) + 1];
  for (int s = 0; s < 2 * ncol; ++s) count[s + 1] += count[s];
  Colouring col;
  col.overflow = overflow;
  col.start.resize(ncol + 1);
  col.split.resize(ncol);
  for (int c = 0; c < ncol; ++c) {
    col.start[c] = count[2 * c];
    col.split[c] = count[2 * c + 1];
  }
  col.start[ncol] = n;
  col.perm.resize(n);
  std::vector<std::int32_t> pos(count.begin(), count.end() - 1);
  for (int i = 0; i < n; ++i) col.perm[pos[slot(i)]++] = i;
  return col;
}

void apply_impulses(const std::vector<ContactRow>& rows, std::vector<BodyVel>& vel, bool rotation) {
  for (const ContactRow& r : rows) {
    BodyVel& A = vel[r.b1];
    BodyVel& B = vel[r.b2];
    const double px = r.nx * r.pn - r.ny * r.pt, py = r.ny * r.pn + r.nx * r.pt;
    B.vx += B.inv_m * px;
    B.vy += B.inv_m * py;
    A.vx -= A.inv_m * px;
    A.vy -= A.inv_m * py;
    if (rotation) {
      B.w += B.inv_I * (r.c2n * r.pt - r.c2t * r.pn);
      A.w -= A.inv_I * (r.c1n * r.pt - r.c1t * r.pn);
    }
  }
}

void law_residuals(const std::vector<ContactRow>& rows, const std::vector<BodyVel>& vel,
                   const SolverParams& prm, SolveStats& st) {
  const int n = static_cast<int>(rows.size());
  if (n == 0) {
    st.residual_max = st.residual_mean = 0;
    return;
  }
  std::vector<RowBlock> blocks;
  push_blocks(blocks, 0, n, true);
  std::vector<BlockStats> bs(blocks.size());
  const int nb = static_cast<int>(blocks.size());
#pragma omp parallel for schedule(static) if (n >= prm.min_parallel)
  for (int b = 0; b < nb; ++b) residual_block(blocks[b], rows.data(), vel, prm.rotation, bs[b]);
  double rmax = 0, rsum = 0, psum = 0;
  for (const BlockStats& s : bs) {
    rmax = std::max(rmax, s.rmax);
    rsum += s.rsum;
  }
  for (const ContactRow& r : rows) psum += std::sqrt(r.pn * r.pn + r.pt * r.pt);
  st.p_mean = psum / n;
  const double scale = st.p_mean > 0 ? st.p_mean : 1.0;
  st.residual_max = rmax / scale;
  st.residual_mean = rsum / n / scale;
}

double update_dof(BoundaryDof& d, ContactRow* rows) {
  // The sweep runs with the dof frozen, so this update is a Jacobi step
  // between the dof and its rows: a change dv of the dof makes each active
  // row answer with about -(an^2/W_nn + at^2/W_tt) dv, and the plain update
  // v = v0 + inv_mass sum(...) overshoots by inv_mass times the sum of those
  // responses. It diverges once the dof is lighter than the grains it
  // touches (measured: a top wall of 0.1 the mass of 100 disks hit the
  // iteration cap and blew up within 400 steps). The step is damped by that
  // response (the Newton step of the dof's equation with the rows' local
  // response): same fixed point, and a contraction.
  double s = 0.0, k = 0.0;
  const std::size_t m = d.rows.size();
  for (std::size_t i = 0; i < m; ++i) {
    const ContactRow& r = rows[d.rows[i]];
    s += d.an[i] * r.pn + d.at[i] * r.pt;
    if (r.pn + r.adh > 0.0) k += d.an[i] * d.an[i] / r.wnn + d.at[i] * d.at[i] / r.wtt;
  }
  const double res = d.v0 + d.inv_mass * s - d.v;  // residual of the dof's equation
  const double dv = res / (1.0 + d.inv_mass * k);
  for (std::size_t i = 0; i < m; ++i) {
    ContactRow& r = rows[d.rows[i]];
    r.bn += d.an[i] * dv;
    r.bt += d.at[i] * dv;
  }
  d.v += dv;
  return std::abs(res) / (d.inv_mass * d.scale);
}

SolveStats nlgs_solve(std::vector<ContactRow>& rows, const Colouring& col,
                      std::vector<BodyVel>& vel, const SolverParams& prm,
                      std::vector<BoundaryDof>* dofs) {
  // The law is resolved once here, never inside the sweep.
  const int key = (prm.friction ? 4 : 0) | (prm.adhesion ? 2 : 0) | (prm.rotation ? 1 : 0);
  switch (key) {
    case 0: return nlgs_impl<Law<false, false>, false>(rows, col, vel, prm, dofs);
    case 1: return nlgs_impl<Law<false, false>, true>(rows, col, vel, prm, dofs);
    case 2: return nlgs_impl<Law<false, true>, false>(rows, col, vel, prm, dofs);
    case 3: return nlgs_impl<Law<false, true>, true>(rows, col, vel, prm, dofs);
    case 4: return nlgs_impl<Law<true, false>, false>(rows, col, vel, prm, dofs);
    case 5: return nlgs_impl<Law<true, false>, true>(rows, col, vel, prm, dofs);
    case 6: return nlgs_impl<Law<true, true>, false>(rows, col, vel, prm, dofs);
    default: return nlgs_impl<Law<true, true>, true>(rows, col, vel, prm, dofs);
  }
}

}  // namespace cd
