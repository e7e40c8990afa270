// The LCD drive through the reference decoder (Eq. 7 inverse, DESIGN §4): targets, round trip against the
// quantised previous drive, the held first frame, and the unreachable shortfall carried by rho.
#include "decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace trm {
namespace {

using test::decoder_config;
using test::max_abs_difference;

// Output quantisation bound for the default merge: |dM/dv_t| = |0.5 - 0.2 (v_t - v_prev)| <= 0.7 and M <= 1, so
// one half code of v_t moves M^gamma by at most gamma 0.7 / 2N.
double lcd_quantisation_bound(const LcdPanel& lcd, int output_bits) {
  return lcd.gamma * 0.7 / (2.0 * ((1 << output_bits) - 1)) + 1e-12;
}

// Checks one decoded LCD frame against Eq. 7 and the DESIGN §4 target, channel sample by channel sample.
void check_lcd_frame(const DecodedFrame& d, const LcdPanel& lcd, int output_bits) {
  ASSERT_TRUE(d.stages);
  const DecodeStages& s = *d.stages;
  const double top = (1 << output_bits) - 1;
  int reachable = 0;
  for (int y = 0; y < d.drive.rows; ++y) {
    for (int x = 0; x < d.drive.cols; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        const double wanted = d.wanted_linear.at<cv::Vec3d>(y, x)[ch];
        const double previous = s.at(Stage::LcdPreviousLinear).at<cv::Vec3d>(y, x)[ch];
        const double v_prev = s.at(Stage::LcdPreviousDrive).at<cv::Vec3d>(y, x)[ch];
        const double v = d.drive.at<cv::Vec3d>(y, x)[ch];
        const double m = std::pow(std::max(0.5 * (wanted + previous), 0.0), 1.0 / lcd.gamma);
        ASSERT_NEAR(s.at(Stage::LcdTarget).at<cv::Vec3d>(y, x)[ch], m, 1e-15);
        // The previous drive is a code: the panel only ever shows quantised drives.
        ASSERT_EQ(v_prev * top, std::round(v_prev * top));
        const double code = d.drive_codes.at<cv::Vec3w>(y, x)[ch];
        ASSERT_EQ(code, std::floor(v * top + 0.5));
        ASSERT_NEAR(d.emitted_linear.at<cv::Vec3d>(y, x)[ch],
                    std::pow(std::max(lcd.merge(code / top, v_prev), 0.0), lcd.gamma), 1e-15);
        if (s.at(Stage::LcdUnreachable).at<cv::Vec3b>(y, x)[ch] == 0) {
          ++reachable;
          ASSERT_NEAR(lcd.merge(v, v_prev), m, 1e-12);
          // The pair (t-1, t) averages to (x_t + x_{t-1}) / 2 within output quantisation.
          ASSERT_NEAR(d.emitted_linear.at<cv::Vec3d>(y, x)[ch], 0.5 * (wanted + previous),
                      lcd_quantisation_bound(lcd, output_bits));
        }
      }
    }
  }
  EXPECT_GT(reachable, 0);
}

TEST(LcdDrive, StaticTextureRoundTrip) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, "lcd");
  ReferenceDecoder decoder(config);
  const TrmEncoder encoder(link);
  const cv::Mat image = test::random_image(24, 16, 31);
  for (std::int64_t t = 0; t < 4; ++t) {
    SCOPED_TRACE(t);
    check_lcd_frame(decoder.decode(encoder.encode(image, t)), config.panel.lcd, config.output_bits);
  }
}

TEST(LcdDrive, LinearMergeRoundTrip) {
  // p1 = 0: M = (v_t + v_prev) / 2, the degenerate linear solve in the decoder path.
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, "lcd:0,0,0.5,0,2.2");
  config.output_bits = 10;
  ReferenceDecoder decoder(config);
  const TrmEncoder encoder(link);
  const cv::Mat image = test::random_image(20, 14, 32);
  for (std::int64_t t = 0; t < 3; ++t) {
    SCOPED_TRACE(t);
    check_lcd_frame(decoder.decode(encoder.encode(image, t)), config.panel.lcd, config.output_bits);
  }
}

