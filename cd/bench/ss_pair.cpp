// ss_pair: does solving the two points of a side-side (ss) contact as one
// block ("forcing equal sliding", ss_pair.hpp) cut NLGS iterations and time?
//
// 1. Unit check of the pair solver: the 4x4 cross blocks against the
//    assembled H^T M^-1 H (cd::assemble_problem), then random pair problems
//    (ss geometry and generic lever arms, with and without adhesion) against
//    Lemke's method on the pair's LCP, counted per branch. Exit code 1 if a
//    check fails.
// 2. Frozen step problems: the step a World takes from a state, replayed from
//    the same warm start, solved by
//      ref   cd::nlgs_solve (coloured sweep, one thread: what the simulator runs)
//      row   a sequential per-row sweep: cd::sweep::solve_units (the
//            production convergence test and residuals) over the
//            production row update (cd::sweep::BodyCoupling)
//      pair  the same sweep with each ss pair updated as one block
//    to eps_f = 1e-2 .. 1e-5 (same convergence test as nlgs.cpp: rms |dp| /
//    mean |p| over a sweep). row and pair visit the rows in the same order
//    (the World's colour order, the second row of a pair moved next to the
//    first) and alternate forward/backward sweeps as nlgs.cpp does, so they
//    differ only in the pair update.
// 3. Dynamic runs: the same states stepped `steps` times by World::step with
//    its solve stage replaced by each solver (World::set_solver); mean
//    sweeps a step and the time of the colour and solve stages.
// States: settled piles of squares and of hexagons (cdbench::polygon_pile),
// and the square pile flowing under gravity tilted by `tilt` degrees.
// Everything on one thread. Writes DIR/frozen.csv, DIR/dynamic.csv and
// DIR/machine.csv.
//
// Result (N = 1000, ~3700 rows of which ~50 % in ss pairs; see the commit
// message for the table): the pair block does not cut sweeps. pair/row sweeps
// are 0.97-1.03 on 18 of the 20 non-trivial frozen solves (best 0.88,
// worst 1.31); over 200 steps, 1.19x / 1.09x the sweeps a step on the
// settled piles and 0.99x on the flowing one (eps_f 1e-3). A pair update
// costs about as much as 6 to 9 row updates (it enumerates cases of a 3x3
// block), so every solve is 1.4-3.4x slower. Re-solving until the
// tangential split is consistent (pair4) changes no sweep count. Decision:
// ss points stay independent rows in cd::nlgs_solve. The slow part of a
// solve is the propagation of forces through the packing, which a local
// block does not touch.
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "law.hpp"
#include "lemke.hpp"
#include "machine.hpp"
#include "pile.hpp"
#include "problem.hpp"
#include "ss_pair.hpp"
#include "coupling.hpp"
#include "world.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

using cdbench::PairBlock;
using cdbench::PairCase;
using cdbench::PairCross;

// ---------------------------------------------------------------- unit check

// The pair's LCP (lemke.hpp's construction with the pair's Coulomb row):
//   z = (z_1, z_2, P+, P-, lambda),  z_i = p_ni + a_i,  P_t = P+ - P-
//   w = (u_n1, u_n2, lambda + u_t, lambda - u_t, mu (z_1 + z_2) - P+ - P-).
bool lemke_pair(const PairBlock& P, const double b[3], double mu, double a1, double a2,
                double x[3]) {
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(5, 5);
  Eigen::VectorXd q(5);
  const double a[2] = {a1, a2};
  for (int i = 0; i < 3; ++i) {
    const double bi = b[i] - P.w[i][0] * a[0] - P.w[i][1] * a[1];
    const double row[4] = {P.w[i][0], P.w[i][1], P.w[i][2], -P.w[i][2]};
    if (i < 2) {
      for (int j = 0; j < 4; ++j) M(i, j) = row[j];
      q(i) = bi;
    } else {
      for (int j = 0; j < 4; ++j) {
        M(2, j) = row[j];
        M(3, j) = -row[j];
      }
      M(2, 4) = M(3, 4) = 1.0;
      q(2) = bi;
      q(3) = -bi;
    }
  }
  M(4, 0) = M(4, 1) = mu;
  M(4, 2) = M(4, 3) = -1.0;
  q(4) = 0.0;
  const cd::LcpSolution s = cd::solve_lcp_lemke(M, q);
  if (s.status != cd::LemkeStatus::Solved) return false;
  x[0] = s.z(0) - a1;
  x[1] = s.z(1) - a2;
  x[2] = s.z(2) - s.z(3);
  return true;
}

