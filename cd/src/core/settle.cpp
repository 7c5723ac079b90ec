#include "settle.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "derived.hpp"
#include "files.hpp"

namespace cd {

SettleRule::SettleRule(const Scene& s) {
  on_ = s.settle_stress > 0;
  if (!on_) return;
  p_ = s.pressure;
  tol_ = s.settle_stress;
  dphi_ = s.settle_phi;
  window_ = s.settle_time * pressure_time(s);
  // The lengths at imposed stress: y, and with isotropic x (3D: and z).
  axes_ = {"syy"};
  if (s.isotropic) axes_ = s.dimension == 3 ? std::vector<std::string>{"sxx", "syy", "szz"}
                                            : std::vector<std::string>{"sxx", "syy"};
}

void SettleRule::add(const std::vector<std::pair<std::string, double>>& row) {
  if (!on_) return;
  const auto value = [&](const std::string& name) {
    for (const auto& [n, x] : row)
      if (n == name) return as_written(x);
    throw std::logic_error("SettleRule: the series row has no column " + name);
  };
  std::vector<double> sigma;
  for (const std::string& a : axes_) sigma.push_back(value(a));
  add_row(value("time"), sigma, value("packing_fraction"));
}

void SettleRule::add_row(double time, const std::vector<double>& sigma, double phi) {
  double dev = 0;
  for (const double s : sigma) dev = std::max(dev, std::abs(s / p_ - 1.0));
  rows_.push_back({time, dev, phi});
  settled_ = false;
  // The window's start: the last row at least window_ before this one (the
  // times are steps x dt: a relative margin keeps an exact multiple in).
  std::ptrdiff_t j = -1;
  for (std::ptrdiff_t i = std::ptrdiff_t(rows_.size()) - 2; i >= 0; --i)
    if (time - rows_[i].time >= window_ * (1 - 1e-9)) {
      j = i;
      break;
    }
  if (j < 0) return;
  rows_.erase(rows_.begin(), rows_.begin() + j);  // later windows start no earlier
  double lo = rows_.front().phi, hi = lo;
  dev_ = 0;
  for (std::size_t i = 1; i < rows_.size(); ++i) {
    dev_ = std::max(dev_, rows_[i].dev);
    lo = std::min(lo, rows_[i].phi);
    hi = std::max(hi, rows_[i].phi);
  }
  range_ = hi - lo;
  settled_ = dev_ <= tol_ && range_ <= dphi_;
}

void SettleRule::resume(const std::string& series_path) {
  if (!on_) return;
  std::ifstream f(series_path);
  std::string line;
  std::vector<std::string> names;
  if (std::getline(f, line))
    for (std::size_t a = 0, b; a <= line.size(); a = b + 1) {
      b = std::min(line.find(',', a), line.size());
      names.push_back(line.substr(a, b - a));
    }
  while (std::getline(f, line)) {
    std::vector<std::pair<std::string, double>> row;
    std::size_t a = 0;
    for (const std::string& n : names) {
      const std::size_t b = std::min(line.find(',', a), line.size());
      row.emplace_back(n, std::strtod(line.substr(a, b - a).c_str(), nullptr));
      a = b + 1;
    }
    add(row);
  }
}

}  // namespace cd