TEST(LcdDrive, FirstFrameIsTreatedAsHeld) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, "lcd");
  ReferenceDecoder decoder(config);
  const DecodedFrame d = decoder.decode(TrmEncoder(link).encode(test::random_image(10, 8, 33), 0));
  ASSERT_TRUE(d.stages);
  EXPECT_EQ(max_abs_difference(d.stages->at(Stage::LcdPreviousLinear), d.wanted_linear), 0.0);
  // v_{t-1}: the held drive of x_t (M(v, v) = v for the defaults, so x^(1/gamma)), quantised.
  cv::Mat held_drive;
  cv::pow(d.wanted_linear, 1.0 / config.panel.lcd.gamma, held_drive);
  const cv::Mat held_codes = quantise(held_drive, config.output_bits);
  EXPECT_LE(max_abs_difference(d.stages->at(Stage::LcdPreviousDrive), dequantise(held_codes, config.output_bits)), 1e-15);
  EXPECT_EQ(d.stats.lcd_unreachable_fraction, 0.0);
  // Solving against its own held drive lands within a code of it.
  EXPECT_LE(cv::norm(d.drive_codes, held_codes, cv::NORM_INF), 1.0);
  check_lcd_frame(d, config.panel.lcd, config.output_bits);
}

TEST(LcdDrive, UnreachableFullFramePushesTheShortfallIntoRho) {
  // Black, then a flat 0.6 full frame: from v_prev = 0 the brightest pair is M(1, 0) = p1 + p3 = 0.4, below
  // m = 0.3^(1/2.2) = 0.58, so v = 1 and frame 2 effectively contributes 2 * 0.4^gamma.
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, "lcd");
  config.lcd_history = LcdHistory::Contributed;
  ReferenceDecoder decoder(config);
  const TrmEncoder encoder(link);
  const cv::Mat black = test::flat_image(12, 10, cv::Vec3d(0, 0, 0));
  const cv::Mat grey = test::flat_image(12, 10, cv::Vec3d(0.6, 0.6, 0.6));
  decoder.decode(encoder.encode(black, 0));
  decoder.decode(encoder.encode(black, 1));
  const DecodedFrame full = decoder.decode(encoder.encode(grey, 2));
  const DecodedFrame reduced = decoder.decode(encoder.encode(grey, 3));

  const LcdPanel& lcd = config.panel.lcd;
  const double gamma = lcd.gamma;
  const double x2 = full.wanted_linear.at<cv::Vec3d>(5, 5)[1];
  EXPECT_NEAR(x2, 0.6, 5e-3);  // the nearest 8-bit sRGB code to 0.6
  const double x2_effective = 2.0 * std::pow(lcd.p1 + lcd.p3, gamma) - 0.0;
  EXPECT_EQ(full.stats.lcd_unreachable_fraction, 1.0);
  EXPECT_EQ(full.drive_codes.at<cv::Vec3w>(5, 5)[1], 255);
  ASSERT_TRUE(full.stages);
  EXPECT_NEAR(full.stages->at(Stage::Residual).at<cv::Vec3d>(5, 5)[1], x2 - x2_effective, 1e-12);
  EXPECT_NEAR(full.stats.residual_max_abs, x2 - x2_effective, 1e-12);

  // The next reduced frame is static (w = 1) and carries the shortfall: alpha' = alpha + rho = 2 x2 - x2_eff.
  ASSERT_TRUE(reduced.stats.residual_applied);
  const double alpha_prime = reduced.wanted_linear.at<cv::Vec3d>(5, 5)[1];
  EXPECT_NEAR(alpha_prime, 2.0 * x2 - x2_effective, 1e-12);
  EXPECT_NEAR(reduced.stages->at(Stage::LcdPreviousLinear).at<cv::Vec3d>(5, 5)[1], x2_effective, 1e-12);
  EXPECT_EQ(reduced.stats.lcd_unreachable_fraction, 0.0);
  // So the (full, reduced) pair averages to the wanted grey, where without the shortfall it would average to
  // (x2 + x2_eff) / 2, far too dark.
  const double pair = reduced.emitted_linear.at<cv::Vec3d>(5, 5)[1];
  EXPECT_NEAR(pair, x2, lcd_quantisation_bound(lcd, config.output_bits));
  EXPECT_GT(std::abs((x2 + x2_effective) / 2.0 - x2), 0.1);
  check_lcd_frame(reduced, lcd, config.output_bits);
}

