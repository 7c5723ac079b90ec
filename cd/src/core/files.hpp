// Run outputs that do not depend on the dimension: the output folder's
// checks, atomic file writes and the time series (series.csv). Every file is
// written to a temporary name and renamed into place, so a reader (or a
// killed run) never sees a half-written file.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cd {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws OutputError naming the folder if it cannot be created or written.
// Creates nothing: it checks the nearest existing ancestor.
void check_output_dir(const std::string& dir);

// The temporary name of `path` for this process, and the rename that puts a
// complete temporary file into place (removing it and throwing OutputError
// if the rename fails): the two halves of an atomic write.
std::string tmp_name(const std::string& path);
void rename_into_place(const std::string& tmp, const std::string& path);

// Writes `text` to `path` atomically (temporary file, then rename).
void write_file_atomic(const std::string& path, const std::string& text);

// series.csv: one row per output interval, columns named by the first row.
class Series {
 public:
  explicit Series(const std::string& path);
  // Continues a file that already holds the header `names` and earlier rows
  // (a restart): nothing is truncated and no header is written again.
  Series(const std::string& path, std::vector<std::string> names)
      : path_(path), names_(std::move(names)) {}
  void row(const std::vector<std::pair<std::string, double>>& cols);
  void flush();

 private:
  std::string path_;
  std::vector<std::string> names_;
  std::string buf_;
};

}  // namespace cd
