// The fixed-point decoders: streaming and frame-at-a-time schedules agree bit for bit (DESIGN §5), both agree with
// the double reference at the output bit depth (DESIGN §6), and bad configurations are rejected by stage.
#include "trm/fixed_decoder.hpp"

#include "decoder_test_support.hpp"
#include "trm/scene.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <cstdlib>
#include <string>
#include <vector>

namespace trm {
namespace {

FixedDecoderConfig fixed_config(const EncoderConfig& link, const std::string& panel = "vive", int output_bits = 8) {
  FixedDecoderConfig config;
  config.decoder.link = link;
  config.decoder.panel = parse_panel(panel);
  config.decoder.output_bits = output_bits;
  return config;
}

EncoderConfig link_config(double r, int phase = 0, bool stereo = false, int bits = 8) {
  EncoderConfig link;
  link.reduction = r;
  link.phase = phase;
  link.stereo = stereo;
  link.bits = bits;
  return link;
}

// The link frames (every eye) of `count` frames of a sequence of linear images.
std::vector<LinkFrame> encode_sequence(const std::vector<cv::Mat>& images, const EncoderConfig& link) {
  const TrmEncoder encoder(link);
  std::vector<LinkFrame> frames;
  for (std::size_t t = 0; t < images.size(); ++t) {
    for (int eye = 0; eye < (link.stereo ? 2 : 1); ++eye) {
      frames.push_back(encoder.encode(images[t], static_cast<std::int64_t>(t), eye));
    }
  }
  return frames;
}

std::vector<cv::Mat> scene_images(const std::string& name, int width, int height, int count) {
  SceneParams params;
  params.width = width;
  params.height = height;
  params.supersample = 2;
  auto scene = make_scene(name, params);
  std::vector<cv::Mat> images;
  for (int t = 0; t < count; ++t) images.push_back(scene->linear_frame(t));
  return images;
}

std::vector<cv::Mat> noise_images(int width, int height, int count, std::uint64_t seed) {
  std::vector<cv::Mat> images;
  for (int t = 0; t < count; ++t) images.push_back(test::random_image(width, height, seed + static_cast<std::uint64_t>(t)));
  return images;
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Streams the frames through both schedules and requires identical bits in every output and statistic.
void expect_schedules_identical(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                                const std::string& what) {
  FixedFrameDecoder frame_decoder(config);
  FixedStreamingDecoder streaming_decoder(config);
  for (const LinkFrame& link_frame : frames) {
    const DecodedFrame a = frame_decoder.decode(link_frame);
    const DecodedFrame b = streaming_decoder.decode(link_frame);
    const std::string where = what + " t=" + std::to_string(link_frame.meta.index) + " eye=" +
                              std::to_string(link_frame.meta.eye);
    ASSERT_TRUE(identical(a.drive_codes, b.drive_codes)) << where;
    ASSERT_TRUE(identical(a.wanted_linear, b.wanted_linear)) << where;
    ASSERT_TRUE(identical(a.drive, b.drive)) << where;
    ASSERT_TRUE(identical(a.emitted_linear, b.emitted_linear)) << where;
    EXPECT_EQ(a.stats.clipped_fraction, b.stats.clipped_fraction) << where;
    EXPECT_EQ(a.stats.residual_mean_abs, b.stats.residual_mean_abs) << where;
    EXPECT_EQ(a.stats.residual_max_abs, b.stats.residual_max_abs) << where;
    EXPECT_EQ(a.stats.dropped_sum, b.stats.dropped_sum) << where;
    EXPECT_EQ(a.stats.mean_motion_weight, b.stats.mean_motion_weight) << where;
    EXPECT_EQ(a.stats.residual_applied, b.stats.residual_applied) << where;
    EXPECT_EQ(frame_decoder.last_counts().residual_saturated, streaming_decoder.last_counts().residual_saturated);
    EXPECT_EQ(frame_decoder.last_counts().alpha_clipped, streaming_decoder.last_counts().alpha_clipped);
  }
}

TEST(FixedDecoder, StreamingMatchesFrameOnEveryScene) {
  for (const std::string& name : scene_names()) {
    const std::vector<cv::Mat> images = scene_images(name, 40, 30, 4);
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      for (int phase : {0, 1}) {
        const EncoderConfig link = link_config(r, phase);
        expect_schedules_identical(encode_sequence(images, link), fixed_config(link),
                                   name + " r=" + std::to_string(r) + " phase=" + std::to_string(phase));
      }
    }
  }
}

TEST(FixedDecoder, StreamingMatchesFrameOnStereoOddSizesAndOptions) {
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(1, 1), cv::Size(2, 3), cv::Size(5, 1)}) {
    const std::vector<cv::Mat> images = noise_images(size.width, size.height, 4, 7);
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r, 0, true);
      const std::string what = std::to_string(size.width) + "x" + std::to_string(size.height) + " r=" + std::to_string(r);
      expect_schedules_identical(encode_sequence(images, link), fixed_config(link), what + " stereo");
    }
  }
  const std::vector<cv::Mat> images = noise_images(33, 21, 4, 11);
  const EncoderConfig link10 = link_config(0.5, 0, false, 10);
  expect_schedules_identical(encode_sequence(images, link10), fixed_config(link10, "rift", 10), "10-bit rift");
  FixedDecoderConfig narrow = fixed_config(link_config(0.5));
  narrow.residual = {1, 7, true, fx::Quant::Rnd, fx::Overflow::Sat};  // sQ1.7: saturates at rho = 1
  expect_schedules_identical(encode_sequence(images, link_config(0.5)), narrow, "sQ1.7 residual");
}

