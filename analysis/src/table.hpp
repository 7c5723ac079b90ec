// A table of doubles with named columns: the reader for series.csv and the
// writer for the analysis tables. Columns are looked up by name, so a reader
// never depends on the simulator's column order.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "error.hpp"

namespace cda {

class Table {
 public:
  Table() = default;
  explicit Table(std::vector<std::string> names);

  // Reads a CSV file whose first row names the columns. Every later row must
  // have as many fields, each a finite number (strtod syntax); nan marks a
  // missing value only in cdanalysis' own tables, read with allow_nan.
  // Throws InputError naming the file for: missing file, no header, no data
  // row, a short/long row, a non-numeric or non-finite field (with line and
  // column). The columns named in `text` hold words (a protocol, a commit):
  // their fields are not read and the table leaves them out.
  static Table read_csv(const std::string& path, bool allow_nan = false,
                        const std::vector<std::string>& text = {});

  bool has(const std::string& name) const;
  // Throws AnalysisError naming the column and the file it was read from.
  const std::vector<double>& column(const std::string& name) const;
  const std::vector<std::string>& names() const { return names_; }
  std::size_t rows() const { return cols_.empty() ? 0 : cols_.front().size(); }
  const std::string& source() const { return source_; }
  // The file's line number of a row read by read_csv (0 for rows added in memory).
  std::size_t line(std::size_t row) const { return row < lines_.size() ? lines_[row] : 0; }

  void add_row(const std::vector<double>& values);
  // A row given by column name: every column of the table exactly once
  // (a missing or unknown name throws), so that a writer never depends on
  // the order in which it lists them.
  void add_named_row(const std::map<std::string, double>& values);
  void add_column(const std::string& name, std::vector<double> values);
  // Full precision (%.17g), so a round trip is exact.
  std::string to_csv() const;
  void write_csv(const std::string& path) const;

 private:
  std::vector<std::string> names_;
  std::vector<std::vector<double>> cols_;
  std::string source_ = "<memory>";
  std::vector<std::size_t> lines_;
};

}  // namespace cda
