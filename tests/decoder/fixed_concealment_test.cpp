// Concealment in the fixed-point decoders: under link faults (lost lines anywhere, whole views lost) the streaming
// schedule stays bit-identical to the frame-at-a-time one, both follow the reference's concealment rules, and the
// agreement with the reference is the same as on fault-free streams (DESIGN §6).
#include "fixed_decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace trm {
namespace {

using test::Arrival;
using test::ArrivalPlan;
using test::encode_sequence;
using test::fixed_config;
using test::link_config;
using test::noise_images;
using test::scene_images;

std::vector<std::uint8_t> random_mask(int lines, double lost, cv::RNG& rng) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(lines));
  for (auto& m : mask) m = rng.uniform(0.0, 1.0) < lost ? 0 : 1;
  return mask;
}

// Every kind of arrival, in a cycle of nine views (odd, so that each kind meets both parities and, in stereo, both
// eyes). A lost view comes first, so the view after it has no stored d_{t-1}: a reduced one conceals from its own
// lines; a partially received full frame still stores d_t, so the reduced frame after it repeats d_t's rows.
Arrival faulty_arrival(std::size_t n, const LinkFrame& frame, std::uint64_t seed) {
  const int lines = frame.codes.rows;
  cv::RNG rng(seed * 7919 + n);
  Arrival a;
  a.kind = Arrival::Kind::Partial;
  a.mask.assign(static_cast<std::size_t>(lines), 1);
  switch (n % 9) {
    case 0: a.kind = Arrival::Kind::Lost; a.mask.clear(); break;      // nothing of the view arrived
    case 1: for (int y = 0; y < (2 * lines + 4) / 5; ++y) a.mask[static_cast<std::size_t>(y)] = 0; break;  // top
    case 2: a.mask = random_mask(lines, 0.3, rng); break;
    case 3: a.mask.front() = 0; break;                                  // first line
    case 4: a.mask.back() = 0; break;                                   // last line
    case 5: a.mask.assign(a.mask.size(), 0); break;                     // every line lost: a lost view
    case 6: a.kind = Arrival::Kind::Whole; a.mask.clear(); break;
    case 7: a.mask.assign(a.mask.size(), 0); a.mask.back() = 1; break;  // only the last line
    default: a.mask = random_mask(lines, 0.7, rng); a.mask.front() = 0; break;
  }
  return a;
}

ArrivalPlan faulty_link(std::uint64_t seed) {
  return [seed](std::size_t n, const LinkFrame& frame) { return faulty_arrival(n, frame, seed); };
}

std::string r_text(double r) { return std::to_string(r).substr(0, 4); }

TEST(FixedConcealment, StreamingMatchesFrameUnderFaults) {
  for (const char* panel : {"vive", "lcd"}) {
    for (double r : {1.0, 0.5, 0.4}) {
      for (bool stereo : {false, true}) {
        const EncoderConfig link = link_config(r, 0, stereo);
        const std::string what = std::string(panel) + " r=" + r_text(r) + (stereo ? " stereo" : " mono");
        // 18 views: two passes of the arrival cycle.
        const std::vector<cv::Mat> images = noise_images(48, 32, stereo ? 9 : 18, 40);
        test::expect_schedules_identical(encode_sequence(images, link), fixed_config(link, panel), what,
                                         faulty_link(1));
      }
    }
  }
}

// Without the motion statistics (the runs of kMotionRunPixels pixels, the composed table) under every kind of
// arrival: the codes of the decoder that weighs every pixel, view by view, on 150-pixel lines (runs of 64, 64 and 22),
// both panels, stereo, one and two threads.
TEST(FixedConcealment, WithoutMotionStatisticsTheCodesAreTheSameUnderFaults) {
  for (const char* panel : {"vive", "lcd"}) {
    for (const int threads : {1, 2}) {
      const EncoderConfig link = link_config(0.5, 0, true);
      const std::vector<LinkFrame> frames = encode_sequence(scene_images("discs", 150, 128, 9), link);
      FixedDecoderConfig measured_config = fixed_config(link, panel);
      measured_config.decoder.report_planes = false;
      measured_config.threads = threads;
      FixedDecoderConfig fast_config = measured_config;
      fast_config.motion_weight_statistics = false;
      FixedStreamingDecoder measured(measured_config);
      FixedStreamingDecoder fast(fast_config);
      const ArrivalPlan plan = faulty_link(4);
      for (std::size_t n = 0; n < frames.size(); ++n) {
        const Arrival arrival = plan(n, frames[n]);
        const DecodedFrame a = test::decode_as_arrived(measured, frames[n], arrival);
        const DecodedFrame b = test::decode_as_arrived(fast, frames[n], arrival);
        ASSERT_TRUE(test::identical(a.drive_codes, b.drive_codes))
            << panel << " threads=" << threads << " view " << n << " arrival " << static_cast<int>(arrival.kind);
        EXPECT_EQ(a.stats.residual_max_abs, b.stats.residual_max_abs) << panel << " view " << n;
      }
    }
  }
}

