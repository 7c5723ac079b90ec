// Text and bytes, one rule for cdsim's scene reader and errors and for
// cdanalysis' readers and messages (analysis/src/error.hpp):
//   utf8_length, utf8_fault  UTF-8 as RFC 3629 allows it. TOML text is
//                            UTF-8, and toml11 3.7 reads outside its buffer
//                            when it reports a string that is not (its error
//                            path counts lines between iterators of two
//                            different buffers): no text reaches it unchecked.
//   printable                text safe to print in a message.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace cd {

// Length of the well-formed UTF-8 sequence that starts at s[i] (RFC 3629's
// table: no overlong forms, surrogates or code points past U+10FFFF), 0 if
// none does.
inline std::size_t utf8_length(std::string_view s, std::size_t i) {
  const auto at = [&](std::size_t k) { return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0u; };
  const unsigned c = at(0);
  const auto tail = [&](std::size_t k, unsigned lo = 0x80, unsigned hi = 0xBF) { return at(k) >= lo && at(k) <= hi; };
  if (i >= s.size()) return 0;
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) return tail(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    const bool second = c == 0xE0 ? tail(1, 0xA0) : c == 0xED ? tail(1, 0x80, 0x9F) : tail(1);
    return second && tail(2) ? 3 : 0;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    const bool second = c == 0xF0 ? tail(1, 0x90) : c == 0xF4 ? tail(1, 0x80, 0x8F) : tail(1);
    return second && tail(2) && tail(3) ? 4 : 0;
  }
  return 0;
}

// The first byte of s that does not start a well-formed UTF-8 sequence:
// its value, its line (from 1) and its byte (from 1); none for UTF-8 text.
struct Utf8Fault {
  unsigned value;
  std::size_t line, byte;
};
inline std::optional<Utf8Fault> utf8_fault(std::string_view s) {
  for (std::size_t i = 0, line = 1; i < s.size();) {
    const std::size_t len = utf8_length(s, i);
    if (len == 0) return Utf8Fault{static_cast<unsigned char>(s[i]), line, i + 1};
    if (s[i] == '\n') ++line;
    i += len;
  }
  return std::nullopt;
}

// Text from a file or the command line, safe to print in a message: control
// characters (but newline and tab) and bytes that are not UTF-8 shown as
// \xNN, and at most `max` bytes (then "..."), so that binary junk never
// reaches the terminal.
inline std::string printable(const std::string& s, std::size_t max = 4000) {
  std::string o;
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n;) {
    if (o.size() >= max) return o + "...";
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const std::size_t len = utf8_length(s, i);
    bool ok = len > 0;
    if (ok && len == 1 && (c < 0x20 || c == 0x7F) && c != '\n' && c != '\t') ok = false;
    if (!ok) {
      o += fmt::format("\\x{:02X}", c);
      ++i;
      continue;
    }
    o.append(s, i, len);
    i += len;
  }
  return o;
}

}  // namespace cd