TEST(FixedDecoder, StreamingMatchesFrameOnLcd) {
  for (const std::string& name : scene_names()) {
    const std::vector<cv::Mat> images = scene_images(name, 40, 30, 4);
    for (double r : {1.0, 0.5, 0.4}) {
      const EncoderConfig link = link_config(r, 0, true);
      expect_schedules_identical(encode_sequence(images, link), fixed_config(link, "lcd"),
                                 name + " lcd stereo r=" + std::to_string(r));
    }
  }
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(1, 1)}) {
    const EncoderConfig link = link_config(0.75);
    FixedDecoderConfig config = fixed_config(link, "lcd:-0.2,0.3,0.6,0.02,2.4", 10);
    config.decoder.lcd_history = LcdHistory::Contributed;
    expect_schedules_identical(encode_sequence(noise_images(size.width, size.height, 4, 5), link), config,
                               "lcd custom contributed");
  }
}

struct Agreement {
  std::uint64_t samples = 0;
  std::uint64_t identical = 0;
  int max_lsb = 0;
  double max_merged_codes = 0.0;  // LCD: max |M_fixed - M_reference| (2^o - 1), the merge the eye sees
  double max_unreachable_difference = 0.0;  // LCD: max per-frame difference of the unreachable fractions
  double identical_fraction() const { return static_cast<double>(identical) / static_cast<double>(samples); }
};

// LcdComparison::Synchronised hands the reference the fixed decoder's drive codes after every frame, so each
// frame's LCD inverse is compared from the same panel state (the comparison the ≤ 1 LSB criterion applies to);
// FreeRunning lets both decoders keep their own panel history.
enum class LcdComparison { FreeRunning, Synchronised };

