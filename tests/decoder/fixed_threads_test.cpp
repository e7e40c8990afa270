// Execution settings of the fixed-point decoder that must not change a bit: the streaming decoder's bands of output
// lines on several threads (FixedDecoderConfig::threads) and the drive codes without the report planes
// (DecoderConfig::report_planes).
#include "fixed_core.hpp"
#include "fixed_decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::expect_identical_outputs;
using test::expect_skip_counts_equal;
using test::fixed_config;
using test::identical;
using test::link_config;
using test::scene_images;

FixedDecoderConfig with_threads(FixedDecoderConfig config, int threads) {
  config.threads = threads;
  return config;
}

// Every view through one pipeline and through 2 and 3 bands: identical outputs, statistics and counters.
void expect_bands_identical(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                            const std::string& what) {
  FixedStreamingDecoder one(with_threads(config, 1));
  FixedStreamingDecoder two(with_threads(config, 2));
  FixedStreamingDecoder three(with_threads(config, 3));
  const cv::Size full(frames.front().meta.full_width, frames.front().meta.full_height);
  ASSERT_EQ(two.threads_for(full), 2) << what << ": the view must be tall enough to share";
  ASSERT_EQ(three.threads_for(full), 3) << what;
  for (const LinkFrame& f : frames) {
    const std::string where = what + " t=" + std::to_string(f.meta.index) + " eye=" + std::to_string(f.meta.eye);
    const DecodedFrame a = one.decode(f);
    const DecodedFrame b = two.decode(f);
    const DecodedFrame c = three.decode(f);
    expect_identical_outputs(a, one.last_counts(), b, two.last_counts(), where + " 2 bands");
    expect_identical_outputs(a, one.last_counts(), c, three.last_counts(), where + " 3 bands");
    expect_skip_counts_equal(one.last_counts(), two.last_counts(), where + " 2 bands");
    expect_skip_counts_equal(one.last_counts(), three.last_counts(), where + " 3 bands");
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// 96 x 200: 200 / kMinBandRows = 3 bands at most.
constexpr int kWidth = 96;
constexpr int kHeight = 200;

TEST(FixedThreads, BandsGiveTheSameBitsAcrossScenesReductionsAndPanels) {
  struct Case {
    std::string scene;
    double r;
    int phase;
    std::string panel;
    int output_bits;
  };
  const std::vector<Case> cases = {
      {"discs", 0.5, 0, "vive", 8},   {"panorama", 0.5, 1, "vive", 10}, {"text", 0.4, 0, "rift", 8},
      {"flash", 0.75, 0, "vive", 8},  {"checker", 0.25, 0, "lcd", 8},   {"discs", 0.5, 0, "lcd", 10},
  };
  for (const Case& c : cases) {
    const auto frames = encode_sequence(scene_images(c.scene, kWidth, kHeight, 4), link_config(c.r, c.phase));
    expect_bands_identical(frames, fixed_config(link_config(c.r, c.phase), c.panel, c.output_bits),
                           c.scene + " r=" + std::to_string(c.r) + " " + c.panel);
    if (HasFatalFailure()) return;
  }
}

TEST(FixedThreads, BandsGiveTheSameBitsInStereoInTheLinearSpaceAndOnTheFullPath) {
  const EncoderConfig stereo = link_config(0.5, 0, true);
  expect_bands_identical(encode_sequence(scene_images("discs", kWidth, kHeight, 4), stereo), fixed_config(stereo),
                         "stereo");
  const EncoderConfig linear = link_config(0.5, 0, false, 8, ResampleSpace::Linear);
  expect_bands_identical(encode_sequence(test::noise_images(kWidth, kHeight, 4, 7), linear), fixed_config(linear),
                         "linear resample space, noise");
  FixedDecoderConfig full_path = fixed_config(link_config(0.5));
  full_path.skip_unneeded = false;
  expect_bands_identical(encode_sequence(scene_images("static", kWidth, kHeight, 4), link_config(0.5)), full_path,
                         "static, no skip");
}

TEST(FixedThreads, ViewsWithLostLinesAndLostViewsMatchOnePipeline) {
  // Partial views run on one pipeline whatever the thread count; the views after them (whole again) in bands.
  const EncoderConfig link = link_config(0.5);
  const auto frames = encode_sequence(scene_images("discs", kWidth, kHeight, 6), link);
  const test::ArrivalPlan plan = [](std::size_t n, const LinkFrame& f) {
    test::Arrival a;
    if (n == 2) a.kind = test::Arrival::Kind::Lost;
    if (n == 1 || n == 4) {
      a.kind = test::Arrival::Kind::Partial;
      a.mask.assign(static_cast<std::size_t>(f.codes.rows), 1);
      for (int y = 5; y < f.codes.rows; y += 7) a.mask[static_cast<std::size_t>(y)] = 0;
    }
    return a;
  };
  FixedStreamingDecoder one(fixed_config(link));
  FixedStreamingDecoder two(with_threads(fixed_config(link), 2));
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const test::Arrival arrival = plan(n, frames[n]);
    const DecodedFrame a = test::decode_as_arrived(one, frames[n], arrival);
    const DecodedFrame b = test::decode_as_arrived(two, frames[n], arrival);
    expect_identical_outputs(a, one.last_counts(), b, two.last_counts(), "view " + std::to_string(n));
    if (HasFatalFailure()) return;
  }
}

// A tall view is cut into more bands than threads (two per thread, each taken by the next thread free): 96 x 640 is
// 4 bands on 2 threads and 6 on 3, in whatever order the threads take them, with the same bits as one pipeline.
TEST(FixedThreads, MoreBandsThanThreadsGiveTheOnePipelineBits) {
  for (const std::string& panel : {std::string("vive"), std::string("lcd")}) {
    FixedDecoderConfig config = fixed_config(link_config(0.5, 0, true), panel);
    config.decoder.report_planes = false;  // drive codes only, as a feed decodes
    config.motion_weight_statistics = false;
    expect_bands_identical(encode_sequence(scene_images("discs", kWidth, 640, 4), link_config(0.5, 0, true)), config,
                           "tall discs " + panel);
    if (HasFatalFailure()) return;
  }
}

// The bands of a whole view balanced by the times of the eye's last view of the same kind: cut where the cost
// measured per row reaches each quarter of the total, and row_bands' equal shares where there is no usable record.
TEST(FixedThreads, BandsAreCutAtEqualCostsOfTheLastView) {
  fixed_detail::FixedKernels kernels(fixed_config(link_config(0.5), "vive"));  // (geometry() builds and keeps one)
  const fixed_detail::Geometry& g = kernels.geometry(cv::Size(kWidth, 1200));
  const auto begins = [](const std::vector<fixed_detail::RowBand>& bands) {
    std::vector<int> out;
    for (const fixed_detail::RowBand& band : bands) out.push_back(band.begin);
    return out;
  };
  const std::vector<int> even = {0, 300, 600, 900};
  EXPECT_EQ(begins(fixed_detail::row_bands(g, 4)), even);
  // The last view: rows 0-599 took 1 s, rows 600-1199 3 s; a quarter of the 4 s is all of the first band.
  fixed_detail::BandTimes last{1200, {0, 600}, {1.0, 3.0}};
  const std::vector<fixed_detail::RowBand> balanced = fixed_detail::balanced_bands(g, 4, last);
  EXPECT_EQ(begins(balanced), (std::vector<int>{0, 600, 800, 1000}));
  // Every band's d_t rows follow the next band's first output row, as row_bands gives them, and cover d_t once.
  ASSERT_EQ(balanced.size(), 4u);
  EXPECT_EQ(balanced.back().end, 1200);
  EXPECT_EQ(balanced.front().reduced_begin, 0);
  EXPECT_EQ(balanced.back().reduced_end, g.reduced.height);
  for (std::size_t b = 0; b + 1 < balanced.size(); ++b) {
    EXPECT_EQ(balanced[b].end, balanced[b + 1].begin);
    EXPECT_EQ(balanced[b + 1].reduced_begin, g.bilinear_rows[static_cast<std::size_t>(balanced[b + 1].begin)].i0);
    EXPECT_EQ(balanced[b].reduced_end, balanced[b + 1].reduced_begin);
  }
  // No usable record: another view size, a time that is not positive or not finite, cuts that would leave bands
  // shorter than kMinBandRows / 2 (all the cost in rows 1000-1059: cuts at 1015, 1030 and 1045).
  for (const fixed_detail::BandTimes& unusable :
       {fixed_detail::BandTimes{}, fixed_detail::BandTimes{1100, {0, 600}, {1.0, 3.0}},
        fixed_detail::BandTimes{1200, {0, 600}, {0.0, 3.0}}, fixed_detail::BandTimes{1200, {0, 600}, {NAN, 3.0}},
        fixed_detail::BandTimes{1200, {0, 1000, 1060}, {1e-9, 1.0, 1e-9}}}) {
    EXPECT_EQ(begins(fixed_detail::balanced_bands(g, 4, unusable)), even);
  }
  // As many bands as row_bands gives: a 100-row view has one.
  const fixed_detail::Geometry& short_view = kernels.geometry(cv::Size(kWidth, 100));
  EXPECT_EQ(fixed_detail::balanced_bands(short_view, 4, fixed_detail::BandTimes{100, {0, 50}, {1.0, 3.0}}).size(), 1u);
}

TEST(FixedThreads, ShortViewsRunOnFewerThreadsAndCountsOutOfRangeAreRejected) {
  FixedStreamingDecoder decoder(with_threads(fixed_config(link_config(0.5)), 8));
  EXPECT_EQ(decoder.threads_for(cv::Size(64, 63)), 1);
  EXPECT_EQ(decoder.threads_for(cv::Size(64, 128)), 2);
  EXPECT_EQ(decoder.threads_for(cv::Size(64, 1200)), 8);
  for (int bad : {0, -1, kMaxDecoderThreads + 1}) {
    FixedDecoderConfig config = fixed_config(link_config(0.5));
    config.threads = bad;
    EXPECT_THROW(config.validate(), std::invalid_argument) << bad;
    EXPECT_THROW(FixedStreamingDecoder{config}, std::invalid_argument) << bad;
  }
}

// The range check of a view's codes runs on the decoder's threads (bands of rows) before any stage: a code beyond the
// link's range in any band, the last included, is rejected with the one-thread message, and the decoder's state is
// untouched (the views after it decode as on a decoder that never saw it).
TEST(FixedThreads, AnOutOfRangeCodeInAnyScanBandIsRejectedBeforeAnyWork) {
  const EncoderConfig link = link_config(0.5);
  const auto frames = encode_sequence(scene_images("panorama", kWidth, 200, 4), link);  // 3 scan bands at 3 threads
  FixedStreamingDecoder one(fixed_config(link));
  FixedStreamingDecoder three(with_threads(fixed_config(link), 3));
  for (const int row : {0, 100, 199}) {
    LinkFrame bad = frames[2];
    bad.codes = frames[2].codes.clone();
    bad.codes.at<cv::Vec3w>(row, kWidth - 1)[2] = 256;
    if (row == 0) {
      const DecodedFrame a = one.decode(frames[0]);
      const DecodedFrame b = three.decode(frames[0]);
      expect_identical_outputs(a, one.last_counts(), b, three.last_counts(), "view 0");
      const DecodedFrame c = one.decode(frames[1]);
      const DecodedFrame d = three.decode(frames[1]);
      expect_identical_outputs(c, one.last_counts(), d, three.last_counts(), "view 1");
    }
    const std::string expected = test::error_of([&] { one.decode(bad); });
    EXPECT_NE(expected.find("code 256 exceeds the 8-bit range"), std::string::npos) << expected;
    EXPECT_EQ(test::error_of([&] { three.decode(bad); }), expected) << "row " << row;
  }
  FixedStreamingDecoder never_saw_it(fixed_config(link));
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const DecodedFrame reference = never_saw_it.decode(frames[n]);
    if (n < 2) continue;
    const DecodedFrame b = three.decode(frames[n]);
    expect_identical_outputs(reference, never_saw_it.last_counts(), b, three.last_counts(),
                             "view " + std::to_string(n) + " after the rejections");
  }
}

