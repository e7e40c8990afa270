// Static content through TrmEncoder + ReferenceDecoder (OLED): Eq. 3, alpha' + beta = 2 I, and the perceived
// pair equals I within output quantisation, with and without clipping, at any size and r.
#include "decoder_test_support.hpp"
#include "trm/metrics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace trm {
namespace {

using test::decoder_config;
using test::max_abs_difference;

struct StaticCase {
  std::string name;
  cv::Mat image;
  double reduction = 0.5;
  ResampleSpace space = ResampleSpace::Encoded;
  int link_bits = 8;
  int output_bits = 8;
};

// The worst output quantisation error of an OLED channel: |(q/N)^g - v^g| <= g max(v, q/N)^(g-1) / (2N) <= g / 2N.
double output_quantisation_bound(const Panel& panel, int output_bits) {
  const double gamma = *std::max_element(panel.oled.gamma.begin(), panel.oled.gamma.end());
  return gamma / (2.0 * ((1 << output_bits) - 1)) + 1e-12;
}

void check_static_pair_is_recovered(const StaticCase& c) {
  SCOPED_TRACE(c.name);
  EncoderConfig link;
  link.reduction = c.reduction;
  link.resample_space = c.space;
  link.bits = c.link_bits;
  DecoderConfig config = decoder_config(link);
  config.output_bits = c.output_bits;
  const TrmEncoder encoder(link);
  ReferenceDecoder decoder(config);

  const LinkFrame full = encoder.encode(c.image, 0);
  const LinkFrame reduced = encoder.encode(c.image, 1);
  ASSERT_EQ(full.meta.parity, Parity::Full);
  ASSERT_EQ(reduced.meta.parity, Parity::Reduced);
  const DecodedFrame f = decoder.decode(full);
  const DecodedFrame r = decoder.decode(reduced);
  ASSERT_TRUE(f.stages && r.stages);

  // Full frame stages against the oracle built from the encoder primitives.
  const test::PairOracle o = test::full_frame_oracle(full.codes, link);
  EXPECT_EQ(max_abs_difference(f.stages->at(Stage::Linear), o.full_linear), 0.0);
  EXPECT_EQ(max_abs_difference(f.stages->at(Stage::LowPass), o.low_linear), 0.0);
  EXPECT_LE(max_abs_difference(f.stages->at(Stage::Beta), o.beta), 1e-15);
  EXPECT_LE(max_abs_difference(f.wanted_linear, o.shown), 1e-15);
  EXPECT_LE(max_abs_difference(f.stages->at(Stage::Residual), o.residual), 1e-15);

  // Static: the reduced frame is exactly the d_t the decoder derived, so the motion test sees nothing.
  EXPECT_EQ(cv::norm(r.stages->at(Stage::Codes), f.stages->at(Stage::Reduced), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(r.stages->at(Stage::Alpha), o.low_linear, cv::NORM_INF), 0.0);  // alpha = L_t bit for bit
  EXPECT_EQ(cv::countNonZero(r.stages->at(Stage::Contrast)), 0);
  EXPECT_EQ(cv::norm(r.stages->at(Stage::Weight), cv::Mat::ones(r.stages->at(Stage::Weight).size(), CV_64FC1), cv::NORM_INF), 0.0);
  EXPECT_TRUE(r.stats.residual_applied);
  EXPECT_EQ(r.stats.mean_motion_weight, 1.0);

  // Eq. 3: alpha' + clamp(beta) = alpha + beta = 2 I. For static content alpha + rho = 2 I - clamp(beta) is always
  // inside [0, 1], so nothing is clipped twice and the whole frame is recovered.
  EXPECT_LE(max_abs_difference(r.wanted_linear + f.wanted_linear, 2.0 * o.full_linear), 1e-12);
  EXPECT_LE(r.stats.dropped_sum, 1e-12);

  // What the eye sees from the quantised drive: I within output quantisation.
  const cv::Mat seen = perceived_pair(f.emitted_linear, r.emitted_linear);
  EXPECT_LE(max_abs_difference(seen, o.full_linear), output_quantisation_bound(config.panel, c.output_bits));
  // And the drive codes are the quantised inverse gamma of what was wanted.
  for (int ch = 0; ch < 3; ++ch) {
    const double gamma = config.panel.oled.gamma[static_cast<std::size_t>(ch)];
    const cv::Vec3d x = f.wanted_linear.at<cv::Vec3d>(0, 0);
    EXPECT_EQ(f.drive_codes.at<cv::Vec3w>(0, 0)[ch],
              std::floor(std::pow(x[ch], 1.0 / gamma) * ((1 << c.output_bits) - 1) + 0.5));
  }
}

TEST(StaticScene, RandomTextureIsRecoveredExactly) {
  const StaticCase c{"random 40x30", test::random_image(40, 30, 7)};
  check_static_pair_is_recovered(c);
  // The random texture does exercise the residual path.
  EncoderConfig link;
  const test::PairOracle o = test::full_frame_oracle(TrmEncoder(link).encode(c.image, 0).codes, link);
  EXPECT_GT(cv::norm(o.residual, cv::NORM_L1), 1.0);
}

TEST(StaticScene, SmoothContentNeedsNoResidual) {
  cv::Mat ramp(24, 32, CV_64FC3);
  for (int y = 0; y < ramp.rows; ++y) {
    for (int x = 0; x < ramp.cols; ++x) ramp.at<cv::Vec3d>(y, x) = cv::Vec3d(0.2 + 0.01 * x, 0.3 + 0.01 * y, 0.5);
  }
  check_static_pair_is_recovered({"ramp", ramp});
  EncoderConfig link;
  ReferenceDecoder decoder(decoder_config(link));
  const DecodedFrame f = decoder.decode(TrmEncoder(link).encode(ramp, 0));
  EXPECT_EQ(f.stats.clipped_fraction, 0.0);
  EXPECT_EQ(f.stats.residual_max_abs, 0.0);
}

TEST(StaticScene, SingleBrightPixelOnBlackClipsAndIsStillRecovered) {
  const cv::Mat image = test::single_bright_pixel(31, 23, 15, 11);
  check_static_pair_is_recovered({"bright pixel", image});
  EncoderConfig link;
  ReferenceDecoder decoder(decoder_config(link));
  const DecodedFrame f = decoder.decode(TrmEncoder(link).encode(image, 0));
  // Maximal overshoot at the pixel, undershoot around it.
  EXPECT_GT(f.stages->at(Stage::Beta).at<cv::Vec3d>(11, 15)[1], 1.5);
  EXPECT_LT(f.stages->at(Stage::Beta).at<cv::Vec3d>(11, 16)[1], 0.0);
  EXPECT_GT(f.stats.clipped_fraction, 0.0);
  EXPECT_GT(f.stats.residual_max_abs, 0.5);
}

TEST(StaticScene, NyquistCheckerboardIsRecovered) {
  check_static_pair_is_recovered({"checkerboard 32x24", test::nyquist_checkerboard(32, 24)});
  check_static_pair_is_recovered({"checkerboard odd 33x25", test::nyquist_checkerboard(33, 25)});
}

TEST(StaticScene, UniformFramesAreExactAtTheExtremes) {
  for (double v : {0.0, 1.0, 0.5}) {
    const cv::Mat image = test::flat_image(9, 7, cv::Vec3d(v, v, v));
    check_static_pair_is_recovered({"flat " + std::to_string(v), image});
  }
}

TEST(StaticScene, AnySizeAndReduction) {
  check_static_pair_is_recovered({"1x1", test::random_image(1, 1, 3)});
  check_static_pair_is_recovered({"1x5", test::random_image(1, 5, 4)});
  check_static_pair_is_recovered({"97x61", test::random_image(97, 61, 5)});
  check_static_pair_is_recovered({"r = 1", test::random_image(20, 15, 6), 1.0});
  check_static_pair_is_recovered({"r = 1/3", test::random_image(31, 29, 8), 1.0 / 3.0});
  check_static_pair_is_recovered({"tiny r", test::random_image(23, 19, 9), 0.05});
}

TEST(StaticScene, LinearResampleSpaceAndTenBitLinkAndDrive) {
  check_static_pair_is_recovered({"linear space", test::random_image(25, 18, 10), 0.5, ResampleSpace::Linear});
  check_static_pair_is_recovered({"10-bit", test::random_image(25, 18, 11), 0.5, ResampleSpace::Encoded, 10, 10});
}

TEST(StaticScene, ReductionOneStillBlurs) {
  // At r = 1 D is the sigma = 1.25 blur, not the identity: the full frame is still compensated.
  EncoderConfig link;
  link.reduction = 1.0;
  ReferenceDecoder decoder(decoder_config(link));
  const DecodedFrame f = decoder.decode(TrmEncoder(link).encode(test::nyquist_checkerboard(12, 10), 0));
  EXPECT_GT(f.stats.clipped_fraction, 0.4);
}

}  // namespace
}  // namespace trm
