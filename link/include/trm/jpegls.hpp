// Lossless JPEG-LS (ISO/IEC 14495-1, through CharLS) for link codes: CV_16UC3 RGB at 8 or 10 bits.
#pragma once

#include "trm/frame.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

namespace trm::link {

class JpegLsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Encodes codes (CV_16UC3, every code < 2^bits, bits 8 or 10) losslessly (NEAR = 0), sample-interleaved,
// no colour transform. Throws std::invalid_argument for a bad input, JpegLsError if CharLS fails.
std::vector<std::uint8_t> jpegls_encode(const cv::Mat& codes, int bits);

// Decodes a JPEG-LS image that must be exactly width x height, 3 components, `bits` bits, lossless; the
// header is checked before any pixel buffer is allocated. Returns CV_16UC3. Throws JpegLsError.
cv::Mat jpegls_decode(std::span<const std::uint8_t> data, int width, int height, int bits);

inline double bits_per_pixel(std::size_t coded_bytes, std::size_t pixels) {
  return pixels == 0 ? 0.0 : static_cast<double>(coded_bytes) * 8.0 / static_cast<double>(pixels);
}

// Lossless size of a stream, per displayed full-resolution pixel: the y axis of the paper's Fig. 13.
// Add every view of a run (full-rate frames for "without TRM", TRM's full and reduced frames for
// "with TRM"); each view is coded as one JPEG-LS image.
struct LosslessTally {
  std::uint64_t coded_bits = 0;
  std::uint64_t sent_pixels = 0;       // pixels of the views as sent (reduced size for reduced frames)
  std::uint64_t displayed_pixels = 0;  // full-resolution pixels they stand for

  void add(const LinkFrame& view);  // throws like jpegls_encode
  double bits_per_displayed_pixel() const {
    return displayed_pixels == 0 ? 0.0 : static_cast<double>(coded_bits) / static_cast<double>(displayed_pixels);
  }
};

}  // namespace trm::link