TEST(FixedConcealment, StreamingMatchesFrameUnderFaultsOnScenesAndOddSizes) {
  const EncoderConfig link = link_config(0.5);
  for (const char* scene : {"discs", "checker", "text"}) {
    test::expect_schedules_identical(encode_sequence(scene_images(scene, 48, 32, 18), link), fixed_config(link),
                                     std::string(scene) + " faulty", faulty_link(2));
  }
  for (const cv::Size size : {cv::Size(13, 7), cv::Size(1, 1), cv::Size(5, 1), cv::Size(1, 5)}) {
    for (double r : {1.0, 0.5, 0.4}) {
      const EncoderConfig odd = link_config(r, 1, true);
      test::expect_schedules_identical(encode_sequence(noise_images(size.width, size.height, 9, 50), odd),
                                       fixed_config(odd, "lcd"),
                                       std::to_string(size.width) + "x" + std::to_string(size.height) + " r=" +
                                           r_text(r),
                                       faulty_link(3));
    }
  }
}

TEST(FixedConcealment, FollowsTheReferenceRules) {
  // Lost full-frame lines show L_t and clear rho; lost reduced-frame lines repeat d_t; a view with no intact line,
  // or none at all, holds the previous output and drops the residual.
  const EncoderConfig link = link_config(0.5);
  const TrmEncoder encoder(link);
  const cv::Mat image = test::nyquist_checkerboard(20, 16);  // clips heavily: every line has a residual
  FixedStreamingDecoder streaming(fixed_config(link));
  const LinkFrame full = encoder.encode(image, 0);
  std::vector<std::uint8_t> mask(16, 1);
  mask[0] = mask[7] = mask[15] = 0;
  const DecodedFrame got = streaming.decode(test::damaged(full, mask), mask);
  EXPECT_EQ(got.stats.concealed_lines, 3);
  EXPECT_FALSE(got.stats.frame_lost);
  // Lost lines show the low-pass estimate L_t (the reference's, within the fixed-point formats).
  ReferenceDecoder reference(test::decoder_config(link));
  const DecodedFrame expected_full = reference.decode(test::damaged(full, mask), mask);
  ASSERT_TRUE(expected_full.stages);
  for (int y : {0, 7, 15}) {
    EXPECT_LE(test::max_abs_difference(got.wanted_linear.row(y), expected_full.stages->at(Stage::LowPass).row(y)), 1e-5) << y;
  }
  // Static content: the stored d_t equals the reduced frame, so repeating its rows conceals perfectly.
  const LinkFrame reduced = encoder.encode(image, 1);
  FixedStreamingDecoder clean(fixed_config(link));
  clean.decode(full);
  const DecodedFrame expected = clean.decode(reduced);
  FixedStreamingDecoder faulty(fixed_config(link));
  faulty.decode(full);
  std::vector<std::uint8_t> reduced_mask(static_cast<std::size_t>(reduced.codes.rows), 1);
  reduced_mask[0] = reduced_mask[3] = 0;
  const DecodedFrame concealed = faulty.decode(test::damaged(reduced, reduced_mask), reduced_mask);
  EXPECT_EQ(concealed.stats.concealed_lines, 2);
  EXPECT_EQ(cv::norm(concealed.drive_codes, expected.drive_codes, cv::NORM_INF), 0.0);
  // A view with no intact line is lost: the previous output is held and the next reduced frame adds no residual.
  const DecodedFrame lost = faulty.decode(encoder.encode(image, 2), std::vector<std::uint8_t>(16, 0));
  EXPECT_TRUE(lost.stats.frame_lost);
  EXPECT_EQ(lost.stats.concealed_lines, 16);
  EXPECT_EQ(cv::norm(lost.drive_codes, concealed.drive_codes, cv::NORM_INF), 0.0);
  EXPECT_FALSE(faulty.decode(encoder.encode(image, 3)).stats.residual_applied);
  // The first view of an eye lost: black.
  FixedFrameDecoder fresh(fixed_config(link));
  const DecodedFrame black = fresh.decode_lost(full.meta);
  EXPECT_TRUE(black.stats.frame_lost);
  EXPECT_EQ(cv::countNonZero(black.drive_codes.reshape(1)), 0);
  EXPECT_THROW(fresh.decode(full, std::vector<std::uint8_t>(5, 1)), std::invalid_argument);
}