// Without the report planes: the same drive codes, statistics and counters, the planes empty, for OLED and LCD,
// both schedules, and the held output of a lost view is the codes alone.
TEST(FixedThreads, DriveCodesWithoutReportPlanesAreTheSameBits) {
  for (const std::string panel : {"vive", "lcd"}) {
    const EncoderConfig link = link_config(0.5);
    const auto frames = encode_sequence(scene_images("panorama", kWidth, 96, 4), link);
    FixedDecoderConfig planes = fixed_config(link, panel);
    FixedDecoderConfig codes_only = planes;
    codes_only.decoder.report_planes = false;
    FixedStreamingDecoder with(planes);
    FixedStreamingDecoder without(codes_only);
    FixedFrameDecoder frame_without(codes_only);
    for (const LinkFrame& f : frames) {
      const std::string where = panel + " t=" + std::to_string(f.meta.index);
      const DecodedFrame a = with.decode(f);
      const DecodedFrame b = without.decode(f);
      const DecodedFrame c = frame_without.decode(f);
      ASSERT_FALSE(a.wanted_linear.empty()) << where;
      for (const DecodedFrame* d : {&b, &c}) {
        EXPECT_TRUE(d->wanted_linear.empty() && d->drive.empty() && d->emitted_linear.empty()) << where;
        ASSERT_TRUE(identical(a.drive_codes, d->drive_codes)) << where;
        EXPECT_EQ(a.stats.clipped_fraction, d->stats.clipped_fraction) << where;
        EXPECT_EQ(a.stats.residual_mean_abs, d->stats.residual_mean_abs) << where;
        EXPECT_EQ(a.stats.mean_motion_weight, d->stats.mean_motion_weight) << where;
        EXPECT_EQ(a.stats.lcd_unreachable_fraction, d->stats.lcd_unreachable_fraction) << where;
      }
      EXPECT_EQ(with.last_counts().lcd_unreachable, without.last_counts().lcd_unreachable) << where;
      EXPECT_EQ(with.last_counts().beta_clipped, without.last_counts().beta_clipped) << where;
    }
    const DecodedFrame held = without.decode_lost(frames.back().meta);
    EXPECT_TRUE(held.wanted_linear.empty()) << panel;
    EXPECT_TRUE(identical(held.drive_codes, with.decode_lost(frames.back().meta).drive_codes)) << panel;
    FixedStreamingDecoder fresh(codes_only);
    const DecodedFrame black = fresh.decode_lost(frames.front().meta);
    EXPECT_TRUE(black.wanted_linear.empty() && black.drive.empty() && black.emitted_linear.empty()) << panel;
    EXPECT_EQ(cv::countNonZero(black.drive_codes.reshape(1)), 0) << panel;
  }
}

}  // namespace
}  // namespace trm