const char* case_name(const PairCase& c) {
  static const char* names[4][3] = {{"open", "open", "open"},
                                    {"1 closed, stick", "1 closed, slide+", "1 closed, slide-"},
                                    {"2 closed, stick", "2 closed, slide+", "2 closed, slide-"},
                                    {"both closed, stick", "both closed, slide+",
                                     "both closed, slide-"}};
  return names[c.mask][c.mask ? c.tang : 0];
}

// Cross blocks against the assembled Delassus matrix of two rows.
double check_cross(std::mt19937_64& g) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    cd::Bodies B;
    B.add_polygon({0, 0}, 1.0 + 0.5 * U(g), 4, 0.0, 1.0 + 0.5 * U(g));
    if (trial % 4 == 0)
      B.add_wall({-1, 0}, {1, 0});
    else
      B.add_polygon({1, 1}, 1.0 + 0.5 * U(g), 6, 0.0, 1.0 + 0.5 * U(g));
    std::vector<cd::ContactRow> rows(2);
    const double th = 3.2 * U(g);
    for (cd::ContactRow& r : rows) {
      r = cd::ContactRow{};
      r.b1 = trial % 4 == 0 ? 1 : 0;
      r.b2 = trial % 4 == 0 ? 0 : 1;
      r.nx = std::cos(th);
      r.ny = std::sin(th);
      r.c1n = U(g);
      r.c1t = U(g);
      r.c2n = U(g);
      r.c2t = U(g);
      cd::set_block(r, B.vel[r.b1], B.vel[r.b2], true);
    }
    const PairCross X = cdbench::pair_cross(rows[0], rows[1], B.vel[rows[0].b1],
                                            B.vel[rows[0].b2], true);
    const Eigen::MatrixXd W(cd::assemble_problem(B, rows, true).W);
    const double e[4] = {W(0, 2) - X.n1n2, W(0, 3) - X.n1t2, W(1, 2) - X.t1n2, W(1, 3) - X.t1t2};
    const double d[4] = {W(0, 0) - rows[0].wnn, W(0, 1) - rows[0].wnt, W(1, 1) - rows[0].wtt,
                         W(2, 2) - rows[1].wnn};
    for (double v : e) worst = std::max(worst, std::abs(v) / W.cwiseAbs().maxCoeff());
    for (double v : d) worst = std::max(worst, std::abs(v) / W.cwiseAbs().maxCoeff());
  }
  return worst;
}

