// The fixed-point decoders: streaming and frame-at-a-time schedules agree bit for bit (DESIGN §5), both agree with
// the double reference at the output bit depth (DESIGN §6), and bad configurations are rejected by stage.
#include "trm/fixed_decoder.hpp"

#include "fixed_decoder_test_support.hpp"
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

using test::Agreement;
using test::compare_with_reference;
using test::encode_sequence;
using test::expect_agreement;
using test::expect_lcd_agreement;
using test::expect_schedules_identical;
using test::fixed_config;
using test::link_config;
using test::noise_images;
using test::scene_images;

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
  expect_agreement(compare_with_reference(frames, config, test::whole, test::LcdComparison::Synchronised),
                   what + " synchronised");
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

// Eq. 3 in fixed point: for static content the reduced frame sees c = 0 (w = 1 exactly, also where D lands on an
// exact half-code tie, which both sides round up: the Nyquist checkerboard), and wherever alpha' is not clipped
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
  c.decoder.panel.lcd.p1 = -1.0;  // dM/dv_t = 0.5 - 2 v_t < 0 near v_t = 1: a panel rule, for every decoder
  c.decoder.panel.lcd.p2 = 0.0;
  expect_rejected(c, "increasing in v_t");
  EXPECT_THROW(ReferenceDecoder{c.decoder}, std::invalid_argument);
  c.decoder.panel = parse_panel("lcd:0,0,0.5,0,2.2");
  c.decoder.panel.lcd.p3 = 1e-9;  // a valid panel, but p3 rounds to 0 in sQ7.28: M would not grow with v_t
  expect_rejected(c, "LCD drive (merge coefficients sQ7.28");
  EXPECT_NO_THROW(ReferenceDecoder{c.decoder});
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
  c.upsample_frac_bits = 33;  // above the 32-bit interpolation weight path
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
  EXPECT_NO_THROW(FixedStreamingDecoder{c});
  c.decoder.link.bits = 10;
  c.decoder.link.transfer = Transfer::Gamma22;
  c.linear_resample_frac_bits = 16;  // (0.5/1023)^2.2 and (1.5/1023)^2.2 both round up to 2^-16
  expect_rejected(c, "D (linear resample space)");
  c.linear_resample_frac_bits = 36;  // 36 + 28 > 62
  expect_rejected(c, "D (linear resample space)");
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
