// DESIGN §7 "leave out what a scene does not need": the fixed-point decoders with FixedDecoderConfig::skip_unneeded
// (static lines skip the motion test, all-zero residual lines skip the residual store traffic) give the same bits
// as the full path, in both schedules, and count what they skipped.
#include "fixed_decoder_test_support.hpp"
#include "fixed_kernels.hpp"
#include "fixed_lines.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::expect_identical_outputs;
using test::expect_skip_counts_equal;
using test::fixed_config;
using test::link_config;
using test::scene_images;

FixedDecoderConfig with_skip(FixedDecoderConfig config, bool skip) {
  config.skip_unneeded = skip;
  return config;
}

// Per view: the skip counters of the skipping streaming decoder (the frame schedule's are asserted equal).
struct SkipRun {
  std::vector<LinkFrame> frames;
  std::vector<FixedStageCounts> counts;
  std::vector<DecodedFrame> decoded;
};

// Decodes the frames with skips on and off in both schedules: all four outputs, statistics and stage counters
// identical; the two skipping schedules count the same skips; the full path counts none.
SkipRun decode_both_ways(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                         const std::string& what) {
  FixedFrameDecoder frame_full(with_skip(config, false));
  FixedStreamingDecoder streaming_full(with_skip(config, false));
  FixedFrameDecoder frame_skip(with_skip(config, true));
  FixedStreamingDecoder streaming_skip(with_skip(config, true));
  SkipRun run;
  run.frames = frames;
  for (const LinkFrame& f : frames) {
    const std::string where = what + " t=" + std::to_string(f.meta.index) + " eye=" + std::to_string(f.meta.eye);
    const DecodedFrame a = frame_full.decode(f);
    const DecodedFrame b = streaming_full.decode(f);
    const DecodedFrame c = frame_skip.decode(f);
    const DecodedFrame d = streaming_skip.decode(f);
    expect_identical_outputs(a, frame_full.last_counts(), b, streaming_full.last_counts(), where + " full path");
    expect_identical_outputs(a, frame_full.last_counts(), c, frame_skip.last_counts(), where + " frame skip");
    expect_identical_outputs(a, frame_full.last_counts(), d, streaming_skip.last_counts(), where + " streaming skip");
    expect_skip_counts_equal(frame_skip.last_counts(), streaming_skip.last_counts(), where + " skip schedules");
    expect_skip_counts_equal(frame_full.last_counts(), FixedStageCounts(), where + " full path counts no skip");
    if (::testing::Test::HasFatalFailure()) return run;
    run.counts.push_back(streaming_skip.last_counts());
    run.decoded.push_back(d);
  }
  return run;
}

struct Rates {
  std::uint64_t reduced_lines = 0;  // output lines of reduced views with a residual
  std::uint64_t full_lines = 0;
  std::uint64_t motion = 0;
  std::uint64_t read = 0;
  std::uint64_t write = 0;
  std::uint64_t grey = 0;
  std::uint64_t all_lines = 0;
  void add(const SkipRun& run) {
    for (std::size_t n = 0; n < run.counts.size(); ++n) {
      const FrameMeta& m = run.frames[n].meta;
      if (m.parity == Parity::Full) {
        full_lines += static_cast<std::uint64_t>(m.full_height);
      } else if (run.decoded[n].stats.residual_applied) {
        reduced_lines += static_cast<std::uint64_t>(m.full_height);
      }
      grey += run.counts[n].grey_lines;
      all_lines += static_cast<std::uint64_t>(m.full_height);
      motion += run.counts[n].motion_test_lines_skipped;
      read += run.counts[n].residual_read_lines_skipped;
      write += run.counts[n].residual_write_lines_skipped;
    }
  }
  static double pct(std::uint64_t n, std::uint64_t of) { return of ? 100.0 * static_cast<double>(n) / static_cast<double>(of) : 0.0; }
};