// Random pair problems against Lemke; returns false if a check fails.
bool unit_check(int trials, std::ostream& out) {
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0), P01(0.0, 1.0);
  const double cross_err = check_cross(g);
  out << fmt::format("cross blocks vs assembled H^T M^-1 H: max rel. error {:.1e}\n", cross_err);
  struct Tally {
    int n = 0, lemke_fail = 0, distinct = 0;
    double dx = 0, res = 0;
  };
  std::array<std::array<Tally, 3>, 4> tally{};
  int fallbacks = 0;
  double worst_res = 0, worst_dx = 0;
  for (int k = 0; k < trials; ++k) {
    // Two bodies with unit-scale inertia; a side of length L on body 1 at
    // distance h1 from its centre along n, body 2's face parallel to it to
    // within 1 % (the ss case), or generic lever arms (every 4th trial).
    cd::BodyVel A{0, 0, 0, 1.0 + 0.9 * U(g), 1.0 + 0.9 * U(g)};
    cd::BodyVel Bv{0, 0, 0, 1.0 + 0.9 * U(g), 1.0 + 0.9 * U(g)};
    if (k % 5 == 0) A.inv_m = A.inv_I = 0.0;  // body 1 a wall
    cd::ContactRow r1{}, r2{};
    r1.nx = r2.nx = 1.0;
    r1.ny = r2.ny = 0.0;
    if (k % 4 != 3) {
      const double L = 0.5 + 0.5 * P01(g), h1 = 0.5 + 0.3 * P01(g), h2 = 0.5 + 0.3 * P01(g);
      const double s0 = L * (0.2 * U(g) - 0.5), s1 = L * (0.5 + 0.2 * U(g)), off = 0.3 * U(g);
      const double tilt = 0.01 * L * U(g);
      r1.c1n = h1;
      r1.c1t = s0;
      r2.c1n = h1 + tilt;
      r2.c1t = s1;
      r1.c2n = -h2;
      r1.c2t = s0 + off;
      r2.c2n = -h2 + tilt;
      r2.c2t = s1 + off;
    } else {
      r1.c1n = U(g), r1.c1t = U(g), r1.c2n = U(g), r1.c2t = U(g);
      r2.c1n = U(g), r2.c1t = U(g), r2.c2n = U(g), r2.c2t = U(g);
    }
    cd::set_block(r1, A, Bv, true);
    cd::set_block(r2, A, Bv, true);
    const PairCross X = cdbench::pair_cross(r1, r2, A, Bv, true);
    const double al1 = k % 7 == 0 ? 0.0 : k % 7 == 1 ? 1.0 : k % 7 == 2 ? 0.5 : P01(g);
    const PairBlock Pb = cdbench::reduce_pair(r1, r2, X, al1, 1.0 - al1);
    const double mu = k % 9 == 0 ? 0.0 : 1.2 * P01(g);
    const double a1 = k % 2 ? 0.0 : 0.3 * P01(g), a2 = k % 2 ? 0.0 : 0.3 * P01(g);
    const double b[3] = {U(g), U(g), 2 * U(g)};
    double x[3], u[3];
    const PairCase c = cdbench::solve_pair(Pb, b, mu, a1, a2, x, u);
    if (c.fallback) ++fallbacks;
    const double scale = 1.0 + std::abs(x[0]) + std::abs(x[1]) + std::abs(x[2]);
    const double rho = 1.0 / std::max(Pb.w[0][0], Pb.w[1][1]);
    const double res = cdbench::pair_residual(x, u, mu, a1, a2, rho) / scale;
    Tally& t = tally[c.mask][c.mask ? c.tang : 0];
    ++t.n;
    t.res = std::max(t.res, res);
    worst_res = std::max(worst_res, res);
    double xl[3];
    if (!lemke_pair(Pb, b, mu, a1, a2, xl)) {
      ++t.lemke_fail;
      continue;
    }
    const double dx =
        (std::abs(x[0] - xl[0]) + std::abs(x[1] - xl[1]) + std::abs(x[2] - xl[2])) / scale;
    if (dx > 1e-9) {
      // Two solutions? Accept only if Lemke's satisfies the law as well.
      double ul[3];
      for (int i = 0; i < 3; ++i)
        ul[i] = b[i] + Pb.w[i][0] * xl[0] + Pb.w[i][1] * xl[1] + Pb.w[i][2] * xl[2];
      if (cdbench::pair_residual(xl, ul, mu, a1, a2, rho) / scale < 1e-12) {
        ++t.distinct;
        continue;
      }
    }
    t.dx = std::max(t.dx, dx);
    worst_dx = std::max(worst_dx, dx);
  }
  out << fmt::format("{} random pair problems against Lemke (natural-map residual / (1 + |x|),"
                     " |x - x_lemke|_1 / (1 + |x|)):\n",
                     trials);
  out << fmt::format("  {:<22} {:>7} {:>10} {:>10} {:>8} {:>8}\n", "branch", "count", "residual",
                     "vs Lemke", "2 sols", "no Lemke");
  bool ok = cross_err < 1e-13 && fallbacks == 0;
  for (int m = 0; m < 4; ++m)
    for (int t = 0; t < (m ? 3 : 1); ++t) {
      const Tally& T = tally[m][t];
      out << fmt::format("  {:<22} {:>7} {:>10.1e} {:>10.1e} {:>8} {:>8}\n",
                         case_name({m, t, false}), T.n, T.res, T.dx, T.distinct, T.lemke_fail);
      if (T.n < 10) ok = false;  // every branch exercised
    }
  out << fmt::format("  fallbacks {}; worst residual {:.1e}, worst distance to Lemke {:.1e}\n",
                     fallbacks, worst_res, worst_dx);
  ok = ok && worst_res < 1e-12 && worst_dx < 1e-9;
  out << (ok ? "unit check passed\n" : "UNIT CHECK FAILED\n");
  return ok;
}