Agreement compare_with_reference(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                                 LcdComparison lcd_comparison = LcdComparison::FreeRunning) {
  ReferenceDecoder reference(config.decoder);
  FixedStreamingDecoder fixed(config);
  Agreement agreement;
  for (const LinkFrame& frame : frames) {
    const DecodedFrame expected_frame = reference.decode(frame);
    const DecodedFrame got_frame = fixed.decode(frame);
    if (lcd_comparison == LcdComparison::Synchronised) reference.adopt_panel_history(got_frame);
    const cv::Mat& expected = expected_frame.drive_codes;
    const cv::Mat& got = got_frame.drive_codes;
    if (config.decoder.panel.kind == PanelKind::Lcd) {
      agreement.max_unreachable_difference =
          std::max(agreement.max_unreachable_difference, std::abs(expected_frame.stats.lcd_unreachable_fraction -
                                                                  got_frame.stats.lcd_unreachable_fraction));
      cv::Mat merged_expected;
      cv::Mat merged_got;
      cv::pow(expected_frame.emitted_linear, 1.0 / config.decoder.panel.lcd.gamma, merged_expected);
      cv::pow(got_frame.emitted_linear, 1.0 / config.decoder.panel.lcd.gamma, merged_got);
      agreement.max_merged_codes =
          std::max(agreement.max_merged_codes, cv::norm(merged_expected, merged_got, cv::NORM_INF) *
                                                   ((1 << config.decoder.output_bits) - 1));
    }
    const cv::Mat e = expected.reshape(1);
    const cv::Mat g = got.reshape(1);
    for (int y = 0; y < e.rows; ++y) {
      for (int k = 0; k < e.cols; ++k) {
        const int difference = std::abs(static_cast<int>(e.at<std::uint16_t>(y, k)) - g.at<std::uint16_t>(y, k));
        agreement.identical += difference == 0 ? 1 : 0;
        agreement.max_lsb = std::max(agreement.max_lsb, difference);
        ++agreement.samples;
      }
    }
  }
  return agreement;
}

void expect_agreement(const Agreement& a, const std::string& what) {
  std::printf("[ fixed vs reference ] %-28s %9llu codes  identical %8.4f %%  max %d LSB\n", what.c_str(),
              static_cast<unsigned long long>(a.samples), 100.0 * a.identical_fraction(), a.max_lsb);
  EXPECT_GE(a.identical_fraction(), 0.999) << what;
  EXPECT_LE(a.max_lsb, 1) << what;
}

// LCD: v_t is solved against the code v_{t-1} actually shown, and dv_t/dv_{t-1} is close to -1 (M(v, v) = v), so
// one code that rounds differently (as in any two implementations) is answered by the opposite difference in the
// pixel's next frames, without decay. Codes may then differ by a few LSB while the merge M(v_t, v_{t-1}) the eye
// sees stays within one code; that, and the fraction of identical codes, is what is asserted.
void expect_lcd_agreement(const Agreement& a, const std::string& what) {
  std::printf("[ fixed vs reference ] %-32s %9llu codes  identical %8.4f %%  max %d LSB  merge within %.3f codes  "
              "unreachable fraction within %.4f\n",
              what.c_str(), static_cast<unsigned long long>(a.samples), 100.0 * a.identical_fraction(), a.max_lsb,
              a.max_merged_codes, a.max_unreachable_difference);
  EXPECT_GE(a.identical_fraction(), 0.999) << what;
  EXPECT_LE(a.max_lsb, 4) << what;
  EXPECT_LE(a.max_merged_codes, 1.0) << what;
  EXPECT_LE(a.max_unreachable_difference, 0.002) << what;
}

TEST(FixedDecoder, AgreesWithReferenceOnEveryScene) {
  for (const std::string& name : scene_names()) {
    const std::vector<cv::Mat> images = scene_images(name, 64, 48, 6);
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r);
      expect_agreement(compare_with_reference(encode_sequence(images, link), fixed_config(link)),
                       name + " r=" + std::to_string(r).substr(0, 4));
    }
  }
}