TEST(FixedSkip, BitIdenticalToTheFullPathOnEveryScene) {
  for (const std::string& panel : {std::string("vive"), std::string("lcd")}) {
    for (const std::string& name : scene_names()) {
      const std::vector<cv::Mat> images = scene_images(name, 24, 18, 4);
      Rates rates;
      for (double r : {1.0, 0.5, 0.4}) {
        const EncoderConfig link = link_config(r, 0, true);
        const std::string what = name + " " + panel + " r=" + std::to_string(r);
        rates.add(decode_both_ways(encode_sequence(images, link), fixed_config(link, panel), what));
        if (HasFatalFailure()) return;
      }
      std::printf("[ skip ] %-10s %-4s motion test %5.1f %%  residual read %5.1f %%  residual write %5.1f %%  grey "
                  "%5.1f %% of lines\n",
                  name.c_str(), panel.c_str(), Rates::pct(rates.motion, rates.reduced_lines),
                  Rates::pct(rates.read, rates.reduced_lines), Rates::pct(rates.write, rates.full_lines),
                  Rates::pct(rates.grey, rates.all_lines));
    }
  }
}

TEST(FixedSkip, BitIdenticalInTheLinearResampleSpaceAndAt10Bits) {
  const std::vector<cv::Mat> images = scene_images("discs", 21, 17, 4);
  for (const EncoderConfig& link : {link_config(0.5, 1, true, 8, ResampleSpace::Linear), link_config(0.4, 0, false, 10)}) {
    decode_both_ways(encode_sequence(images, link), fixed_config(link, "vive", 10), "discs variant");
    if (HasFatalFailure()) return;
  }
}

// Without the motion statistics a line with a residual runs the motion test on the runs of kMotionRunPixels pixels
// that hold a residual sample that is not 0: a residual at a single column, at the first or last pixel of a run or of
// the short run at the line's end (150 pixels: runs [0, 64), [64, 128), [128, 150)), must still be weighed. A full
// frame of grey 0.4 with a white column clips there alone (beta = 2 - L_t > 1, and 2 (0.4) - L_t > 0 beside it); the
// next reduced frame, grey 0.2, moves (w < 1 at the column). Against the decoder with the statistics, which weighs
// every pixel.
TEST(FixedSkip, WithoutMotionStatisticsEveryRunHoldingAResidualIsWeighed) {
  constexpr int kWidth = 150;
  // At r = 1/2 the OLED through the composed table (the line's codes, then the runs with a residual again); the LCD,
  // and both panels at r = 3/4 (U's interpolation over the runs' sub-ranges), through the whole line's kernels with w
  // computed on those runs.
  for (const auto& [r, panel] : {std::pair{0.5, "vive"}, {0.5, "lcd"}, {0.75, "vive"}, {0.75, "lcd"}}) {
    const EncoderConfig link = link_config(r);
    // (the OLED's table is built at either r; at 3/4 no row is exact, so it is not read)
    const bool table = !fixed_detail::FixedKernels(fixed_config(link, panel)).line_plans().drive_of_node.empty();
    ASSERT_EQ(table, std::string(panel) == "vive") << panel << " r=" << r;
    for (const int column : {0, 63, 64, 127, 128, 149}) {
      const std::string where = std::string(panel) + " r=" + std::to_string(r) + " column " + std::to_string(column);
      cv::Mat full(16, kWidth, CV_64FC3, cv::Scalar::all(0.4));
      full.col(column).setTo(cv::Scalar::all(1.0));
      const cv::Mat reduced(16, kWidth, CV_64FC3, cv::Scalar::all(0.2));
      const std::vector<LinkFrame> frames = encode_sequence({full, reduced}, link);
      ASSERT_EQ(frames.at(1).meta.parity, Parity::Reduced);
      FixedDecoderConfig with_statistics = fixed_config(link, panel);
      with_statistics.decoder.report_planes = false;  // drive codes only, as a feed decodes
      FixedDecoderConfig without = with_statistics;
      without.motion_weight_statistics = false;
      FixedStreamingDecoder measured(with_statistics);
      FixedStreamingDecoder streaming(without);
      for (const LinkFrame& f : frames) {
        const DecodedFrame a = measured.decode(f);
        const DecodedFrame b = streaming.decode(f);
        ASSERT_TRUE(test::identical(a.drive_codes, b.drive_codes)) << where << " t=" << f.meta.index;
        EXPECT_EQ(a.stats.residual_max_abs, b.stats.residual_max_abs) << where;
        EXPECT_EQ(a.stats.clipped_fraction, b.stats.clipped_fraction) << where;
        if (f.meta.parity == Parity::Full) {
          ASSERT_GT(a.stats.residual_max_abs, 0.0) << where << ": the white column clips";
        } else {
          EXPECT_LT(a.stats.mean_motion_weight, 1.0) << where << ": the reduced frame moves";
          EXPECT_TRUE(std::isnan(b.stats.mean_motion_weight)) << where << ": runs skipped";
        }
      }
    }
  }
}

