// The TRM headset decoder as a user would write it with OpenCV in float32 (GaussianBlur + resize + pow / exp, OpenCV's
// own threads on): the same per-pair math as DESIGN §4 without the hardware model's bit-exactness, line buffers or
// statistics. It is the yardstick of `trm bench`, not a decoder of the project: its codes differ from the reference's
// wherever float32 and the blur-then-resize D differ from the polyphase Gaussian.
#pragma once

#include "trm/decoder.hpp"

#include <map>
#include <opencv2/core.hpp>

namespace trm::bench {

class OpencvTrmDecoder {
 public:
  explicit OpencvTrmDecoder(const DecoderConfig& config);
  // One view (per-eye state as the project's decoders keep it); returns the drive codes (CV_16UC3, full size).
  cv::Mat decode(const LinkFrame& frame);

 private:
  struct Eye {
    cv::Mat low;             // L_t of the last full frame (linear, CV_32FC3)
    cv::Mat residual;        // rho of the last full frame (CV_32FC3)
    std::int64_t residual_index = -1;
    cv::Mat previous_drive;  // LCD: v_{t-1} (CV_32FC3)
    cv::Mat previous_linear; // LCD: x_{t-1} (CV_32FC3)
  };
  cv::Mat linear_of_encoded(const cv::Mat& encoded) const;
  cv::Mat drive_codes(const cv::Mat& wanted, Eye& eye) const;

  DecoderConfig config_;
  cv::Mat code_lut_;  // 8-bit link: code -> linear (CV_32F, 256 entries)
  std::map<int, Eye> eyes_;
};

}  // namespace trm::bench
