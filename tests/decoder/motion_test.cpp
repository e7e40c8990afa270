// Moving content and the motion weight (Eqs. 4-6): w -> 0 where content moved, the extremes of s, the residual
// used once, stereo eyes independent, stream-start and lost-frame handling, long runs stay bounded.
#include "decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace trm {
namespace {

using test::decoder_config;
using test::max_abs_difference;

// Eq. 5 from the encoder's luma(): c = |Y(L) - Y(alpha)| / (Y(L) + Y(alpha)), 0 where the sum is 0.
cv::Mat oracle_contrast(const cv::Mat& low_previous, const cv::Mat& alpha) {
  const cv::Mat y_prev = luma(low_previous);
  const cv::Mat y_alpha = luma(alpha);
  cv::Mat c(alpha.size(), CV_64FC1);
  for (int y = 0; y < c.rows; ++y) {
    for (int x = 0; x < c.cols; ++x) {
      const double a = y_prev.at<double>(y, x);
      const double b = y_alpha.at<double>(y, x);
      c.at<double>(y, x) = a + b > 0.0 ? std::abs(a - b) / (a + b) : 0.0;
    }
  }
  return c;
}

cv::Mat bright_square_at(int x0) { return test::bright_square(48, 32, x0, 10, 10); }

struct MovingPair {
  LinkFrame full;
  LinkFrame reduced;
};

// A bright square at x = 8 in the full frame that has moved to x = 20 by the reduced frame.
MovingPair moving_square(const EncoderConfig& link) {
  const TrmEncoder encoder(link);
  return {encoder.encode(bright_square_at(8), 0), encoder.encode(bright_square_at(20), 1)};
}

TEST(Motion, WeightFollowsEquations5And6AndVanishesWhereContentMoved) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link);
  ReferenceDecoder decoder(config);
  const MovingPair pair = moving_square(link);
  const DecodedFrame f = decoder.decode(pair.full);
  const DecodedFrame r = decoder.decode(pair.reduced);
  ASSERT_TRUE(r.stats.residual_applied);

  const test::PairOracle o = test::full_frame_oracle(pair.full.codes, link);
  const cv::Mat alpha = test::oracle_upsampled_linear(pair.reduced.codes, o.full_linear.size(), link);
  // The motion test reads L_t and alpha bit for bit as U and lin of the encoder's primitives give them (the
  // reference keeps L_t from the full frame, where the design recomputes it from d_t).
  EXPECT_EQ(max_abs_difference(r.stages->at(Stage::PreviousLowPass), o.low_linear), 0.0);
  EXPECT_EQ(max_abs_difference(f.stages->at(Stage::LowPass), o.low_linear), 0.0);
  EXPECT_EQ(max_abs_difference(r.stages->at(Stage::Alpha), alpha), 0.0);
  const cv::Mat c = oracle_contrast(o.low_linear, alpha);
  EXPECT_LE(max_abs_difference(r.stages->at(Stage::Contrast), c), 1e-15);
  cv::Mat w(c.size(), CV_64FC1);
  for (int y = 0; y < c.rows; ++y) {
    for (int x = 0; x < c.cols; ++x) w.at<double>(y, x) = std::exp(-config.sensitivity * c.at<double>(y, x));
  }
  EXPECT_LE(max_abs_difference(r.stages->at(Stage::Weight), w), 1e-15);

  // Where the square left (x 8..17) and arrived (x 20..29) the contrast is large and w is tiny; far away it is 1.
  EXPECT_LT(r.stages->at(Stage::Weight).at<double>(15, 12), 0.01);
  EXPECT_LT(r.stages->at(Stage::Weight).at<double>(15, 25), 0.01);
  EXPECT_EQ(r.stages->at(Stage::Weight).at<double>(15, 44), 1.0);
  EXPECT_EQ(r.stages->at(Stage::Weight).at<double>(2, 2), 1.0);
  EXPECT_LT(r.stats.mean_motion_weight, 1.0);

  // Eq. 4 with the per-pixel w shared by the channels.
  cv::Mat expected(alpha.size(), CV_64FC3);
  for (int y = 0; y < alpha.rows; ++y) {
    for (int x = 0; x < alpha.cols; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        const double v = alpha.at<cv::Vec3d>(y, x)[ch] + w.at<double>(y, x) * o.residual.at<cv::Vec3d>(y, x)[ch];
        expected.at<cv::Vec3d>(y, x)[ch] = std::clamp(v, 0.0, 1.0);
      }
    }
  }
  EXPECT_LE(max_abs_difference(r.wanted_linear, expected), 1e-15);
  // No ghost of the old edge: where the square was, alpha' is alpha to within the faded residual.
  EXPECT_LT(std::abs(r.wanted_linear.at<cv::Vec3d>(15, 8)[0] - alpha.at<cv::Vec3d>(15, 8)[0]), 0.01);
  EXPECT_GT(f.stats.residual_max_abs, 0.1);  // there was a residual to ghost with
}