TEST(FixedDecoder, AgreesWithReferenceOnNoise) {
  for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
    const EncoderConfig link = link_config(r);
    expect_agreement(compare_with_reference(encode_sequence(noise_images(64, 48, 6, 100), link), fixed_config(link)),
                     "noise r=" + std::to_string(r).substr(0, 4));
  }
  const EncoderConfig stereo = link_config(0.5, 1, true);
  expect_agreement(compare_with_reference(encode_sequence(noise_images(61, 37, 6, 200), stereo), fixed_config(stereo)),
                   "noise stereo 61x37");
  const EncoderConfig link10 = link_config(0.5, 0, false, 10);
  expect_agreement(
      compare_with_reference(encode_sequence(noise_images(64, 48, 6, 300), link10), fixed_config(link10, "vive", 10)),
      "noise 10-bit link+drive");
}

// Both ways: synchronised, every LCD code within 1 LSB; free-running, the merge the eye sees within one code.
void expect_lcd_both_ways(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                          const std::string& what) {
  expect_agreement(compare_with_reference(frames, config, LcdComparison::Synchronised), what + " synchronised");
  expect_lcd_agreement(compare_with_reference(frames, config), what + " free-running");
}

TEST(FixedDecoder, AgreesWithReferenceOnLcd) {
  for (const std::string& name : scene_names()) {
    const EncoderConfig link = link_config(0.5);
    expect_lcd_both_ways(encode_sequence(scene_images(name, 48, 32, 6), link), fixed_config(link, "lcd"),
                         name + " lcd");
  }
  for (double r : {1.0, 0.75, 0.4}) {
    const EncoderConfig link = link_config(r);
    expect_lcd_both_ways(encode_sequence(noise_images(48, 32, 6, 400), link), fixed_config(link, "lcd"),
                         "noise lcd r=" + std::to_string(r).substr(0, 4));
  }
  const EncoderConfig link = link_config(0.5);
  FixedDecoderConfig contributed = fixed_config(link, "lcd:-0.2,0.3,0.6,0.02,2.4", 10);
  contributed.decoder.lcd_history = LcdHistory::Contributed;
  expect_lcd_both_ways(encode_sequence(noise_images(48, 32, 6, 500), link), contributed,
                       "noise lcd custom contributed 10b");
  expect_lcd_both_ways(encode_sequence(scene_images("discs", 48, 32, 6), link), contributed,
                       "discs lcd custom contributed 10b");
}

// Longer runs are where free-running codes drift (the neutral mode); synchronised they must not.
TEST(FixedDecoder, AgreesWithReferenceOnLongLcdRuns) {
  const EncoderConfig link = link_config(0.5);
  for (const std::string& name : {std::string("panorama"), std::string("jitter")}) {
    expect_lcd_both_ways(encode_sequence(scene_images(name, 96, 64, 24), link), fixed_config(link, "lcd"),
                         name + " lcd 24 frames");
  }
}

TEST(ReferenceDecoderLcd, AdoptPanelHistoryRejectsWhatItCannotUse) {
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames = encode_sequence(noise_images(16, 8, 2, 7), link);
  ReferenceDecoder oled(fixed_config(link).decoder);
  const DecodedFrame shown = oled.decode(frames[0]);
  EXPECT_THROW(oled.adopt_panel_history(shown), std::invalid_argument);
  ReferenceDecoder lcd(fixed_config(link, "lcd").decoder);
  EXPECT_THROW(lcd.adopt_panel_history(shown), std::invalid_argument);  // no history yet
  const DecodedFrame first = lcd.decode(frames[0]);
  DecodedFrame wrong_size = first;
  wrong_size.drive_codes = cv::Mat::zeros(4, 4, CV_16UC3);
  EXPECT_THROW(lcd.adopt_panel_history(wrong_size), std::invalid_argument);
  DecodedFrame too_deep = first;
  too_deep.drive_codes = cv::Mat(first.drive_codes.size(), CV_16UC3, cv::Scalar::all(256));
  EXPECT_THROW(lcd.adopt_panel_history(too_deep), std::invalid_argument);
  // Adopting its own codes changes nothing.
  ReferenceDecoder twin(fixed_config(link, "lcd").decoder);
  twin.decode(frames[0]);
  lcd.adopt_panel_history(first);
  EXPECT_EQ(cv::norm(lcd.decode(frames[1]).drive_codes, twin.decode(frames[1]).drive_codes, cv::NORM_INF), 0.0);
}

