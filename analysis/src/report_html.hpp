// The report's page, index.html: the campaign's cost, the table of points
// (physics and cost side by side), the fit sections, the cost against I,
// the problems, and each run's own section. Made from the scan
// (report_scan.hpp), the summary and the sections' HTML.
#pragma once
#include <string>

#include "report.hpp"
#include "report_scan.hpp"

namespace cda {

// Text for the page: <, > and & escaped.
std::string html_escape(const std::string& s);

// A run's section under Runs: what failed, its shear profile, its series
// plot and its fabric.
std::string run_html(const ReportRun& r);
// The table of points: the steady physics, then what each run cost.
std::string points_html(const ReportScan& scan);
// The campaign's total wall and CPU time, over the runs with a summary.toml.
std::string cost_total_html(const ReportSummary& sum);

// The whole page. fits_html: the Fits section (the kind and each kind's
// fits); cost_html: the cost against I, or empty.
std::string report_page(const ReportScan& scan, const ReportSummary& sum, const std::string& fits_html,
                        const std::string& cost_html);

}  // namespace cda