// The held output (what a lost view shows) gives its plane to the next checked view of its eye where no caller keeps
// it: one output plane per eye in steady state. A plane a caller keeps is never written; a view rejected by its
// range check leaves the held output as it was; a lost view shows the last view's codes in either case.
TEST(FixedConcealment, TheHeldOutputGivesItsPlaneToTheNextViewAndSurvivesARejectedOne) {
  const EncoderConfig link = link_config(0.5);
  const TrmEncoder encoder(link);
  const std::vector<cv::Mat> images = test::scene_images("discs", 64, 48, 6);
  for (const bool streaming : {true, false}) {
    FixedDecoderConfig config = fixed_config(link);
    config.decoder.report_planes = false;
    std::unique_ptr<HeadsetDecoder> decoder;
    if (streaming) decoder = std::make_unique<FixedStreamingDecoder>(config);
    else decoder = std::make_unique<FixedFrameDecoder>(config);
    const std::string what = streaming ? "streaming" : "frame";
    const std::uint8_t* first_plane = decoder->decode(encoder.encode(images[0], 0)).drive_codes.data;
    const std::uint8_t* second_plane = decoder->decode(encoder.encode(images[1], 1)).drive_codes.data;
    EXPECT_EQ(second_plane, first_plane) << what << ": the released plane is the next view's";
    const DecodedFrame kept = decoder->decode(encoder.encode(images[2], 2));
    const cv::Mat kept_codes = kept.drive_codes.clone();
    const DecodedFrame next = decoder->decode(encoder.encode(images[3], 3));
    EXPECT_NE(next.drive_codes.data, kept.drive_codes.data) << what << ": a kept plane is not written";
    EXPECT_EQ(cv::norm(kept.drive_codes, kept_codes, cv::NORM_INF), 0.0) << what;
    // A view with a code past the link's depth is rejected before any work: the held output is view 3's.
    LinkFrame bad = encoder.encode(images[4], 4);
    bad.codes.at<std::uint16_t>(5, 7) = 4096;
    EXPECT_THROW(decoder->decode(bad), std::invalid_argument) << what;
    const DecodedFrame lost = decoder->decode_lost(encoder.encode(images[4], 4).meta);
    EXPECT_TRUE(lost.stats.frame_lost) << what;
    EXPECT_EQ(cv::norm(lost.drive_codes, next.drive_codes, cv::NORM_INF), 0.0) << what << ": the held output";
  }
}

TEST(FixedConcealment, AgreesWithReferenceUnderFaultsOled) {
  for (double r : {1.0, 0.5, 0.4}) {
    for (bool stereo : {false, true}) {
      const EncoderConfig link = link_config(r, 0, stereo);
      const std::string what = "faulty noise r=" + r_text(r) + (stereo ? " stereo" : "");
      const test::Agreement a = test::compare_with_reference(encode_sequence(noise_images(48, 32, stereo ? 9 : 18, 60), link),
                                                             fixed_config(link), faulty_link(4));
      EXPECT_GT(a.concealed_lines, 0);
      test::expect_agreement(a, what);
    }
  }
  for (const char* scene : {"discs", "text", "panorama", "checker"}) {
    const EncoderConfig link = link_config(0.5);
    test::expect_agreement(test::compare_with_reference(encode_sequence(scene_images(scene, 48, 32, 18), link),
                                                        fixed_config(link), faulty_link(5)),
                           std::string("faulty ") + scene);
  }
}

// Synchronised (same panel state every frame): codes within 1 LSB; free-running: the merge within a code.
void expect_lcd_both_ways(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                          const test::ArrivalPlan& plan, const std::string& what) {
  test::expect_agreement(test::compare_with_reference(frames, config, plan, test::LcdComparison::Synchronised),
                         what + " synchronised");
  test::expect_lcd_agreement(test::compare_with_reference(frames, config, plan), what + " free-running");
}

TEST(FixedConcealment, AgreesWithReferenceUnderFaultsLcd) {
  for (double r : {1.0, 0.5, 0.4}) {
    for (bool stereo : {false, true}) {
      const EncoderConfig link = link_config(r, 0, stereo);
      expect_lcd_both_ways(encode_sequence(noise_images(48, 32, stereo ? 9 : 18, 70), link),
                           fixed_config(link, "lcd"), faulty_link(6),
                           "faulty noise lcd r=" + r_text(r) + (stereo ? " stereo" : ""));
    }
  }
  const EncoderConfig link = link_config(0.5);
  expect_lcd_both_ways(encode_sequence(scene_images("discs", 48, 32, 18), link), fixed_config(link, "lcd"),
                       faulty_link(7), "faulty discs lcd");
}

}  // namespace
}  // namespace trm
