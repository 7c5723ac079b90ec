// The stop rule of a compaction at imposed pressure (shear.settle_stress,
// settle_phi, settle_time): a preparation ends when its sample is jammed at
// p, not after a fixed time chosen for the slowest case. Decided on the rows
// of series.csv as written (files.hpp, as_written), in both dimensions: at
// the row that ends a window of at least settle_time t_p (from the row
// before the window), the run has settled if every row of the window had its
// mean contact stress sigma_aa within settle_stress p of p on each axis at
// imposed stress (the contacts, not the grains' momentum, carry the load)
// and the packing fraction of those rows and the one before them spans at
// most settle_phi (nothing still compacts). A resumed run reads its rows
// back (resume), so it stops where the run never stopped does, and a run
// that had settled does not step on.
#pragma once
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "scene.hpp"

namespace cd {

class SettleRule {
 public:
  // Off unless the scene sets shear.settle_stress (config.cpp checks the
  // three keys and the protocol).
  SettleRule() = default;
  explicit SettleRule(const Scene& s);
  bool on() const { return on_; }
  // A series row (its columns, as the run loop writes them).
  void add(const std::vector<std::pair<std::string, double>>& row);
  // The rows of an existing series.csv (a resume; already cut back to the
  // checkpoint's step), in order.
  void resume(const std::string& series_path);
  // Whether the last row added ends a settled window.
  bool settled() const { return settled_; }
  // What the last row measured, for the run's message: the largest
  // |sigma_aa / p - 1| of the window and the packing fraction's range.
  double stress_dev() const { return dev_; }
  double phi_range() const { return range_; }

 private:
  struct Row {
    double time, dev, phi;
  };
  void add_row(double time, const std::vector<double>& sigma, double phi);
  bool on_ = false;
  double p_ = 0, tol_ = 0, dphi_ = 0, window_ = 0;  // window in s
  std::vector<std::string> axes_;                   // the controlled axes' series columns
  std::deque<Row> rows_;
  bool settled_ = false;
  double dev_ = 0, range_ = 0;
};

}  // namespace cd