TEST(FixedDecoder, AgreesWithReferenceAcrossSensitivities) {
  for (double s : {0.0, 1.0, 100.0, std::numeric_limits<double>::infinity()}) {
    for (const std::string& name : {std::string("discs"), std::string("jitter")}) {
      const EncoderConfig link = link_config(0.5);
      FixedDecoderConfig config = fixed_config(link);
      config.decoder.sensitivity = s;
      expect_agreement(compare_with_reference(encode_sequence(scene_images(name, 48, 32, 4), link), config),
                       name + " s=" + std::to_string(s).substr(0, 5));
    }
  }
}

// Eq. 3 in fixed point: for static content the reduced frame sees c = 0 (w = 1 exactly, also where the encoder's
// double D rounded an exact half-code tie either way: the Nyquist checkerboard), and wherever alpha' is not clipped
// the pair sums to 2 I within the rounding of the I ROM.
TEST(FixedDecoder, StaticContentIsRecoveredExactly) {
  for (const std::string& name : {std::string("checker"), std::string("static"), std::string("text")}) {
    for (double r : {0.5, 0.4}) {
      const EncoderConfig link = link_config(r);
      const cv::Mat image = scene_images(name, 48, 32, 1)[0];
      const std::vector<LinkFrame> frames = encode_sequence({image, image}, link);
      FixedStreamingDecoder decoder(fixed_config(link));
      const DecodedFrame full = decoder.decode(frames[0]);
      const DecodedFrame reduced = decoder.decode(frames[1]);
      EXPECT_TRUE(reduced.stats.residual_applied);
      EXPECT_EQ(reduced.stats.mean_motion_weight, 1.0) << name << " r=" << r;
      const cv::Mat linear = to_linear(dequantise(frames[0].codes, link.bits), link.transfer);
      double worst = 0.0;
      for (int y = 0; y < linear.rows; ++y) {
        for (int x = 0; x < linear.cols; ++x) {
          for (int ch = 0; ch < 3; ++ch) {
            const double a = reduced.wanted_linear.at<cv::Vec3d>(y, x)[ch];
            if (a <= 0.0 || a >= 1.0) continue;
            const double pair = full.wanted_linear.at<cv::Vec3d>(y, x)[ch] + a;
            worst = std::max(worst, std::abs(pair - 2.0 * linear.at<cv::Vec3d>(y, x)[ch]));
          }
        }
      }
      EXPECT_LE(worst, std::ldexp(1.0, -24)) << name << " r=" << r;
    }
  }
}

TEST(FixedDecoder, StreamingReportsLatencyAndBuffers) {
  const FixedStreamingDecoder decoder(fixed_config(link_config(0.5)));
  const FixedStreamingReport report = decoder.report(cv::Size(1080, 1200));
  const int radius = gaussian_radius(default_sigma(0.5));
  std::printf("[ streaming ] 1080x1200 r=0.5: full latency %d lines, reduced latency %d lines\n",
              report.full_latency_lines, report.reduced_latency_lines);
  for (const FixedBufferReport& b : report.buffers) {
    std::printf("[ streaming ]   %-58s %5d x %5d x %2d bits\n", b.name.c_str(), b.lines, b.samples, b.bits);
  }
  EXPECT_LE(report.buffers[0].lines, 2 * radius + 1);
  EXPECT_EQ(report.buffers[2].lines, 2);
  EXPECT_EQ(report.buffers[3].lines, 2);
  EXPECT_GT(report.full_latency_lines, 0);
  EXPECT_LE(report.full_latency_lines, 2 * radius + 4);
}

