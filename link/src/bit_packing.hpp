// Raw payload packing: the components R, G, B of each pixel of a rectangle in raster order, each
// `bits` wide, written MSB first into a byte stream; the last byte is zero-padded.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace trm::link::detail {

// Appends the rectangle `rect` of `codes` (CV_16UC3; codes already checked < 2^bits) to `out`.
void pack_codes(const cv::Mat& codes, const cv::Rect& rect, int bits, std::vector<std::uint8_t>& out);

// Whether the padding bits after the last code of a payload of exactly raw_payload_bytes(rect) bytes are zero.
bool raw_padding_is_zero(std::span<const std::uint8_t> payload, int bits, const cv::Rect& rect);

// Unpacks a payload of exactly raw_payload_bytes(rect) bytes into `rect` of `codes` (CV_16UC3).
// Returns false (writing nothing) if the padding bits are not zero.
bool unpack_codes(std::span<const std::uint8_t> payload, int bits, cv::Mat& codes, const cv::Rect& rect);

}  // namespace trm::link::detail
