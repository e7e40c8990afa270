// Concealment of lines lost on the link, and recovery: a pair that arrives intact decodes to exactly the
// bits of a fault-free run (OLED has no state beyond the pair).
#include "decoder_test_support.hpp"

#include <gtest/gtest.h>

namespace trm {
namespace {

std::vector<std::uint8_t> mask_with_lost(int lines, std::initializer_list<int> lost) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(lines), 1);
  for (int y : lost) mask[static_cast<std::size_t>(y)] = 0;
  return mask;
}

TEST(Concealment, LostFullFrameLinesShowTheLowPassEstimateAndClearTheirResidual) {
  EncoderConfig link;
  DecoderConfig config = test::decoder_config(link);
  ReferenceDecoder decoder(config);
  const cv::Mat image = test::nyquist_checkerboard(20, 16);  // clips heavily: every line has a residual
  const LinkFrame full = TrmEncoder(link).encode(image, 0);
  const auto mask = mask_with_lost(16, {0, 7, 15});
  const DecodedFrame d = decoder.decode(full, mask);
  ASSERT_TRUE(d.stages);
  EXPECT_EQ(d.stats.concealed_lines, 3);
  for (int y : {0, 7, 15}) {
    // beta of a lost line is L_t, which lies in [0, 1]: shown = L_t, rho = 0.
    EXPECT_EQ(test::max_abs_difference(d.wanted_linear.row(y), d.stages->low_linear.row(y)), 0.0) << y;
    EXPECT_EQ(cv::norm(d.stages->residual.row(y), cv::NORM_INF), 0.0) << y;
  }
  // Intact lines keep their residual.
  EXPECT_GT(cv::norm(d.stages->residual.row(3), cv::NORM_INF), 0.0);
}

TEST(Concealment, LostReducedFrameLinesRepeatThePreviousLowPassFrame) {
  EncoderConfig link;
  ReferenceDecoder decoder(test::decoder_config(link));
  ReferenceDecoder clean(test::decoder_config(link));
  const TrmEncoder encoder(link);
  const cv::Mat image = test::random_image(24, 18, 5);
  const LinkFrame full = encoder.encode(image, 0);
  LinkFrame reduced = encoder.encode(image, 1);
  decoder.decode(full);
  clean.decode(full);
  const DecodedFrame expected = clean.decode(reduced);
  // Static content: the stored d_t equals the reduced frame, so repeating its lines conceals perfectly.
  LinkFrame damaged{reduced.meta, reduced.codes.clone()};
  damaged.codes.row(2).setTo(cv::Scalar::all(0));
  const DecodedFrame got = decoder.decode(damaged, mask_with_lost(reduced.codes.rows, {2}));
  EXPECT_EQ(got.stats.concealed_lines, 1);
  EXPECT_EQ(cv::norm(got.drive_codes, expected.drive_codes, cv::NORM_INF), 0.0);
}

TEST(Concealment, AViewWithNoIntactLineIsALostFrame) {
  EncoderConfig link;
  ReferenceDecoder decoder(test::decoder_config(link));
  const TrmEncoder encoder(link);
  const cv::Mat image = test::random_image(16, 12, 6);
  const DecodedFrame first = decoder.decode(encoder.encode(image, 0));
  const LinkFrame reduced = encoder.encode(image, 1);
  const DecodedFrame lost = decoder.decode(reduced, std::vector<std::uint8_t>(static_cast<std::size_t>(reduced.codes.rows), 0));
  EXPECT_TRUE(lost.stats.frame_lost);
  // The panel holds the previous output.
  EXPECT_EQ(cv::norm(lost.drive_codes, first.drive_codes, cv::NORM_INF), 0.0);
  // The residual of the broken pair is gone: the next reduced frame (t = 3, after a lost t = 2) adds none.
  const DecodedFrame next = decoder.decode(encoder.encode(image, 3));
  EXPECT_FALSE(next.stats.residual_applied);
}

TEST(Concealment, FirstIntactPairAfterFaultsIsBitExact) {
  EncoderConfig link;
  ReferenceDecoder faulty(test::decoder_config(link));
  ReferenceDecoder clean(test::decoder_config(link));
  const TrmEncoder encoder(link);
  for (std::int64_t t = 0; t < 8; ++t) {
    const cv::Mat image = test::random_image(21, 13, 100 + static_cast<std::uint64_t>(t));
    const LinkFrame sent = encoder.encode(image, t);
    const DecodedFrame expected = clean.decode(sent);
    DecodedFrame got;
    if (t < 4) {
      LinkFrame damaged{sent.meta, sent.codes.clone()};
      damaged.codes.row(1).setTo(cv::Scalar::all(0));
      got = faulty.decode(damaged, mask_with_lost(sent.codes.rows, {1}));
    } else {
      got = faulty.decode(sent, std::vector<std::uint8_t>(static_cast<std::size_t>(sent.codes.rows), 1));
    }
    if (t >= 4) {
      EXPECT_EQ(cv::norm(got.drive_codes, expected.drive_codes, cv::NORM_INF), 0.0) << "t = " << t;
      EXPECT_EQ(test::max_abs_difference(got.drive, expected.drive), 0.0) << "t = " << t;
    }
  }
}

TEST(Concealment, MaskOfTheWrongLengthIsRejected) {
  EncoderConfig link;
  ReferenceDecoder decoder(test::decoder_config(link));
  const LinkFrame full = TrmEncoder(link).encode(test::random_image(8, 6, 7), 0);
  EXPECT_THROW(decoder.decode(full, std::vector<std::uint8_t>(5, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace trm