TEST(FixedDecoder, SaturationIsCounted) {
  // A single bright pixel on black gives rho = 1 next to it; sQ1.7 holds at most 1 - 2^-7.
  FixedDecoderConfig config = fixed_config(link_config(0.5));
  config.residual = {1, 7, true, fx::Quant::Rnd, fx::Overflow::Sat};
  FixedStreamingDecoder decoder(config);
  const std::vector<LinkFrame> frames =
      encode_sequence({test::single_bright_pixel(16, 16, 8, 8)}, config.decoder.link);
  decoder.decode(frames[0]);
  EXPECT_GT(decoder.last_counts().beta_clipped, 0u);
  EXPECT_GT(decoder.last_counts().residual_saturated, 0u);
}

void expect_rejected(const FixedDecoderConfig& config, const std::string& stage) {
  try {
    FixedFrameDecoder decoder(config);
    ADD_FAILURE() << "accepted a bad configuration for " << stage;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(stage), std::string::npos) << error.what();
  }
}

TEST(FixedDecoder, RejectsBadConfiguration) {
  const FixedDecoderConfig good = fixed_config(link_config(0.5));
  EXPECT_NO_THROW(FixedStreamingDecoder{good});
  FixedDecoderConfig c = good;
  c.decoder.panel = parse_panel("lcd");
  EXPECT_NO_THROW(FixedStreamingDecoder{c});
  c.decoder.panel = parse_panel("lcd:-1,0,0.5,0,2.2");  // dM/dv_t = 0.5 - 2 v_t < 0 near v_t = 1
  expect_rejected(c, "LCD drive");
  c.decoder.panel = parse_panel("lcd");
  c.lcd_segments_per_octave = 3;
  expect_rejected(c, "LCD drive (target LUT)");
  c = good;
  c.decoder.output_bits = 12;
  expect_rejected(c, "output_bits");
  c = good;
  c.linear_frac_bits = 16;  // drive codes 0, 1, 2 collapse near black
  c.residual.frac_bits = 16;
  expect_rejected(c, "drive (linear light)");
  c = good;
  c.upsample_frac_bits = 20;  // 8 + 20 address bits > 24
  expect_rejected(c, "U (output)");
  c = good;
  c.eotf_segments_per_code_log2 = 9;
  expect_rejected(c, "EOTF LUT");
  c = good;
  c.reciprocal_entries = 8;
  expect_rejected(c, "reciprocal LUT");
  c = good;
  c.exp_entries = 3;
  expect_rejected(c, "exp LUT");
  c = good;
  c.residual = {0, 8, true, fx::Quant::Rnd, fx::Overflow::Sat};
  expect_rejected(c, "residual store");
  c = good;
  c.residual = {2, 40, true, fx::Quant::Rnd, fx::Overflow::Sat};
  expect_rejected(c, "residual store");
  c = good;
  c.residual.is_signed = false;
  expect_rejected(c, "residual store");
  c = good;
  c.gaussian_tap_frac_bits = 4;
  expect_rejected(c, "D (Gaussian taps)");
  c = good;
  c.decoder.sensitivity = 300.0;
  expect_rejected(c, "motion weight");
  c = good;
  c.decoder.link.resample_space = ResampleSpace::Linear;
  expect_rejected(c, "resample space");
}

TEST(FixedDecoder, RejectsMismatchedFrames) {
  const EncoderConfig link = link_config(0.5);
  FixedStreamingDecoder decoder(fixed_config(link));
  std::vector<LinkFrame> frames = encode_sequence(noise_images(8, 8, 1, 1), link);
  LinkFrame bad = frames[0];
  bad.meta.bits = 10;
  EXPECT_THROW(decoder.decode(bad), std::invalid_argument);
  bad = frames[0];
  bad.codes.at<cv::Vec3w>(0, 0)[0] = 300;
  EXPECT_THROW(decoder.decode(bad), std::invalid_argument);
}

}  // namespace
}  // namespace trm
