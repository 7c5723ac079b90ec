// The reference campaigns of `make regress` (tests/data/regress*: the
// stored mu(I) fit and the committed series) as numbers a test compares a
// live run with (test_mu_i_live, test_shear).
#pragma once
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <toml.hpp>

namespace cdtest {

constexpr int kBlocks = 8;

// mu(I) = mu1 + (mu2 - mu1) / (1 + I0/I) from a cdanalysis fit file, with
// its standard error at I from the covariance (gradient g: 1 - s, s,
// -(mu2 - mu1) s^2 / I with s = 1/(1 + I0/I)).
struct RefFit {
  double mu1, mu2, I0;
  double C[3][3];
  double mu(double I) const { return mu1 + (mu2 - mu1) / (1 + I0 / I); }
  double se(double I) const {
    const double s = 1 / (1 + I0 / I);
    const double g[3] = {1 - s, s, -(mu2 - mu1) * s * s / I};
    double v = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) v += g[a] * C[a][b] * g[b];
    return std::sqrt(v);
  }
};

inline RefFit read_fit(const std::string& path) {
  const toml::value t = toml::parse(path);
  const toml::value& m = toml::find(t, "mu_I");
  RefFit f;
  f.mu1 = toml::find<double>(m, "params", "mu1", "value");
  f.mu2 = toml::find<double>(m, "params", "mu2", "value");
  f.I0 = toml::find<double>(m, "params", "I0", "value");
  const auto C = toml::find<std::vector<std::vector<double>>>(m, "covariance");
  // The stored covariance is the one of the errors (error scale applied).
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) f.C[a][b] = C.at(a).at(b);
  EXPECT_NEAR(std::sqrt(f.C[0][0]), toml::find<double>(m, "params", "mu1", "error"), 1e-12);
  return f;
}

// Mean and standard error of the means of kBlocks consecutive blocks.
struct Est {
  double mean = 0, se = 0;
};
inline Est blocks(const std::vector<double>& x) {
  const std::size_t len = x.size() / kBlocks;
  double s = 0, s2 = 0;
  for (int b = 0; b < kBlocks; ++b) {
    double m = 0;
    for (std::size_t k = 0; k < len; ++k) m += x[b * len + k] / len;
    s += m / kBlocks;
    s2 += m * m / kBlocks;
  }
  return {s, std::sqrt(std::max(0.0, s2 - s * s) / (kBlocks - 1))};
}

// A reference run's packing fraction over strain 1-3 (its series.csv:
// one row per output interval), block mean and error.
inline Est reference_phi(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  {
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) names.push_back(c);
  }
  int ci = -1, cs = -1;
  for (int k = 0; k < static_cast<int>(names.size()); ++k) {
    if (names[k] == "packing_fraction") ci = k;
    if (names[k] == "strain") cs = k;
  }
  EXPECT_GE(ci, 0);
  EXPECT_GE(cs, 0);
  std::vector<double> phi;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string c;
    std::vector<double> v;
    while (std::getline(ss, c, ',')) v.push_back(std::stod(c));
    if (v.at(cs) >= 1.0) phi.push_back(v.at(ci));
  }
  return blocks(phi);
}

}  // namespace cdtest