// FixedDecoderConfig::motion_weight_statistics = false: lines with no residual to weight skip the motion test too,
// and lines with a residual skip it outside the runs of kMotionRunPixels pixels that hold one (150 pixels: runs of
// 64, 64 and 22). Against the same decoder with the statistics: the same codes, planes and statistics but the mean
// weight (NaN where a pixel's test was skipped) and the underflow count (of the pixels tested); the skipped lines are
// the static ones and those without a residual. Both schedules, both line paths (report planes on and off), one and
// two threads; at s = 255 the moving lines without a residual underflow Eq. 6, so the underflow count shows that the
// test did not run there.
TEST(FixedSkip, WithoutMotionStatisticsLinesWithoutResidualSkipTheMotionTest) {
  const EncoderConfig link = link_config(0.5, 0, true);
  const std::vector<LinkFrame> frames = encode_sequence(scene_images("discs", 150, 48, 8), link);
  for (const double sensitivity : {10.0, 255.0}) {
    for (const std::string& panel : {std::string("vive"), std::string("lcd")}) {
      for (const bool planes : {false, true}) {
        for (const int threads : {1, 2}) {
          FixedDecoderConfig with_statistics = fixed_config(link, panel);
          with_statistics.decoder.sensitivity = sensitivity;
          with_statistics.decoder.report_planes = planes;
          with_statistics.threads = threads;
          FixedDecoderConfig without = with_statistics;
          without.motion_weight_statistics = false;
          FixedStreamingDecoder measured(with_statistics);
          FixedStreamingDecoder streaming(without);
          FixedFrameDecoder frame(without);
          std::uint64_t extra_lines = 0;
          std::uint64_t fewer_underflows = 0;  // frames whose skipped lines held underflowing pixels
          std::uint64_t skipped_in_lines = 0;  // reduced frames that skipped runs of lines with a residual alone
          for (const LinkFrame& f : frames) {
            const std::string where = panel + (planes ? " planes" : " codes") + " threads=" + std::to_string(threads) +
                                      " s=" + std::to_string(sensitivity) + " t=" + std::to_string(f.meta.index) +
                                      " eye=" + std::to_string(f.meta.eye);
            const DecodedFrame a = measured.decode(f);
            const DecodedFrame b = streaming.decode(f);
            const DecodedFrame c = frame.decode(f);
            expect_identical_outputs(b, streaming.last_counts(), c, frame.last_counts(), where + " schedules");
            expect_skip_counts_equal(streaming.last_counts(), frame.last_counts(), where + " schedules");
            ASSERT_TRUE(test::identical(a.drive_codes, b.drive_codes)) << where;
            ASSERT_TRUE(test::identical(a.wanted_linear, b.wanted_linear)) << where;
            ASSERT_TRUE(test::identical(a.drive, b.drive)) << where;
            ASSERT_TRUE(test::identical(a.emitted_linear, b.emitted_linear)) << where;
            EXPECT_EQ(a.stats.lcd_unreachable_fraction, b.stats.lcd_unreachable_fraction) << where;
            EXPECT_EQ(a.stats.clipped_fraction, b.stats.clipped_fraction) << where;
            EXPECT_EQ(a.stats.dropped_sum, b.stats.dropped_sum) << where;
            EXPECT_EQ(a.stats.residual_mean_abs, b.stats.residual_mean_abs) << where;
            EXPECT_EQ(a.stats.residual_max_abs, b.stats.residual_max_abs) << where;
            const FixedStageCounts& on = measured.last_counts();
            const FixedStageCounts& off = streaming.last_counts();
            EXPECT_EQ(on.alpha_clipped, off.alpha_clipped) << where;
            EXPECT_EQ(on.lcd_unreachable, off.lcd_unreachable) << where;
            EXPECT_EQ(on.residual_read_lines_skipped, off.residual_read_lines_skipped) << where;
            // Static lines or lines without a residual: at least either set, at most both.
            EXPECT_GE(off.motion_test_lines_skipped,
                      std::max(on.motion_test_lines_skipped, off.residual_read_lines_skipped))
                << where;
            EXPECT_LE(off.motion_test_lines_skipped,
                      on.motion_test_lines_skipped + off.residual_read_lines_skipped)
                << where;
            const std::uint64_t extra = off.motion_test_lines_skipped - on.motion_test_lines_skipped;
            extra_lines += extra;
            if (extra > 0) {
              EXPECT_TRUE(std::isnan(b.stats.mean_motion_weight)) << where;
            }
            if (std::isnan(b.stats.mean_motion_weight)) {
              EXPECT_FALSE(std::isnan(a.stats.mean_motion_weight)) << where;
              EXPECT_LE(off.weight_underflow, on.weight_underflow) << where;
              fewer_underflows += off.weight_underflow < on.weight_underflow ? 1 : 0;
              skipped_in_lines += extra == 0 && f.meta.parity == Parity::Reduced ? 1 : 0;
            } else {
              EXPECT_EQ(a.stats.mean_motion_weight, b.stats.mean_motion_weight) << where;
              EXPECT_EQ(on.weight_underflow, off.weight_underflow) << where;
            }
            if (HasFatalFailure()) return;
          }
          EXPECT_GT(extra_lines, 0u) << panel << " the scene has moving lines without a residual";
          EXPECT_GT(skipped_in_lines, 0u) << panel << " runs without a residual in lines with one";
          if (sensitivity == 255.0) {
            EXPECT_GT(fewer_underflows, 0u) << panel << " the skipped lines' pixels were not tested";
          }
        }
      }
    }
  }
  // Stage taps (test vectors) record w everywhere: the flag has no effect there.
  FixedDecoderConfig without = fixed_config(link, "vive");
  without.motion_weight_statistics = false;
  FixedFrameDecoder tapped(without);
  FixedFrameDecoder reference_run(fixed_config(link, "vive"));
  for (const LinkFrame& f : frames) {
    FixedStageTaps taps, reference_taps;
    const DecodedFrame a = tapped.decode(f, taps);
    const DecodedFrame b = reference_run.decode(f, reference_taps);
    expect_identical_outputs(a, tapped.last_counts(), b, reference_run.last_counts(), "taps");
    expect_skip_counts_equal(tapped.last_counts(), reference_run.last_counts(), "taps");
    for (std::size_t s = 0; s < taps.planes.size(); ++s) {
      EXPECT_EQ(taps.planes[s].values, reference_taps.planes[s].values);
    }
  }
}