// ------------------------------------------------------------------ sweeps

// Units of a sweep: a row (j < 0) or an ss pair, in the order of their first
// row; cross blocks of the pairs.
struct Units {
  std::vector<std::array<std::int32_t, 2>> u;
  std::vector<PairCross> cross;  // per unit (unused for single rows)
  int pairs = 0;
};

Units make_units(const std::vector<cd::ContactRow>& rows, const std::vector<cd::ContactInfo>& info,
                 const std::vector<cd::BodyVel>& vel) {
  const int n = static_cast<int>(rows.size());
  std::vector<std::pair<std::uint64_t, std::int32_t>> ss;
  for (int i = 0; i < n; ++i)
    if (info[i].type == cd::ContactType::SideSide) ss.emplace_back(info[i].key >> 4, i);
  std::sort(ss.begin(), ss.end());
  std::vector<std::int32_t> partner(n, -1);
  for (std::size_t k = 0; k + 1 < ss.size(); ++k)
    if (ss[k].first == ss[k + 1].first) {
      const int i = ss[k].second, j = ss[k + 1].second;
      if (rows[i].nx != rows[j].nx || rows[i].ny != rows[j].ny || rows[i].b1 != rows[j].b1 ||
          rows[i].mu != rows[j].mu)
        throw std::runtime_error("ss pair with different frames");
      partner[i] = j;
      partner[j] = i;
      ++k;
    }
  Units U;
  std::vector<char> placed(n, 0);
  for (int i = 0; i < n; ++i) {
    if (placed[i]) continue;
    const int j = partner[i];
    placed[i] = 1;
    if (j >= 0) {
      placed[j] = 1;
      ++U.pairs;
      U.cross.push_back(
          cdbench::pair_cross(rows[i], rows[j], vel[rows[i].b1], vel[rows[i].b2], true));
    } else {
      U.cross.push_back({});
    }
    U.u.push_back({i, j});
  }
  return U;
}

struct SweepStats {
  cd::SolveStats st;
  long fallbacks = 0;
  double pair_res_max = 0;  // pair-law residual, max over pairs / mean |p|
};

// Pair-law residual of the pairs at the current state (alpha = stored split).
double pair_law_residual(const std::vector<cd::ContactRow>& rows,
                         const std::vector<cd::BodyVel>& vel, const Units& U, double pmean) {
  double worst = 0;
  for (std::size_t k = 0; k < U.u.size(); ++k) {
    const auto [i, j] = U.u[k];
    if (j < 0) continue;
    const cd::ContactRow &r1 = rows[i], &r2 = rows[j];
    double un1, ut1, un2, ut2;
    cd::row_velocity(r1, vel, true, un1, ut1);
    cd::row_velocity(r2, vel, true, un2, ut2);
    const double z1 = std::max(r1.pn + r1.adh, 0.0), z2 = std::max(r2.pn + r2.adh, 0.0);
    const double al1 = z1 + z2 > 0 ? z1 / (z1 + z2) : 0.5;
    const double x[3] = {r1.pn, r2.pn, r1.pt + r2.pt};
    const double u[3] = {un1 + r1.bn, un2 + r2.bn,
                         al1 * (ut1 + r1.bt) + (1 - al1) * (ut2 + r2.bt)};
    const double rho = 1.0 / std::max(r1.wnn, r2.wnn);
    worst = std::max(worst, cdbench::pair_residual(x, u, r1.mu, r1.adh, r2.adh, rho));
  }
  return worst / (pmean > 0 ? pmean : 1.0);
}

