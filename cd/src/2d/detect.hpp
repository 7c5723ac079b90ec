// Contact detection at the midpoint configuration: O(N) broad phase on a cell
// list, then the narrow phase of each shape pair. Output order is the cell
// order whatever the thread count (each thread takes a contiguous range of
// cell rows and the per-thread lists are joined in thread order).
#pragma once
#include <vector>

#include "bodies.hpp"
#include "cell_grid.hpp"
#include "contact.hpp"
#include "polygon.hpp"

namespace cd {

// Periodic boundaries (method.md section 9): the cell [0, width) x [0,
// height), periodic in x and/or y. Across the top boundary the images are
// Lees-Edwards images: a body at (x, y) is seen at (x + offset, y + height)
// (plus any multiple of the width). Periodic directions need at least 4
// (x) and 3 (y) grid cells of 2 r_max + alert: detect throws otherwise.
struct PeriodicCell {
  bool x = false, y = false;
  double width = 0.0, height = 0.0;
  double offset = 0.0;  // in [0, width)
};

// Scratch kept between steps to avoid reallocation (core/cell_grid.hpp).
using CellGrid = CellGridScratch<ContactRow, ContactInfo>;

// Candidate contacts with gap <= alert among the bodies at positions x and
// angles th. Fills geometry only (b1, b2, frame, lever arms, gap, point);
// the caller fills W blocks, offsets and impulses. cell: periodic
// boundaries, or nullptr for none (the scene's choice, made once).
void detect(const Bodies& bodies, const std::vector<Vec2>& x, const std::vector<double>& th,
            double alert, CellGrid& grid, std::vector<ContactRow>& rows,
            std::vector<ContactInfo>& info, const PeriodicCell* cell = nullptr);

// The largest overlap among the bodies at their positions and angles (depth
// 0 if none) and a pair that has it, through the periodic cell if given:
// a state's consistency (a checkpoint's against the depth it recorded).
struct Overlap {
  double depth = 0.0;
  std::int32_t b1 = -1, b2 = -1;
};
Overlap largest_overlap(const Bodies& bodies, const PeriodicCell* cell);

// Narrow phase of one disk pair (i < j), frame from i to j. Returns false if
// the gap exceeds alert.
bool disk_disk(int i, int j, const Vec2& xi, const Vec2& xj, double ri, double rj, double alert,
               ContactRow& row, ContactInfo& info);

// Narrow phase of two polygons (method.md section 7): separating axis over
// the faces of both, the face of largest separation is the reference (body 1,
// frame from it); the most opposed face of the other polygon is clipped to it,
// giving at most two points: side-side (two points, both typed SideSide) when
// the faces are parallel to within 2 % of the face length, else side-vertex.
// Appends 0 to 2 contacts.
int polygon_polygon(int i, int j, const PolyView& A, const PolyView& B, double alert,
                    std::vector<ContactRow>& rows, std::vector<ContactInfo>& info);

// Polygon p (body 1) and disk k (body 2): one side-vertex point.
bool polygon_disk(int p, int k, const PolyView& P, const Vec2& xk, double rk, double alert,
                  ContactRow& row, ContactInfo& info);

// Segment wall w (body 1, reference face) and polygon p: 0 to 2 points.
int segment_polygon(int w, int p, const Vec2& wa, const Vec2& wb, const Vec2& wc, const PolyView& P,
                    double alert, std::vector<ContactRow>& rows, std::vector<ContactInfo>& info);

// Narrow phase of a segment wall w (body 1) and a disk k (body 2).
bool segment_disk(int w, int k, const Vec2& wa, const Vec2& wb, const Vec2& wc, const Vec2& xk,
                  double rk, double alert, ContactRow& row, ContactInfo& info);

}  // namespace cd