TEST(FixedSkip, StaticSceneSkipsTheMotionTestOnEveryLine) {
  for (const std::string& panel : {std::string("vive"), std::string("lcd")}) {
    for (double r : {1.0, 0.5, 0.4}) {
      const EncoderConfig link = link_config(r, 0, true);
      const SkipRun run =
          decode_both_ways(encode_sequence(scene_images("static", 32, 24, 6), link), fixed_config(link, panel), "static");
      ASSERT_FALSE(HasFatalFailure());
      int checked = 0;
      for (std::size_t n = 0; n < run.counts.size(); ++n) {
        const FrameMeta& m = run.frames[n].meta;
        if (m.parity != Parity::Reduced) continue;
        if (!run.decoded[n].stats.residual_applied) continue;  // the eye's first view (no full frame before it)
        EXPECT_EQ(run.counts[n].motion_test_lines_skipped, static_cast<std::uint64_t>(m.full_height))
            << panel << " r=" << r << " t=" << m.index << " eye=" << m.eye;
        EXPECT_EQ(run.decoded[n].stats.mean_motion_weight, 1.0);
        ++checked;
      }
      EXPECT_EQ(checked, 5);  // stereo, 6 frames: every reduced view after each eye's first full view
    }
  }
}

// The chroma skip: 16x48 at r = 1/2 (8x24 reduced). Full frame: grey everywhere except one red pixel on line 40, so
// input line 10 is not grey, nor are the d_t rows whose vertical taps reach it, nor the output lines whose U rows
// include one of those; the rest is. The reduced frame after it: grey received rows, so its lines are grey where
// the d_{t-1} rows it reads and the residual line are. Both schedules count alike (decode_both_ways), and every
// output is the full path's.
TEST(FixedSkip, GreyLinesComputeOneChannelWithTheSameBits) {
  const EncoderConfig link = link_config(0.5);
  const FixedDecoderConfig config = fixed_config(link, "vive");
  std::vector<cv::Mat> images;
  for (int t = 0; t < 2; ++t) {
    cv::Mat image(48, 16, CV_64FC3);
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 16; ++x) {
        const double v = 0.05 + 0.05 * ((x + y + t) % 7);  // grey texture, clipping at the steps
        image.at<cv::Vec3d>(y, x) = cv::Vec3d(v, v, v);
      }
    }
    if (t == 0) image.at<cv::Vec3d>(40, 5) = cv::Vec3d(0.9, 0.1, 0.1);
    images.push_back(image);
  }
  const std::vector<LinkFrame> frames = encode_sequence(images, link);
  const SkipRun run = decode_both_ways(frames, config, "grey");
  ASSERT_FALSE(HasFatalFailure());
  const FixedStageCounts& full = run.counts[0];
  EXPECT_GT(full.grey_reduced_rows, 0u);
  EXPECT_LT(full.grey_reduced_rows, 24u);
  EXPECT_GT(full.grey_lines, 0u);
  EXPECT_LT(full.grey_lines, 48u);
  EXPECT_EQ(run.counts[1].grey_reduced_rows, 0u);  // reduced frames compute no d_t
  EXPECT_GT(run.counts[1].grey_lines, 0u);
  EXPECT_LT(run.counts[1].grey_lines, 48u);  // the d_{t-1} rows the red pixel reached
  // An all-grey sequence: every line grey once the residual lines are grey; a colour one: none.
  for (cv::Mat& image : images) image.at<cv::Vec3d>(40, 5) = cv::Vec3d(0.5, 0.5, 0.5);
  const SkipRun all_grey = decode_both_ways(encode_sequence(images, link), config, "all grey");
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_EQ(all_grey.counts[0].grey_lines, 48u);
  EXPECT_EQ(all_grey.counts[0].grey_reduced_rows, 24u);
  EXPECT_EQ(all_grey.counts[1].grey_lines, 48u);
  const SkipRun colour = decode_both_ways(encode_sequence(scene_images("panorama", 16, 16, 2), link), config, "colour");
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_EQ(colour.counts[0].grey_lines + colour.counts[1].grey_lines, 0u);
}

