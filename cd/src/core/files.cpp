#include "files.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace cd {

namespace fs = std::filesystem;

// Unique per process, so two runs writing into one folder do not collide.
std::string tmp_name(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw OutputError(fmt::format("cannot write '{}': {}", path, ec.message()));
  }
}

void check_output_dir(const std::string& dir) {
  const fs::path p = fs::absolute(fs::path(dir.empty() ? "." : dir)).lexically_normal();
  auto fail = [&](const std::string& why) {
    throw OutputError(fmt::format("output folder '{}' {}", dir, why));
  };
  std::error_code ec;
  // status() reports not_found for ENOENT and ENOTDIR alike, so a path below
  // a regular file walks up to that file and fails there.
  if (fs::exists(fs::status(p, ec))) {
    if (!fs::is_directory(p, ec)) fail("exists and is not a folder");
    if (::access(p.c_str(), W_OK | X_OK) != 0) fail("is not writable");
    return;
  }
  fs::path a = p.has_filename() ? p.parent_path() : p.parent_path().parent_path();
  while (!fs::exists(fs::status(a, ec)) && a != a.root_path()) a = a.parent_path();
  if (!fs::is_directory(a, ec))
    fail(fmt::format("cannot be created: '{}' is not a folder", a.string()));
  if (::access(a.c_str(), W_OK | X_OK) != 0)
    fail(fmt::format("cannot be created: '{}' is not writable", a.string()));
}

void write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = tmp_name(path);
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.close();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw OutputError(fmt::format("cannot write '{}'", path));
    }
  }
  rename_into_place(tmp, path);
}

// ---------------------------------------------------------------------------
// Series

// The file is truncated here, so a rerun into the same folder does not append
// to an old series; the header goes out with the first flush.
Series::Series(const std::string& path) : path_(path) {
  std::ofstream f(path_, std::ios::trunc);
  if (!f) throw OutputError(fmt::format("cannot write '{}'", path_));
}

void Series::row(const std::vector<std::pair<std::string, double>>& cols) {
  if (names_.empty()) {
    if (cols.empty()) throw std::logic_error("Series::row: no columns");
    for (std::size_t c = 0; c < cols.size(); ++c) {
      names_.push_back(cols[c].first);
      buf_ += (c ? "," : "") + cols[c].first;
    }
    buf_ += '\n';
  } else {
    bool same = cols.size() == names_.size();
    for (std::size_t c = 0; same && c < cols.size(); ++c) same = cols[c].first == names_[c];
    if (!same)
      throw std::logic_error(fmt::format("Series::row: columns differ from the header of '{}'", path_));
  }
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const double v = cols[c].second;
    if (c) buf_ += ',';
    // Counts (step, contacts) print as integers; 2^53 bounds exact integers.
    if (v == std::trunc(v) && std::abs(v) < 9007199254740992.0)
      buf_ += fmt::format("{:.0f}", v);
    else
      buf_ += fmt::format("{:.10g}", v);
  }
  buf_ += '\n';
}

void Series::flush() {
  if (buf_.empty()) return;
  std::ofstream f(path_, std::ios::app);
  f << buf_;
  f.close();
  if (!f) throw OutputError(fmt::format("cannot write '{}'", path_));
  buf_.clear();
}

}  // namespace cd
