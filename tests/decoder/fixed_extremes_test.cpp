// The fixed-point decoders on the DESIGN §7 stiff and extreme cases that apply to the decoder: flat and Nyquist
// content, maximal over- and undershoot (also through narrow residual stores), r = 1 and tiny r, degenerate and odd
// sizes, long runs, LCD targets without a root and degenerate merges, s -> 0 and s -> inf, and input that must be
// rejected. On every case the two schedules agree bit for bit and the streaming decoder agrees with the double
// reference (DESIGN §6: >= 99.9 % identical codes, the rest within 1 LSB).
#include "trm/fixed_decoder.hpp"

#include "fixed_decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::error_of;
using test::fixed_config;
using test::link_config;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------------------------
// Running a case: both schedules and the reference in lock step.

struct CaseRun {
  test::Agreement agreement;  // streaming decoder's drive codes against the reference's
  double max_residual = 0.0;  // largest max |rho| of any frame (fixed, as stored)
  FixedStageCounts totals;    // the fixed decoder's stage counters summed over the frames
  int frames = 0;
};

// Per-frame check: the link frame, the fixed output and counters, the reference output (empty past the frames the
// reference is run on).
using FrameCheck =
    std::function<void(const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&, const DecodedFrame*)>;

// Decodes the frames with FixedFrameDecoder and FixedStreamingDecoder (bit-identical, every frame) and, for the
// first `reference_frames` frames, with the reference (LCD: from the fixed decoder's panel state).
CaseRun run_case(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config, const std::string& what,
                 const FrameCheck& check = {}, std::size_t reference_frames = std::numeric_limits<std::size_t>::max()) {
  FixedFrameDecoder frame_decoder(config);
  FixedStreamingDecoder streaming_decoder(config);
  ReferenceDecoder reference(config.decoder);
  const bool lcd = config.decoder.panel.has_history();
  CaseRun run;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const LinkFrame& frame = frames[n];
    const std::string where =
        what + " t=" + std::to_string(frame.meta.index) + " eye=" + std::to_string(frame.meta.eye);
    const DecodedFrame a = frame_decoder.decode(frame);
    const DecodedFrame b = streaming_decoder.decode(frame);
    const FixedStageCounts& counts = streaming_decoder.last_counts();
    test::expect_identical_outputs(a, frame_decoder.last_counts(), b, counts, where);
    if (::testing::Test::HasFatalFailure()) return run;
    run.totals += counts;
    run.max_residual = std::max(run.max_residual, b.stats.residual_max_abs);
    ++run.frames;
    if (n >= reference_frames) {
      if (check) check(frame, b, counts, nullptr);
      continue;
    }
    const DecodedFrame expected = reference.decode(frame);
    run.agreement.add_codes(expected.drive_codes, b.drive_codes);
    // LCD: the reference continues from the panel state the fixed decoder left (see adopt_panel_history).
    if (lcd) reference.adopt_panel_history(b);
    if (check) check(frame, b, counts, &expected);
  }
  return run;
}

// The DESIGN §6 criterion on a run (printed either way).
void expect_agrees(const CaseRun& run, const std::string& what) {
  test::expect_agreement(run.agreement, what);
}

CaseRun expect_case(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config, const std::string& what,
                    const FrameCheck& check = {}) {
  CaseRun run = run_case(frames, config, what, check);
  expect_agrees(run, what);
  return run;
}

std::string r_name(double r) { return "r=" + std::to_string(r).substr(0, 4); }