// The off-chip traffic the skips save, by hand. A flat grey 16x8 view at r = 1/2 (8x4 reduced),
// static, on the OLED at the default formats (residual sQ2.28: 30 bits, linear F = 28, 8-bit link and drive): D of a
// flat image is the image, so beta = I and rho = 0 on every line, and the reduced frame is d_t code for code.
TEST(FixedSkip, TrafficSavedIsTheCountersTimesTheStoreWidths) {
  const EncoderConfig link = link_config(0.5);
  const FixedDecoderConfig config = fixed_config(link, "vive");
  ASSERT_EQ(config.residual.width(), 30);
  ASSERT_EQ(config.linear_frac_bits, 28);
  const std::vector<cv::Mat> images(2, cv::Mat(8, 16, CV_64FC3, cv::Scalar(0.4, 0.4, 0.4)));
  const SkipRun run = decode_both_ways(encode_sequence(images, link), config, "flat");
  ASSERT_FALSE(HasFatalFailure());
  FixedStageCounts total = run.counts[0];
  total += run.counts[1];
  EXPECT_EQ(total.residual_write_lines_skipped, 8u);  // the full frame's 8 lines, all rho = 0
  EXPECT_EQ(total.residual_read_lines_skipped, 8u);   // the reduced frame's 8 lines
  EXPECT_EQ(total.motion_test_lines_skipped, 8u);
  const FixedSkipTraffic t = skip_traffic_saved(config, cv::Size(16, 8), total, 2);
  EXPECT_EQ(t.residual_write_bits, 8 * (3 * 16) * 30);   // 11,520
  EXPECT_EQ(t.residual_read_bits, 8 * (3 * 16) * 30);    // 11,520
  EXPECT_EQ(t.previous_low_read_bits, 8 * 2 * (3 * 8) * 8);  // two d_{t-1} rows of 8 pixels per line: 3,072
  EXPECT_EQ(t.lcd_store_bits, 2 * (3 * 16 * 8) * (8 + 2 * 31));  // v read, x read and write, 2 views: 53,760
  EXPECT_EQ(t.total_bits(), 79872);
  // The LCD keeps its stores; its other savings are the same arithmetic.
  const FixedDecoderConfig lcd = fixed_config(link, "lcd");
  EXPECT_EQ(skip_traffic_saved(lcd, cv::Size(16, 8), total, 2).lcd_store_bits, 0);
  EXPECT_EQ(skip_traffic_saved(lcd, cv::Size(16, 8), total, 2).residual_write_bits, t.residual_write_bits);
  EXPECT_THROW(skip_traffic_saved(config, cv::Size(0, 8), total, 2), std::invalid_argument);
  EXPECT_THROW(skip_traffic_saved(config, cv::Size(16, 8), total, -1), std::invalid_argument);
}

