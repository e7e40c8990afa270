#include "view_size.hpp"

#include "trm/frame.hpp"

#include <CLI/CLI.hpp>

#include <cctype>
#include <charconv>

namespace trm::cli {

std::vector<int> parse_int_list(const std::string& text, std::size_t count, const std::string& option,
                                const std::string& expected, char separator) {
  std::vector<int> values;
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  while (values.size() < count) {
    int value = 0;
    const auto [next, error] = std::from_chars(p, end, value);
    if (error == std::errc::result_out_of_range) {
      throw CLI::ValidationError(option, "'" + text + "': " + std::string(p, next) + " is out of range");
    }
    if (error != std::errc() || next == p) break;
    values.push_back(value);
    p = next;
    if (values.size() < count) {
      if (p == end || (*p != separator && std::tolower(static_cast<unsigned char>(*p)) != separator)) break;
      ++p;
    }
  }
  if (values.size() != count || p != end) throw CLI::ValidationError(option, "expected " + expected + ", got '" + text + "'");
  return values;
}

cv::Size parse_view_size(const std::string& text, const std::string& option) {
  const std::string expected = "WxH with 1 <= W, H <= " + std::to_string(kMaxViewSide);
  const std::vector<int> wh = parse_int_list(text, 2, option, expected, 'x');
  if (wh[0] < 1 || wh[1] < 1 || wh[0] > kMaxViewSide || wh[1] > kMaxViewSide) {
    throw CLI::ValidationError(option, "expected " + expected + ", got '" + text + "'");
  }
  return {wh[0], wh[1]};
}

}  // namespace trm::cli