std::string size_name(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// ---------------------------------------------------------------------------------------------------------------
// Content.

cv::Mat grey(int width, int height, double v) { return test::flat_image(width, height, cv::Vec3d(v, v, v)); }

// One-pixel line, white on black (or black on white), horizontal at row `at` or vertical at column `at`.
cv::Mat line_image(int width, int height, int at, bool vertical, bool white_on_black) {
  cv::Mat image = grey(width, height, white_on_black ? 0.0 : 1.0);
  const cv::Rect line = vertical ? cv::Rect(at, 0, 1, height) : cv::Rect(0, at, width, 1);
  image(line & cv::Rect(0, 0, width, height)).setTo(cv::Scalar::all(white_on_black ? 1.0 : 0.0));
  return image;
}

// Maximal-contrast edge: white left of column x0 (vertical) or above row x0 (horizontal), black beyond.
cv::Mat edge_image(int width, int height, int x0, bool vertical) {
  cv::Mat image = grey(width, height, 0.0);
  const cv::Rect white = vertical ? cv::Rect(0, 0, x0, height) : cv::Rect(0, 0, width, x0);
  image(white & cv::Rect(0, 0, width, height)).setTo(cv::Scalar::all(1.0));
  return image;
}

std::vector<cv::Mat> repeated(const cv::Mat& image, int count) { return std::vector<cv::Mat>(count, image); }

std::vector<cv::Mat> generated(int count, const std::function<cv::Mat(int)>& frame) {
  std::vector<cv::Mat> images;
  for (int t = 0; t < count; ++t) images.push_back(frame(t));
  return images;
}

// ---------------------------------------------------------------------------------------------------------------
// Flat frames.

TEST(FixedExtremes, FlatFramesAreExactAndAgree) {
  struct Level {
    std::string name;
    double linear;
  };
  const std::vector<Level> levels = {{"black", 0.0}, {"white", 1.0}, {"grey 0.5 linear", 0.5},
                                     {"grey code 128", to_linear(128.0 / 255.0, Transfer::Srgb)}};
  for (const cv::Size size : {cv::Size(16, 12), cv::Size(15, 9)}) {
    for (double r : {1.0, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r);
      for (const Level& level : levels) {
        const std::string what = level.name + " " + size_name(size) + " " + r_name(r);
        const std::vector<LinkFrame> frames =
            encode_sequence(repeated(grey(size.width, size.height, level.linear), 4), link);
        const CaseRun run = expect_case(frames, fixed_config(link), what,
                                        [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&,
                                            const DecodedFrame* reference) {
                                          // Flat in, flat out: no clipping, no residual, one code per channel.
                                          for (int ch = 0; ch < 3; ++ch) {
                                            double lo = 0.0;
                                            double hi = 0.0;
                                            cv::Mat channel;
                                            cv::extractChannel(fixed.drive_codes, channel, ch);
                                            cv::minMaxLoc(channel, &lo, &hi);
                                            EXPECT_EQ(lo, hi) << what;
                                          }
                                          EXPECT_EQ(fixed.stats.residual_max_abs, 0.0) << what;
                                          if (fixed.stats.residual_applied) {
                                            EXPECT_EQ(fixed.stats.mean_motion_weight, 1.0) << what;
                                          }
                                          ASSERT_NE(reference, nullptr);
                                          EXPECT_EQ(reference->stats.residual_max_abs, 0.0) << what;
                                        });
        EXPECT_EQ(run.totals.beta_clipped + run.totals.alpha_clipped + run.totals.residual_saturated +
                      run.totals.residual_rounded,
                  0u)
            << what;
      }
    }
  }
}

TEST(FixedExtremes, BlackAndWhiteDriveTheEndCodes) {
  for (int bits : {8, 10}) {
    const EncoderConfig link = link_config(0.5, 0, false, bits);
    const FixedDecoderConfig config = fixed_config(link, "vive", bits);
    const std::uint16_t top = static_cast<std::uint16_t>((1 << bits) - 1);
    for (const bool white : {false, true}) {
      const std::string what = std::string(white ? "white " : "black ") + std::to_string(bits) + "-bit link+drive";
      expect_case(encode_sequence(repeated(grey(9, 7, white ? 1.0 : 0.0), 2), link), config, what,
                  [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&, const DecodedFrame*) {
                    double lo = 0.0;
                    double hi = 0.0;
                    cv::minMaxLoc(fixed.drive_codes.reshape(1), &lo, &hi);
                    EXPECT_EQ(lo, white ? top : 0) << what;
                    EXPECT_EQ(hi, white ? top : 0) << what;
                  });
    }
  }
}

TEST(FixedExtremes, FlashesBetweenBlackWhiteAndGrey) {
  // Every transition between the extremes, hitting full and reduced frames (both phases), stereo included.
  const std::vector<double> levels = {0.0, 1.0, 0.5, 1.0, 0.0, 0.0, 1.0, 1.0, 0.5, 0.0, 1.0, 0.0};
  for (double r : {1.0, 0.5, 0.25}) {
    for (int phase : {0, 1}) {
      const EncoderConfig link = link_config(r, phase, phase == 1);
      const std::vector<LinkFrame> frames =
          encode_sequence(generated(static_cast<int>(levels.size()), [&](int t) { return grey(13, 9, levels[t]); }),
                          link);
      expect_case(frames, fixed_config(link), "flash " + r_name(r) + (phase ? " phase 1 stereo" : ""));
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Nyquist checkerboards.

TEST(FixedExtremes, NyquistCheckerboards) {
  struct Grid {
    double r;
    int reduced_cell;  // cell of the checkerboard at the reduced-grid period, ~1/r pixels
  };
  for (const Grid grid : {Grid{0.5, 2}, Grid{0.25, 4}, Grid{0.4, 3}}) {
    for (const cv::Size size : {cv::Size(24, 16), cv::Size(25, 17)}) {
      const EncoderConfig link = link_config(grid.r);
      for (int cell : {1, grid.reduced_cell}) {
        const std::string board = "checker cell " + std::to_string(cell) + " " + size_name(size) + " " + r_name(grid.r);
        for (int phase : {0, 1}) {
          // Static: the reduced frame sees c = 0, so w = 1 exactly (also where D lands on an exact half-code tie).
          const cv::Mat image = test::checkerboard(size.width, size.height, cell, phase);
          expect_case(encode_sequence(repeated(image, 4), link), fixed_config(link),
                      board + " phase " + std::to_string(phase),
                      [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts& counts,
                          const DecodedFrame* reference) {
                        if (!fixed.stats.residual_applied) return;
                        EXPECT_EQ(fixed.stats.mean_motion_weight, 1.0) << board;
                        EXPECT_EQ(reference->stats.mean_motion_weight, 1.0) << board;
                        EXPECT_EQ(counts.weight_underflow, 0u);
                      });
        }
        // Counter-phase: the board inverts every frame, the largest change there is.
        expect_case(encode_sequence(generated(6, [&](int t) {
                                      return test::checkerboard(size.width, size.height, cell, t % 2);
                                    }),
                                    link),
                    fixed_config(link), board + " counter-phase");
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// A single bright pixel on black: beta near 2 on the pixel, below 0 around it.

// The residual store's rounding (fx::Quant::Rnd: nearest, ties up) and saturation of one rho sample with F
// fraction bits: the value it must hold, and whether rho fell outside the range (saturated) or between two
// representable values (rounded).
struct StoredRho {
  std::int64_t value = 0;
  bool saturated = false;
  bool rounded = false;
};

StoredRho store_rho(std::int64_t rho, int linear_frac_bits, const fx::RuntimeFormat& store) {
  const int shift = linear_frac_bits - store.frac_bits;
  const std::int64_t nearest = shift == 0 ? rho : (rho + (std::int64_t{1} << (shift - 1))) >> shift;
  StoredRho out;
  out.value = std::clamp(nearest, store.min_raw(), store.max_raw());
  out.saturated = out.value != nearest;
  out.rounded = !out.saturated && nearest * (std::int64_t{1} << shift) != rho;
  return out;
}

struct FullFrameTaps {
  DecodedFrame frame;
  FixedStageTaps taps;
  FixedStageCounts counts;
};

// The first (full) frame through FixedFrameDecoder with the stage taps (the same bits as without them).
FullFrameTaps full_frame_taps(const LinkFrame& frame, const FixedDecoderConfig& config) {
  FixedFrameDecoder decoder(config);
  FullFrameTaps out;
  out.frame = decoder.decode(frame, out.taps);
  out.counts = decoder.last_counts();
  FixedStreamingDecoder streaming_decoder(config);
  test::expect_identical_outputs(out.frame, out.counts, streaming_decoder.decode(frame),
                                 streaming_decoder.last_counts(), "decode with taps");
  return out;
}

TEST(FixedExtremes, SingleBrightPixelOvershootAndUndershoot) {
  struct Spot {
    cv::Size size;
    cv::Point at;
  };
  for (const Spot spot : {Spot{{16, 16}, {8, 8}}, Spot{{16, 16}, {0, 0}}, Spot{{15, 13}, {14, 6}}}) {
    for (double r : {1.0, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r);
      const FixedDecoderConfig config = fixed_config(link);
      const std::string what = "bright pixel " + size_name(spot.size) + " at (" + std::to_string(spot.at.x) + "," +
                               std::to_string(spot.at.y) + ") " + r_name(r);
      const cv::Mat image = test::single_bright_pixel(spot.size.width, spot.size.height, spot.at.x, spot.at.y);
      const std::vector<LinkFrame> frames = encode_sequence(repeated(image, 4), link);

      const FullFrameTaps full = full_frame_taps(frames[0], config);
      const FixedStagePlane& beta = full.taps[Stage::Beta];
      const FixedStagePlane& shown = full.taps[Stage::Shown];
      const FixedStagePlane& rho = full.taps[Stage::Residual];
      const double one = std::ldexp(1.0, config.linear_frac_bits);
      const auto [lowest, highest] = std::minmax_element(beta.values.begin(), beta.values.end());
      EXPECT_GE(static_cast<double>(*highest) / one, 1.8) << what;  // maximal overshoot: beta = 2 - L
      EXPECT_LT(*lowest, 0) << what;                                 // undershoot around the pixel: beta = -L
      // The default store (sQ2.F) holds every rho (in [-1, 1]) exactly.
      std::uint64_t rounded = 0;
      for (std::size_t k = 0; k < rho.values.size(); ++k) {
        const StoredRho stored = store_rho(beta.values[k] - shown.values[k], config.linear_frac_bits, config.residual);
        ASSERT_FALSE(stored.saturated) << what << " sample " << k;
        ASSERT_EQ(rho.values[k], stored.value) << what << " sample " << k;
        rounded += stored.rounded ? 1 : 0;
      }
      EXPECT_EQ(full.counts.residual_saturated, 0u) << what;
      EXPECT_EQ(full.counts.residual_rounded, rounded) << what;
      EXPECT_EQ(rounded, 0u) << what;
      const CaseRun run = expect_case(frames, config, what,
                                      [&](const LinkFrame& frame, const DecodedFrame& fixed, const FixedStageCounts&,
                                          const DecodedFrame* reference) {
                                        if (frame.meta.parity != Parity::Full) return;
                                        EXPECT_NEAR(fixed.stats.residual_max_abs, reference->stats.residual_max_abs,
                                                    1e-6)
                                            << what;
                                      });
      EXPECT_GE(run.max_residual, 0.8) << what;
      EXPECT_LE(run.max_residual, 1.0) << what;
    }
  }
  // Moving one pixel per frame: the residual must be held back (w -> 0) where the pixel left.
  for (double r : {0.5, 0.25}) {
    const EncoderConfig link = link_config(r);
    expect_case(encode_sequence(generated(8, [](int t) { return test::single_bright_pixel(17, 11, 3 + t, 5); }), link),
                fixed_config(link), "moving bright pixel " + r_name(r));
  }
}

TEST(FixedExtremes, NarrowResidualStoresCountExactlyTheSamplesOutsideTheirRange) {
  // rho of a white pixel on black is 0.98 to 0.9995 (from r = 1 to r = 1/4): beyond sQ1.5 (max 0.96875) and mostly
  // beyond sQ1.7 (max 0.9921875); sQ2.6 holds it rounded, sQ1.23 exactly (unless within half an LSB of 1).
  for (const fx::RuntimeFormat store : {fx::RuntimeFormat{1, 5, true, fx::Quant::Rnd, fx::Overflow::Sat},
                                        fx::RuntimeFormat{1, 7, true, fx::Quant::Rnd, fx::Overflow::Sat},
                                        fx::RuntimeFormat{2, 6, true, fx::Quant::Rnd, fx::Overflow::Sat},
                                        fx::RuntimeFormat{1, 23, true, fx::Quant::Rnd, fx::Overflow::Sat}}) {
    for (double r : {1.0, 0.5, 0.25}) {
      const EncoderConfig link = link_config(r);
      FixedDecoderConfig config = fixed_config(link);
      config.residual = store;
      const std::string what = "bright pixels, store " + store.to_string() + " " + r_name(r);
      cv::Mat image = test::single_bright_pixel(16, 12, 7, 5);
      image.at<cv::Vec3d>(0, 0) = cv::Vec3d(1.0, 0.0, 1.0);
      image.at<cv::Vec3d>(11, 15) = cv::Vec3d(0.0, 1.0, 0.0);
      const std::vector<LinkFrame> frames = encode_sequence(repeated(image, 4), link);

      const FullFrameTaps full = full_frame_taps(frames[0], config);
      const FixedStagePlane& beta = full.taps[Stage::Beta];
      const FixedStagePlane& shown = full.taps[Stage::Shown];
      const FixedStagePlane& rho = full.taps[Stage::Residual];
      std::uint64_t saturated = 0;
      std::uint64_t rounded = 0;
      for (std::size_t k = 0; k < rho.values.size(); ++k) {
        const StoredRho expected = store_rho(beta.values[k] - shown.values[k], config.linear_frac_bits, store);
        ASSERT_EQ(rho.values[k], expected.value) << what << " sample " << k;
        saturated += expected.saturated ? 1 : 0;
        rounded += expected.rounded ? 1 : 0;
      }
      std::printf("[ residual store ] %-44s saturated %3llu  rounded %3llu of %zu\n", what.c_str(),
                  static_cast<unsigned long long>(saturated), static_cast<unsigned long long>(rounded),
                  rho.values.size());
      EXPECT_EQ(full.counts.residual_saturated, saturated) << what;
      EXPECT_EQ(full.counts.residual_rounded, rounded) << what;
      if (store.frac_bits == 5) {
        EXPECT_GE(saturated, 3u) << what;  // the white pixel's rho >= 0.99
      }
      if (store.int_bits == 2 || store.frac_bits == 23) {
        EXPECT_EQ(saturated, 0u) << what;
      }

      // Both schedules saturate alike; the full frames (not touched by the store) still agree with the reference.
      const CaseRun run = run_case(frames, config, what, {}, 1);
      EXPECT_EQ(run.totals.residual_saturated, 2 * saturated) << what;  // frames 0 and 2
      expect_agrees(run, what + " full frame");
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Lines and edges.

TEST(FixedExtremes, BrightAndDarkLines) {
  for (double r : {0.5, 0.4}) {
    const EncoderConfig link = link_config(r);
    for (const bool vertical : {false, true}) {
      for (const bool white_on_black : {true, false}) {
        const std::string what = std::string(white_on_black ? "white" : "black") +
                                 (vertical ? " vertical" : " horizontal") + " line " + r_name(r);
        const CaseRun run = expect_case(
            encode_sequence(repeated(line_image(24, 16, vertical ? 11 : 7, vertical, white_on_black), 4), link),
            fixed_config(link), what + " static");
        EXPECT_GT(run.totals.beta_clipped, 0u) << what;
        expect_case(encode_sequence(generated(8, [&](int t) {
                                      return line_image(24, 16, 3 + t, vertical, white_on_black);
                                    }),
                                    link),
                    fixed_config(link), what + " moving");
      }
    }
  }
}

TEST(FixedExtremes, MaxContrastMovingEdge) {
  for (double r : {0.5, 0.4}) {
    const EncoderConfig link = link_config(r);
    for (int speed : {1, 3}) {
      for (const bool vertical : {true, false}) {
        const std::string what = std::string(vertical ? "vertical" : "horizontal") + " edge " +
                                 std::to_string(speed) + " px/frame " + r_name(r);
        double least_weight = 1.0;
        expect_case(encode_sequence(generated(10, [&](int t) { return edge_image(32, 24, 4 + speed * t, vertical); }),
                                    link),
                    fixed_config(link), what,
                    [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&, const DecodedFrame*) {
                      if (!fixed.stats.residual_applied) return;
                      least_weight = std::min(least_weight, fixed.stats.mean_motion_weight);
                    });
        EXPECT_LT(least_weight, 1.0) << what;  // the motion test held some residual back
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// r = 1, tiny r, degenerate and odd sizes.

TEST(FixedExtremes, ReductionOneAndTinyReductions) {
  struct Case {
    double r;
    cv::Size full;
    cv::Size reduced;
  };
  // r = 1: the reduced frame has the full size and D is still the sigma = 1.25 blur. r = 0.05 on 64x48: 3x2
  // (3.2 and 2.4 round down); r = 0.01: 1x1 (0.64 rounds up, 0.48 is lifted to one pixel).
  for (const Case c : {Case{1.0, {16, 12}, {16, 12}}, Case{0.05, {64, 48}, {3, 2}}, Case{0.01, {64, 48}, {1, 1}}}) {
    const EncoderConfig link = link_config(c.r);
    const int w = c.full.width;
    const int h = c.full.height;
    const std::vector<std::pair<std::string, std::vector<cv::Mat>>> contents = {
        {"noise", test::noise_images(w, h, 4, 900)},
        {"bright pixel", repeated(test::single_bright_pixel(w, h, w / 2, h / 2), 4)},
        {"checkerboard", repeated(test::nyquist_checkerboard(w, h), 4)},
        {"moving edge", generated(6, [&](int t) { return edge_image(w, h, w / 4 + 5 * t, true); })},
    };
    for (const auto& [name, images] : contents) {
      const std::vector<LinkFrame> frames = encode_sequence(images, link);
      ASSERT_EQ(frames[1].codes.size(), c.reduced) << r_name(c.r);
      expect_case(frames, fixed_config(link), name + " " + size_name(c.full) + " " + r_name(c.r));
    }
  }
}

TEST(FixedExtremes, DegenerateAndOddSizes) {
  const std::vector<cv::Size> sizes = {{1, 1}, {1, 7}, {7, 1}, {2, 1}, {1, 2}, {3, 3}, {5, 3}, {13, 7}, {23, 13}};
  for (const cv::Size size : sizes) {
    CaseRun total;
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25, 0.05}) {
      // A 2-pixel axis reduced to 1 pixel averages exactly two codes: half-code ties (ExactHalfCodeTiesOfD).
      const EncoderConfig link = link_config(r, 0, true);  // stereo: both parities in every link frame
      const std::string what = size_name(size) + " " + r_name(r);
      const cv::Point spot(size.width / 2, size.height / 2);
      for (const std::vector<cv::Mat>& images :
           {test::noise_images(size.width, size.height, 4, 77),
            repeated(test::single_bright_pixel(size.width, size.height, spot.x, spot.y), 3),
            generated(4, [&](int t) { return test::checkerboard(size.width, size.height, 1, t % 2); })}) {
        const CaseRun run = run_case(encode_sequence(images, link), fixed_config(link), what);
        if (::testing::Test::HasFatalFailure()) return;
        total.agreement += run.agreement;
      }
    }
    expect_agrees(total, size_name(size) + " all r, stereo");
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Long runs: the residual stays bounded and the output keeps agreeing.

// A 3x3 white square bouncing around the view one pixel per frame in x and y.
cv::Mat bouncing_square(int width, int height, int t) {
  const auto bounce = [](int t, int span) {
    const int p = t % (2 * span);
    return p < span ? p : 2 * span - p;
  };
  cv::Mat image = grey(width, height, 0.02);
  image(cv::Rect(bounce(t, width - 3), bounce(t, height - 3), 3, 3)).setTo(cv::Scalar::all(1.0));
  return image;
}

// A white 4x4 square and a single bright pixel, on for 3 frames of every 7 (so both parities see both states),
// over a background alternating black and white every 5 frames: periodic with period 70.
constexpr int kFlashPeriod = 70;
cv::Mat flashing_square(int width, int height, int t) {
  cv::Mat image = grey(width, height, (t / 5) % 2 == 0 ? 0.0 : 1.0);
  if (t % 7 < 3) {
    image(cv::Rect(2, 2, 4, 4)).setTo(cv::Scalar::all(1.0));
    image.at<cv::Vec3d>(height - 3, width - 3) = (t / 5) % 2 == 0 ? cv::Vec3d(1, 1, 1) : cv::Vec3d(0, 0, 0);
  }
  return image;
}

// Over a long run: every frame's max |rho| within `bound`, the largest in each half, the saturated samples, and the
// drive codes of the last two periods (for periodic input).
struct LongRun {
  LongRun(int frame_count, double residual_bound) : frames(frame_count), bound(residual_bound) {}
  int frames;
  double bound;
  double max_residual_first_half = 0.0;
  double max_residual_second_half = 0.0;
  std::uint64_t saturated = 0;
  std::vector<cv::Mat> last_codes;

  FrameCheck check(const std::string& what) {
    return [this, what](const LinkFrame& frame, const DecodedFrame& fixed, const FixedStageCounts& counts,
                        const DecodedFrame*) {
      ASSERT_LE(fixed.stats.residual_max_abs, bound) << what << " t=" << frame.meta.index;
      double& half = frame.meta.index < frames / 2 ? max_residual_first_half : max_residual_second_half;
      half = std::max(half, fixed.stats.residual_max_abs);
      saturated += counts.residual_saturated;
      if (frame.meta.index >= frames - 2 * kFlashPeriod) last_codes.push_back(fixed.drive_codes);
    };
  }
  // The output repeats with the input's period, bit for bit.
  void expect_periodic(const std::string& what) const {
    ASSERT_EQ(last_codes.size(), static_cast<std::size_t>(2 * kFlashPeriod)) << what;
    for (std::size_t t = 0; t < kFlashPeriod; ++t) {
      ASSERT_TRUE(test::identical(last_codes[t], last_codes[t + kFlashPeriod])) << what << " period offset " << t;
    }
  }
};

TEST(FixedExtremes, LongRunsKeepTheResidualBounded) {
  constexpr int kFrames = 2000;
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> flashing =
      encode_sequence(generated(kFrames, [](int t) { return flashing_square(16, 12, t); }), link);
  const std::vector<LinkFrame> moving =
      encode_sequence(generated(kFrames, [](int t) { return bouncing_square(16, 12, t); }), link);
  const std::string frames = " " + std::to_string(kFrames) + " frames";

  // OLED: |rho| <= 1 by construction (beta = 2 I - L is in [-1, 2]), and the default store never saturates.
  for (const auto& [name, sequence] :
       {std::pair{"flashing square", &flashing}, std::pair{"bouncing square", &moving}}) {
    const std::string what = name + frames;
    LongRun run(kFrames, 1.0);
    expect_agrees(run_case(*sequence, fixed_config(link), what, run.check(what)), what);
    EXPECT_EQ(run.saturated, 0u) << what;
    std::printf("[ long run ] %-40s max |rho| first half %.6f, second half %.6f\n", what.c_str(),
                run.max_residual_first_half, run.max_residual_second_half);
    if (sequence == &flashing) run.expect_periodic(what);
  }

  // LCD, the flashing square: unreachable targets at both ends in most frames, so rho also carries shortfalls
  // (|rho| <= 2); the panel history is the one state that lives through the whole run, and it must not drift: the
  // output is periodic like the input. The reference (a 2^16-entry emission table per frame) joins for 100 frames.
  const std::string what = "flashing square lcd" + frames;
  LongRun run(kFrames, 2.0);
  const CaseRun lcd = run_case(flashing, fixed_config(link, "lcd"), what, run.check(what), 100);
  expect_agrees(lcd, what + " (first 100)");
  std::printf("[ long run ] %-40s max |rho| first half %.6f, second half %.6f, %llu unreachable samples\n",
              what.c_str(), run.max_residual_first_half, run.max_residual_second_half,
              static_cast<unsigned long long>(lcd.totals.lcd_unreachable));
  EXPECT_GT(lcd.totals.lcd_unreachable, 0u);
  run.expect_periodic(what);
}

// ---------------------------------------------------------------------------------------------------------------
// LCD: targets with no root, degenerate and custom merges, the shortfall reaching rho.

TEST(FixedExtremes, LcdUnreachableTargetsAtBothEnds) {
  // Black -> white (above the brightest merge from v_prev = 0: M(1, 0) = 0.4) and white -> black (below the darkest
  // from v_prev = 1: M(0, 1) = 0.4), on full frames (phase 0) and reduced frames (phase 1); 10-bit drive once (the
  // reference tabulates 2^20 merges per 10-bit LCD frame).
  const std::vector<double> levels = {0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.6, 0.6};
  for (int bits : {8, 10}) {
    for (int phase : {0, 1}) {
      if (bits == 10 && phase == 1) continue;
      const EncoderConfig link = link_config(0.5, phase);
      const FixedDecoderConfig config = fixed_config(link, "lcd", bits);
      const std::string what = "lcd black/white " + std::to_string(bits) + "b phase " + std::to_string(phase);
      const std::vector<LinkFrame> frames =
          encode_sequence(generated(bits == 8 ? 12 : 8, [&](int t) { return grey(12, 10, levels[t]); }), link);
      bool above = false;
      bool below = false;
      const CaseRun run = expect_case(
          frames, config, what,
          [&](const LinkFrame& frame, const DecodedFrame& fixed, const FixedStageCounts& counts,
              const DecodedFrame* reference) {
            if (counts.lcd_unreachable == 0) return;
            // Flat frames: every sample clamps to the same end.
            (fixed.drive_codes.at<cv::Vec3w>(0, 0)[1] == 0 ? below : above) = true;
            const std::int64_t t = frame.meta.index;
            EXPECT_EQ(fixed.stats.lcd_unreachable_fraction, reference->stats.lcd_unreachable_fraction) << what;
            if (frame.meta.parity == Parity::Full) {
              // The shortfall joins rho (beta itself is in [0, 1] for flat content).
              EXPECT_GT(fixed.stats.residual_max_abs, 0.0) << what << " t=" << t;
              EXPECT_NEAR(fixed.stats.residual_max_abs, reference->stats.residual_max_abs, 1e-6) << what;
              EXPECT_NEAR(fixed.stats.residual_mean_abs, reference->stats.residual_mean_abs, 1e-6) << what;
            }
          });
      EXPECT_TRUE(above) << what;
      EXPECT_TRUE(below) << what;
      EXPECT_GT(run.totals.lcd_unreachable, 0u) << what;
    }
  }
}

TEST(FixedExtremes, LcdShortfallReachesTheNextReducedFrame) {
  // Black, then a flat 0.6: the full frame cannot be reached, its shortfall goes into rho, and the static reduced
  // frame after it carries it (alpha' = alpha + rho > alpha).
  for (const LcdHistory history : {LcdHistory::Wanted, LcdHistory::Contributed}) {
    const EncoderConfig link = link_config(0.5);
    FixedDecoderConfig config = fixed_config(link, "lcd");
    config.decoder.lcd_history = history;
    const std::string what = std::string("lcd shortfall ") + (history == LcdHistory::Wanted ? "wanted" : "contributed");
    const std::vector<LinkFrame> frames =
        encode_sequence({grey(12, 10, 0.0), grey(12, 10, 0.0), grey(12, 10, 0.6), grey(12, 10, 0.6)}, link);
    std::vector<DecodedFrame> fixed_frames;
    expect_case(frames, config, what,
                [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&, const DecodedFrame*) {
                  fixed_frames.push_back(fixed);
                });
    ASSERT_EQ(fixed_frames.size(), 4u);
    const DecodedFrame& full = fixed_frames[2];
    const DecodedFrame& reduced = fixed_frames[3];
    EXPECT_EQ(full.stats.lcd_unreachable_fraction, 1.0) << what;
    EXPECT_EQ(full.drive_codes.at<cv::Vec3w>(5, 5)[1], 255) << what;
    const LcdPanel& lcd = config.decoder.panel.lcd;
    const double x2 = full.wanted_linear.at<cv::Vec3d>(5, 5)[1];
    const double shortfall = x2 - 2.0 * std::pow(lcd.p1 + lcd.p3, lcd.gamma);
    EXPECT_NEAR(full.stats.residual_max_abs, shortfall, 1e-6) << what;
    EXPECT_TRUE(reduced.stats.residual_applied) << what;
    EXPECT_NEAR(reduced.wanted_linear.at<cv::Vec3d>(5, 5)[1], x2 + shortfall, 1e-6) << what;
  }
}

TEST(FixedExtremes, LcdDegenerateAndCustomMerges) {
  // p1 = 0: M = (v_t + v_prev) / 2, a linear solve. p1 = 1e-9: numerically linear in the reference, exactly linear
  // once quantised to sQ7.24 in the fixed decoder. p1 > 0: a convex merge. The custom merge has p4 > 0, so black is
  // never reachable (M(0, 0) = 0.02).
  const std::vector<std::string> panels = {"lcd:0,0,0.5,0,2.2", "lcd:1e-9,-2e-9,0.5,0,2.2", "lcd:0.1,-0.2,0.5,0,2.2",
                                           "lcd:-0.2,0.3,0.6,0.02,2.4", "lcd"};
  const EncoderConfig link = link_config(0.5);
  const std::vector<std::pair<std::string, std::vector<cv::Mat>>> contents = {
      {"noise", test::noise_images(16, 12, 6, 31)},
      {"flash", generated(6, [](int t) { return grey(16, 12, t % 2 == 0 ? 0.0 : 1.0); })},
      {"edge", generated(6, [](int t) { return edge_image(16, 12, 2 + 3 * t, true); })},
      {"black", repeated(grey(16, 12, 0.0), 4)},
  };
  for (const std::string& panel : panels) {
    for (const LcdHistory history : {LcdHistory::Wanted, LcdHistory::Contributed}) {
      // Contributed history for the custom and the default merge only.
      if (history == LcdHistory::Contributed && panel != "lcd" && panel != "lcd:-0.2,0.3,0.6,0.02,2.4") continue;
      FixedDecoderConfig config = fixed_config(link, panel);
      config.decoder.lcd_history = history;
      for (const auto& [name, images] : contents) {
        const std::string what =
            name + " " + panel + (history == LcdHistory::Wanted ? "" : " contributed");
        const CaseRun run = expect_case(encode_sequence(images, link), config, what);
        if (panel == "lcd:-0.2,0.3,0.6,0.02,2.4" && name == "black" && history == LcdHistory::Wanted) {
          EXPECT_EQ(run.totals.lcd_unreachable, static_cast<std::uint64_t>(4 * 3 * 16 * 12)) << what;
        }
      }
    }
  }
  // 10-bit drive, once (the reference tabulates 2^20 merges per 10-bit LCD frame).
  FixedDecoderConfig ten_bit = fixed_config(link, "lcd:-0.2,0.3,0.6,0.02,2.4", 10);
  ten_bit.decoder.lcd_history = LcdHistory::Contributed;
  expect_case(encode_sequence(test::noise_images(16, 12, 4, 37), link), ten_bit, "noise custom lcd 10b contributed");
}

TEST(FixedExtremes, LcdNoRootWithANearlyLinearMerge) {
  // p1 -> 0 with p2 = -2 p1, p3 = 1/2, p4 = 0: M(v, v_prev) = p1 (v - v_prev)^2 + (v + v_prev) / 2, the quadratic
  // degenerating to a linear solve. Black, then white on a full frame: the target ((1 + 0) / 2)^(1/gamma) = 0.730
  // lies above the brightest merge M(1, 0) = 1/2 + p1, so no drive in [0, 1] reaches it: every sample clamps to
  // code 255 and the full frame's shortfall 1 - 2 (1/2 + p1)^gamma goes into rho, which the static reduced frame
  // after it adds to its alpha = 1: clamped there, the whole shortfall is dropped and counted. Coefficients below half an LSB of the fixed decoder's sQ7.f (f = linear_frac_bits)
  // round to 0, so those merges give the very bits of p1 = 0.
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames =
      encode_sequence({grey(12, 10, 0.0), grey(12, 10, 0.0), grey(12, 10, 1.0), grey(12, 10, 1.0),
                       grey(12, 10, 1.0), grey(12, 10, 1.0)}, link);
  for (const LcdHistory history : {LcdHistory::Wanted, LcdHistory::Contributed}) {
    std::vector<cv::Mat> linear_codes;  // the p1 = 0 run's drive codes
    for (const double p1 : {0.0, 1e-9, -1e-9, 1e-12, -1e-15}) {
      const std::string panel = "lcd:" + std::to_string(p1) + "," + std::to_string(-2.0 * p1) + ",0.5,0,2.2";
      FixedDecoderConfig config = fixed_config(link, "lcd:0,0,0.5,0,2.2");
      config.decoder.panel.lcd.p1 = p1;  // exactly, not through the text's six decimals
      config.decoder.panel.lcd.p2 = -2.0 * p1;
      config.decoder.lcd_history = history;
      const std::string what = "p1 = " + testing::PrintToString(p1) + (history == LcdHistory::Wanted ? " wanted" : " contributed");
      std::vector<DecodedFrame> shown;
      const CaseRun run = expect_case(frames, config, what,
                                      [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts&,
                                          const DecodedFrame*) { shown.push_back(fixed); });
      ASSERT_EQ(shown.size(), frames.size()) << what;
      const DecodedFrame& full = shown[2];
      const DecodedFrame& reduced = shown[3];
      EXPECT_EQ(full.stats.lcd_unreachable_fraction, 1.0) << what;
      EXPECT_EQ(full.drive_codes.at<cv::Vec3w>(4, 6)[0], 255) << what;
      const double shortfall = 1.0 - 2.0 * std::pow(0.5 + p1, 2.2);
      EXPECT_NEAR(full.stats.residual_max_abs, shortfall, 1e-6) << what;
      EXPECT_TRUE(reduced.stats.residual_applied) << what;
      EXPECT_EQ(reduced.wanted_linear.at<cv::Vec3d>(4, 6)[0], 1.0) << what;
      EXPECT_NEAR(reduced.stats.dropped_sum, 12 * 10 * 3 * shortfall, 1e-3) << what;
      EXPECT_GT(run.totals.lcd_unreachable, 0u) << what;
      if (p1 == 0.0) {
        for (const DecodedFrame& d : shown) linear_codes.push_back(d.drive_codes);
      } else if (2.0 * std::abs(p1) < std::ldexp(1.0, -(config.linear_frac_bits + 1))) {
        for (std::size_t t = 0; t < shown.size(); ++t) {
          EXPECT_TRUE(test::identical(shown[t].drive_codes, linear_codes[t])) << what << " t=" << t;
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Motion sensitivity s -> 0 and s -> inf.

TEST(FixedExtremes, MotionSensitivityExtremes) {
  const EncoderConfig link = link_config(0.5);
  const std::vector<std::pair<std::string, std::vector<cv::Mat>>> contents = {
      {"edge", generated(8, [](int t) { return edge_image(24, 16, 3 + 2 * t, true); })},
      {"bright pixel", generated(8, [](int t) { return test::single_bright_pixel(24, 16, 4 + t, 7); })},
      {"noise", test::noise_images(24, 16, 6, 51)},
      {"discs", test::scene_images("discs", 48, 32, 6)},
  };
  // The fixed decoder holds s in uQ8.16: 1e-9 rounds to 0 (w = 1 exactly), 255 is the largest finite s.
  for (double s : {0.0, 1e-9, 1e-3, 255.0, kInf}) {
    FixedDecoderConfig config = fixed_config(link);
    config.decoder.sensitivity = s;
    CaseRun all;
    double least_weight = 1.0;
    double most_weight_difference = 0.0;
    for (const auto& [name, images] : contents) {
      const std::string what = name + " s=" + std::to_string(s).substr(0, 8);
      const CaseRun run = expect_case(
          encode_sequence(images, link), config, what,
          [&](const LinkFrame&, const DecodedFrame& fixed, const FixedStageCounts& counts,
              const DecodedFrame* reference) {
            if (!fixed.stats.residual_applied) return;
            least_weight = std::min(least_weight, fixed.stats.mean_motion_weight);
            most_weight_difference = std::max(most_weight_difference, std::abs(fixed.stats.mean_motion_weight -
                                                                               reference->stats.mean_motion_weight));
            if (s < 1e-6) {
              EXPECT_EQ(fixed.stats.mean_motion_weight, 1.0) << what;
            }
            if (std::isinf(s)) {
              EXPECT_EQ(counts.weight_underflow, 0u) << what;  // w = 0 directly, no exp
            }
          });
      all.totals.weight_underflow += run.totals.weight_underflow;
    }
    std::printf("[ sensitivity ] s=%-10g least mean w %.6f, mean w within %.2e of the reference, %llu underflows\n", s,
                least_weight, most_weight_difference, static_cast<unsigned long long>(all.totals.weight_underflow));
    EXPECT_LE(most_weight_difference, 1e-5) << s;
    if (s == 255.0) {
      EXPECT_GT(all.totals.weight_underflow, 0u);  // s c >= 16: w forced to 0
    }
    if (s < 1e-6 || std::isinf(s)) {
      EXPECT_EQ(all.totals.weight_underflow, 0u);
    }
    if (s >= 255.0) {
      EXPECT_LT(least_weight, 0.5) << s;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// NaN, Inf and out-of-range input: rejected with a std::invalid_argument that names the problem.

// Both schedules reject the configuration, naming `fragment`.
void expect_config_rejected(const FixedDecoderConfig& config, const std::string& fragment, const std::string& what) {
  const std::string frame_error = error_of([&] { FixedFrameDecoder decoder(config); });
  const std::string streaming_error = error_of([&] { FixedStreamingDecoder decoder(config); });
  EXPECT_NE(frame_error.find(fragment), std::string::npos) << what << ": '" << frame_error << "'";
  EXPECT_NE(streaming_error.find(fragment), std::string::npos) << what << ": '" << streaming_error << "'";
}

TEST(FixedExtremes, RejectsNanInfAndOutOfRangeConfiguration) {
  const FixedDecoderConfig good = fixed_config(link_config(0.5));
  FixedDecoderConfig c = good;

  for (double s : {kNaN, -kInf, -1.0, -1e-300}) {
    c = good;
    c.decoder.sensitivity = s;
    expect_config_rejected(c, "sensitivity", "s=" + std::to_string(s));
  }
  for (double s : {255.0 + 1e-9, 256.0, 1e300}) {  // finite s beyond uQ8: rejected by every decoder
    c = good;
    c.decoder.sensitivity = s;
    expect_config_rejected(c, "motion weight", "s=" + std::to_string(s));
    EXPECT_NE(error_of([&] { ReferenceDecoder reference(c.decoder); }).find("motion weight"), std::string::npos);
  }
  for (double gamma : {kNaN, kInf, -kInf, 0.0, -2.2}) {
    c = good;
    c.decoder.panel.oled.gamma[2] = gamma;
    expect_config_rejected(c, "OLED gamma", "OLED gamma " + std::to_string(gamma));
  }
  for (double duty : {kNaN, kInf, 0.0, 1.5}) {
    c = good;
    c.decoder.panel.oled.duty = duty;
    expect_config_rejected(c, "duty", "OLED duty " + std::to_string(duty));
  }
  const FixedDecoderConfig lcd = fixed_config(link_config(0.5), "lcd");
  for (int k = 0; k < 4; ++k) {
    for (double p : {kNaN, kInf, -kInf}) {
      c = lcd;
      double* coefficient[] = {&c.decoder.panel.lcd.p1, &c.decoder.panel.lcd.p2, &c.decoder.panel.lcd.p3,
                               &c.decoder.panel.lcd.p4};
      *coefficient[k] = p;
      const std::string name[] = {"p1", "p2", "p3", "p4"};
      expect_config_rejected(c, "LCD parameters", name[k] + " = " + std::to_string(p));
    }
  }
  for (double gamma : {kNaN, kInf, 0.0, -1.0}) {
    c = lcd;
    c.decoder.panel.lcd.gamma = gamma;
    expect_config_rejected(c, "LCD gamma", "LCD gamma " + std::to_string(gamma));
  }
  c = lcd;
  c.decoder.panel.lcd.p3 = 1e6;  // finite, but beyond sQ7
  expect_config_rejected(c, "within [-16, 16]", "p3 = 1e6");
  c = lcd;
  c.decoder.panel.lcd.p3 = -0.5;  // M decreasing in v_t: no threshold search
  expect_config_rejected(c, "increasing", "p3 = -0.5");

  for (double r : {kNaN, kInf, 0.0, -0.5, 1.0 + 1e-12, 2.0}) {
    c = good;
    c.decoder.link.reduction = r;
    expect_config_rejected(c, "reduction r", "r=" + std::to_string(r));
  }
  for (double sigma : {kNaN, kInf, -1.0}) {
    c = good;
    c.decoder.link.sigma = sigma;
    expect_config_rejected(c, "sigma", "sigma=" + std::to_string(sigma));
  }
  c = good;
  c.decoder.link.bits = 9;
  expect_config_rejected(c, "link bits", "link bits 9");
  c = good;
  c.decoder.output_bits = 9;
  expect_config_rejected(c, "output_bits", "output_bits 9");
}

// What a decoder says about one frame: the std::invalid_argument message (empty: accepted).
template <typename Decoder>
std::string frame_error(Decoder& decoder, const LinkFrame& frame) {
  return error_of([&] { decoder.decode(frame); });
}

TEST(FixedExtremes, RejectsMalformedFramesAndKeepsWorking) {
  const EncoderConfig link = link_config(0.5);
  const FixedDecoderConfig config = fixed_config(link);
  const std::vector<LinkFrame> good = encode_sequence(test::noise_images(11, 9, 4, 61), link);
  const LinkFrame& full = good[0];
  const LinkFrame& reduced = good[1];
  ASSERT_EQ(reduced.codes.size(), cv::Size(6, 5));

  struct Bad {
    std::string what;
    LinkFrame frame;
    std::string fragment;  // in the fixed decoders' message and the reference's
  };
  std::vector<Bad> bad;
  const auto with_code = [](const LinkFrame& f, int value) {
    LinkFrame out{f.meta, f.codes.clone()};
    out.codes.at<cv::Vec3w>(out.codes.rows - 1, out.codes.cols - 1)[2] = static_cast<std::uint16_t>(value);
    return out;
  };
  bad.push_back({"full code 256 on an 8-bit link", with_code(full, 256), "exceeds"});
  bad.push_back({"reduced code 65535", with_code(reduced, 65535), "exceeds"});
  {
    LinkFrame f{full.meta, cv::Mat(full.codes.size(), CV_16UC3, cv::Scalar::all(1023))};
    f.meta.bits = 10;
    bad.push_back({"10-bit frame on an 8-bit decoder", f, "link bits"});
  }
  {
    LinkFrame f = full;
    f.meta.transfer = Transfer::Gamma22;
    bad.push_back({"other transfer", f, "transfer"});
  }
  {
    LinkFrame f = full;
    f.meta.eye = -1;
    bad.push_back({"negative eye", f, "eye"});
  }
  for (const cv::Size size : {cv::Size(10, 9), cv::Size(11, 10)}) {
    LinkFrame f{full.meta, cv::Mat::zeros(size, CV_16UC3)};
    f.meta.width = size.width;
    f.meta.height = size.height;
    bad.push_back({"full frame of " + size_name(size), f, "must be 11x9"});
  }
  for (const cv::Size size : {cv::Size(5, 5), cv::Size(6, 4), cv::Size(11, 9), cv::Size(1, 1)}) {
    LinkFrame f{reduced.meta, cv::Mat::zeros(size, CV_16UC3)};
    f.meta.width = size.width;
    f.meta.height = size.height;
    bad.push_back({"reduced frame of " + size_name(size), f, "must be 6x5"});
  }
  for (const cv::Size full_size : {cv::Size(0, 9), cv::Size(11, -1)}) {
    LinkFrame f = full;
    f.meta.full_width = full_size.width;
    f.meta.full_height = full_size.height;
    bad.push_back({"full size " + size_name(full_size), f, "at least 1x1"});
  }
  for (const int type : {CV_16UC1, CV_16UC4, CV_16UC2, CV_8UC3, CV_16SC3, CV_32FC3, CV_64FC3}) {
    LinkFrame f = full;
    full.codes.convertTo(f.codes, CV_MAKETYPE(CV_MAT_DEPTH(type), 3));
    if (CV_MAT_CN(type) != 3) f.codes = cv::Mat::zeros(full.codes.size(), type);
    bad.push_back({"codes of type " + std::to_string(type), f, "CV_16UC3"});
  }
  bad.push_back({"empty codes", LinkFrame{full.meta, cv::Mat()}, "CV_16UC3"});

  FixedFrameDecoder frame_decoder(config);
  FixedStreamingDecoder streaming_decoder(config);
  ReferenceDecoder reference(config.decoder);
  // Interleaved with good frames: a rejected frame leaves the decoder's state as it was.
  for (const Bad& b : bad) {
    for (const LinkFrame& g : good) {
      const DecodedFrame a = frame_decoder.decode(g);
      const DecodedFrame s = streaming_decoder.decode(g);
      const DecodedFrame e = reference.decode(g);
      ASSERT_TRUE(test::identical(a.drive_codes, s.drive_codes)) << "after " << b.what;
      const std::string error_frame = frame_error(frame_decoder, b.frame);
      const std::string error_streaming = frame_error(streaming_decoder, b.frame);
      const std::string error_reference = frame_error(reference, b.frame);
      EXPECT_NE(error_frame.find(b.fragment), std::string::npos) << b.what << ": '" << error_frame << "'";
      EXPECT_NE(error_streaming.find(b.fragment), std::string::npos) << b.what << ": '" << error_streaming << "'";
      EXPECT_NE(error_reference.find(b.fragment), std::string::npos) << b.what << ": '" << error_reference << "'";
    }
  }
  // After every rejection the decoders give what fresh ones give.
  FixedStreamingDecoder fresh(config);
  for (const LinkFrame& g : good) {
    ASSERT_TRUE(test::identical(streaming_decoder.decode(g).drive_codes, fresh.decode(g).drive_codes));
  }
}

TEST(FixedExtremes, ViewSizeChangeStartsAfresh) {
  // A reduced frame that follows a full frame of another view size must not use that residual.
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> small = encode_sequence(repeated(test::single_bright_pixel(8, 6, 3, 3), 2), link);
  const std::vector<LinkFrame> large = encode_sequence(repeated(test::single_bright_pixel(16, 12, 7, 7), 2), link);
  const CaseRun run = expect_case({small[0], large[1], large[0], small[1]}, fixed_config(link), "size change",
                                  [](const LinkFrame& frame, const DecodedFrame& fixed, const FixedStageCounts&,
                                     const DecodedFrame* reference) {
                                    if (frame.meta.parity == Parity::Full) return;
                                    EXPECT_FALSE(fixed.stats.residual_applied);
                                    EXPECT_FALSE(reference->stats.residual_applied);
                                  });
  EXPECT_EQ(run.frames, 4);
}

// ---------------------------------------------------------------------------------------------------------------
// Cases that once showed decoder bugs, kept as regression tests.

// Exact half-code ties of D. Where D(E_t) is exactly k + 1/2 codes (a 2-pixel axis reduced to 1 averages two codes;
// content mirror-symmetric about a reduced sample centre: Nyquist checkerboards, an edge midway between two rows),
// the encoder's double D lands within its rounding error (~1e-13 codes) either side of the half. The reduced frame's
// quantiser (quantise_reduced, used by the encoder and through reduce_codes by the reference) counts a value within
// 1e-9 code of a half as the half and rounds it up; the fixed decoder computes the tie exactly and rounds it up too,
// so d_t, L_{t-1}, c and w rho agree. (Before, the encoder rounded such ties either way by float noise, and the
// fixed decoder, which could only guess, was up to 47 LSB off: 2x1 stereo, 1-pixel checkerboard inverting every
// frame, r = 0.05.)
TEST(FixedExtremes, ExactHalfCodeTiesOfD) {
  const auto counter_phase = [](cv::Size size, int cell) {
    return generated(6, [=](int t) { return test::checkerboard(size.width, size.height, cell, t % 2); });
  };
  struct Case {
    std::string what;
    std::vector<cv::Mat> images;
    EncoderConfig link;
  };
  const std::vector<Case> cases = {
      {"2x1 counter-phase r=0.05 stereo", counter_phase({2, 1}, 1), link_config(0.05, 0, true)},
      {"2x1 noise r=0.5 stereo", test::noise_images(2, 1, 4, 77), link_config(0.5, 0, true)},
      {"1x2 noise r=0.4 stereo", test::noise_images(1, 2, 4, 77), link_config(0.4, 0, true)},
      {"24x16 counter-phase cell 1 r=0.5", counter_phase({24, 16}, 1), link_config(0.5)},
      {"horizontal edge 1 px/frame r=0.4",
       generated(10, [](int t) { return edge_image(32, 24, 4 + t, false); }), link_config(0.4)},
      {"tiny sigma noise r=0.5", test::noise_images(12, 8, 4, 31),
       [] {
         EncoderConfig link = link_config(0.5);
         link.sigma = 0.01;  // D averages the two nearest codes: a tie wherever their sum is odd
         return link;
       }()},
  };
  for (const Case& c : cases) {
    const std::vector<LinkFrame> frames = encode_sequence(c.images, c.link);
    // Every case has exact ties, and the fixed decoder's d_t is the encoder's reduced frame code for code.
    int ties = 0;
    for (const LinkFrame& frame : frames) {
      if (frame.meta.parity != Parity::Full) continue;
      const cv::Size reduced(reduced_size(frame.codes.cols, c.link.reduction),
                             reduced_size(frame.codes.rows, c.link.reduction));
      const cv::Mat d = downsample(dequantise(frame.codes, c.link.bits), reduced.width, reduced.height,
                                   c.link.effective_sigma());
      const double top = (1 << c.link.bits) - 1;
      const cv::Mat values = d.reshape(1);
      for (int y = 0; y < values.rows; ++y) {
        for (int k = 0; k < values.cols; ++k) {
          const double v = values.at<double>(y, k) * top;
          ties += std::abs(v - std::floor(v) - 0.5) < 1e-9 ? 1 : 0;
        }
      }
      const FullFrameTaps taps = full_frame_taps(frame, fixed_config(c.link));
      const std::vector<std::int64_t>& fixed_d = taps.taps[Stage::Reduced].values;
      const cv::Mat expected = reduce_codes(frame.codes, c.link).reshape(1, 1);
      ASSERT_EQ(fixed_d.size(), expected.total()) << c.what;
      for (std::size_t i = 0; i < fixed_d.size(); ++i) {
        EXPECT_EQ(fixed_d[i], expected.at<std::uint16_t>(0, static_cast<int>(i))) << c.what << " sample " << i;
      }
    }
    EXPECT_GT(ties, 0) << c.what;
    expect_case(frames, fixed_config(c.link), c.what);
  }

  // The quantiser itself: exact halves and values within the tolerance of one round up, others to the nearest.
  for (int bits : {8, 10}) {
    const double top = (1 << bits) - 1;
    for (int k : {0, 1, 100, (1 << bits) - 2}) {
      const double half = (k + 0.5) / top;
      EXPECT_EQ(quantise_reduced(half, bits), k + 1) << bits << " bits, k=" << k;
      EXPECT_EQ(quantise_reduced(half - 1e-12 / top, bits), k + 1) << bits << " bits, k=" << k;
      EXPECT_EQ(quantise_reduced(half + 1e-12 / top, bits), k + 1) << bits << " bits, k=" << k;
      EXPECT_EQ(quantise_reduced(half - 1e-6 / top, bits), k) << bits << " bits, k=" << k;
    }
    EXPECT_EQ(quantise_reduced(1.0, bits), static_cast<int>(top));
    EXPECT_EQ(quantise_reduced(0.0, bits), 0);
  }
}

// A frame whose metadata claims a huge view (a wrong size, e.g. a corrupted header) is rejected before the geometry
// of that view is built (once: std::bad_alloc, or an abort under ASan, at 2^31 - 1), and a lost view claiming one
// allocates nothing either.
TEST(FixedExtremes, RejectsAHugeClaimedViewBeforeBuildingItsGeometry) {
  const EncoderConfig link = link_config(0.5);
  const LinkFrame reduced = encode_sequence(test::noise_images(4, 4, 2, 3), link)[1];
  LinkFrame huge = reduced;
  huge.meta.full_width = std::numeric_limits<int>::max();
  huge.meta.full_height = std::numeric_limits<int>::max();
  FixedStreamingDecoder decoder(fixed_config(link));
  EXPECT_NE(frame_error(decoder, huge).find("must be"), std::string::npos);
  FixedFrameDecoder frame_decoder(fixed_config(link));
  EXPECT_NE(frame_error(frame_decoder, huge).find("must be"), std::string::npos);
  ReferenceDecoder reference(fixed_config(link).decoder);
  EXPECT_NE(frame_error(reference, huge).find("must be"), std::string::npos);
  // Just beyond the largest side: rejected by name even where the codes would match.
  LinkFrame wide = reduced;
  wide.meta.full_width = kMaxViewSide + 1;
  wide.meta.full_height = 4;
  for (const std::string& error : {frame_error(decoder, wide), frame_error(frame_decoder, wide), frame_error(reference, wide)}) {
    EXPECT_NE(error.find("at most 65535x65535"), std::string::npos) << "'" << error << "'";
  }
  for (const std::string& error : {error_of([&] { decoder.decode_lost(huge.meta); }),
                                   error_of([&] { frame_decoder.decode_lost(huge.meta); }),
                                   error_of([&] { reference.decode_lost(huge.meta); })}) {
    EXPECT_NE(error.find("at most 65535x65535"), std::string::npos) << "'" << error << "'";
  }
  // The decoders still work afterwards.
  EXPECT_NO_THROW(decoder.decode(reduced));
  EXPECT_NO_THROW(frame_decoder.decode(reduced));
  // The encoder has the same bound.
  EXPECT_NE(error_of([&] { TrmEncoder(link).encode(cv::Mat(1, kMaxViewSide + 1, CV_64FC3, cv::Scalar::all(0.5)), 0); })
                .find("at most 65535"),
            std::string::npos);
}

// A frame whose metadata size disagrees with its codes is named as such by all three decoders (the fixed decoders
// once said "codes are 11x9 but must be 11x9").
TEST(FixedExtremes, MetadataSizeMismatchIsNamed) {
  const EncoderConfig link = link_config(0.5);
  LinkFrame frame = encode_sequence(test::noise_images(11, 9, 1, 61), link)[0];
  frame.meta.width = 10;
  FixedFrameDecoder frame_decoder(fixed_config(link));
  FixedStreamingDecoder streaming_decoder(fixed_config(link));
  ReferenceDecoder reference(fixed_config(link).decoder);
  for (const std::string& error :
       {frame_error(frame_decoder, frame), frame_error(streaming_decoder, frame), frame_error(reference, frame)}) {
    EXPECT_NE(error.find("metadata says 10x9"), std::string::npos) << "'" << error << "'";
  }
}

// The residual adjacency test compares the stored index with meta.index - 1 (once eye.residual_index + 1, which
// overflowed for a full frame at INT64_MAX); negative indices are rejected by all three decoders.
TEST(FixedExtremes, FrameIndexAtTheEndOfItsRange) {
  const EncoderConfig link = link_config(0.5);
  std::vector<LinkFrame> frames = encode_sequence(test::noise_images(6, 4, 2, 5), link);
  frames[0].meta.index = std::numeric_limits<std::int64_t>::max();
  frames[1].meta.index = 0;
  FixedStreamingDecoder streaming_decoder(fixed_config(link));
  FixedFrameDecoder frame_decoder(fixed_config(link));
  ReferenceDecoder reference(fixed_config(link).decoder);
  streaming_decoder.decode(frames[0]);
  frame_decoder.decode(frames[0]);
  reference.decode(frames[0]);
  EXPECT_FALSE(streaming_decoder.decode(frames[1]).stats.residual_applied);
  EXPECT_FALSE(frame_decoder.decode(frames[1]).stats.residual_applied);
  EXPECT_FALSE(reference.decode(frames[1]).stats.residual_applied);
  // INT64_MAX - 1 then INT64_MAX: adjacent, the residual applies.
  frames[0].meta.index = std::numeric_limits<std::int64_t>::max() - 1;
  frames[1].meta.index = std::numeric_limits<std::int64_t>::max();
  streaming_decoder.decode(frames[0]);
  frame_decoder.decode(frames[0]);
  reference.decode(frames[0]);
  EXPECT_TRUE(streaming_decoder.decode(frames[1]).stats.residual_applied);
  EXPECT_TRUE(frame_decoder.decode(frames[1]).stats.residual_applied);
  EXPECT_TRUE(reference.decode(frames[1]).stats.residual_applied);
  LinkFrame negative = frames[0];
  negative.meta.index = -1;
  for (const std::string& error : {frame_error(streaming_decoder, negative), frame_error(frame_decoder, negative),
                                   frame_error(reference, negative),
                                   error_of([&] { streaming_decoder.decode_lost(negative.meta); }),
                                   error_of([&] { reference.decode_lost(negative.meta); })}) {
    EXPECT_NE(error.find("frame index must be >= 0"), std::string::npos) << "'" << error << "'";
  }
}

// A known limit of the criterion, not of the arithmetic: 24x16 checkerboards with 1- and 3-pixel cells inverting
// every frame at r = 0.4. D has no ties there and d_t equals the encoder's code for code. On the reduced frames the
// residual is large (rho ~ -0.21) and the motion contrast small (c = 0.0035); the fixed path's error in w rho is
// ~1e-6 linear, and the red drive of one pixel position per period is 32.50038 codes in the reference, 4e-4 code
// from a rounding boundary. A periodic 24x16 pattern repeats that one knife-edge value 24 times: 24 of 6912 codes
// (0.35 %) differ, by 1 LSB. (A finer EOTF LUT, 16 segments per code, does not move it.) What holds is asserted:
// every code within 1 LSB, and the share identical at its measured value.
// Counter-phase checkerboards across reductions, cell sizes, sizes and contrasts. The motion test amplifies the
// error of L_{t-1} and alpha (FixedDecoderConfig::linear_frac_bits), and a periodic pattern repeats a pixel that
// lands near a drive rounding boundary in every period: at the former defaults 7 of these sequences fell below
// 99.9 % identical (24x16, cell 1, r = 0.4: 99.65 %, one position per period 4e-4 code from a boundary).
TEST(FixedExtremes, CounterPhaseBoardsAcrossReductions) {
  for (const char* panel : {"vive", "rift"}) {
    for (int output_bits : {8, 10}) {
      std::int64_t differing = 0;
      for (double r : {0.25, 0.4, 0.5, 0.6, 0.75}) {
        const EncoderConfig link = link_config(r);
        for (int cell : {1, 2, 3, 4, 5}) {
          for (const cv::Size size : {cv::Size(24, 16), cv::Size(31, 19), cv::Size(40, 30)}) {
            for (double low : {0.0, 0.1}) {  // black/white, and 0.1/0.9
              const std::string what = std::string(panel) + " " + std::to_string(output_bits) + "-bit counter-phase cell " +
                                       std::to_string(cell) + " " + size_name(size) + " " + r_name(r) +
                                       (low > 0.0 ? " reduced contrast" : "");
              const std::vector<LinkFrame> frames = encode_sequence(generated(6, [&](int t) {
                                                                      cv::Mat board = test::checkerboard(
                                                                          size.width, size.height, cell, t % 2);
                                                                      board.convertTo(board, -1, 1.0 - 2.0 * low, low);
                                                                      return board;
                                                                    }),
                                                                    link);
              const CaseRun run = expect_case(frames, fixed_config(link, panel, output_bits), what);
              differing += run.agreement.differing();
            }
          }
        }
      }
      std::printf("[ fixed vs reference ] %s %d-bit, 150 counter-phase boards: %lld differing codes\n", panel,
                  output_bits, static_cast<long long>(differing));
    }
  }
}

// Degenerate Gaussian sigma. sigma = 0.01 at r = 1/2: every absolute weight at the half-integer centres underflows
// to 0; gaussian_taps weighs each tap relative to the nearest one, so D is the two nearest taps averaged (once 0 / 0:
// NaN taps, undefined integer conversion in the fixed decoder, garbage output). It is a valid D: both decoders run it
// and agree. sigma = 1e10 (once an int overflow in gaussian_radius) is beyond kMaxSigma and rejected by name.
TEST(FixedExtremes, DegenerateGaussianSigma) {
  for (double sigma : {0.01, 1e-6}) {
    EncoderConfig link = link_config(0.5);
    link.sigma = sigma;
    const GaussianTaps taps = gaussian_taps(1, 12, 6, sigma);
    double sum = 0.0;
    for (double w : taps.weights) {
      EXPECT_TRUE(std::isfinite(w));
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-15) << "sigma=" << sigma;
    const std::vector<LinkFrame> frames = encode_sequence(test::noise_images(12, 8, 4, 31), link);
    expect_case(frames, fixed_config(link), "sigma=" + std::to_string(sigma));
  }
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames = encode_sequence(repeated(grey(6, 4, 0.2), 2), link);
  for (double sigma : {kMaxSigma * 1.01, 1e10}) {
    FixedDecoderConfig config = fixed_config(link);
    config.decoder.link.sigma = sigma;
    const std::string error = error_of([&] {
      FixedStreamingDecoder decoder(config);
      decoder.decode(frames[0]);
      decoder.decode(frames[1]);
    });
    EXPECT_NE(error.find("sigma"), std::string::npos) << "sigma=" << sigma << ": '" << error << "'";
    EXPECT_NE(error_of([&] { ReferenceDecoder reference(config.decoder); }).find("sigma"), std::string::npos);
  }
  // The default sigma 1.25 / r is bounded too: r below 1.25 / kMaxSigma needs a narrower sigma given explicitly.
  EncoderConfig tiny = link_config(0.001);
  EXPECT_NE(error_of([&] { tiny.validate(); }).find("sigma"), std::string::npos);
  tiny.sigma = 100.0;
  EXPECT_NO_THROW(tiny.validate());
}

}  // namespace
}  // namespace trm