// A smooth, dim scene never clips: no full line is written to the residual store and no reduced line reads one.
TEST(FixedSkip, NoClippingMeansNoResidualTraffic) {
  std::vector<cv::Mat> images;
  for (int t = 0; t < 4; ++t) {
    cv::Mat image(20, 28, CV_64FC3);
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        const double v = 0.25 + 0.004 * (x + 2 * t) + 0.002 * y;  // a gentle ramp, drifting
        image.at<cv::Vec3d>(y, x) = cv::Vec3d(v, 0.9 * v, 0.8 * v);
      }
    }
    images.push_back(image);
  }
  for (double r : {1.0, 0.5, 0.4}) {
    const EncoderConfig link = link_config(r, 0, true);
    const SkipRun run = decode_both_ways(encode_sequence(images, link), fixed_config(link, "vive"), "ramp");
    ASSERT_FALSE(HasFatalFailure());
    for (std::size_t n = 0; n < run.counts.size(); ++n) {
      const FrameMeta& m = run.frames[n].meta;
      const auto lines = static_cast<std::uint64_t>(m.full_height);
      if (m.parity == Parity::Full) {
        EXPECT_EQ(run.decoded[n].stats.clipped_fraction, 0.0) << "r=" << r << " t=" << m.index;
        EXPECT_EQ(run.counts[n].residual_write_lines_skipped, lines) << "r=" << r << " t=" << m.index;
      } else if (run.decoded[n].stats.residual_applied) {
        EXPECT_EQ(run.counts[n].residual_read_lines_skipped, lines) << "r=" << r << " t=" << m.index;
      }
    }
  }
}

// A constructed case with counts known in advance: 16x16 at r = 1/2 (8x8 reduced, U rows i0 = floor(y/2 - 1/4)).
// Full frame: flat code 100 with one white pixel at (3, 6): only line 6 clips, so 15 of 16 lines write no residual
// and the next reduced frame reads the residual on line 6 alone. Reduced frame: the decoder's own d_t except reduced
// row 5, so output lines 9..12 (whose U rows include 5) run the motion test and the other 12 skip it.
TEST(FixedSkip, CountsAreExactOnAConstructedCase) {
  const EncoderConfig link = link_config(0.5);
  const FixedDecoderConfig config = fixed_config(link, "vive");
  LinkFrame full;
  full.meta.index = 0;
  full.meta.parity = Parity::Full;
  full.meta.width = full.meta.full_width = 16;
  full.meta.height = full.meta.full_height = 16;
  full.meta.bits = 8;
  full.codes = cv::Mat(16, 16, CV_16UC3, cv::Scalar(100, 100, 100));
  full.codes.at<cv::Vec<std::uint16_t, 3>>(6, 3) = cv::Vec<std::uint16_t, 3>(255, 255, 255);

  FixedFrameDecoder tapping(with_skip(config, false));
  FixedStageTaps taps;
  tapping.decode(full, taps);
  const FixedStagePlane& d = taps[Stage::Reduced];
  ASSERT_EQ(d.size, cv::Size(8, 8));
  LinkFrame reduced;
  reduced.meta = full.meta;
  reduced.meta.index = 1;
  reduced.meta.parity = Parity::Reduced;
  reduced.meta.width = reduced.meta.height = 8;
  reduced.codes = cv::Mat(8, 8, CV_16UC3);
  for (int k = 0; k < 8; ++k) {
    for (int i = 0; i < 24; ++i) {
      const std::int64_t stored = d.values[static_cast<std::size_t>(k * 24 + i)];
      ASSERT_LT(stored, 256) << "no exact tie expected";
      reduced.codes.ptr<std::uint16_t>(k)[i] = static_cast<std::uint16_t>(k == 5 ? stored + 7 : stored);
    }
  }
  int residual_lines = 0;
  const FixedStagePlane& rho = taps[Stage::Residual];
  for (int y = 0; y < 16; ++y) {
    bool nonzero = false;
    for (int i = 0; i < 48; ++i) nonzero = nonzero || rho.values[static_cast<std::size_t>(y * 48 + i)] != 0;
    residual_lines += nonzero ? 1 : 0;
  }
  ASSERT_EQ(residual_lines, 1);  // the construction: only the white pixel's line clips

  const SkipRun run = decode_both_ways({full, reduced}, config, "constructed");
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_EQ(run.counts[0].residual_write_lines_skipped, 15u);
  EXPECT_EQ(run.counts[0].motion_test_lines_skipped, 0u);
  EXPECT_EQ(run.counts[0].residual_read_lines_skipped, 0u);
  EXPECT_EQ(run.counts[1].motion_test_lines_skipped, 12u);
  EXPECT_EQ(run.counts[1].residual_read_lines_skipped, 15u);
  EXPECT_EQ(run.counts[1].residual_write_lines_skipped, 0u);
  EXPECT_LT(run.decoded[1].stats.mean_motion_weight, 1.0);  // the motion test did run on lines 9..12
}