// Sequential symmetric Gauss-Seidel over the units (cd::sweep::solve_units);
// Pair: ss pairs as blocks. Single rows, and both rows of a pair when Pair
// is off, take the production row update (Coulomb, rotation, body 1 written:
// a driven body has inv_m = inv_I = 0 and is left unchanged).
template <bool Pair>
SweepStats sweep_solve(std::vector<cd::ContactRow>& rows, std::vector<cd::BodyVel>& vel,
                       const Units& U, const cd::SolverParams& prm, int alpha_passes = 1) {
  SweepStats out;
  cd::ContactRow* R = rows.data();
  const cd::sweep::BodyCoupling<true> c{vel.data()};
  const auto row = [&](cd::ContactRow& r, double& dp2, double& pabs) {
    c.update<cd::Coulomb, true>(r, dp2, pabs);
    pabs = cd::impulse_norm(r);  // the update gives a bound (kNormBound); solve_units sums |p|
  };
  out.st = cd::sweep::solve_units(
      rows, static_cast<int>(U.u.size()), c, prm, static_cast<std::vector<cd::BoundaryDof>*>(nullptr), {},
      [&](int k, bool backward, double& dp2, double& pabs) {
        const auto [i, j] = U.u[k];
        if (j < 0) {
          row(R[i], dp2, pabs);
        } else if constexpr (Pair) {
          if (cdbench::update_pair(R[i], R[j], U.cross[k], c.vel, dp2, pabs, alpha_passes)
                  .fallback)
            ++out.fallbacks;
        } else {
          double d2, p2;
          row(R[backward ? j : i], dp2, pabs);
          row(R[backward ? i : j], d2, p2);
          dp2 += d2;
          pabs += p2;
        }
      });
  if (!rows.empty()) out.pair_res_max = pair_law_residual(rows, vel, U, out.st.p_mean);
  return out;
}

// ------------------------------------------------------------ step problems

// The step a World takes from its current state, frozen: rows in the
// World's colour order with the warm-start impulses the World started from,
// body velocities = free velocities + those impulses.
struct Frozen {
  std::string name;
  std::vector<cd::ContactRow> rows;
  std::vector<cd::ContactInfo> info;
  std::vector<cd::BodyVel> vel;
  cd::Colouring col;
  cd::SolverParams prm;
  int world_iterations = 0;  // what World::step took (its own tolerance)
};

Frozen freeze(const cd::World& w0, const std::string& name, bool cold) {
  cd::World w1 = w0;
  w1.step();
  Frozen f;
  f.name = name;
  f.rows = w1.rows();
  f.info = w1.infos();
  f.vel = w1.bodies.vel;
  f.prm = w1.params().solver;
  f.world_iterations = w1.last().solve.iterations;
  // Remove the solved impulses, put back the warm start.
  std::vector<cd::ContactRow> neg = f.rows;
  for (cd::ContactRow& r : neg) {
    r.pn = -r.pn;
    r.pt = -r.pt;
  }
  cd::apply_impulses(neg, f.vel, true);
  const cd::World::WarmStart& ws = w0.warm_start();
  for (std::size_t k = 0; k < f.rows.size(); ++k) {
    const auto it = std::lower_bound(ws.keys.begin(), ws.keys.end(), f.info[k].key);
    const bool hit = !cold && it != ws.keys.end() && *it == f.info[k].key;
    f.rows[k].pn = hit ? ws.p[it - ws.keys.begin()].first : 0.0;
    f.rows[k].pt = hit ? ws.p[it - ws.keys.begin()].second : 0.0;
  }
  cd::apply_impulses(f.rows, f.vel, true);
  // The rows are already in colour order; colouring them again in that order
  // gives the same colours (greedy), so 'ref' replays the World's solve.
  f.col = cd::colour_rows(f.rows, w1.bodies);
  return f;
}

struct Run {
  int iterations = 0;
  bool cap = false;
  double time = 0, res_max = 0, res_mean = 0, pair_res = 0;
  long fallbacks = 0;
};