TEST(Motion, ZeroSensitivityAddsTheWholeResidualEverywhere) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link);
  config.sensitivity = 0.0;
  ReferenceDecoder decoder(config);
  const MovingPair pair = moving_square(link);
  decoder.decode(pair.full);
  const DecodedFrame r = decoder.decode(pair.reduced);
  EXPECT_GT(cv::countNonZero(r.stages->at(Stage::Contrast)), 0);
  EXPECT_EQ(cv::norm(r.stages->at(Stage::Weight), cv::Mat::ones(r.stages->at(Stage::Weight).size(), CV_64FC1), cv::NORM_INF), 0.0);
  EXPECT_EQ(r.stats.mean_motion_weight, 1.0);
}

TEST(Motion, HugeSensitivityIgnoresTheResidualWhereverContrastIsPositive) {
  {
    // A finite s beyond the uQ8 register is no decoder's: rejected by name, as by the fixed-point decoders.
    DecoderConfig config = decoder_config(EncoderConfig{});
    config.sensitivity = 1e300;
    EXPECT_NE(test::error_of([&] { ReferenceDecoder decoder(config); }).find("sensitivity"), std::string::npos);
  }
  for (double s : {std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE(s);
    EncoderConfig link;
    DecoderConfig config = decoder_config(link);
    config.sensitivity = s;
    ReferenceDecoder decoder(config);
    const MovingPair pair = moving_square(link);
    decoder.decode(pair.full);
    const DecodedFrame r = decoder.decode(pair.reduced);
    ASSERT_TRUE(test::all_finite(r.stages->at(Stage::Weight)));
    ASSERT_TRUE(test::all_finite(r.wanted_linear));
    const test::PairOracle o = test::full_frame_oracle(pair.full.codes, link);
    int moved = 0;
    for (int y = 0; y < r.wanted_linear.rows; ++y) {
      for (int x = 0; x < r.wanted_linear.cols; ++x) {
        const double c = r.stages->at(Stage::Contrast).at<double>(y, x);
        const double w = r.stages->at(Stage::Weight).at<double>(y, x);
        if (c > 0.0) {
          ++moved;
          EXPECT_EQ(w, 0.0);
          EXPECT_EQ(r.wanted_linear.at<cv::Vec3d>(y, x), r.stages->at(Stage::Alpha).at<cv::Vec3d>(y, x));
        } else {
          EXPECT_EQ(w, 1.0);  // static pixels keep their residual, no inf * 0
        }
      }
    }
    EXPECT_GT(moved, 100);
  }
}

TEST(Motion, ContrastIsZeroWhereBothFramesAreBlack) {
  EncoderConfig link;
  ReferenceDecoder decoder(decoder_config(link));
  const TrmEncoder encoder(link);
  const cv::Mat black = cv::Mat::zeros(8, 8, CV_64FC3);
  decoder.decode(encoder.encode(black, 0));
  const DecodedFrame r = decoder.decode(encoder.encode(black, 1));
  ASSERT_TRUE(test::all_finite(r.stages->at(Stage::Contrast)));
  EXPECT_EQ(cv::countNonZero(r.stages->at(Stage::Contrast)), 0);
  EXPECT_EQ(cv::countNonZero(r.wanted_linear.reshape(1)), 0);
}

TEST(ResidualLifetime, AReducedFrameFirstAddsNothing) {
  EncoderConfig link;
  ReferenceDecoder decoder(decoder_config(link));
  const cv::Mat image = test::random_image(20, 14, 21);
  const LinkFrame reduced = TrmEncoder(link).encode(image, 1);
  const DecodedFrame r = decoder.decode(reduced);
  EXPECT_FALSE(r.stats.residual_applied);
  EXPECT_TRUE(r.stages->at(Stage::Weight).empty());
  const cv::Mat alpha = test::oracle_upsampled_linear(reduced.codes, image.size(), link);
  EXPECT_EQ(max_abs_difference(r.wanted_linear, alpha), 0.0);
}

TEST(ResidualLifetime, UsedByExactlyOneReducedFrameAndNotAcrossALostFrame) {
  EncoderConfig link;
  const TrmEncoder encoder(link);
  const cv::Mat image = test::nyquist_checkerboard(16, 12);
  const cv::Mat alpha =
      test::oracle_upsampled_linear(encoder.encode(image, 1).codes, image.size(), link);

  // full 0, reduced 1 (uses rho_0), reduced 1 again (nothing left).
  ReferenceDecoder decoder(decoder_config(link));
  decoder.decode(encoder.encode(image, 0));
  EXPECT_TRUE(decoder.decode(encoder.encode(image, 1)).stats.residual_applied);
  const DecodedFrame again = decoder.decode(encoder.encode(image, 1));
  EXPECT_FALSE(again.stats.residual_applied);
  EXPECT_EQ(max_abs_difference(again.wanted_linear, alpha), 0.0);

  // full 0, then reduced 3: frames 1 and 2 were lost, rho_0 does not belong to frame 3.
  ReferenceDecoder after_loss(decoder_config(link));
  after_loss.decode(encoder.encode(image, 0));
  const DecodedFrame late = after_loss.decode(encoder.encode(image, 3));
  EXPECT_FALSE(late.stats.residual_applied);
  EXPECT_EQ(max_abs_difference(late.wanted_linear, alpha), 0.0);
}

TEST(Stereo, EyesAreIndependent) {
  EncoderConfig link;
  link.stereo = true;
  const TrmEncoder encoder(link);
  ReferenceDecoder both(decoder_config(link));
  ReferenceDecoder left_only(decoder_config(link));
  ReferenceDecoder right_only(decoder_config(link));
  for (std::int64_t t = 0; t < 6; ++t) {
    // Different content per eye, changing over time.
    const cv::Mat left = test::random_image(18, 12, static_cast<std::uint64_t>(100 + t / 3));
    const cv::Mat right = test::single_bright_pixel(18, 12, static_cast<int>(3 + t), 5);
    const LinkFrame l = encoder.encode(left, t, 0);
    const LinkFrame r = encoder.encode(right, t, 1);
    ASSERT_NE(l.meta.parity, r.meta.parity);  // off-phase
    const DecodedFrame bl = both.decode(l);
    const DecodedFrame br = both.decode(r);
    const DecodedFrame ol = left_only.decode(l);
    const DecodedFrame orr = right_only.decode(r);
    EXPECT_EQ(max_abs_difference(bl.wanted_linear, ol.wanted_linear), 0.0) << "t=" << t;
    EXPECT_EQ(max_abs_difference(br.wanted_linear, orr.wanted_linear), 0.0) << "t=" << t;
    EXPECT_EQ(cv::norm(bl.drive_codes, ol.drive_codes, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(br.drive_codes, orr.drive_codes, cv::NORM_INF), 0.0);
    EXPECT_EQ(bl.stats.residual_applied, ol.stats.residual_applied);
    EXPECT_EQ(br.stats.residual_applied, orr.stats.residual_applied);
    if (l.meta.parity == Parity::Reduced && t > 0) {
      EXPECT_TRUE(bl.stats.residual_applied);
    }
  }
}

// Flash content: black and white swap every third frame, with a bright pixel for overshoot, so full and reduced
// frames see every combination of old and new content.
cv::Mat flash_frame(std::int64_t t) {
  const bool white = (t / 3) % 2 == 1;
  cv::Mat image = test::flat_image(16, 12, white ? cv::Vec3d(1, 1, 1) : cv::Vec3d(0, 0, 0));
  image.at<cv::Vec3d>(6, static_cast<int>(t % 16)) = white ? cv::Vec3d(0, 0, 0) : cv::Vec3d(1, 1, 1);
  return image;
}

void run_long_flash(const std::string& panel) {
  SCOPED_TRACE(panel);
  EncoderConfig link;
  DecoderConfig config = decoder_config(link, panel);
  config.record_stages = false;
  const TrmEncoder encoder(link);
  ReferenceDecoder decoder(config);
  double worst_residual = 0.0;
  for (std::int64_t t = 0; t < 10000; ++t) {
    const DecodedFrame d = decoder.decode(encoder.encode(flash_frame(t), t));
    worst_residual = std::max(worst_residual, d.stats.residual_max_abs);
    ASSERT_TRUE(test::all_finite(d.wanted_linear)) << "t=" << t;
    ASSERT_TRUE(test::all_finite(d.emitted_linear)) << "t=" << t;
    double lo = 0.0;
    double hi = 0.0;
    cv::minMaxLoc(d.wanted_linear.reshape(1), &lo, &hi);
    ASSERT_GE(lo, 0.0);
    ASSERT_LE(hi, 1.0);
  }
  // beta = 2 I - L lies in [-1, 2], so |rho| <= 1 (the LCD shortfall adds at most 2 more); it is never
  // accumulated, so it cannot grow over the run.
  EXPECT_LE(worst_residual, panel == "lcd" ? 3.0 : 1.0);
  EXPECT_GT(worst_residual, 0.1);
}

TEST(LongRun, ResidualStaysBoundedOverTenThousandFlashFrames) {
  run_long_flash("vive");
  run_long_flash("lcd");
}

}  // namespace
}  // namespace trm
