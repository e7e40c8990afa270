#include "view_size.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>

namespace trm::cli {

cv::Size parse_view_size(const std::string& text, const std::string& option) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 1 || h < 1) {
    throw CLI::ValidationError(option, "expected WxH with W, H >= 1, got '" + text + "'");
  }
  return {w, h};
}

}  // namespace trm::cli