Run run_frozen(const Frozen& f, const std::string& variant, double tol, int max_iter, int repeat) {
  Run out;
  out.time = 1e300;
  cd::SolverParams prm = f.prm;
  prm.tol = tol;
  prm.max_iter = max_iter;
  for (int rep = 0; rep < repeat; ++rep) {
    std::vector<cd::ContactRow> rows = f.rows;
    std::vector<cd::BodyVel> vel = f.vel;
    SweepStats s;
    const auto t0 = Clock::now();
    if (variant == "ref") {
      cd::ContactProblem cp{std::move(rows), f.col, std::move(vel), {}, cd::Coulomb{}, true};
      s.st = cd::nlgs_solve(cp, prm);
      rows = std::move(cp.rows);
      vel = std::move(cp.vel);
    } else {
      const Units U = make_units(rows, f.info, vel);  // timed: part of the pair solver's cost
      s = variant == "row"     ? sweep_solve<false>(rows, vel, U, prm)
          : variant == "pair"  ? sweep_solve<true>(rows, vel, U, prm)
                               : sweep_solve<true>(rows, vel, U, prm, 4);  // "pair4"
    }
    out.time = std::min(out.time, since(t0));
    if (out.time > 1.0) repeat = rep + 1;  // long solves: one timing is enough
    out.iterations = s.st.iterations;
    out.cap = s.st.cap_hit;
    out.res_max = s.st.residual_max;
    out.res_mean = s.st.residual_mean;
    out.fallbacks = s.fallbacks;
    if (variant == "ref") {
      const Units U = make_units(rows, f.info, vel);
      out.pair_res = pair_law_residual(rows, vel, U, s.st.p_mean);
    } else {
      out.pair_res = s.pair_res_max;
    }
  }
  return out;
}

// ------------------------------------------------------------ dynamic runs

// The solve stage of World::step for variant v (World::set_solver): ref is
// cd::nlgs_solve, what World::step runs; row, pair and pair4 the unit sweeps,
// with the ss pairs found from the World's contact info of the step (in the
// problem's colour order, as the rows). The pair solve covers Coulomb
// friction with rotation and no boundary dofs.
cd::World::Solver variant_solver(const std::string& v, const cd::World& w) {
  return [v, &w](cd::ContactProblem& p, const cd::SolverParams& prm) {
    if (v == "ref") return cd::nlgs_solve(p, prm);
    if (!std::holds_alternative<cd::Coulomb>(p.law) || !p.rotation || !p.dofs.empty())
      throw std::runtime_error("ss_pair: only Coulomb, rotation, no boundary dofs");
    const Units U = make_units(p.rows, w.infos(), p.vel);
    return v == "row"    ? sweep_solve<false>(p.rows, p.vel, U, prm).st
           : v == "pair" ? sweep_solve<true>(p.rows, p.vel, U, prm).st
                         : sweep_solve<true>(p.rows, p.vel, U, prm, 4).st;  // "pair4"
  };
}

// Largest position difference between World::step with the ref solver put
// in by set_solver and World::step itself over a few steps: 0 if replacing
// the solve stage leaves the step unchanged.
double check_solver(const cd::World& w0, int steps) {
  cd::World w = w0, s = w0;
  s.set_solver(variant_solver("ref", s));
  for (int k = 0; k < steps; ++k) {
    w.step();
    s.step();
  }
  double d = 0;
  for (std::size_t i = 0; i < w.bodies.size(); ++i)
    d = std::max({d, (w.bodies.pos[i] - s.bodies.pos[i]).cwiseAbs().maxCoeff(),
                  std::abs(w.bodies.angle[i] - s.bodies.angle[i])});
  return d;
}

struct Dyn {
  double mean_iter = 0, solve_time = 0, ke = 0;
  int max_iter = 0, caps = 0;
};

