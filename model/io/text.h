// Small text helpers shared by the model's parsers.
#pragma once

#include <string_view>
#include <vector>

namespace shd {

// `s` cut at every `sep`: n separators give n + 1 fields, empty ones included ("a,,b" gives
// "a", "", "b"; "" gives one empty field). The views point into `s`.
inline std::vector<std::string_view> splitFields(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  size_t start = 0;
  for (;;) {
    const size_t pos = s.find(sep, start);
    out.push_back(s.substr(start, pos == std::string_view::npos ? std::string_view::npos : pos - start));
    if (pos == std::string_view::npos) return out;
    start = pos + 1;
  }
}

}  // namespace shd
