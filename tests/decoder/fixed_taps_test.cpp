// The stage taps of the frame-at-a-time fixed-point decoder (the source of the golden vectors) and the hardware
// report's ROMs, arithmetic and frame-store comparison.
#include "trm/fixed_decoder.hpp"
#include "trm/reference_decoder.hpp"

#include "decoder_test_support.hpp"

#include "trm/resample.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace trm {
namespace {

FixedDecoderConfig taps_config(const std::string& panel) {
  FixedDecoderConfig config;
  config.decoder.link.reduction = 0.5;
  config.decoder.panel = parse_panel(panel);
  return config;
}

std::int64_t raw_at(const cv::Mat& m, int y, int k, int frac_bits) {
  return static_cast<std::int64_t>(std::ldexp(m.ptr<double>(y)[k], frac_bits));
}

// Moving content then a static pair: taps leave the output untouched and agree with it stage by stage.
void check_sequence(const std::string& panel) {
  const FixedDecoderConfig config = taps_config(panel);
  const int F = config.linear_frac_bits;
  FixedFrameDecoder tapped(config);
  FixedStreamingDecoder plain(config);
  const TrmEncoder encoder(config.decoder.link);
  const int width = 21, height = 14;
  std::vector<cv::Mat> images = {test::bright_square(width, height, 2, 3, 6), test::bright_square(width, height, 5, 4, 6),
                                 test::random_image(width, height, 7), test::random_image(width, height, 7)};
  for (std::size_t t = 0; t < images.size(); ++t) {
    SCOPED_TRACE(panel + " frame " + std::to_string(t));
    const LinkFrame frame = encoder.encode(images[t], static_cast<std::int64_t>(t), 0);
    FixedStageTaps taps;
    const DecodedFrame a = tapped.decode(frame, taps);
    const DecodedFrame b = plain.decode(frame);
    ASSERT_EQ(cv::norm(a.drive_codes, b.drive_codes, cv::NORM_INF), 0.0);
    const bool full = frame.meta.parity == Parity::Full;
    const FixedStagePlane& drive = taps[Stage::Drive];
    const FixedStagePlane& codes = taps[Stage::Codes];
    ASSERT_TRUE(drive.present && codes.present);
    EXPECT_EQ(codes.size, frame.codes.size());
    for (int y = 0; y < height; ++y) {
      for (int k = 0; k < 3 * width; ++k) {
        const std::size_t i = static_cast<std::size_t>(y * 3 * width + k);
        ASSERT_EQ(drive.values[i], a.drive_codes.ptr<std::uint16_t>(y)[k]);
        const std::int64_t wanted = raw_at(a.wanted_linear, y, k, F);
        if (full) {
          const auto& beta = taps[Stage::Beta].values;
          const auto& shown = taps[Stage::Shown].values;
          const auto& rho = taps[Stage::Residual].values;
          const auto& I = taps[Stage::Linear].values;
          const auto& L = taps[Stage::LowPass].values;
          ASSERT_EQ(beta[i], 2 * I[i] - L[i]);
          ASSERT_EQ(shown[i], std::clamp<std::int64_t>(beta[i], 0, std::int64_t{1} << F));
          ASSERT_EQ(shown[i], wanted);
          if (panel != "lcd") {
            ASSERT_EQ(rho[i], beta[i] - shown[i]);  // the default store sQ2.F holds rho exactly
          }
        } else {
          ASSERT_EQ(taps[Stage::AlphaPrime].values[i], wanted);
        }
      }
    }
    if (!full) {
      ASSERT_TRUE(taps[Stage::Weight].present);
      const auto& c = taps[Stage::Contrast].values;
      const auto& w = taps[Stage::Weight].values;
      if (t == 3) {  // static pair: nothing moved, c = 0 and w = 1 everywhere
        EXPECT_EQ(*std::max_element(c.begin(), c.end()), 0);
        EXPECT_EQ(*std::min_element(w.begin(), w.end()), std::int64_t{1} << F);
      } else {
        EXPECT_GT(*std::max_element(c.begin(), c.end()), 0);
        EXPECT_LT(*std::min_element(w.begin(), w.end()), std::int64_t{1} << F);
      }
    }
  }
}

// Both decoders record their stages in one vocabulary: every stage the fixed-point taps hold the reference records
// too, for the same frame kind, at the same size and channel count, and the integer stages (codes, d_t, drive
// codes) agree exactly where the two decoders compute the same thing.
TEST(StageVocabulary, ReferenceRecordsEveryTappedStage) {
  for (const char* panel : {"vive", "lcd"}) {
    FixedDecoderConfig config = taps_config(panel);
    FixedFrameDecoder tapped(config);
    config.decoder.record_stages = true;
    ReferenceDecoder reference(config.decoder);
    const TrmEncoder encoder(config.decoder.link);
    for (std::int64_t t = 0; t < 2; ++t) {
      SCOPED_TRACE(std::string(panel) + " frame " + std::to_string(t));
      const LinkFrame frame = encoder.encode(test::random_image(21, 14, 11), t, 0);
      FixedStageTaps taps;
      (void)tapped.decode(frame, taps);
      const DecodedFrame recorded = reference.decode(frame);
      ASSERT_TRUE(recorded.stages);
      for (int k = 0; k < kStageCount; ++k) {
        const auto stage = static_cast<Stage>(k);
        const FixedStagePlane& plane = taps[stage];
        if (!plane.present) continue;
        EXPECT_EQ(plane.name, stage_name(stage));
        const cv::Mat& m = recorded.stages->at(stage);
        ASSERT_FALSE(m.empty()) << stage_name(stage);
        EXPECT_EQ(m.size(), plane.size) << stage_name(stage);
        EXPECT_EQ(m.channels(), plane.channels) << stage_name(stage);
      }
      for (Stage stage : {Stage::Codes, Stage::Reduced}) {
        if (!taps[stage].present) continue;
        const cv::Mat& m = recorded.stages->at(stage);
        for (int y = 0; y < m.rows; ++y) {
          for (int i = 0; i < 3 * m.cols; ++i) {
            ASSERT_EQ(taps[stage].values[static_cast<std::size_t>(y * 3 * m.cols + i)], m.ptr<std::uint16_t>(y)[i])
                << stage_name(stage);
          }
        }
      }
    }
  }
}

TEST(FixedTaps, StagesAgreeWithTheOutputOled) { check_sequence("vive"); }
TEST(FixedTaps, StagesAgreeWithTheOutputLcd) { check_sequence("lcd"); }

TEST(FixedTaps, ReducedFrameWithoutResidualHasNoMotionStages) {
  FixedFrameDecoder decoder(taps_config("vive"));
  EncoderConfig link;
  link.reduction = 0.5;
  link.phase = 1;  // frame 0 is reduced
  const TrmEncoder encoder(link);
  FixedStageTaps taps;
  decoder.decode(encoder.encode(test::random_image(9, 7, 3), 0, 0), taps);
  EXPECT_TRUE(taps[Stage::Alpha].present);
  EXPECT_TRUE(taps[Stage::AlphaPrime].present);
  EXPECT_FALSE(taps[Stage::Contrast].present);
  EXPECT_FALSE(taps[Stage::Weight].present);
  EXPECT_FALSE(taps[Stage::Beta].present);
}

TEST(FixedHardwareReport, RomsArithmeticAndFrameStores) {
  for (const char* panel : {"vive", "lcd"}) {
    SCOPED_TRACE(panel);
    const FixedStreamingDecoder decoder(taps_config(panel));
    const FixedStreamingReport r = decoder.report(cv::Size(1080, 1200));
    EXPECT_EQ(r.reduced, cv::Size(540, 600));
    ASSERT_FALSE(r.roms.empty());
    for (const auto& rom : r.roms) EXPECT_GT(rom.total_bits(), 0) << rom.name;
    const bool has_lcd_rom = std::any_of(r.roms.begin(), r.roms.end(), [](const FixedRomReport& rom) {
      return rom.name.rfind("LCD", 0) == 0;
    });
    EXPECT_EQ(has_lcd_rom, std::string(panel) == "lcd");
    ASSERT_FALSE(r.arithmetic.empty());
    for (const auto& a : r.arithmetic) EXPECT_GT(a.evaluations, 0) << a.stage;
    // Paper: full previous frame (8 bits) + residual; here: reduced d_t (8-bit link codes) + residual.
    const std::int64_t full = 3LL * 1080 * 1200;
    const std::int64_t reduced = 3LL * 540 * 600;
    EXPECT_EQ(r.paper_frame_store_bits, full * 8 + full * 30);  // residual sQ2.28
    EXPECT_EQ(r.model_frame_store_bits, reduced * 8 + full * 30);
  }
}

// The ROM and arithmetic entries, derived here from the formats and the geometry alone (not from the decoder's own
// tables): a change of a format or a stage that the report does not follow fails this test.
TEST(FixedHardwareReport, RomsAndArithmeticFollowTheFormats) {
  for (const int output_bits : {8, 10}) {
    for (const cv::Size view : {cv::Size(1080, 1200), cv::Size(31, 19)}) {
      SCOPED_TRACE(std::to_string(output_bits) + "-bit drive at " + std::to_string(view.width) + "x" +
                   std::to_string(view.height));
      FixedDecoderConfig config = taps_config("vive");
      config.decoder.output_bits = output_bits;
      const FixedStreamingDecoder decoder(config);
      const FixedStreamingReport r = decoder.report(view);
      const int link_codes = 1 << config.decoder.link.bits;
      const int linear_word = 1 + config.linear_frac_bits;  // uQ1.F
      const auto rom = [&](const std::string& prefix) {
        const auto it = std::find_if(r.roms.begin(), r.roms.end(),
                                     [&](const FixedRomReport& x) { return x.name.rfind(prefix, 0) == 0; });
        EXPECT_NE(it, r.roms.end()) << prefix;
        return it == r.roms.end() ? FixedRomReport{} : *it;
      };
      const FixedRomReport lin = rom("I = lin(E)");
      EXPECT_EQ(lin.entries, link_codes);
      EXPECT_EQ(lin.word_bits, linear_word);
      const FixedRomReport eotf = rom("L, alpha = lin(U(.))");
      EXPECT_EQ(eotf.entries, (link_codes - 1) * (1 << config.eotf_segments_per_code_log2) + 1);
      EXPECT_EQ(eotf.word_bits, linear_word);
      const FixedRomReport thresholds = rom("OLED drive thresholds");
      EXPECT_EQ(thresholds.count, 3);  // one per channel: the Vive's gammas differ per primary
      EXPECT_EQ(thresholds.entries, 1 << output_bits);
      EXPECT_EQ(thresholds.word_bits, linear_word);
      EXPECT_EQ(rom("Eq. 6 exp(-f)").entries, config.exp_entries);
      EXPECT_EQ(rom("Eq. 5 1/(Yp + Ya)").entries, config.reciprocal_entries);

      // Per output pixel: operators x evaluations / (W H), with the evaluations counted from the geometry.
      const double pixels = static_cast<double>(view.width) * view.height;
      const int reduced_width = reduced_size(view.width, 0.5), reduced_height = reduced_size(view.height, 0.5);
      int taps = 0;  // the polyphase filter's length: the longest phase
      for (int x = 0; x < reduced_width; ++x) {
        taps = std::max(taps, static_cast<int>(gaussian_taps(x, view.width, reduced_width, 2.5).weights.size()));
      }
      const auto stage = [&](const std::string& prefix) {
        const auto it = std::find_if(r.arithmetic.begin(), r.arithmetic.end(),
                                     [&](const FixedArithmeticReport& a) { return a.stage.rfind(prefix, 0) == 0; });
        EXPECT_NE(it, r.arithmetic.end()) << prefix;
        return it == r.arithmetic.end() ? FixedArithmeticReport{} : *it;
      };
      const FixedArithmeticReport horizontal = stage("D horizontal");
      EXPECT_EQ(horizontal.evaluations, 3LL * reduced_width * view.height);
      EXPECT_EQ(horizontal.multipliers, taps);
      const FixedArithmeticReport vertical = stage("D vertical");
      EXPECT_EQ(vertical.evaluations, 3LL * reduced_width * reduced_height);
      const FixedArithmeticReport drive = stage("OLED drive code");
      EXPECT_EQ(drive.evaluations, 3LL * view.width * view.height);
      EXPECT_EQ(drive.comparators, output_bits);  // a binary search over 2^b thresholds
      EXPECT_EQ(stage("Eq. 5 motion contrast").evaluations, static_cast<std::int64_t>(pixels));
      EXPECT_EQ(stage("U bilinear of i").evaluations, 3LL * view.width * view.height);
    }
  }
}

}  // namespace
}  // namespace trm