// Exact half-code ties of D round up in d_t, as the encoder's quantise_reduced rounds its reduced frame, so the
// encoder's next (static) reduced frame equals the stored d_t code for code and every line skips the motion test.
TEST(FixedSkip, ExactTiesKeepStaticLinesStatic) {
  // Columns alternating 100 / 101 at r = 1/2: mirror-symmetric taps pair an even with an odd column, so D is exactly
  // 100.5 away from the borders, and rounds up to 101.
  const EncoderConfig link = link_config(0.5);
  const FixedDecoderConfig config = fixed_config(link, "vive");
  cv::Mat image(12, 48, CV_64FC3);
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 48; ++x) {
      const double v = to_linear((x % 2 == 0 ? 100.0 : 101.0) / 255.0, Transfer::Srgb);
      image.at<cv::Vec3d>(y, x) = cv::Vec3d(v, v, v);
    }
  }
  const std::vector<LinkFrame> frames = encode_sequence({image, image}, link);
  int ties_rounded_up = 0;
  const cv::Mat reduced = frames[1].codes.reshape(1);
  for (int k = 0; k < reduced.rows; ++k) {
    for (int i = 3 * 3; i < reduced.cols - 3 * 3; ++i) ties_rounded_up += reduced.at<std::uint16_t>(k, i) == 101 ? 1 : 0;
  }
  ASSERT_GT(ties_rounded_up, 0) << "the construction needs exact ties";
  const SkipRun run = decode_both_ways(frames, config, "ties");
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_EQ(run.counts[1].motion_test_lines_skipped, 12u);
}

TEST(FixedSkip, ReportListsTheSkipStorageAndNoLcdStoresForOled) {
  const EncoderConfig link = link_config(0.5);
  const auto names = [](const FixedStreamingReport& r) {
    std::string all;
    for (const FixedBufferReport& b : r.buffers) all.append(b.name).append("\n");
    return all;
  };
  const FixedStreamingReport oled = FixedStreamingDecoder(fixed_config(link, "vive")).report(cv::Size(64, 48));
  const std::string oled_names = names(oled);
  EXPECT_EQ(oled_names.find("LCD"), std::string::npos) << oled_names;
  bool flags_found = false;
  for (const FixedBufferReport& b : oled.buffers) {
    if (b.name.find("residual-nonzero") == std::string::npos) continue;
    flags_found = true;
    EXPECT_EQ(b.total_bits(), 48);  // one bit per full line
  }
  EXPECT_TRUE(flags_found) << oled_names;
  const FixedStreamingReport full_path =
      FixedStreamingDecoder(with_skip(fixed_config(link, "vive"), false)).report(cv::Size(64, 48));
  EXPECT_EQ(names(full_path).find("residual-nonzero"), std::string::npos);
  const FixedStreamingReport lcd = FixedStreamingDecoder(fixed_config(link, "lcd")).report(cv::Size(64, 48));
  EXPECT_NE(names(lcd).find("LCD"), std::string::npos);
}

}  // namespace
}  // namespace trm
