// Option values made of integers (--size, --hw-size, --roi), in a translation unit of its own so that it can be
// built and fuzzed without the rest of the pipeline (fuzz/fuzz_view_size.cpp).
#pragma once

#include <opencv2/core/types.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace trm::cli {

// "WxH" with 1 <= W, H <= kMaxViewSide (trm/frame.hpp); throws CLI::ValidationError naming `option` otherwise.
cv::Size parse_view_size(const std::string& text, const std::string& option = "--size");

// Exactly `count` decimal ints separated by `separator` (nothing else, no wrap-around: out-of-range values are an
// error); throws CLI::ValidationError naming `option` and what was `expected`.
std::vector<int> parse_int_list(const std::string& text, std::size_t count, const std::string& option,
                                const std::string& expected, char separator = ',');

}  // namespace trm::cli
