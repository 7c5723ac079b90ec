// The broad phase's machinery that does not depend on the dimension
// (2d/detect.cpp, 3d/detect3.cpp): which bodies go in the cell list and the
// box they span, the counting sort of those bodies into cells, and the pair
// loop run on a thread team with per-thread contact lists joined in thread
// order. The engines keep what differs: the grid's layout (cell size and
// coarsening), the stencil and its periodic images, and the narrow phase,
// all reaching this file through functors (a body's cell, the loop body),
// which inline: no call through a pointer in the loops.
//
// Contact order is fixed whatever the thread count: a cell holds its bodies
// in index order, and the loop body's `omp for schedule(static)` gives each
// thread a contiguous block of cells, so that the lists joined in thread
// order are the one-thread list (the state hashes depend on that order).
#pragma once
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace cd {

// The bodies split into grid members (grains) and the rest (walls, planes:
// few, tested against every member), with the members' largest radius and
// the box spanned by their positions pos(i) (a Vec2 or Vec3).
template <class Vec>
struct GridMembers {
  std::vector<int> members, others;
  double rmax = 0.0;
  Vec lo = Vec::Constant(1e300), hi = Vec::Constant(-1e300);
};

template <class Vec, class IsOther, class Pos>
GridMembers<Vec> grid_members(int nb, const std::vector<double>& radius, IsOther&& is_other, Pos&& pos) {
  GridMembers<Vec> g;
  g.members.reserve(nb);
  for (int i = 0; i < nb; ++i) {
    if (is_other(i)) {
      g.others.push_back(i);
    } else {
      g.members.push_back(i);
      g.rmax = std::max(g.rmax, radius[i]);
      const Vec p = pos(i);
      g.lo = g.lo.cwiseMin(p);
      g.hi = g.hi.cwiseMax(p);
    }
  }
  return g;
}

// The members sorted by cell (a counting sort): cell c holds
// items[cell_start[c] .. cell_start[c + 1]), in the members' (index) order.
// Kept between steps to avoid reallocation.
struct CellBins {
  std::vector<int> cell_start, items, cell_of;

  // cell(i): body i's cell, in [0, ncell).
  template <class Cell>
  void bin(std::size_t ncell, const std::vector<int>& members, Cell&& cell) {
    const int n = static_cast<int>(members.size());
    cell_start.assign(ncell + 1, 0);
    cell_of.resize(n);
    for (int a = 0; a < n; ++a) {
      const int c = cell(members[a]);
      cell_of[a] = c;
      ++cell_start[c + 1];
    }
    for (std::size_t c = 0; c < ncell; ++c) cell_start[c + 1] += cell_start[c];
    items.resize(n);
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (int a = 0; a < n; ++a) items[fill[cell_of[a]]++] = members[a];
  }
};

// Per-thread contact lists (rows and their info), kept between steps.
template <class Row, class Info>
struct ThreadContacts {
  std::vector<std::vector<Row>> rows;
  std::vector<std::vector<Info>> info;

  // Runs body(rows_t, info_t) on a team (one thread unless `parallel`),
  // each thread with its own emptied lists, and appends the lists to
  // out_rows and out_info in thread order. The body's loop over cells must
  // be an `omp for schedule(static)` (contiguous blocks in thread order).
  template <class Body>
  void run(bool parallel, Body&& body, std::vector<Row>& out_rows, std::vector<Info>& out_info) {
    const int nthreads = omp_get_max_threads();
    rows.resize(nthreads);
    info.resize(nthreads);
    for (int t = 0; t < nthreads; ++t) {  // a team may be smaller than nthreads
      rows[t].clear();
      info[t].clear();
    }
#pragma omp parallel if (parallel)
    {
      const int t = omp_get_thread_num();
      body(rows[t], info[t]);
    }
    for (int t = 0; t < nthreads; ++t) {
      out_rows.insert(out_rows.end(), rows[t].begin(), rows[t].end());
      out_info.insert(out_info.end(), info[t].begin(), info[t].end());
    }
  }
};

// The scratch a detection keeps between steps.
template <class Row, class Info>
struct CellGridScratch {
  CellBins bins;
  ThreadContacts<Row, Info> threads;
};

}  // namespace cd
