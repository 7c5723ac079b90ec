#include "table.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace cda {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(trim(field));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace

Table::Table(std::vector<std::string> names) : names_(std::move(names)), cols_(names_.size()) {}

std::string toml_text(const std::string& path) {
  refuse_folder(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot open '{}'", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string s = std::move(ss).str();
  if (const auto f = cd::utf8_fault(s))
    throw InputError(fmt::format("'{}' is not TOML text: invalid UTF-8 byte 0x{:02x} at line {}, byte {}", path,
                                 f->value, f->line, f->byte));
  return s;
}

Table Table::read_csv(const std::string& path, bool allow_nan, const std::vector<std::string>& text) {
  refuse_folder(path);
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("cannot open '{}'", path));
  Table t;
  t.source_ = path;
  std::string line;
  std::size_t lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (!trim(line).empty()) break;
  }
  if (trim(line).empty()) throw InputError(fmt::format("'{}' is empty (no header row)", path));
  const auto header = split(line);
  std::vector<bool> keep;
  for (const auto& n : header) {
    if (n.empty()) throw InputError(fmt::format("'{}': empty column name in the header", path));
    if (std::find(header.begin(), header.begin() + keep.size(), n) != header.begin() + keep.size())
      throw InputError(fmt::format("'{}': column '{}' appears twice in the header", path, printable(n, 40)));
    keep.push_back(std::find(text.begin(), text.end(), n) == text.end());
    if (keep.back()) t.names_.push_back(n);
  }
  t.cols_.assign(t.names_.size(), {});
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) continue;
    const auto fields = split(line);
    if (fields.size() != header.size())
      throw InputError(fmt::format("'{}' line {}: {} fields, the header has {}", path, lineno,
                                      fields.size(), header.size()));
    for (std::size_t j = 0, k = 0; j < fields.size(); ++j) {
      if (!keep[j]) continue;
      const char* s = fields[j].c_str();
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(s, &end);
      // The whole field: a NUL byte inside it would end strtod's reading
      // there, and "0.\0403" read as 0.
      if (fields[j].empty() || end != s + fields[j].size())
        throw InputError(fmt::format("'{}' line {}, column '{}': '{}' is not a number", path,
                                        lineno, header[j], printable(fields[j], 40)));
      if (!std::isfinite(v) && !(allow_nan && std::isnan(v)))
        throw InputError(fmt::format("'{}' line {}, column '{}': '{}' is not a finite number", path,
                                     lineno, header[j], printable(fields[j], 40)));
      t.cols_[k++].push_back(v);
    }
    t.lines_.push_back(lineno);
  }
  if (t.rows() == 0) throw InputError(fmt::format("'{}' has a header but no data rows", path));
  return t;
}

bool Table::has(const std::string& name) const {
  return std::find(names_.begin(), names_.end(), name) != names_.end();
}

const std::vector<double>& Table::column(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end()) {
    std::string list;
    for (const auto& n : names_) list += (list.empty() ? "" : ",") + n;
    throw InputError(
        fmt::format("'{}' has no column '{}' (columns: {})", source_, name, list));
  }
  return cols_[static_cast<std::size_t>(it - names_.begin())];
}

void Table::add_row(const std::vector<double>& values) {
  if (values.size() != names_.size())
    throw InputError(fmt::format("table row of {} values for {} columns", values.size(),
                                    names_.size()));
  for (std::size_t j = 0; j < values.size(); ++j) cols_[j].push_back(values[j]);
}

void Table::add_named_row(const std::map<std::string, double>& values) {
  std::vector<double> row;
  row.reserve(names_.size());
  for (const auto& n : names_) {
    const auto it = values.find(n);
    if (it == values.end()) throw AnalysisError(fmt::format("table row without column '{}'", n));
    row.push_back(it->second);
  }
  if (values.size() != names_.size())
    for (const auto& [n, v] : values)
      if (std::find(names_.begin(), names_.end(), n) == names_.end())
        throw AnalysisError(fmt::format("table row with column '{}' the table does not have", n));
  add_row(row);
}

void Table::add_column(const std::string& name, std::vector<double> values) {
  if (!cols_.empty() && values.size() != rows())
    throw InputError(fmt::format("column '{}' has {} rows, the table {}", name, values.size(),
                                    rows()));
  names_.push_back(name);
  cols_.push_back(std::move(values));
}

std::string Table::to_csv() const {
  std::string s;
  for (std::size_t j = 0; j < names_.size(); ++j) s += (j ? "," : "") + names_[j];
  s += '\n';
  for (std::size_t i = 0; i < rows(); ++i) {
    for (std::size_t j = 0; j < names_.size(); ++j)
      s += fmt::format("{}{:.17g}", j ? "," : "", cols_[j][i]);
    s += '\n';
  }
  return s;
}

void Table::write_csv(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("cannot write '{}'", path));
  out << to_csv();
  if (!out) throw InputError(fmt::format("error while writing '{}'", path));
}

}  // namespace cda
