// Shared helpers for the fixed-point decoder tests: configurations, encoded sequences, the bit-for-bit comparison of
// the two schedules and the agreement with the double reference (DESIGN §6), for whole views and for views received
// over a faulty link (a line mask, or not at all).
#pragma once

#include "decoder_test_support.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/metrics.hpp"
#include "trm/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace trm::test {

inline FixedDecoderConfig fixed_config(const EncoderConfig& link, const std::string& panel = "vive",
                                       int output_bits = 8) {
  FixedDecoderConfig config;
  config.decoder.link = link;
  config.decoder.panel = parse_panel(panel);
  config.decoder.output_bits = output_bits;
  return config;
}

inline EncoderConfig link_config(double r, int phase = 0, bool stereo = false, int bits = 8,
                                 ResampleSpace space = ResampleSpace::Encoded) {
  EncoderConfig link;
  link.reduction = r;
  link.phase = phase;
  link.stereo = stereo;
  link.bits = bits;
  link.resample_space = space;
  return link;
}

// The link frames (every eye) of a sequence of linear images.
inline std::vector<LinkFrame> encode_sequence(const std::vector<cv::Mat>& images, const EncoderConfig& link) {
  const TrmEncoder encoder(link);
  std::vector<LinkFrame> frames;
  for (std::size_t t = 0; t < images.size(); ++t) {
    for (int eye = 0; eye < (link.stereo ? 2 : 1); ++eye) {
      frames.push_back(encoder.encode(images[t], static_cast<std::int64_t>(t), eye));
    }
  }
  return frames;
}

inline std::vector<cv::Mat> scene_images(const std::string& name, int width, int height, int count) {
  SceneParams params;
  params.width = width;
  params.height = height;
  params.supersample = 2;
  auto scene = make_scene(name, params);
  std::vector<cv::Mat> images;
  for (int t = 0; t < count; ++t) images.push_back(scene->linear_frame(t));
  return images;
}

inline std::vector<cv::Mat> noise_images(int width, int height, int count, std::uint64_t seed) {
  std::vector<cv::Mat> images;
  for (int t = 0; t < count; ++t) images.push_back(random_image(width, height, seed + static_cast<std::uint64_t>(t)));
  return images;
}

inline bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// How one view reaches the decoder: whole, with some lines lost (mask: 0 = lost), or not at all.
struct Arrival {
  enum class Kind { Whole, Partial, Lost } kind = Kind::Whole;
  std::vector<std::uint8_t> mask;
};
// The arrival of the n-th view of a sequence.
using ArrivalPlan = std::function<Arrival(std::size_t n, const LinkFrame& frame)>;

inline Arrival whole(std::size_t, const LinkFrame&) { return {}; }

// The view as the link receiver hands it over: lost lines hold garbage (here: alternating extreme codes), which
// concealment must never show.
inline LinkFrame damaged(const LinkFrame& frame, const std::vector<std::uint8_t>& mask) {
  LinkFrame out{frame.meta, frame.codes.clone()};
  const std::uint16_t top = static_cast<std::uint16_t>((1 << frame.meta.bits) - 1);
  for (int y = 0; y < out.codes.rows; ++y) {
    if (mask[static_cast<std::size_t>(y)] != 0) continue;
    std::uint16_t* row = out.codes.ptr<std::uint16_t>(y);
    for (int i = 0; i < 3 * out.codes.cols; ++i) row[i] = (i + y) % 2 == 0 ? top : 0;
  }
  return out;
}

// Decodes one view as it arrived, with any decoder of the common interface.
template <typename Decoder>
DecodedFrame decode_as_arrived(Decoder& decoder, const LinkFrame& frame, const Arrival& arrival) {
  switch (arrival.kind) {
    case Arrival::Kind::Whole: return decoder.decode(frame);
    case Arrival::Kind::Lost: return decoder.decode_lost(frame.meta);
    case Arrival::Kind::Partial: break;
  }
  return decoder.decode(damaged(frame, arrival.mask), std::span<const std::uint8_t>(arrival.mask));
}

// One view decoded by both schedules: identical bits in every output, statistic and stage counter. Fatal failures
// return early (callers looping over frames check HasFatalFailure()).
inline void expect_identical_outputs(const DecodedFrame& a, const FixedStageCounts& counts_a, const DecodedFrame& b,
                                     const FixedStageCounts& counts_b, const std::string& where) {
  ASSERT_TRUE(identical(a.drive_codes, b.drive_codes)) << where;
  ASSERT_TRUE(identical(a.wanted_linear, b.wanted_linear)) << where;
  ASSERT_TRUE(identical(a.drive, b.drive)) << where;
  ASSERT_TRUE(identical(a.emitted_linear, b.emitted_linear)) << where;
  expect_same_stats(a.stats, b.stats, where);
  EXPECT_EQ(counts_a.beta_clipped, counts_b.beta_clipped) << where;
  EXPECT_EQ(counts_a.residual_saturated, counts_b.residual_saturated) << where;
  EXPECT_EQ(counts_a.residual_rounded, counts_b.residual_rounded) << where;
  EXPECT_EQ(counts_a.alpha_clipped, counts_b.alpha_clipped) << where;
  EXPECT_EQ(counts_a.weight_underflow, counts_b.weight_underflow) << where;
  EXPECT_EQ(counts_a.lcd_unreachable, counts_b.lcd_unreachable) << where;
}

