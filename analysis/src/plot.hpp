// The bottom of the analysis' plotting: gnuplot scripts written beside their
// data and run, and the text helpers every writer uses. Depends on tables
// and windows only, so that every concept (fits, trends, cohesion, the
// report) draws its own figures through it without including the others.
#pragma once
#include <string>

#include "steady.hpp"
#include "table.hpp"

namespace cda {

// Writes text to path; throws InputError naming the file when it cannot.
void write_text(const std::string& path, const std::string& text);

// A number as exact text (%.17g, always with a '.', "nan", "inf"): TOML and
// gnuplot read it back to the same double.
std::string toml_num(double v);

// Runs gnuplot on a script; returns false (and leaves the script for a rerun)
// when gnuplot is missing or fails.
bool run_gnuplot(const std::string& script_path);

// Writes `<stem>.gp` that draws `body` to both <stem>.png and <stem>.svg, and
// runs it. `body` holds the set/plot commands of one plot.
bool plot_both(const std::string& dir, const std::string& stem, const std::string& body,
               int width = 800, int height = 500);

// A series column's axis label: what it is, then its name ("q/p (q_over_p)").
std::string column_label(const std::string& column);

// Time series of `column`; with s, its steady window shaded and its steady
// mean drawn across the window, the mean ± error in the key.
bool plot_series(const std::string& dir, const std::string& stem, const Table& series,
                 const std::string& x_column, const std::string& column, const SteadyStats* s);

}  // namespace cda
