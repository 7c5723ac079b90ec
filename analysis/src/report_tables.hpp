// The report's tables, made from the scan of a campaign (report_scan.hpp):
//   runs.csv    every run, its folder, status and cost ("n/a" without a
//               summary.toml: a text table);
//   steady.csv  the runs with every steady mean measured;
//   fabric.csv  the runs with a fabric (2D: the last snapshot's
//               anisotropies; 3D: the spherical-harmonic ones over the
//               steady window).
// steady.csv and fabric.csv are read back as numbers: nan where runs.csv
// says n/a. Each ends with the cost columns.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "cost.hpp"
#include "report_scan.hpp"
#include "table.hpp"

namespace cda {

// The cost columns of every table, and their values (nan without a summary).
extern const std::vector<std::string> kCostColumns;
std::vector<double> cost_values(const std::optional<RunCost>& c);

// A value for a text table (runs.csv, the page's tables): "n/a" when not
// measured; v ± err, v alone without a finite error.
std::string or_na(double v, const char* spec = "{:.4g}");
std::string or_na(double v, double err);

std::string runs_csv(const ReportScan& scan);
Table steady_table(const ReportScan& scan);
Table fabric_table(const ReportScan& scan);

// runs.csv, steady.csv and fabric.csv into out_dir.
void write_tables(const ReportScan& scan, const std::string& out_dir);

}  // namespace cda
