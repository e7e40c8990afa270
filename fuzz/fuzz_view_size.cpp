// libFuzzer target for the WxH view-size option parser (parse_view_size, --size / --hw-size). The input
// is the option text. The parser must throw CLI::ValidationError naming the option, or return 1 <= W, H <=
// kMaxViewSide (never a wrapped value).
#include "fuzz_support.hpp"
#include "view_size.hpp"

#include "trm/frame.hpp"

#include <CLI/CLI.hpp>

#include <string>

using trm::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cv::Size s = trm::cli::parse_view_size(text, "--size");
    check(s.width >= 1 && s.height >= 1, "a size below 1x1");
    check(s.width <= trm::kMaxViewSide && s.height <= trm::kMaxViewSide, "a side beyond kMaxViewSide");
  } catch (const CLI::ValidationError& e) {
    check(std::string(e.what()).find("--size") != std::string::npos, "message does not name the option");
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_view_size");
  }
  return 0;
}