TEST(LcdDrive, DesignRuleBuildsOnTheWantedPreviousValue) {
  // The design's rule (default): frame t's pair target uses the x_{t-1} the decoder wanted. After an unreachable
  // full frame whose shortfall went into rho, the (full, reduced) pair therefore lands shortfall / 2 above the
  // wanted grey: (x2 + alpha') / 2 with alpha' = 2 x2 - x2_eff.
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, "lcd");
  ASSERT_EQ(config.lcd_history, LcdHistory::Wanted);
  ReferenceDecoder decoder(config);
  const TrmEncoder encoder(link);
  const cv::Mat black = test::flat_image(12, 10, cv::Vec3d(0, 0, 0));
  const cv::Mat grey = test::flat_image(12, 10, cv::Vec3d(0.6, 0.6, 0.6));
  decoder.decode(encoder.encode(black, 0));
  decoder.decode(encoder.encode(black, 1));
  const DecodedFrame full = decoder.decode(encoder.encode(grey, 2));
  const DecodedFrame reduced = decoder.decode(encoder.encode(grey, 3));
  const LcdPanel& lcd = config.panel.lcd;
  const double x2 = full.wanted_linear.at<cv::Vec3d>(5, 5)[1];
  const double x2_effective = 2.0 * std::pow(lcd.p1 + lcd.p3, lcd.gamma);
  ASSERT_TRUE(reduced.stages);
  EXPECT_EQ(reduced.stages->at(Stage::LcdPreviousLinear).at<cv::Vec3d>(5, 5)[1], x2);
  const double alpha_prime = reduced.wanted_linear.at<cv::Vec3d>(5, 5)[1];
  EXPECT_NEAR(alpha_prime, 2.0 * x2 - x2_effective, 1e-12);
  const double pair = reduced.emitted_linear.at<cv::Vec3d>(5, 5)[1];
  EXPECT_NEAR(pair, (x2 + alpha_prime) / 2.0, lcd_quantisation_bound(lcd, config.output_bits));
  check_lcd_frame(reduced, lcd, config.output_bits);
}

TEST(LcdDrive, UnreachableReducedFrameIsClampedWithoutTouchingTheNextResidual) {
  // A reduced frame jumping from black to white cannot be reached; it is clamped and flagged, and the next full
  // frame starts a fresh residual.
  EncoderConfig link;
  ReferenceDecoder decoder(decoder_config(link, "lcd"));
  const TrmEncoder encoder(link);
  const cv::Mat black = test::flat_image(6, 4, cv::Vec3d(0, 0, 0));
  const cv::Mat white = test::flat_image(6, 4, cv::Vec3d(1, 1, 1));
  decoder.decode(encoder.encode(black, 0));
  const DecodedFrame r = decoder.decode(encoder.encode(white, 1));
  EXPECT_EQ(r.stats.lcd_unreachable_fraction, 1.0);
  EXPECT_EQ(r.drive_codes.at<cv::Vec3w>(0, 0), cv::Vec3w(255, 255, 255));
  const DecodedFrame f = decoder.decode(encoder.encode(white, 2));
  EXPECT_TRUE(test::all_finite(f.emitted_linear));
  EXPECT_TRUE(test::all_finite(f.stages->at(Stage::Residual)));
}

}  // namespace
}  // namespace trm