Dyn run_dynamic(const cd::World& w0, const std::string& v, int steps) {
  cd::World w = w0;
  w.set_solver(variant_solver(v, w));
  const cd::StageTimes t0 = w.times;
  Dyn d;
  long sum = 0;
  for (int k = 0; k < steps; ++k) {
    w.step();
    const cd::SolveStats& st = w.last().solve;
    sum += st.iterations;
    d.max_iter = std::max(d.max_iter, st.iterations);
    d.caps += st.cap_hit;
  }
  using cd::Stage;
  d.solve_time = w.times[Stage::Colour] - t0[Stage::Colour] + w.times[Stage::Solve] -
                 t0[Stage::Solve];
  d.mean_iter = static_cast<double>(sum) / steps;
  d.ke = w.kinetic_energy();
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ss_pair: side-side contacts as one block in the NLGS"};
  std::string out_dir = "outputs/ss-pair";
  int n = 1000, steps = 200, repeat = 3, max_iter = 20000, checks = 200000, flow_steps = 150;
  double tilt = 40.0;
  std::vector<double> tols = {1e-2, 1e-3, 1e-4, 1e-5};
  bool check_only = false, no_frozen = false, no_dynamic = false;
  std::vector<std::string> variants = {"ref", "row", "pair", "pair4"}, only;
  double dyn_tol = 0;  // 0: the scene's eps_f
  int dyn_cap = 0;     // 0: the scene's cap
  app.add_option("--out", out_dir, "output directory");
  app.add_option("-n", n, "polygons in each pile");
  app.add_option("--steps", steps, "steps of each dynamic run");
  app.add_option("--repeat", repeat, "timed repeats of each frozen solve (min taken)");
  app.add_option("--max-iter", max_iter, "iteration cap of the frozen solves");
  app.add_option("--tol", tols, "tolerances of the frozen solves");
  app.add_option("--checks", checks, "random pair problems checked against Lemke");
  app.add_option("--tilt", tilt, "gravity tilt of the flowing state (degrees)");
  app.add_option("--flow-steps", flow_steps, "steps under tilted gravity before freezing");
  app.add_flag("--check-only", check_only, "unit check only");
  app.add_flag("--no-frozen", no_frozen, "skip the frozen problems");
  app.add_flag("--no-dynamic", no_dynamic, "skip the dynamic runs");
  app.add_option("--variants", variants, "solvers: ref row pair pair4 (row first for ratios)");
  app.add_option("--states", only, "states to run (default all): squares hexagons squares_tilt");
  app.add_option("--dyn-tol", dyn_tol, "eps_f of the dynamic runs (0: the scene's)");
  app.add_option("--dyn-cap", dyn_cap, "iteration cap of the dynamic runs (0: the scene's)");
  CLI11_PARSE(app, argc, argv);
  omp_set_num_threads(1);

  if (!unit_check(checks, std::cout)) return 1;
  if (check_only) return 0;

  const std::string load_start = cdbench::load_average();
  std::filesystem::create_directories(out_dir);

  // States.
  std::vector<std::pair<std::string, cd::World>> states;
  {
    auto t0 = Clock::now();
    auto wanted = [&](const std::string& s) {
      return only.empty() || std::find(only.begin(), only.end(), s) != only.end();
    };
    if (wanted("squares") || wanted("squares_tilt")) {
      cd::World sq = cdbench::polygon_pile(n, 4);
      if (wanted("squares_tilt")) {
        cd::World flow = sq;
        cd::WorldParams p = flow.params();
        const double g = p.gravity.norm(), th = tilt * std::numbers::pi / 180;
        p.gravity = cd::Vec2(g * std::sin(th), -g * std::cos(th));
        flow.set_params(p);
        for (int k = 0; k < flow_steps; ++k) flow.step();
        states.emplace_back(fmt::format("squares_tilt{:.0f}", tilt), flow);
      }
      if (wanted("squares")) states.emplace(states.begin(), "squares", std::move(sq));
    }
    if (wanted("hexagons"))
      states.emplace(states.begin() + (wanted("squares") ? 1 : 0), "hexagons",
                     cdbench::polygon_pile(n, 6));
    std::cout << fmt::format("states built in {:.1f} s\n", since(t0));
  }

  std::ofstream fcsv(out_dir + "/frozen.csv");
  fcsv << "state,start,rows,ss_rows,tol,variant,iterations,cap_hit,time_s,res_max,res_mean,"
          "pair_res_max,fallbacks\n";
  std::cout << "\nFrozen step problems (one thread; time = min of " << repeat
            << " runs; res = law residual / mean |p|, max and mean over rows; pair res = pair-law"
               " residual, max over ss pairs; * = cap hit)\n";
  for (const auto& [name, w] : states)
    for (const bool cold : {false, true}) {
      if (no_frozen) break;
      const Frozen f = freeze(w, name, cold);
      const Units U = make_units(f.rows, f.info, f.vel);
      const int nrow = static_cast<int>(f.rows.size());
      std::cout << fmt::format(
          "\n{}, {} start: {} rows, {} ss pairs ({:.0f} % of rows), {} colours, KE {:.2e} J, "
          "World took {} sweeps at eps_f {:.0e}\n",
          name, cold ? "cold" : "warm", nrow, U.pairs, 200.0 * U.pairs / nrow,
          f.col.start.size() - 1, w.kinetic_energy(), f.world_iterations, f.prm.tol);
      std::cout << fmt::format("  {:>6} {:>5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>7} {:>7}\n", "tol",
                               "var", "sweeps", "time ms", "res max", "res mean", "pair res",
                               "it/row", "t/row");
      for (double tol : tols) {
        Run base;
        for (const std::string& v : variants) {
          const Run r = run_frozen(f, v, tol, max_iter, repeat);
          if (v == "row") base = r;
          std::cout << fmt::format("  {:>6.0e} {:>5} {:>7}{} {:>9.2f} {:>9.1e} {:>9.1e} {:>9.1e}",
                                   tol, v, r.iterations, r.cap ? "*" : " ", 1e3 * r.time,
                                   r.res_max, r.res_mean, r.pair_res);
          if (v.starts_with("pair") && base.iterations > 0)
            std::cout << fmt::format(" {:>7.2f} {:>7.2f}", double(r.iterations) / base.iterations,
                                     r.time / base.time);
          std::cout << std::endl;
          fcsv << fmt::format("{},{},{},{},{:g},{},{},{},{:.6g},{:.4g},{:.4g},{:.4g},{}\n", name,
                              cold ? "cold" : "warm", nrow, 2 * U.pairs, tol, v, r.iterations,
                              int(r.cap), r.time, r.res_max, r.res_mean, r.pair_res, r.fallbacks);
        }
      }
    }

  std::ofstream dcsv(out_dir + "/dynamic.csv");
  dcsv << "state,steps,tol,cap,variant,mean_iter,max_iter,caps,solve_s,ke_end\n";
  if (!no_dynamic && !states.empty())
    std::cout << fmt::format("\nDynamic runs: {} steps from each state, eps_f {:.0e}, cap {}\n",
                             steps, dyn_tol > 0 ? dyn_tol : states[0].second.params().solver.tol,
                             dyn_cap > 0 ? dyn_cap : states[0].second.params().solver.max_iter);
  for (auto& [name, w] : states) {
    if (no_dynamic) break;
    cd::WorldParams p = w.params();
    if (dyn_tol > 0) p.solver.tol = dyn_tol;
    if (dyn_cap > 0) p.solver.max_iter = dyn_cap;
    w.set_params(p);
    std::cout << fmt::format("{}: ref through World::set_solver vs World::step over 3 steps, "
                             "max |dx|, |dtheta| = {:.1e}\n",
                             name, check_solver(w, 3));
    Dyn base;
    for (const std::string& v : variants) {
      const Dyn d = run_dynamic(w, v, steps);
      if (v == "row") base = d;
      std::cout << fmt::format("  {:>5} mean sweeps {:8.1f}  max {:6}  caps {:3}  solve {:7.2f} s"
                               "  KE end {:.3e} J",
                               v, d.mean_iter, d.max_iter, d.caps, d.solve_time, d.ke);
      if (v.starts_with("pair") && base.mean_iter > 0)
        std::cout << fmt::format("  pair/row: sweeps {:.2f}, time {:.2f}",
                                 d.mean_iter / base.mean_iter, d.solve_time / base.solve_time);
      std::cout << std::endl;
      dcsv << fmt::format("{},{},{:g},{},{},{:.3f},{},{},{:.4g},{:.4g}\n", name, steps,
                          p.solver.tol, p.solver.max_iter, v, d.mean_iter,
                          d.max_iter, d.caps, d.solve_time, d.ke);
    }
  }
  cdbench::write_machine_csv(out_dir + "/machine.csv", cdbench::machine(load_start));
  return 0;
}
