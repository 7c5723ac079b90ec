// Text from a file or the command line, safe to print in a message: control
// characters (but newline and tab) and bytes that are not UTF-8 shown as
// \xNN, and at most `max` bytes (then "..."), so that binary junk never
// reaches the terminal. The one rule of cdsim's scene errors and of
// cdanalysis' messages (analysis/src/error.hpp).
#pragma once
#include <cstddef>
#include <string>

#include <fmt/format.h>

namespace cd {

inline std::string printable(const std::string& s, std::size_t max = 4000) {
  std::string o;
  const auto* b = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n;) {
    if (o.size() >= max) return o + "...";
    const unsigned char c = b[i];
    // Length of the UTF-8 sequence starting here (0: not a valid lead byte).
    const std::size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = len > 0 && i + len <= n;
    for (std::size_t k = 1; ok && k < len; ++k) ok = (b[i + k] & 0xC0) == 0x80;
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
