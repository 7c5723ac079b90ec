// Regression of fitted curves: the parameters of two fit TOML files (as
// written by fits_to_toml, report.hpp) compared one by one.
//
// Rule. A parameter FAILs when its change d = new - old is both
//   |d| > tol_sigma * sqrt(err_old^2 + err_new^2)   (statistically significant)
//   and |d| > tol_rel * |old|                       (large enough to matter).
// The combined uncertainty treats the two fits as independent (a rerun of a
// campaign is a new realisation of the noise); for a re-analysis of the same
// data it is conservative. tol_rel = 0 leaves the sigma test alone; a positive
// tol_rel lets a very precise fit move by a physically irrelevant amount.
// A parameter or model of the reference missing from the new file FAILs; a
// non-finite value or error, or a fit that no longer converges, FAILs too.
// Models and parameters only in the new file are listed, not failed.
#pragma once
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "error.hpp"

namespace cda {

struct FitParam {
  double value = 0, error = 0;
};

struct FitRecord {
  bool converged = true;
  double chi2 = std::numeric_limits<double>::quiet_NaN();  // NaN, dof -1: not in the file
  int dof = -1;
  std::vector<std::string> order;          // parameter names in file order
  std::map<std::string, FitParam> params;
};

struct FitFile {
  std::string path;
  std::vector<std::string> order;          // model names in file order
  std::map<std::string, FitRecord> models;
};

// Throws AnalysisError naming the file (and model/parameter) when it is
// missing, does not parse, or a [model.params.name] lacks value or error.
FitFile read_fit_toml(const std::string& path);

struct ComparisonRow {
  std::string model, param;
  bool in_reference = true, in_new = true;
  FitParam ref, now;
  double sigmas = 0;    // |d| / combined error (inf when that error is 0 and d != 0)
  double relative = 0;  // |d| / |old| (inf when old is 0 and d != 0)
  bool ok = true;
  std::string note;     // why it failed, or "new" for parameters only in the new file
};

struct Comparison {
  std::vector<ComparisonRow> rows;
  bool ok() const;
  std::size_t failures() const;
};

Comparison compare_fits(const FitFile& reference, const FitFile& now, double tol_sigma, double tol_rel);

// The table printed by `cdanalysis compare-fits`.
std::string format_comparison(const Comparison& c, double tol_sigma, double tol_rel);

}  // namespace cda
