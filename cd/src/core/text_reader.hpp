// A whitespace-token reader over a whole text file that keeps line numbers
// for its error messages: the frozen-problem files of both engines (.dat,
// .cdp, .cdp3) read through it, so that every malformed file is reported
// the same way ("FILE:LINE: what was expected").
#pragma once
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <istream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace cd {

// Whitespace-token reader over the whole file, keeping line numbers for the
// error messages. The CSparse listing mixes free text (two header lines) with
// numbers, so the reader can also hand out whole lines.
class TextReader {
 public:
  TextReader(std::istream& in, std::string name) : name_(std::move(name)) {
    for (std::string l; std::getline(in, l);) lines_.push_back(std::move(l));
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(fmt::format("{}:{}: {}", name_, last_ + 1, what));
  }

  // Next token, empty at end of file.
  std::string_view token() {
    while (li_ < lines_.size()) {
      const std::string& l = lines_[li_];
      while (col_ < l.size() && std::isspace(static_cast<unsigned char>(l[col_]))) ++col_;
      if (col_ < l.size()) {
        const std::size_t b = col_;
        while (col_ < l.size() && !std::isspace(static_cast<unsigned char>(l[col_]))) ++col_;
        last_ = li_;
        return std::string_view(l).substr(b, col_ - b);
      }
      ++li_;
      col_ = 0;
    }
    last_ = lines_.empty() ? 0 : lines_.size() - 1;
    return {};
  }

  // The next token without taking it (empty at end of file).
  std::string_view peek() {
    const std::size_t li = li_, col = col_, last = last_;
    const std::string_view t = token();
    li_ = li, col_ = col, last_ = last;
    return t;
  }

  // The line after the one the cursor is on (the rest of that one is dropped).
  const std::string& next_line(const char* what) {
    if (col_ > 0) {
      ++li_;
      col_ = 0;
    }
    if (li_ >= lines_.size()) fail(fmt::format("unexpected end of file, expected {}", what));
    last_ = li_;
    return lines_[li_++];
  }

  std::string_view need(const std::string& what) {
    const std::string_view t = token();
    if (t.empty()) fail(fmt::format("unexpected end of file, expected {}", what));
    for (char c : t)
      if (!std::isprint(static_cast<unsigned char>(c)))
        fail(fmt::format("binary data where {} was expected: not a text file", what));
    return t;
  }

  void expect(std::string_view word, const std::string& where) {
    const std::string_view t = need(fmt::format("'{}' {}", word, where));
    if (t != word) fail(fmt::format("expected '{}' {}, got '{}'", word, where, t));
  }

  long long integer(const std::string& what, long long lo, long long hi) {
    const std::string t(need(what));
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (*end != '\0' || errno != 0)
      fail(fmt::format("expected {} (an integer), got '{}'", what, t));
    if (v < lo || v > hi) fail(fmt::format("{} is {}, expected {} to {}", what, v, lo, hi));
    return v;
  }

  double number(const std::string& what) {
    const std::string t(need(what));
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0') fail(fmt::format("expected {} (a number), got '{}'", what, t));
    if (!std::isfinite(v)) fail(fmt::format("{} is '{}', not a finite number", what, t));
    return v;
  }

  // A finite number >= 0 (> 0 if `positive`).
  double non_negative(const std::string& what, bool positive = false) {
    const double v = number(what);
    if (positive ? !(v > 0) : !(v >= 0)) fail(fmt::format("{} is {}, expected {} 0", what, v, positive ? ">" : ">="));
    return v;
  }

  // A count of items that take at least `tokens_each` tokens each: bounded
  // by what the rest of the file holds, so that a damaged header is refused
  // before anything is allocated for it.
  long long count(const std::string& what, long long hi, long long tokens_each) {
    const long long v = integer(what, 0, hi);
    const long long left = remaining_tokens();
    if (v > left / tokens_each)
      fail(fmt::format("{} is {}: unexpected end of file, {} numbers left where {} are needed", what, v, left,
                       v * tokens_each));
    return v;
  }

  // Tokens from the cursor to the end of the file.
  long long remaining_tokens() const {
    long long n = 0;
    for (std::size_t li = li_; li < lines_.size(); ++li) {
      const std::string& l = lines_[li];
      bool in = false;
      for (std::size_t c = li == li_ ? col_ : 0; c < l.size(); ++c) {
        const bool space = std::isspace(static_cast<unsigned char>(l[c])) != 0;
        n += !space && !in;
        in = !space;
      }
    }
    return n;
  }

 private:
  std::string name_;
  std::vector<std::string> lines_;
  std::size_t li_ = 0, col_ = 0, last_ = 0;
};

}  // namespace cd
