// Shared helpers for the reference decoder tests: test content, the encoder round trip and an oracle of the
// DESIGN §4 formulas built directly from the encoder's primitives (transfer, D, U), not from the decoder.
#pragma once

#include "trm/encoder.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm::test {

// Uniform random linear RGB in [0, 1]: plenty of high frequencies, so beta clips often.
inline cv::Mat random_image(int width, int height, std::uint64_t seed) {
  cv::Mat image(height, width, CV_64FC3);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
  return image;
}

// Frame t of random content whose left half moves 3 pixels a frame (wrapping within the half) and whose right half
// stands still: the residual, the motion test and the clamps all take part.
inline cv::Mat half_moving_frame(int width, int height, std::uint64_t seed, std::int64_t t) {
  const cv::Mat source = random_image(width, height, seed);
  cv::Mat frame = source.clone();
  const int half = width / 2;
  const int shift = static_cast<int>(3 * t) % half;
  for (int y = 0; y < frame.rows; ++y) {
    for (int x = 0; x < half; ++x) frame.at<cv::Vec3d>(y, x) = source.at<cv::Vec3d>(y, (x + shift) % half);
  }
  return frame;
}

inline cv::Mat flat_image(int width, int height, cv::Vec3d value) {
  return cv::Mat(height, width, CV_64FC3, cv::Scalar(value[0], value[1], value[2]));
}

inline cv::Mat single_bright_pixel(int width, int height, int x, int y) {
  cv::Mat image = cv::Mat::zeros(height, width, CV_64FC3);
  image.at<cv::Vec3d>(y, x) = cv::Vec3d(1.0, 1.0, 1.0);
  return image;
}

// Black and white squares of `cell` pixels; phase 1 swaps the colours.
inline cv::Mat checkerboard(int width, int height, int cell, int phase = 0) {
  cv::Mat image(height, width, CV_64FC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double v = (x / cell + y / cell + phase) % 2 == 0 ? 1.0 : 0.0;
      image.at<cv::Vec3d>(y, x) = cv::Vec3d(v, v, v);
    }
  }
  return image;
}

inline cv::Mat nyquist_checkerboard(int width, int height) { return checkerboard(width, height, 1); }

// A bright square on a dark background with its top-left corner at (x0, y0).
inline cv::Mat bright_square(int width, int height, int x0, int y0, int side) {
  cv::Mat image = flat_image(width, height, cv::Vec3d(0.05, 0.05, 0.05));
  image(cv::Rect(x0, y0, side, side) & cv::Rect(0, 0, width, height)).setTo(cv::Scalar(0.9, 0.8, 0.7));
  return image;
}

inline DecoderConfig decoder_config(const EncoderConfig& link, const std::string& panel = "vive") {
  DecoderConfig config;
  config.link = link;
  config.panel = parse_panel(panel);
  config.record_stages = true;
  return config;
}

// The DESIGN §4 quantities of one full frame E_t and its successor reduced frame i_{t+1}, computed from the
// encoder primitives.
struct PairOracle {
  cv::Mat full_linear;  // I_t = lin(E_t)
  cv::Mat low_linear;   // L_t = lin(U(Q(D(E_t))))
  cv::Mat beta;         // 2 I_t - L_t
  cv::Mat shown;        // clamp(beta, 0, 1)
  cv::Mat residual;     // beta - shown
};

inline cv::Mat oracle_upsampled_linear(const cv::Mat& reduced_codes, cv::Size full, const EncoderConfig& link) {
  const cv::Mat encoded = dequantise(reduced_codes, link.bits);
  if (link.resample_space == ResampleSpace::Encoded) {
    return to_linear(upsample(encoded, full.width, full.height), link.transfer);
  }
  return upsample(to_linear(encoded, link.transfer), full.width, full.height);
}

inline PairOracle full_frame_oracle(const cv::Mat& full_codes, const EncoderConfig& link) {
  PairOracle o;
  o.full_linear = to_linear(dequantise(full_codes, link.bits), link.transfer);
  o.low_linear = oracle_upsampled_linear(reduce_codes(full_codes, link), full_codes.size(), link);
  o.beta = 2.0 * o.full_linear - o.low_linear;
  o.shown = cv::max(cv::min(o.beta, 1.0), 0.0);
  o.residual = o.beta - o.shown;
  return o;
}

// The message of the std::invalid_argument `action` throws; empty when it throws nothing (any other exception
// propagates and fails the test).
inline std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

inline double max_abs_difference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

inline bool all_finite(const cv::Mat& m) { return cv::checkRange(m, true, nullptr, -1e300, 1e300); }

// The same statistics of one view from two decoders or two settings, bit for bit (a mean motion weight NaN on both
// sides, not measured, counts as the same).
inline void expect_same_stats(const FrameStats& a, const FrameStats& b, const std::string& where) {
  EXPECT_EQ(a.clipped_fraction, b.clipped_fraction) << where;
  EXPECT_EQ(a.residual_mean_abs, b.residual_mean_abs) << where;
  EXPECT_EQ(a.residual_max_abs, b.residual_max_abs) << where;
  EXPECT_EQ(a.dropped_sum, b.dropped_sum) << where;
  if (!std::isnan(a.mean_motion_weight) || !std::isnan(b.mean_motion_weight)) {
    EXPECT_EQ(a.mean_motion_weight, b.mean_motion_weight) << where;
  }
  EXPECT_EQ(a.residual_applied, b.residual_applied) << where;
  EXPECT_EQ(a.lcd_unreachable_fraction, b.lcd_unreachable_fraction) << where;
  EXPECT_EQ(a.concealed_lines, b.concealed_lines) << where;
  EXPECT_EQ(a.frame_lost, b.frame_lost) << where;
}

}  // namespace trm::test
