// Contact detection at the midpoint configuration: O(N) broad phase on a cell
// list, then the narrow phase of each shape pair. Output order is the cell
// order whatever the thread count (each thread takes a contiguous range of
// cell rows and the per-thread lists are joined in thread order).
#pragma once
#include <vector>

#include "bodies.hpp"
#include "contact.hpp"

namespace cd {

struct CellGrid {  // scratch kept between steps to avoid reallocation
  std::vector<int> cell_start, items;
  std::vector<std::vector<ContactRow>> rows_t;
  std::vector<std::vector<ContactInfo>> info_t;
};

// Candidate contacts with gap <= alert among the bodies at positions x and
// angles th. Fills geometry only (b1, b2, frame, lever arms, gap, point);
// the caller fills W blocks, offsets and impulses.
void detect(const Bodies& bodies, const std::vector<Vec2>& x, const std::vector<double>& th,
            double alert, CellGrid& grid, std::vector<ContactRow>& rows,
            std::vector<ContactInfo>& info);

// Narrow phase of one disk pair (i < j), frame from i to j. Returns false if
// the gap exceeds alert.
bool disk_disk(int i, int j, const Vec2& xi, const Vec2& xj, double ri, double rj, double alert,
               ContactRow& row, ContactInfo& info);

// Narrow phase of a segment wall w (body 1) and a disk k (body 2).
bool segment_disk(int w, int k, const Vec2& wa, const Vec2& wb, const Vec2& wc, const Vec2& xk,
                  double rk, double alert, ContactRow& row, ContactInfo& info);

}  // namespace cd
