// The WxH view-size option value (--size, --hw-size), in a translation unit of its own so that it can be
// built and fuzzed without the rest of the pipeline (fuzz/fuzz_view_size.cpp).
#pragma once

#include <opencv2/core/types.hpp>

#include <string>

namespace trm::cli {

// "WxH" with W, H >= 1; throws CLI::ValidationError naming `option` otherwise.
cv::Size parse_view_size(const std::string& text, const std::string& option = "--size");

}  // namespace trm::cli
