// Numbers in error messages: the shortest text that reads back as the same double, so a message never shows
// 1.0000001 as 1.000000 (std::to_string) or 1000.0000001 as 1000 (an ostream's default precision).
#pragma once

#include <charconv>
#include <string>

namespace trm::detail {

inline std::string exact_text(double value) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
  return ec == std::errc() ? std::string(text, end) : std::to_string(value);
}

}  // namespace trm::detail
