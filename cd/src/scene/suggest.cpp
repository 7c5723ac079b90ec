#include "suggest.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace cd {
namespace {

// Optimal string alignment distance (edits, adjacent swaps).
std::size_t distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

std::string_view last(std::string_view s) { return s.substr(s.rfind('.') + 1); }
std::string_view section(std::string_view s) {
  const auto dot = s.rfind('.');
  return dot == std::string_view::npos ? std::string_view() : s.substr(0, dot);
}
// One name the other cut short (at least 3 characters of a word kept), in
// the same section: an abbreviation or a spelled-out key.
bool extends(std::string_view a, std::string_view b) {
  if (section(a) != section(b)) return false;
  std::string_view x = last(a), y = last(b);
  if (x.size() > y.size()) std::swap(x, y);
  const std::size_t word = x.find_first_not_of('-') == std::string_view::npos ? 0 : x.find_first_not_of('-');
  return x.size() >= word + 3 && x != y && y.starts_with(x);
}

}  // namespace

std::string closest(std::string_view name, const std::vector<std::string>& candidates) {
  std::size_t best = 1 + last(name).size() / 5;  // the largest distance accepted
  std::string hint;
  for (const std::string& c : candidates) {
    std::size_t d = std::min(distance(name, c), distance(last(name), last(c)) + 1);
    if (extends(name, c)) d = std::min<std::size_t>(d, 1);
    if (d <= best && (d < best || hint.empty())) best = d, hint = c;
  }
  return hint;
}

std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates) {
  const std::string hint = closest(name, candidates);
  return hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint);
}

}  // namespace cd