// The DESIGN §7 skip counters of two decodes of one view (skipping decoders of two schedules or thread counts).
inline void expect_skip_counts_equal(const FixedStageCounts& a, const FixedStageCounts& b, const std::string& where) {
  EXPECT_EQ(a.motion_test_lines_skipped, b.motion_test_lines_skipped) << where;
  EXPECT_EQ(a.residual_read_lines_skipped, b.residual_read_lines_skipped) << where;
  EXPECT_EQ(a.residual_write_lines_skipped, b.residual_write_lines_skipped) << where;
  EXPECT_EQ(a.grey_lines, b.grey_lines) << where;
  EXPECT_EQ(a.grey_reduced_rows, b.grey_reduced_rows) << where;
}

// Streams the frames through both schedules and requires identical bits in every output and statistic.
inline void expect_schedules_identical(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                                       const std::string& what, const ArrivalPlan& plan = whole) {
  FixedFrameDecoder frame_decoder(config);
  FixedStreamingDecoder streaming_decoder(config);
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const LinkFrame& link_frame = frames[n];
    const Arrival arrival = plan(n, link_frame);
    const DecodedFrame a = decode_as_arrived(frame_decoder, link_frame, arrival);
    const DecodedFrame b = decode_as_arrived(streaming_decoder, link_frame, arrival);
    const std::string where = what + " t=" + std::to_string(link_frame.meta.index) + " eye=" +
                              std::to_string(link_frame.meta.eye);
    expect_identical_outputs(a, frame_decoder.last_counts(), b, streaming_decoder.last_counts(), where);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// Drive codes against the reference's (CodeAgreement), and for the LCD the merge and unreachable fractions.
struct Agreement : CodeAgreement {
  double max_merged_codes = 0.0;  // LCD: max |M_fixed - M_reference| (2^o - 1), the merge the eye sees
  double max_unreachable_difference = 0.0;  // LCD: max per-frame difference of the unreachable fractions
  int concealed_lines = 0;        // fixed decoder's count, asserted equal to the reference's view by view

  // Counts one frame's drive codes (same size and type) against the reference's.
  void add_codes(const cv::Mat& expected, const cv::Mat& got) { *this += compare_codes(got, expected); }
};

// LcdComparison::Synchronised hands the reference the fixed decoder's drive codes after every decoded frame
// (ReferenceDecoder::adopt_panel_history), so each frame's LCD inverse is compared from the same panel state: the
// comparison the <= 1 LSB criterion applies to. FreeRunning lets both decoders keep their own panel history.
enum class LcdComparison { FreeRunning, Synchronised };

inline Agreement compare_with_reference(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                                        const ArrivalPlan& plan = whole,
                                        LcdComparison lcd_comparison = LcdComparison::FreeRunning) {
  ReferenceDecoder reference(config.decoder);
  FixedStreamingDecoder fixed(config);
  Agreement agreement;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const LinkFrame& frame = frames[n];
    const Arrival arrival = plan(n, frame);
    const DecodedFrame expected_frame = decode_as_arrived(reference, frame, arrival);
    const DecodedFrame got_frame = decode_as_arrived(fixed, frame, arrival);
    if (lcd_comparison == LcdComparison::Synchronised && !got_frame.stats.frame_lost) {
      reference.adopt_panel_history(got_frame);
    }
    EXPECT_EQ(expected_frame.stats.concealed_lines, got_frame.stats.concealed_lines);
    EXPECT_EQ(expected_frame.stats.frame_lost, got_frame.stats.frame_lost);
    agreement.concealed_lines += got_frame.stats.concealed_lines;
    const cv::Mat& expected = expected_frame.drive_codes;
    const cv::Mat& got = got_frame.drive_codes;
    if (config.decoder.panel.has_history()) {
      agreement.max_unreachable_difference =
          std::max(agreement.max_unreachable_difference, std::abs(expected_frame.stats.lcd_unreachable_fraction -
                                                                  got_frame.stats.lcd_unreachable_fraction));
      agreement.max_merged_codes = std::max(
          agreement.max_merged_codes,
          max_merge_difference_codes(got_frame.emitted_linear, expected_frame.emitted_linear,
                                     config.decoder.panel.lcd, config.decoder.output_bits));
    }
    agreement.add_codes(expected, got);
  }
  return agreement;
}

// The DESIGN §6 criterion (printed either way).
inline void expect_agreement(const Agreement& a, const std::string& what) {
  std::printf("[ fixed vs reference ] %-28s %9lld codes  identical %8.4f %%  max %.0f LSB\n", what.c_str(),
              static_cast<long long>(a.compared), a.identical_percent(), a.max_lsb);
  EXPECT_TRUE(kReferenceAgreementCriterion.met_by(a))
      << what << ": " << a.identical_percent() << " % identical, max " << a.max_lsb << " LSB";
}

// LCD compared free-running: v_t is solved against the code v_{t-1} actually shown, and dv_t/dv_{t-1} is close to
// -1 (M(v, v) = v), so one code that rounds differently (as in any two implementations) is answered by the
// opposite difference in the pixel's next frames, without decay. Codes may then differ by a few LSB while the
// merge M(v_t, v_{t-1}) the eye sees stays within one code; that, and the fraction of identical codes, is what is
// asserted. (Synchronised, the codes themselves meet expect_agreement.)
inline void expect_lcd_agreement(const Agreement& a, const std::string& what) {
  std::printf("[ fixed vs reference ] %-32s %9lld codes  identical %8.4f %%  max %.0f LSB  merge within %.3f codes  "
              "unreachable fraction within %.4f\n",
              what.c_str(), static_cast<long long>(a.compared), a.identical_percent(), a.max_lsb,
              a.max_merged_codes, a.max_unreachable_difference);
  EXPECT_GE(a.identical_fraction(), kReferenceAgreementCriterion.min_identical_fraction) << what;
  EXPECT_LE(a.max_lsb, 4) << what;
  EXPECT_LE(a.max_merged_codes, 1.0) << what;
  EXPECT_LE(a.max_unreachable_difference, 0.002) << what;
}

}  // namespace trm::test
