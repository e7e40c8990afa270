// The line kernels (FixedDecoderConfig::line_kernels, decoder/src/fixed_lines.hpp) against the per-sample stage
// functions they replace: the same drive codes, report planes, statistics and counters, on every instruction set
// Highway compiled them for that this CPU runs (the scalar target included), with line widths that leave vector
// tails.
#include "fixed_decoder_test_support.hpp"
#include "fixed_kernels.hpp"
#include "fixed_lines.hpp"
#include "fixed_tables.hpp"
#include "trm/fx_quantise.hpp"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::expect_identical_outputs;
using test::expect_skip_counts_equal;
using test::fixed_config;
using test::link_config;
using test::scene_images;

// Restores the CPU's own targets when a test ends.
struct TargetMock {
  explicit TargetMock(std::int64_t target) { hwy::SetSupportedTargetsForTest(target); }
  ~TargetMock() { hwy::SetSupportedTargetsForTest(0); }
  TargetMock(const TargetMock&) = delete;
  TargetMock& operator=(const TargetMock&) = delete;
};

FixedDecoderConfig with_kernels(FixedDecoderConfig config, bool kernels, bool planes) {
  config.line_kernels = kernels;
  config.decoder.report_planes = planes;
  return config;
}

// Both schedules with and without the line kernels, every view: identical outputs, statistics and counters. Every
// third view of a reduced parity loses a band of lines (concealment reads the per-sample path beside the kernels).
void expect_kernels_identical(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config, bool planes,
                              const std::string& what) {
  FixedStreamingDecoder per_sample(with_kernels(config, false, planes));
  FixedStreamingDecoder kernels(with_kernels(config, true, planes));
  FixedFrameDecoder frame_per_sample(with_kernels(config, false, planes));
  FixedFrameDecoder frame_kernels(with_kernels(config, true, planes));
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const LinkFrame& f = frames[i];
    const std::string where = what + (planes ? " planes" : " codes") + " t=" + std::to_string(f.meta.index) +
                              " eye=" + std::to_string(f.meta.eye);
    std::vector<std::uint8_t> intact(static_cast<std::size_t>(f.meta.height), 1);
    if (i % 3 == 2) std::fill(intact.begin() + f.meta.height / 3, intact.begin() + f.meta.height / 2, 0);
    const DecodedFrame a = per_sample.decode(f, intact);
    const DecodedFrame b = kernels.decode(f, intact);
    expect_identical_outputs(a, per_sample.last_counts(), b, kernels.last_counts(), where + " streaming");
    expect_skip_counts_equal(per_sample.last_counts(), kernels.last_counts(), where + " streaming");
    const DecodedFrame c = frame_per_sample.decode(f);
    const DecodedFrame d = frame_kernels.decode(f);
    expect_identical_outputs(c, frame_per_sample.last_counts(), d, frame_kernels.last_counts(), where + " frame");
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(FixedLines, KernelsGiveThePerSampleBitsOnEveryInstructionSet) {
  struct Case {
    std::string scene;
    double r;
    std::string panel;
    int output_bits;
    bool stereo;
    bool skip;
    int width;
  };
  // 67 pixels: 201 samples per line, a tail after every vector width; r = 0.4 gives non-dyadic U weights; the 8-bit
  // LCD takes its drive kernel. 66 and 68 pixels at r = 1/2 and 1/4 divide evenly, so D's horizontal half takes its
  // polyphase planes (33 and 17 columns: tails again; asserted below).
  const std::vector<Case> cases = {
      {"panorama", 0.5, "vive", 8, false, true, 67},  {"discs", 0.4, "rift", 10, false, true, 67},
      {"checker", 0.5, "vive", 8, true, false, 67},   {"text", 0.75, "vive", 8, false, true, 67},
      {"zoneplate", 0.25, "rift", 8, false, true, 67}, {"flash", 0.5, "vive", 10, false, true, 67},
      {"jitter", 0.5, "vive", 8, false, false, 67},  {"panorama", 0.5, "lcd", 8, false, true, 67},
      {"discs", 0.4, "lcd", 8, true, false, 67},     {"panorama", 0.5, "vive", 8, true, true, 66},
      {"zoneplate", 0.25, "lcd", 8, false, false, 68},
      // 203 pixels: 609 samples a line, two chunks of the kernels' lookup passes (256 samples) and a tail.
      {"panorama", 0.5, "vive", 8, false, true, 203}, {"discs", 0.4, "lcd", 8, false, true, 203},
  };
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  for (const std::int64_t target : targets) {
    const TargetMock mock(target);
    ASSERT_STREQ(fixed_detail::lines::target_name(), hwy::TargetName(target)) << "the dispatch follows the mock";
    for (const Case& c : cases) {
      const EncoderConfig link = link_config(c.r, 0, c.stereo);
      const auto frames = encode_sequence(scene_images(c.scene, c.width, 46, 6), link);
      FixedDecoderConfig config = fixed_config(link, c.panel, c.output_bits);
      config.skip_unneeded = c.skip;
      if (c.width % 2 == 0) {
        fixed_detail::FixedKernels kernels(config);
        ASSERT_NE(kernels.geometry(cv::Size(c.width, 46)).gauss_columns.decimation, 0u) << c.scene << " polyphase";
      }
      for (const bool planes : {true, false}) {
        expect_kernels_identical(frames, config, planes,
                                 std::string(hwy::TargetName(target)) + " " + c.scene + " r=" + std::to_string(c.r) +
                                     " " + c.panel + " " + std::to_string(c.output_bits) + "-bit");
        if (HasFatalFailure()) return;
      }
    }
  }
}

// Eq. 4 of every sample by the stage function (sample s weighted by pixel s / 3's w), and what it adds to a tally.
std::vector<std::int64_t> weighted_by_stage_function(const fixed_detail::FixedKernels& kernels,
                                                     const std::vector<std::int64_t>& alpha,
                                                     const std::vector<std::int64_t>& weight,
                                                     const std::vector<std::int32_t>& residual,
                                                     fixed_detail::MotionTally& tally) {
  std::vector<std::int64_t> shown(alpha.size());
  for (std::size_t s = 0; s < alpha.size(); ++s) {
    const fixed_detail::WeightedSample w = kernels.add_weighted_residual(alpha[s], weight[s / 3], residual[s]);
    shown[s] = w.alpha_prime;
    tally.clipped += w.clipped ? 1 : 0;
    tally.dropped_sum += w.dropped;
    const std::int64_t magnitude = residual[s] < 0 ? -std::int64_t{residual[s]} : residual[s];
    tally.residual_abs_sum += magnitude;
    tally.residual_abs_max = std::max(tally.residual_abs_max, magnitude);
  }
  return shown;
}

// The motion kernels (Eqs. 4-6 over a line) against the stage functions, operand by operand: random linear values in
// [0, 1], equal pairs (c = 0), black, the top value, sums of a few LSB (whose contrast shift leaves the lanes), values
// outside [0, 1] (the stage functions' pixels), on every instruction set, at three sensitivities (s = 255 underflows
// Eq. 6 wherever c > 1/16).
TEST(FixedLines, MotionKernelsGiveTheStageFunctionsBitsOperandByOperand) {
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  for (const double sensitivity : {10.0, 255.0, 0.01}) {
    FixedDecoderConfig config = fixed_config(link_config(0.5), "vive");
    config.decoder.sensitivity = sensitivity;
    const fixed_detail::FixedKernels kernels(config);
    const auto& plan = kernels.line_plans().motion;
    ASSERT_TRUE(plan.has_value()) << "s = " << sensitivity;
    const std::int64_t one = kernels.one();
    // Three chunks of the kernels' passes (256 pixels) and a tail after every vector width; pixels outside [0, 1] in
    // each chunk.
    constexpr std::size_t kPixels = 3 * 256 + 11;
    std::mt19937_64 random(7);
    std::uniform_int_distribution<std::int64_t> linear(0, one);
    std::uniform_int_distribution<std::int64_t> tiny(0, 12);
    std::uniform_int_distribution<std::int32_t> residual_value(-(1 << 29), (1 << 29) - 1);
    std::vector<std::int64_t> previous(3 * kPixels), alpha(3 * kPixels);
    std::vector<std::int32_t> residual(3 * kPixels);
    for (std::size_t s = 0; s < 3 * kPixels; ++s) {
      const std::size_t x = s / 3;
      switch (x % 11) {
        case 0: previous[s] = alpha[s] = linear(random); break;
        case 1: previous[s] = alpha[s] = 0; break;
        case 2: previous[s] = tiny(random); alpha[s] = tiny(random); break;
        case 3: previous[s] = one; alpha[s] = linear(random); break;
        case 4:
          // -1, and 2^32 (upper half 1, lower half 0: within [0, 1] by its lower half alone)
          previous[s] = x % 256 == 4 ? -1 : x % 256 == 26 ? std::int64_t{1} << 32 : linear(random);
          alpha[s] = x % 256 == 15 ? one + 1 : linear(random);
          break;
        default: previous[s] = linear(random); alpha[s] = linear(random); break;
      }
      residual[s] = x % 7 == 0 ? 0 : residual_value(random);
    }
    residual[3 * 300] = std::numeric_limits<std::int32_t>::min();  // |rho| = 2^31, past int32
    residual[3 * 600 + 1] = std::numeric_limits<std::int32_t>::max();
    std::vector<std::int64_t> expected_weight(kPixels), expected_shown(3 * kPixels);
    fixed_detail::MotionTally expected;
    for (std::size_t x = 0; x < kPixels; ++x) {
      bool underflow = false;
      expected_weight[x] = kernels.motion_weight(kernels.luma(&previous[3 * x]), kernels.luma(&alpha[3 * x]), underflow);
      expected.underflow += underflow ? 1 : 0;
      expected.weight_sum += expected_weight[x];
    }
    expected_shown = weighted_by_stage_function(kernels, alpha, expected_weight, residual, expected);
    EXPECT_GT(expected.clipped, 0u) << "the operands reach Eq. 4's clamp";
    if (sensitivity == 255.0) {
      EXPECT_GT(expected.underflow, 0u) << "the operands reach Eq. 6's underflow";
    }
    // alpha' into a 64-bit line and into a 32-bit one (what the OLED's drive search reads).
    const auto check = [&](auto shown_word, const std::string& where) {
      std::vector<std::int64_t> weight(kPixels);
      std::vector<decltype(shown_word)> shown(3 * kPixels);
      fixed_detail::MotionTally tally;
      fixed_detail::lines::motion_weights(previous.data(), alpha.data(), kPixels, *plan, kernels, weight.data(), tally);
      fixed_detail::lines::add_weighted_residuals(alpha.data(), weight.data(), residual.data(), 3 * kPixels, *plan,
                                                  kernels, shown.data(), tally);
      for (std::size_t x = 0; x < kPixels; ++x) ASSERT_EQ(weight[x], expected_weight[x]) << where << " pixel " << x;
      for (std::size_t s = 0; s < 3 * kPixels; ++s) ASSERT_EQ(shown[s], expected_shown[s]) << where << " sample " << s;
      EXPECT_EQ(tally.underflow, expected.underflow) << where;
      EXPECT_EQ(tally.weight_sum, expected.weight_sum) << where;
      EXPECT_EQ(tally.clipped, expected.clipped) << where;
      EXPECT_EQ(tally.dropped_sum, expected.dropped_sum) << where;
      EXPECT_EQ(tally.residual_abs_sum, expected.residual_abs_sum) << where;
      EXPECT_EQ(tally.residual_abs_max, expected.residual_abs_max) << where;
    };
    for (const std::int64_t target : targets) {
      const TargetMock mock(target);
      const std::string where = std::string(hwy::TargetName(target)) + " s=" + std::to_string(sensitivity);
      check(std::int64_t{0}, where + " 64-bit line");
      check(std::int32_t{0}, where + " 32-bit line");
      if (HasFatalFailure()) return;
    }
  }
}

// Eq. 4 over a line with operands its 32-bit lanes must not take (MotionPlan::narrow_weighted_sum): alpha and w
// outside [0, 1] (-1, one + 1, 2^32 and 2^32 + k, whose lower halves lie in [0, 1]) and residuals at and past the
// format's magnitude 2^(width - 1), beside random in-range ones, against the stage function sample by sample, both
// line widths, every instruction set.
TEST(FixedLines, WeightedResidualsTakeTheStageFunctionsOutsideTheirLanes) {
  const FixedDecoderConfig config = fixed_config(link_config(0.5), "vive");
  const fixed_detail::FixedKernels kernels(config);
  const auto& plan = kernels.line_plans().motion;
  ASSERT_TRUE(plan.has_value() && plan->narrow_weighted_sum);
  const std::int64_t one = kernels.one();
  const std::int64_t limit = std::int64_t{1} << (config.residual.width() - 1);
  const std::int64_t two_to_32 = std::int64_t{1} << 32;
  constexpr std::size_t kPixels = 61;  // tails after every vector width
  constexpr std::size_t kSamples = 3 * kPixels;
  std::mt19937_64 random(29);
  std::uniform_int_distribution<std::int64_t> linear(0, one);
  std::uniform_int_distribution<std::int64_t> in_format(-limit, limit - 1);
  std::vector<std::int64_t> alpha(kSamples), weight(kPixels);
  std::vector<std::int32_t> residual(kSamples);
  for (std::size_t s = 0; s < kSamples; ++s) {
    alpha[s] = linear(random);
    residual[s] = static_cast<std::int32_t>(in_format(random));
  }
  for (std::int64_t& w : weight) w = linear(random);
  for (const auto& [at, value] : {std::pair{5, two_to_32 + 5}, {20, -1}, {33, one + 1}, {50, two_to_32}, {140, one}}) {
    alpha[static_cast<std::size_t>(at)] = value;
  }
  for (const auto& [at, value] : {std::pair{8, std::int64_t{-1}}, {14, one + 1}, {22, two_to_32}, {30, two_to_32 + 1},
                                  {40, one}, {41, 0}}) {
    weight[static_cast<std::size_t>(at)] = value;
  }
  for (const auto& [at, value] : {std::pair{70, limit}, {90, limit + 1}, {100, -limit}, {110, -limit - 1},
                                  {120, std::int64_t{INT32_MIN}}, {121, std::int64_t{INT32_MAX}}}) {
    residual[static_cast<std::size_t>(at)] = static_cast<std::int32_t>(value);
  }
  fixed_detail::MotionTally expected_tally;
  const std::vector<std::int64_t> expected =
      weighted_by_stage_function(kernels, alpha, weight, residual, expected_tally);
  const auto check = [&](auto shown_word, const std::string& where) {
    std::vector<decltype(shown_word)> shown(kSamples);
    fixed_detail::MotionTally tally;
    fixed_detail::lines::add_weighted_residuals(alpha.data(), weight.data(), residual.data(), kSamples, *plan, kernels,
                                                shown.data(), tally);
    for (std::size_t s = 0; s < kSamples; ++s) ASSERT_EQ(shown[s], expected[s]) << where << " sample " << s;
    EXPECT_EQ(tally.clipped, expected_tally.clipped) << where;
    EXPECT_EQ(tally.dropped_sum, expected_tally.dropped_sum) << where;
    EXPECT_EQ(tally.residual_abs_sum, expected_tally.residual_abs_sum) << where;
    EXPECT_EQ(tally.residual_abs_max, expected_tally.residual_abs_max) << where;
  };
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    const TargetMock mock(target);
    check(std::int64_t{0}, std::string(hwy::TargetName(target)) + " 64-bit line");
    check(std::int32_t{0}, std::string(hwy::TargetName(target)) + " 32-bit line");
    if (HasFatalFailure()) return;
  }
}

// The residual store over a line against FixedKernels::store_residual sample by sample, at the default residual
// format and at a narrow one (sQ1.6) where rho both rounds and saturates; runs of zeros as long as a vector and
// isolated non-zero samples, on every instruction set.
TEST(FixedLines, ResidualStoreKernelGivesTheStageFunctionsBits) {
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  for (const bool narrow : {false, true}) {
    FixedDecoderConfig config = fixed_config(link_config(0.5), "vive");
    if (narrow) {
      config.residual = {1, 6, true, fx::Quant::Rnd, fx::Overflow::Sat};
    }
    const fixed_detail::FixedKernels kernels(config);
    const std::int64_t one = kernels.one();
    constexpr std::size_t kSamples = 3 * 203;
    std::mt19937_64 random(11);
    std::uniform_int_distribution<std::int64_t> rho_value(-one, one);
    std::vector<std::int64_t> rho(kSamples, 0);
    for (std::size_t s = 0; s < kSamples; ++s) {
      if ((s / 40) % 2 == 1 || s % 17 == 0) rho[s] = rho_value(random);  // zero runs between non-zero stretches
    }
    rho[100] = one;
    rho[101] = -one;
    rho[102] = 1;
    rho[103] = -1;
    std::vector<std::int32_t> expected(kSamples);
    fixed_detail::ResidualTally expected_tally;
    for (std::size_t s = 0; s < kSamples; ++s) {
      const fixed_detail::StoredResidual stored = kernels.store_residual(rho[s]);
      expected[s] = static_cast<std::int32_t>(stored.value);
      expected_tally.saturated += stored.saturated ? 1 : 0;
      expected_tally.rounded += stored.rounded ? 1 : 0;
      const std::int64_t magnitude = stored.value < 0 ? -stored.value : stored.value;
      expected_tally.abs_sum += magnitude;
      expected_tally.abs_max = std::max(expected_tally.abs_max, magnitude);
    }
    if (narrow) {
      EXPECT_GT(expected_tally.saturated, 0u) << "the operands reach the narrow store's saturation";
      EXPECT_GT(expected_tally.rounded, 0u) << "the operands reach the narrow store's rounding";
    }
    for (const std::int64_t target : targets) {
      const TargetMock mock(target);
      const std::string where = std::string(hwy::TargetName(target)) + (narrow ? " sQ1.6" : " default");
      const std::vector<std::int32_t> rho32(rho.begin(), rho.end());  // the 32-bit lines (rho within [-1, 1])
      for (const bool narrow_line : {false, true}) {
        const std::string line = narrow_line ? ", 32-bit line" : ", 64-bit line";
        std::vector<std::int32_t> stored(kSamples, 12345);
        fixed_detail::ResidualTally tally;
        const bool nonzero = narrow_line
                                 ? fixed_detail::lines::store_residuals(rho32.data(), kSamples, kernels, stored.data(), tally)
                                 : fixed_detail::lines::store_residuals(rho.data(), kSamples, kernels, stored.data(), tally);
        for (std::size_t s = 0; s < kSamples; ++s) ASSERT_EQ(stored[s], expected[s]) << where << line << " sample " << s;
        EXPECT_EQ(nonzero, std::any_of(expected.begin(), expected.end(), [](std::int32_t v) { return v != 0; }))
            << where << line;
        // A line of zeros, and one whose rho rounds to zero in the narrow store (|rho| below its half LSB).
        std::vector<std::int32_t> zeros(kSamples, 7);
        const std::vector<std::int64_t> tiny(kSamples, narrow ? 1 : 0);
        const std::vector<std::int32_t> tiny32(tiny.begin(), tiny.end());
        fixed_detail::ResidualTally ignored;
        EXPECT_FALSE(narrow_line ? fixed_detail::lines::store_residuals(tiny32.data(), kSamples, kernels, zeros.data(), ignored)
                                 : fixed_detail::lines::store_residuals(tiny.data(), kSamples, kernels, zeros.data(), ignored))
            << where << line << ": nothing but zeros stored";
        EXPECT_EQ(tally.saturated, expected_tally.saturated) << where << line;
        EXPECT_EQ(tally.rounded, expected_tally.rounded) << where << line;
        EXPECT_EQ(tally.abs_sum, expected_tally.abs_sum) << where << line;
        EXPECT_EQ(tally.abs_max, expected_tally.abs_max) << where << line;
      }
    }
  }
}

// D's kernels against the rounding they name (fx::rounded_shift, half to even and half up) on random tap slots, a
// third of them with weights that leave exact ties, on every instruction set.
TEST(FixedLines, GaussianKernelsRoundAsTheLineFormatsSay) {
  std::mt19937_64 random(11);
  constexpr std::size_t kRowSamples = 3 * 67;
  constexpr std::size_t kSamples = 3 * 34 + 1;  // a tail after every vector width
  constexpr std::size_t kTaps = 5;
  constexpr int kHorizontalShift = 8;   // T - L at the defaults
  constexpr int kVerticalShift = 40;    // T + L
  fixed_detail::GaussianColumnsPlan plan;
  plan.taps = kTaps;
  plan.samples = kSamples;
  std::uniform_int_distribution<std::int32_t> index(0, kRowSamples - 1);
  std::uniform_int_distribution<std::uint32_t> weight(0, (1u << 24) / kTaps);
  for (std::size_t t = 0; t < kTaps; ++t) {
    for (std::size_t s = 0; s < kSamples; ++s) {
      plan.index.push_back(index(random));
      const std::uint32_t w = weight(random);
      plan.weight.push_back(s % 3 == 0 ? w & ~0x7fu : w);  // multiples of 2^7: half of those sums are exact ties
    }
  }
  std::vector<std::uint16_t> row(kRowSamples);
  for (std::uint16_t& code : row) code = static_cast<std::uint16_t>(random() % 256);
  std::vector<std::int64_t> expected_columns(kSamples);
  int ties = 0;
  for (std::size_t s = 0; s < kSamples; ++s) {
    std::int64_t acc = 0;
    for (std::size_t t = 0; t < kTaps; ++t) acc += std::int64_t{plan.weight[t * kSamples + s]} * row[plan.index[t * kSamples + s]];
    ties += (acc & 0xff) == 0x80 ? 1 : 0;
    expected_columns[s] = fx::rounded_shift(acc, kHorizontalShift, fx::Quant::RndConv);
  }
  EXPECT_GT(ties, 4) << "the half-to-even rounding is exercised";
  std::vector<std::vector<std::int64_t>> rows(kTaps, std::vector<std::int64_t>(kSamples));
  std::array<std::uint32_t, kTaps> row_weight{};
  for (std::size_t j = 0; j < kTaps; ++j) {
    row_weight[j] = (weight(random) & ~((1u << 23) - 1)) | (j == 0 ? 1u << 23 : 0u);  // multiples of 2^23
    for (std::size_t i = 0; i < kSamples; ++i) {
      const auto value = static_cast<std::int64_t>(random() % (255u << 16));
      rows[j][i] = i % 2 == 0 ? value & ~std::int64_t{0xffff} : value;  // multiples of 2^16: ties at bit 39
    }
  }
  std::vector<const std::int64_t*> row_pointers;
  for (const auto& r : rows) row_pointers.push_back(r.data());
  std::vector<std::vector<std::uint32_t>> rows32;
  std::vector<const std::uint32_t*> row_pointers32;
  for (const auto& r : rows) rows32.emplace_back(r.begin(), r.end());
  for (const auto& r : rows32) row_pointers32.push_back(r.data());
  // The vertical weights as drawn, and mirrored (w_j = w_{n-1-j}: the folded sum where the caller allows it).
  std::array<std::uint32_t, kTaps> mirrored_weight = row_weight;
  for (std::size_t j = 0; j < kTaps / 2; ++j) mirrored_weight[kTaps - 1 - j] = mirrored_weight[j];
  const auto expected_rows = [&](const std::array<std::uint32_t, kTaps>& w) {
    std::vector<std::uint16_t> out(kSamples);
    for (std::size_t i = 0; i < kSamples; ++i) {
      std::int64_t acc = 0;
      for (std::size_t j = 0; j < kTaps; ++j) acc += std::int64_t{w[j]} * rows[j][i];
      out[i] = static_cast<std::uint16_t>(fx::rounded_shift(acc, kVerticalShift, fx::Quant::Rnd));
    }
    return out;
  };
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    const TargetMock mock(target);
    std::vector<std::int64_t> columns(kSamples);
    std::vector<std::uint32_t> columns32(kSamples);  // the 32-bit line words
    fixed_detail::lines::gaussian_columns(row.data(), kRowSamples, plan, kHorizontalShift, columns.data());
    fixed_detail::lines::gaussian_columns(row.data(), kRowSamples, plan, kHorizontalShift, columns32.data());
    for (std::size_t s = 0; s < kSamples; ++s) {
      ASSERT_EQ(columns[s], expected_columns[s]) << hwy::TargetName(target) << " horizontal sample " << s;
      ASSERT_EQ(columns32[s], expected_columns[s]) << hwy::TargetName(target) << " horizontal sample " << s << ", 32-bit";
    }
    for (const bool fold : {false, true}) {
      for (const auto* w : {&row_weight, &mirrored_weight}) {
        const std::vector<std::uint16_t> expected = expected_rows(*w);
        std::vector<std::uint16_t> vertical(kSamples);
        std::vector<std::uint16_t> vertical32(kSamples);
        fixed_detail::lines::gaussian_rows(row_pointers.data(), w->data(), kTaps, kSamples, kVerticalShift, fold,
                                           vertical.data());
        fixed_detail::lines::gaussian_rows(row_pointers32.data(), w->data(), kTaps, kSamples, kVerticalShift, fold,
                                           vertical32.data());
        for (std::size_t s = 0; s < kSamples; ++s) {
          ASSERT_EQ(vertical[s], expected[s]) << hwy::TargetName(target) << " vertical sample " << s
                                              << (fold ? " fold" : "") << (w == &row_weight ? "" : " mirrored");
          ASSERT_EQ(vertical32[s], expected[s]) << hwy::TargetName(target) << " vertical sample " << s
                                                << (fold ? " fold" : "") << (w == &row_weight ? "" : " mirrored")
                                                << ", 32-bit";
        }
      }
    }
    // Mirrored weights over values near 2^32, whose pairs leave a 32-bit operand: the caller does not allow the fold
    // there, and the kernel must not sum them.
    std::vector<std::vector<std::int64_t>> wide_rows(kTaps, std::vector<std::int64_t>(kSamples));
    std::vector<const std::int64_t*> wide_pointers;
    for (auto& r : wide_rows) {
      for (std::int64_t& v : r) v = (std::int64_t{1} << 32) - 1 - static_cast<std::int64_t>(random() % 4096);
      wide_pointers.push_back(r.data());
    }
    std::vector<std::uint16_t> wide(kSamples);
    fixed_detail::lines::gaussian_rows(wide_pointers.data(), mirrored_weight.data(), kTaps, kSamples, kVerticalShift,
                                       false, wide.data());
    std::vector<std::vector<std::uint32_t>> wide_rows32;
    std::vector<const std::uint32_t*> wide_pointers32;
    for (const auto& r : wide_rows) wide_rows32.emplace_back(r.begin(), r.end());
    for (const auto& r : wide_rows32) wide_pointers32.push_back(r.data());
    std::vector<std::uint16_t> wide32(kSamples);
    fixed_detail::lines::gaussian_rows(wide_pointers32.data(), mirrored_weight.data(), kTaps, kSamples,
                                       kVerticalShift, false, wide32.data());
    for (std::size_t i = 0; i < kSamples; ++i) {
      std::int64_t acc = 0;
      for (std::size_t j = 0; j < kTaps; ++j) acc += std::int64_t{mirrored_weight[j]} * wide_rows[j][i];
      const auto expected = static_cast<std::uint16_t>(fx::rounded_shift(acc, kVerticalShift, fx::Quant::Rnd));
      ASSERT_EQ(wide[i], expected) << hwy::TargetName(target) << " vertical sample " << i << " near 2^32, no fold";
      ASSERT_EQ(wide32[i], expected) << hwy::TargetName(target) << " vertical sample " << i
                                     << " near 2^32, no fold, 32-bit";
    }
  }
}

// D's horizontal half through the polyphase planes (regular taps: column k's support starts at f k + c, clamped at
// both ends) against the sums of the taps themselves, at decimations 2 and 4 with columns of fewer taps than the
// slots and exact ties; and the same taps with one index moved off the pattern, which must take the gather.
TEST(FixedLines, GaussianPolyphaseGivesTheTapsBits) {
  std::mt19937_64 random(23);
  constexpr int kColumns = 35;  // a tail after every vector width
  constexpr int kHorizontalShift = 8;
  for (const int f : {2, 4}) {
    for (const bool regular : {true, false}) {
     // Mirrored: every column's weights symmetric (w_t = w_{n-1-t}, the folded sums); else some columns shorter.
     for (const bool mirrored : {false, true}) {
      fixed_detail::Geometry g;
      g.full = cv::Size(f * kColumns, 1);
      g.reduced = cv::Size(kColumns, 1);
      const int taps_per_column = 4 * f + 1;
      for (int k = 0; k < kColumns; ++k) {
        fixed_detail::PolyphaseTaps taps;
        const int count = k % 5 == 0 && !mirrored ? taps_per_column - 1 : taps_per_column;
        for (int t = 0; t < count; ++t) {
          taps.index.push_back(std::clamp(f * k - 2 * f + t, 0, g.full.width - 1));
          const auto w = static_cast<std::int64_t>(random() % ((1u << 24) / taps_per_column));
          if (mirrored && t > count - 1 - t) {
            taps.weight.push_back(taps.weight[static_cast<std::size_t>(count - 1 - t)]);
          } else {
            taps.weight.push_back(k % 3 == 0 ? w & ~std::int64_t{0x7f} : w);  // multiples of 2^7: exact ties
          }
        }
        g.gauss_cols.push_back(taps);
      }
      if (!regular) g.gauss_cols[kColumns / 3].index[1] += 1;
      const fixed_detail::GaussianColumnsPlan plan = fixed_detail::gaussian_columns_plan(g);
      ASSERT_EQ(plan.decimation, regular ? static_cast<std::size_t>(f) : 0u) << "f=" << f;
      ASSERT_EQ(plan.symmetric, regular && mirrored) << "f=" << f;
      const std::size_t row_samples = 3 * static_cast<std::size_t>(g.full.width);
      std::vector<std::uint16_t> row(row_samples);
      for (std::uint16_t& code : row) code = static_cast<std::uint16_t>(random() % 256);
      std::vector<std::int64_t> expected(plan.samples);
      int ties = 0;
      for (int k = 0; k < kColumns; ++k) {
        const fixed_detail::PolyphaseTaps& taps = g.gauss_cols[static_cast<std::size_t>(k)];
        for (int ch = 0; ch < 3; ++ch) {
          std::int64_t acc = 0;
          for (std::size_t t = 0; t < taps.weight.size(); ++t) acc += taps.weight[t] * row[3 * taps.index[t] + ch];
          ties += (acc & 0xff) == 0x80 ? 1 : 0;
          expected[3 * static_cast<std::size_t>(k) + ch] = fx::rounded_shift(acc, kHorizontalShift, fx::Quant::RndConv);
        }
      }
      EXPECT_GT(ties, 2) << "the half-to-even rounding is exercised";
      for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        const TargetMock mock(target);
        std::vector<std::int64_t> columns(plan.samples, -1);
        std::vector<std::uint32_t> columns32(plan.samples, ~0u);
        fixed_detail::lines::gaussian_columns(row.data(), row_samples, plan, kHorizontalShift, columns.data());
        fixed_detail::lines::gaussian_columns(row.data(), row_samples, plan, kHorizontalShift, columns32.data());
        for (std::size_t s = 0; s < plan.samples; ++s) {
          ASSERT_EQ(columns[s], expected[s]) << hwy::TargetName(target) << " f=" << f
                                              << (regular ? " polyphase" : " gather") << (mirrored ? " mirrored" : "")
                                              << " sample " << s;
          ASSERT_EQ(columns32[s], expected[s]) << hwy::TargetName(target) << " f=" << f
                                                << (regular ? " polyphase" : " gather")
                                                << (mirrored ? " mirrored" : "") << " sample " << s << ", 32-bit";
        }
      }
     }
    }
  }
}

// result_of(values[s], s mod 3) for every sample s (sample s is read as channel s mod 3).
template <typename Result>
auto per_channel(const std::vector<std::int64_t>& values, const Result& result_of) {
  std::vector<decltype(result_of(std::int64_t{0}, 0))> out;
  for (std::size_t s = 0; s < values.size(); ++s) out.push_back(result_of(values[s], static_cast<int>(s % 3)));
  return out;
}

// The values a 32-bit line holds, each at its own channel's place (`filler` put before it where a value left out
// would shift it), and their results.
template <typename Result>
auto on_32bit_line(const std::vector<std::int64_t>& values, std::int64_t filler, const Result& result_of) {
  std::vector<std::int32_t> values32;
  std::vector<decltype(result_of(std::int64_t{0}, 0))> expected32;
  for (std::size_t s = 0; s < values.size(); ++s) {
    if (values[s] > std::numeric_limits<std::int32_t>::max()) continue;
    while (values32.size() % 3 != s % 3) {
      expected32.push_back(result_of(filler, static_cast<int>(values32.size() % 3)));
      values32.push_back(static_cast<std::int32_t>(filler));
    }
    expected32.push_back(result_of(values[s], static_cast<int>(s % 3)));
    values32.push_back(static_cast<std::int32_t>(values[s]));
  }
  return std::make_pair(values32, expected32);
}

// The inputs of an octave-segmented ROM read above `shift` low bits that a kernel must place exactly: each octave's
// and segment's first input and either side of it, with the low bits clear and all set, those within [0, max].
void append_octave_rom_ends(std::vector<std::int64_t>& out, int input_bits, int segments_log2, int shift,
                            std::int64_t max) {
  const std::int64_t segments = std::int64_t{1} << segments_log2;
  for (int k = 0; k < input_bits; ++k) {
    const std::int64_t start = std::int64_t{1} << k;
    for (std::int64_t j = 0; j <= segments; ++j) {
      const std::int64_t input = start + j * start / segments;
      for (const std::int64_t c : {input - 1, input, input + 1}) {
        for (const std::int64_t low : {std::int64_t{0}, (std::int64_t{1} << shift) - 1}) {
          const std::int64_t v = (c << shift) + low;
          if (v >= 0 && v <= max) out.push_back(v);
        }
      }
    }
  }
}

// The OLED drive code kernel (both lane widths: the 32-bit tables of DrivePlan and the 64-bit ones) against
// FixedKernels::drive_code, value by value: every channel's thresholds and their neighbours, both sides of 2^24 (where
// the 32-bit lanes' float conversion changes form), every octave, random values, and values outside [0, 1] (the
// generic search), on every instruction set.
// Both output depths: at 10 bits the index needs up to three steps (the base gather and three threshold gathers); at
// 8 bits one, which takes the packed single gather (DrivePlan::packed32), and the stepped search of the same tables
// beside it.
TEST(FixedLines, OledDriveKernelGivesTheThresholdIndexCodes) {
  for (const int output_bits : {10, 8}) {
    const FixedDecoderConfig config = fixed_config(link_config(0.5), "vive", output_bits);
    const fixed_detail::FixedKernels kernels(config);
    ASSERT_TRUE(kernels.line_plans().drive.has_value());
    const fixed_detail::DrivePlan& narrow = *kernels.line_plans().drive;
    ASSERT_FALSE(narrow.base32.empty()) << "the default formats take the 32-bit lanes";
    ASSERT_EQ(narrow.packed32.empty(), output_bits == 10) << output_bits << "-bit output";
    fixed_detail::DrivePlan unpacked_tables = narrow;
    unpacked_tables.packed32.clear();
    fixed_detail::DrivePlan wide_tables = unpacked_tables;
    wide_tables.base32.clear();
    const fixed_detail::DrivePlan& unpacked = unpacked_tables;
    const fixed_detail::DrivePlan& wide = wide_tables;
    const std::int64_t one = kernels.one();
    // Values outside the index first, so that the vectors after the generic search's keep their channel phase.
    std::vector<std::int64_t> values = {-1, one + 1, std::int64_t{1} << 40};
    // Sample s is read as channel s mod 3: each channel's thresholds go to its own samples.
    for (int ch = 0; ch < 3; ++ch) {
      for (const std::int64_t t : kernels.drive_index(ch).padded()) {
        if (t > one + 1) continue;  // the padding past the last threshold (up to INT64_MAX) has no value in [0, 1]
        for (const std::int64_t v : {t - 1, t, t + 1}) {
          if (v < 0 || v > one) continue;
          while (values.size() % 3 != static_cast<std::size_t>(ch)) values.push_back(one / 2);
          values.push_back(v);
        }
      }
    }
    for (int bit = 0; bit <= config.linear_frac_bits; ++bit) {
      for (const std::int64_t v : {(std::int64_t{1} << bit) - 1, std::int64_t{1} << bit, (std::int64_t{1} << bit) + 31}) {
        if (v >= 0 && v <= one) values.push_back(v);
      }
    }
    std::mt19937_64 random(29);
    std::uniform_int_distribution<std::int64_t> linear(0, one);
    for (int i = 0; i < 20000; ++i) values.push_back(linear(random));
    values.push_back(-1);
    values.push_back(one + 1);
    values.push_back(std::int64_t{1} << 40);
    const auto code_of = [&](std::int64_t v, int ch) { return kernels.drive_code(v, ch); };
    const std::vector<std::uint16_t> expected = per_channel(values, code_of);
    // The 32-bit lines (the 32-bit tables only): the same values but 2^40, which no 32-bit line holds.
    const auto [values32, expected32] = on_32bit_line(values, one / 2, code_of);
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      for (const fixed_detail::DrivePlan* plan : {&narrow, &unpacked, &wide}) {
        std::vector<std::uint16_t> codes(values.size());
        fixed_detail::lines::drive_codes(values.data(), values.size(), *plan, codes.data());
        for (std::size_t s = 0; s < values.size(); ++s) {
          ASSERT_EQ(codes[s], expected[s]) << hwy::TargetName(target) << " " << output_bits << "-bit output, "
                                           << (plan == &wide ? "64-bit" : plan == &unpacked ? "32-bit" : "packed")
                                           << " sample " << s << " value " << values[s];
        }
        if (plan == &wide) continue;
        std::vector<std::uint16_t> codes32(values32.size());
        fixed_detail::lines::drive_codes(values32.data(), values32.size(), *plan, codes32.data());
        for (std::size_t s = 0; s < values32.size(); ++s) {
          ASSERT_EQ(codes32[s], expected32[s]) << hwy::TargetName(target) << " " << output_bits << "-bit output, "
                                               << (plan == &unpacked ? "32-bit" : "packed") << " on a 32-bit line, sample "
                                               << s << " value " << values32[s];
        }
      }
    }
  }
}

// The OLED's report drive values (the planes trm run reads) against FixedKernels::drive_value: codes at each octave's
// and each segment's ends and either side of them, with and without the bits below the ROM's input code, random
// values, 0 and 1, and values outside [0, 1] (the stage function), on lines of both widths, at two output depths, at
// F = 20 (no bits below the code), F = 26 (two) and the default 28 (four), with 1, 8, 32 and 64 segments per octave.
TEST(FixedLines, OledDriveValueKernelGivesTheStageFunctionsValues) {
  std::vector<FixedDecoderConfig> configs = {fixed_config(link_config(0.5), "vive"),
                                             fixed_config(link_config(0.5), "rift", 10)};
  configs.push_back(configs[0]);
  configs.back().linear_frac_bits = 20;
  configs.back().residual.frac_bits = 20;
  configs.push_back(configs[0]);
  configs.back().drive_segments_per_octave = 8;
  configs.push_back(configs[1]);
  configs.back().drive_segments_per_octave = 64;
  configs.push_back(configs[0]);  // one segment an octave, the widest drive words, two bits below the ROM's input
  configs.back().drive_segments_per_octave = 1;
  configs.back().drive_frac_bits = 24;
  configs.back().linear_frac_bits = 26;
  configs.back().residual.frac_bits = 26;
  for (const FixedDecoderConfig& config : configs) {
    const fixed_detail::FixedKernels kernels(config);
    ASSERT_TRUE(kernels.line_plans().drive_value.has_value());
    const fixed_detail::DriveValuePlan& plan = *kernels.line_plans().drive_value;
    const std::int64_t one = kernels.one();
    const int shift = plan.input_shift;
    const int input_bits = std::bit_width(static_cast<std::uint64_t>(plan.top_code));
    // Values outside the kernel's lanes first and last, so that the vectors between keep their channel phase.
    std::vector<std::int64_t> values = {-1, one + 1, std::int64_t{1} << 40};
    append_octave_rom_ends(values, input_bits, plan.segments_per_octave_log2, shift, one);
    std::mt19937_64 random(31);
    std::uniform_int_distribution<std::int64_t> linear(0, one);
    for (int i = 0; i < 20000; ++i) values.push_back(linear(random));
    for (const std::int64_t v : {std::int64_t{0}, one - 1, one, one + 1, std::int64_t{-5}}) values.push_back(v);
    const auto value_of = [&](std::int64_t v, int ch) { return kernels.drive_value(v, ch); };
    const std::vector<std::int64_t> expected = per_channel(values, value_of);
    const auto [values32, expected32] = on_32bit_line(values, one / 3, value_of);
    const std::string what = config.decoder.panel.name + " F=" + std::to_string(config.linear_frac_bits) + " " +
                             std::to_string(config.drive_segments_per_octave) + " segments per octave";
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      std::vector<std::int64_t> drive(values.size());
      fixed_detail::lines::drive_values(values.data(), values.size(), plan, kernels, drive.data());
      for (std::size_t s = 0; s < values.size(); ++s) {
        ASSERT_EQ(drive[s], expected[s]) << hwy::TargetName(target) << " " << what << " sample " << s << " value "
                                         << values[s];
      }
      std::vector<std::int64_t> drive32(values32.size());
      fixed_detail::lines::drive_values(values32.data(), values32.size(), plan, kernels, drive32.data());
      for (std::size_t s = 0; s < values32.size(); ++s) {
        ASSERT_EQ(drive32[s], expected32[s]) << hwy::TargetName(target) << " " << what << " on a 32-bit line, sample "
                                             << s << " value " << values32[s];
      }
    }
  }
}

// The LCD target kernel against the stage function: sums at every octave's and segment's ends of the target ROM's
// input and either side (and the LSBs below the input), random sums, and sums at or below 0 and at or above 2 (the
// clamped ends), on every instruction set; F = 28 (the default, 512 segments an octave), 20 (64 segments) and 26 (one
// segment an octave, three bits below the ROM's 24-bit input), and F = 28 with 2048 segments.
TEST(FixedLines, LcdTargetKernelGivesTheStageFunctionsTargets) {
  std::vector<FixedDecoderConfig> configs = {fixed_config(link_config(0.5), "lcd")};
  for (const auto& [frac_bits, segments] : {std::pair{20, 64}, std::pair{26, 1}, std::pair{28, 2048}}) {
    configs.push_back(configs[0]);
    configs.back().linear_frac_bits = frac_bits;
    configs.back().residual.frac_bits = frac_bits;
    configs.back().lcd_segments_per_octave = segments;
  }
  for (const FixedDecoderConfig& config : configs) {
    const fixed_detail::FixedKernels kernels(config);
    ASSERT_TRUE(kernels.line_plans().lcd.has_value());
    const fixed_detail::LcdPlan& plan = *kernels.line_plans().lcd;
    const std::int64_t two = 2 * kernels.one();
    std::vector<std::int64_t> sums = {-two, -1, 0, 1, two - 1, two, two + 1, std::int64_t{1} << 40};
    append_octave_rom_ends(sums, plan.target_input_bits, plan.segments_per_octave_log2, plan.target_shift, two);
    std::mt19937_64 random(37);
    std::uniform_int_distribution<std::int64_t> in_range(0, two);
    for (int i = 0; i < 20000; ++i) sums.push_back(in_range(random));
    std::vector<std::int64_t> expected(sums.size());
    for (std::size_t s = 0; s < sums.size(); ++s) expected[s] = kernels.lcd_target(sums[s]);
    ASSERT_EQ(expected[1], 0);
    ASSERT_EQ(expected[5], kernels.one());
    const std::string what = "F=" + std::to_string(config.linear_frac_bits) + " " +
                             std::to_string(config.lcd_segments_per_octave) + " segments per octave";
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      std::vector<std::int64_t> targets(sums.size());
      fixed_detail::lines::lcd_targets(sums.data(), sums.size(), plan, kernels, targets.data());
      for (std::size_t s = 0; s < sums.size(); ++s) {
        ASSERT_EQ(targets[s], expected[s]) << hwy::TargetName(target) << " " << what << " sample " << s << " sum "
                                           << sums[s];
      }
    }
  }
}

// The LCD's report drive value kernel against the stage function, operand by operand: random x_t and x_{t-1} (and
// values outside [0, 1], which the contributed history stores), every v_{t-1}, the code the drive gives and random
// codes (the interpolation clamps the target to the code's thresholds), sums at the unreachable ends; on every
// instruction set, at drive_frac_bits 8, 16 and 30, F = 20 and 28, and a panel of other coefficients.
TEST(FixedLines, LcdDriveValueKernelGivesTheStageFunctionsValues) {
  std::vector<FixedDecoderConfig> configs = {fixed_config(link_config(0.5), "lcd")};
  configs.push_back(configs[0]);
  configs.back().drive_frac_bits = 8;
  configs.back().linear_frac_bits = 20;
  configs.back().residual.frac_bits = 20;
  configs.push_back(configs[0]);
  configs.back().drive_frac_bits = 30;
  configs.back().linear_frac_bits = 28;
  configs.back().residual.frac_bits = 28;
  configs.push_back(fixed_config(link_config(0.5), "lcd:0.3,0.2,0.1,0.05,2.4"));
  configs.back().decoder.lcd_history = LcdHistory::Contributed;
  for (const FixedDecoderConfig& config : configs) {
    const fixed_detail::FixedKernels kernels(config);
    ASSERT_TRUE(kernels.line_plans().lcd.has_value());
    const fixed_detail::LcdPlan& plan = *kernels.line_plans().lcd;
    ASSERT_FALSE(plan.report_merge.empty()) << "the kernel's table is built at these formats";
    const std::int64_t one = kernels.one();
    std::mt19937_64 random(41);
    std::uniform_int_distribution<std::int64_t> linear(-one / 8, one + one / 8);
    std::uniform_int_distribution<int> code_of(0, plan.top);
    std::vector<std::int64_t> wanted, previous_wanted;
    std::vector<std::uint16_t> rows, codes;
    for (int i = 0; i < 30000; ++i) {
      const std::int64_t x = i % 7 == 0 ? std::clamp<std::int64_t>(linear(random), 0, one) : linear(random);
      const std::int64_t x_previous = i % 5 == 0 ? x : linear(random);
      // v_{t-1} at random, or the code that held x_{t-1} (mostly reachable).
      const auto j = i % 2 == 0 ? static_cast<std::uint16_t>(code_of(random))
                                : kernels.lcd_drive(x_previous, 0, 0, true, false).code;
      const fixed_detail::LcdSample sample = kernels.lcd_drive(x, x_previous, j, false, false);
      wanted.push_back(x);
      previous_wanted.push_back(x_previous);
      rows.push_back(j);
      codes.push_back(i % 3 == 0 ? static_cast<std::uint16_t>(code_of(random)) : sample.code);
    }
    for (const std::uint16_t j : {std::uint16_t{0}, static_cast<std::uint16_t>(plan.top)}) {  // black and white rows
      for (const std::int64_t x : {std::int64_t{0}, one}) {
        for (const std::int64_t x_previous : {std::int64_t{0}, one}) {
          wanted.push_back(x);
          previous_wanted.push_back(x_previous);
          rows.push_back(j);
          codes.push_back(kernels.lcd_drive(x, x_previous, j, false, false).code);
        }
      }
    }
    const std::size_t n = wanted.size();
    std::vector<std::int64_t> sums(n), targets(n), expected(n);
    std::size_t unreachable = 0;
    for (std::size_t s = 0; s < n; ++s) {
      sums[s] = wanted[s] + previous_wanted[s];
      targets[s] = kernels.lcd_target(sums[s]);
      const fixed_detail::LcdSample sample =
          kernels.lcd_report(wanted[s], previous_wanted[s], rows[s], false, codes[s]);
      expected[s] = sample.drive;
      unreachable += sample.unreachable ? 1 : 0;
    }
    ASSERT_GT(unreachable, 100u) << "the operands reach both kinds of samples";
    ASSERT_LT(unreachable, n / 2);
    const std::string what = config.decoder.panel.name + " D=" + std::to_string(config.drive_frac_bits) +
                             " F=" + std::to_string(config.linear_frac_bits);
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      std::vector<std::int64_t> drive(n);
      fixed_detail::lines::lcd_drive_values(sums.data(), targets.data(), rows.data(), codes.data(), n, plan, kernels,
                                            drive.data());
      for (std::size_t s = 0; s < n; ++s) {
        ASSERT_EQ(drive[s], expected[s]) << hwy::TargetName(target) << " " << what << " sample " << s << " x "
                                         << wanted[s] << " x_previous " << previous_wanted[s] << " row " << rows[s]
                                         << " code " << codes[s];
      }
    }
  }
}

// The same kernel's quotient where its double estimate is wrong: exactly on a rounding half with operands of 60 bits
// and more, whose doubles are rounded, so that the estimate lands on either side and only the remainder settles it
// (and one offset either side). A plan whose target needs no scaling and whose row r serves code r: a span
// 2^(D+1) u (u odd, the span near 2^52) puts the quotient 2^D (t_lo span + offset dt) / (span 2 Mx) on k + 1/2 at
// offset u ((2k + 1) 2 Mx - t_lo 2^(D+1)) / dt, and the row's words are placed so that this offset is the target
// 2^31. The definition of lcd_drive_value, in 128 bits, is the oracle, at drive_frac_bits 8, 16 and 30, every code.
TEST(FixedLines, LcdDriveValueKernelSettlesQuotientsOnTheHalf) {
  using fx::detail::int128;
  const fixed_detail::FixedKernels kernels(fixed_config(link_config(0.5), "lcd"));
  ASSERT_TRUE(kernels.line_plans().lcd.has_value());
  fixed_detail::LcdPlan plan = *kernels.line_plans().lcd;
  plan.scale = 1;
  const std::int64_t top = plan.top;
  const std::int64_t two_top = 2 * top;
  const std::int64_t words = plan.report_row_words;
  ASSERT_EQ(words, top + 2);
  for (std::size_t k = 0; k < plan.ends.size(); k += 2) {  // every sum of 0 reachable
    plan.ends[k] = -1;
    plan.ends[k + 1] = 1;
  }
  constexpr std::int64_t kTarget = std::int64_t{1} << 31;
  std::mt19937_64 random(47);
  std::size_t estimates_low = 0;
  for (const int drive_frac_bits : {8, 16, 30}) {
    plan.drive_frac_bits = drive_frac_bits;
    const std::int64_t u = ((std::int64_t{1} << 52) >> (drive_frac_bits + 1)) - 1;
    const std::int64_t span = u << (drive_frac_bits + 1);
    plan.report_merge.assign(static_cast<std::size_t>(plan.width * words), 0);
    std::vector<std::int64_t> targets;
    std::vector<std::uint16_t> codes;
    for (std::int64_t code = 0; code <= top; ++code) {
      const std::int64_t t_lo = std::max<std::int64_t>(0, 2 * code - 1);
      const std::int64_t dt = std::min<std::int64_t>(two_top, 2 * code + 1) - t_lo;
      // The ks whose half lies within the span: (2k + 1) 2 Mx in [t_lo 2^(D+1), (t_lo + dt) 2^(D+1)].
      const std::int64_t k_first = (t_lo << (drive_frac_bits + 1)) / (2 * two_top);
      const std::int64_t k_last = ((t_lo + dt) << (drive_frac_bits + 1)) / (2 * two_top) - 1;
      if (k_last < k_first) continue;
      const std::int64_t k = std::uniform_int_distribution<std::int64_t>(k_first, k_last)(random);
      const int128 offset = int128{u} * ((2 * k + 1) * two_top - (t_lo << (drive_frac_bits + 1))) / dt;
      if (offset < 0 || offset > span) continue;
      const std::int64_t m_lo = kTarget - static_cast<std::int64_t>(offset);
      for (std::int64_t c = 0; c < words; ++c) {
        plan.report_merge[static_cast<std::size_t>(code * words + c)] = m_lo + (c - code) * span;
      }
      for (const std::int64_t target : {kTarget - 1, kTarget, kTarget + 1}) {
        targets.push_back(target);
        codes.push_back(static_cast<std::uint16_t>(code));
      }
    }
    // Whole vectors of every width: a tail would take the stage function, whose merges are the panel's.
    while (targets.size() % 8 != 0) {
      targets.push_back(targets.back());
      codes.push_back(codes.back());
    }
    const std::size_t n = targets.size();
    const std::vector<std::int64_t> sums(n, 0);
    const std::vector<std::uint16_t>& rows = codes;
    std::vector<std::int64_t> expected(n);
    std::size_t on_half = 0, estimate_high = 0, estimate_low = 0;
    for (std::size_t s = 0; s < n; ++s) {
      const std::int64_t t_lo = std::max<std::int64_t>(0, 2 * codes[s] - 1);
      const std::int64_t t_hi = std::min<std::int64_t>(two_top, 2 * codes[s] + 1);
      const std::int64_t m_lo = plan.report_merge[static_cast<std::size_t>(codes[s] * words + codes[s])];
      const std::int64_t offset = std::clamp<std::int64_t>(targets[s] - m_lo, 0, span);
      const int128 part = int128{t_lo} * span + int128{offset} * (t_hi - t_lo);
      const int128 denominator = int128{span} * two_top;
      const int128 rounded = (part << drive_frac_bits) + denominator / 2;
      expected[s] = static_cast<std::int64_t>(rounded / denominator);
      on_half += rounded % denominator == 0 ? 1 : 0;
      const auto estimate = static_cast<std::int64_t>(static_cast<double>(part) * std::ldexp(1.0, drive_frac_bits) /
                                                          static_cast<double>(denominator) +
                                                      0.5);
      estimate_high += estimate > expected[s] ? 1 : 0;
      estimate_low += estimate < expected[s] ? 1 : 0;
    }
    ASSERT_GT(on_half, static_cast<std::size_t>(top / 2)) << "quotients on a rounding half, D=" << drive_frac_bits;
    EXPECT_GT(estimate_high + estimate_low, 0u) << "estimates the remainder corrects, D=" << drive_frac_bits;
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      if (target == HWY_SCALAR) continue;  // the stage function throughout
      const TargetMock mock(target);
      std::vector<std::int64_t> drive(n);
      fixed_detail::lines::lcd_drive_values(sums.data(), targets.data(), rows.data(), codes.data(), n, plan, kernels,
                                            drive.data());
      for (std::size_t s = 0; s < n; ++s) {
        ASSERT_EQ(drive[s], expected[s]) << hwy::TargetName(target) << " D=" << drive_frac_bits << " sample " << s
                                         << " code " << codes[s] << " target " << targets[s];
      }
    }
    estimates_low += estimate_low;
  }
  EXPECT_GT(estimates_low, 0u) << "estimates below the quotient, which the remainder raises";
}

// ROMs with thresholds where a float conversion or a bucket's bounds could go wrong, up to the index's 2^30, through
// the two-gather search and the packed single gather:
//   * ends: at 2^k - 1, 2^k and the second bucket of each octave, 2^k + 2^(k-7): the last value of an octave and of
//     its first bucket each have a code of their own, which a float conversion that rounded a run of ones up into the
//     next bucket would miss (below 2^30 the shifted value must stay under 2^24); thresholds on bucket starts;
//   * inside: at 2^k + 1 and at the last value of the second bucket, 2^k + 2^(k-6) - 1 (one threshold per bucket, at
//     the smallest and the largest offset within it).
TEST(FixedLines, OledDriveKernelAtOctaveAndBucketEnds) {
  std::vector<std::int64_t> ends{0};
  std::vector<std::int64_t> inside{0};
  for (int k = 1; k < 30; ++k) {
    if ((std::int64_t{1} << k) - 1 > ends.back()) ends.push_back((std::int64_t{1} << k) - 1);
    ends.push_back(std::int64_t{1} << k);
    if (k >= 8) ends.push_back((std::int64_t{1} << k) + (std::int64_t{1} << (k - 7)));
    if (k < 8) {
      if ((std::int64_t{1} << k) - 1 > inside.back()) inside.push_back((std::int64_t{1} << k) - 1);
      inside.push_back(std::int64_t{1} << k);
    } else {
      inside.push_back((std::int64_t{1} << k) + 1);
      inside.push_back((std::int64_t{1} << k) + (std::int64_t{1} << (k - 6)) - 1);
    }
  }
  for (const std::vector<std::int64_t>* thresholds : {&ends, &inside}) {
    const char* name = thresholds == &ends ? "octave ends" : "inside buckets";
    const fixed_detail::ThresholdIndex index(*thresholds, 30);
    const std::optional<fixed_detail::DrivePlan> plan = fixed_detail::drive_plan({&index, &index, &index});
    ASSERT_TRUE(plan.has_value() && !plan->base32.empty()) << name;
    ASSERT_FALSE(plan->packed32.empty()) << name << ": one step per bucket";
    fixed_detail::DrivePlan unpacked = *plan;
    unpacked.packed32.clear();
    std::vector<std::int64_t> values;
    for (const std::int64_t t : *thresholds) {
      for (const std::int64_t v : {t - 2, t - 1, t, t + 1}) values.push_back(v);
    }
    for (const std::int64_t v : {(std::int64_t{1} << 30) - 1, (std::int64_t{1} << 30) - 32, std::int64_t{541065215}}) {
      values.push_back(v);  // the top of the index, and 2^29 + 2^22 - 1 (bits 0-21 set)
    }
    std::vector<std::uint16_t> expected(values.size());
    for (std::size_t s = 0; s < values.size(); ++s) expected[s] = index.search(values[s]);
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      for (const fixed_detail::DrivePlan* p : {&plan.value(), static_cast<const fixed_detail::DrivePlan*>(&unpacked)}) {
        std::vector<std::uint16_t> codes(values.size());
        fixed_detail::lines::drive_codes(values.data(), values.size(), *p, codes.data());
        const std::vector<std::int32_t> values32(values.begin(), values.end());  // all below 2^30
        std::vector<std::uint16_t> codes32(values.size());
        fixed_detail::lines::drive_codes(values32.data(), values32.size(), *p, codes32.data());
        for (std::size_t s = 0; s < values.size(); ++s) {
          ASSERT_EQ(codes[s], expected[s]) << hwy::TargetName(target) << " " << name
                                           << (p == &unpacked ? " two gathers" : " packed") << ", value " << values[s];
          ASSERT_EQ(codes32[s], expected[s]) << hwy::TargetName(target) << " " << name
                                             << (p == &unpacked ? " two gathers" : " packed") << " on a 32-bit line, value "
                                             << values[s];
        }
      }
    }
  }
}

// U's column blend at r = 1/2 by the quarters' sums (ColumnBlendPlan::half), through its windows (a vector's taps
// within one vector of row samples, permuted), through its double windows (two vectors) and through the gather,
// against the blend's formula, at a headset width and narrow ones with tails, on every instruction set.
TEST(FixedLines, ColumnBlendWindowsGiveTheBlendsBits) {
  std::mt19937_64 random(31);
  for (const auto& [width, r] :
       {std::pair{2160, 0.5}, std::pair{68, 0.5}, std::pair{46, 0.5}, std::pair{67, 0.25}, std::pair{67, 0.75}}) {
    fixed_detail::FixedKernels kernels(fixed_config(link_config(r), "vive"));
    const fixed_detail::Geometry& g = kernels.geometry(cv::Size(width, 24));
    const fixed_detail::ColumnBlendPlan& plan = g.column_blend;
    ASSERT_FALSE(plan.left.empty());
    EXPECT_EQ(plan.half, r == 0.5) << "width " << width << " r " << r;
    fixed_detail::ColumnBlendPlan windows_copy = plan;
    windows_copy.half = false;
    const fixed_detail::ColumnBlendPlan& windows_only = windows_copy;
    fixed_detail::ColumnBlendPlan double_copy = windows_copy;
    double_copy.windows = {};
    const fixed_detail::ColumnBlendPlan& double_only = double_copy;
    fixed_detail::ColumnBlendPlan gather_copy = double_copy;
    gather_copy.double_windows = {};
    const fixed_detail::ColumnBlendPlan& gather_only = gather_copy;
    std::vector<std::uint16_t> row(3 * static_cast<std::size_t>(g.reduced.width));
    for (std::uint16_t& code : row) code = static_cast<std::uint16_t>(random() % 256);
    const std::size_t n = plan.left.size();
    std::vector<std::uint32_t> expected(n);
    for (std::size_t s = 0; s < n; ++s) {
      expected[s] = (plan.unit - plan.upper[s]) * row[static_cast<std::size_t>(plan.left[s])] +
                    plan.upper[s] * row[static_cast<std::size_t>(plan.right[s])];
    }
    bool some_windows = false;
    for (const auto& w : plan.windows) some_windows = some_windows || !w.start.empty();
    if (width == 2160) {
      EXPECT_TRUE(some_windows) << "r = 1/2 at a headset width takes the windows on some width";
      EXPECT_TRUE(plan.windows_for(8) == nullptr && plan.double_windows_for(8) != nullptr)
          << "r = 1/2 at 8 lanes (AVX2) takes the double windows";
    }
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      for (const fixed_detail::ColumnBlendPlan* p : {&plan, &windows_only, &double_only, &gather_only}) {
        std::vector<std::uint32_t> out(n);
        fixed_detail::lines::blend_columns(row.data(), *p, n, out.data());
        for (std::size_t s = 0; s < n; ++s) {
          ASSERT_EQ(out[s], expected[s]) << hwy::TargetName(target) << " width " << width << " r " << r
                                         << (p == &plan            ? " as planned"
                                             : p == &windows_only  ? " windows"
                                             : p == &double_only   ? " double windows"
                                                                   : " gather")
                                         << " sample " << s;
        }
      }
    }
  }
}

// U's row blend and EOTF over every output row of a view against the per-sample U (FixedKernels::upsample_line), on
// 64- and 32-bit lines: at r = 1/2 through the exact path (quarter weights: one ROM node per sample), at r = 0.4 and
// 3/4 through the ROM interpolation, and at r = 1/2 with the exact path refused (a column weight's bits said too
// many), on every instruction set. Random codes, and the rows of black and of the top code. The tables of the path
// that must not run are zeroed, so that a sample taking it would fail. The exact path composed with the OLED drive
// (blend_rows_drive) against the drive code of each sample's U by the stage function.
TEST(FixedLines, RowBlendGivesThePerSampleUpsampleOnEveryRow) {
  std::mt19937_64 random(37);
  // 202 pixels at r = 1/2: an exact factor 2, quarter weights; 203: 102 reduced columns, weights of no short fraction.
  for (const auto& [width, r, exact] : {std::tuple{202, 0.5, true}, std::tuple{202, 0.5, false},
                                        std::tuple{203, 0.5, false}, std::tuple{203, 0.4, false},
                                        std::tuple{67, 0.75, false}}) {
    fixed_detail::FixedKernels kernels(fixed_config(link_config(r), "vive"));
    const fixed_detail::Geometry& g = kernels.geometry(cv::Size(width, 14));
    fixed_detail::EotfPlan eotf = *kernels.line_plans().eotf;
    // Refused: a column weight's bits said to be more than the ROM's segment bits.
    const int column_bits = exact || width != 202 ? g.column_blend.weight_bits : eotf.segments_log2 + 1;
    if (width == 202) {
      ASSERT_EQ(g.column_blend.weight_bits, 2) << "quarter weights at r = 1/2";
      ASSERT_EQ(eotf.segments_log2, 4);
      ASSERT_FALSE(eotf.node32.empty());
    } else {
      ASSERT_GT(g.column_blend.weight_bits, eotf.segments_log2) << "r = " << r << " takes the interpolation";
    }
    if (exact) {
      std::fill(eotf.packed.begin(), eotf.packed.end(), 0);
      std::fill(eotf.node.begin(), eotf.node.end(), 0);
      std::fill(eotf.step.begin(), eotf.step.end(), 0);
    } else {
      std::fill(eotf.node32.begin(), eotf.node32.end(), 0);
    }
    const std::size_t row_samples = 3 * static_cast<std::size_t>(g.reduced.width);
    std::vector<std::vector<std::uint16_t>> rows(static_cast<std::size_t>(g.reduced.height),
                                                 std::vector<std::uint16_t>(row_samples));
    for (std::size_t k = 0; k < rows.size(); ++k) {
      for (std::uint16_t& code : rows[k]) code = k == 1 ? 0 : k == 2 ? 255 : static_cast<std::uint16_t>(random() % 256);
    }
    const std::size_t n = 3 * static_cast<std::size_t>(width);
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      for (int y = 0; y < g.full.height; ++y) {
        const fixed_detail::BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
        const auto& row0 = rows[static_cast<std::size_t>(row.i0)];
        const auto& row1 = rows[static_cast<std::size_t>(row.i1)];
        std::vector<std::int64_t> expected(n);
        kernels.upsample_line(row0.data(), row1.data(), g, row.upper, expected.data(), false);
        std::vector<std::uint32_t> top(n), bottom(n);
        fixed_detail::lines::blend_columns(row0.data(), g.column_blend, n, top.data());
        fixed_detail::lines::blend_columns(row1.data(), g.column_blend, n, bottom.data());
        std::vector<std::int64_t> wide(n);
        std::vector<std::int32_t> narrow(n);
        const auto upper = static_cast<std::uint32_t>(row.upper);
        fixed_detail::lines::blend_rows_eotf(top.data(), bottom.data(), n, upper, column_bits, eotf, wide.data());
        fixed_detail::lines::blend_rows_eotf(top.data(), bottom.data(), n, upper, column_bits, eotf, narrow.data());
        // The exact path's nodes as drive codes (FixedLinePlans::drive_of_node), by the drive's stage function;
        // refused, writing nothing, where the path does not apply.
        std::vector<std::uint16_t> codes(n, 0xFFFF);
        ASSERT_EQ(fixed_detail::lines::blend_rows_drive(top.data(), bottom.data(), n, upper, column_bits, eotf,
                                                        kernels.line_plans().drive_of_node, codes.data()),
                  exact)
            << hwy::TargetName(target) << " r " << r << " row " << y;
        for (std::size_t s = 0; s < n; ++s) {
          ASSERT_EQ(wide[s], expected[s]) << hwy::TargetName(target) << " r " << r << (exact ? " exact" : "")
                                          << " row " << y << " sample " << s << ", 64-bit line";
          ASSERT_EQ(narrow[s], expected[s]) << hwy::TargetName(target) << " r " << r << (exact ? " exact" : "")
                                            << " row " << y << " sample " << s << ", 32-bit line";
          const std::uint16_t code = exact ? kernels.drive_code(expected[s], static_cast<int>(s % 3)) : 0xFFFF;
          ASSERT_EQ(codes[s], code) << hwy::TargetName(target) << " r " << r << (exact ? " exact" : "") << " row "
                                    << y << " sample " << s << ", drive codes";
        }
      }
    }
  }
}

// An LCD configuration at linear format F (the residual's fraction no finer than F).
FixedDecoderConfig lcd_config_at(int linear_frac_bits) {
  FixedDecoderConfig config = fixed_config(link_config(0.5), "lcd");
  config.linear_frac_bits = linear_frac_bits;
  config.residual.frac_bits = std::min(config.residual.frac_bits, linear_frac_bits);
  return config;
}

// The LCD drive kernel against FixedKernels::lcd_drive and emit's frame-store update, sample by sample: random wanted
// and previous values (sums from 0 to past 2, so the target ROM's every octave, its bottom region and the clamp to
// 1 are read), random v_{t-1}, both history modes (Contributed stores negative values after a dark shortfall), the
// eye's first frame (held: the stores are written, not read), on every instruction set.
TEST(FixedLines, LcdDriveKernelGivesTheStageFunctionsBitsSampleBySample) {
  struct Case {
    LcdHistory history;
    int linear_frac_bits;
    bool held;
  };
  // F = 20 besides the default: there one LSB of the target m moves a code often enough to be seen.
  for (const auto& [history, linear_frac_bits, held] :
       {Case{LcdHistory::Wanted, 28, false}, Case{LcdHistory::Contributed, 28, false}, Case{LcdHistory::Wanted, 20, false},
        Case{LcdHistory::Wanted, 28, true}, Case{LcdHistory::Contributed, 20, true}}) {
    FixedDecoderConfig config = lcd_config_at(linear_frac_bits);
    config.decoder.lcd_history = history;
    const fixed_detail::FixedKernels kernels(config);
    const auto& plan = kernels.line_plans().lcd;
    ASSERT_TRUE(plan.has_value());
    const std::int64_t one = kernels.one();
    constexpr std::size_t kSamples = 3 * 20011;  // many, so that a target one LSB off crosses a merge threshold
    std::mt19937_64 random(13);
    std::uniform_int_distribution<std::int64_t> linear(0, one);
    std::uniform_int_distribution<int> octave(0, linear_frac_bits);
    std::vector<std::int64_t> wanted(kSamples);
    std::vector<std::int32_t> previous_linear(kSamples);
    std::vector<std::uint8_t> previous_code(kSamples);  // the 8-bit v_{t-1} store
    for (std::size_t s = 0; s < kSamples; ++s) {
      // Every third sample small, spread over the octaves (down to the ROM's bottom region), others uniform.
      wanted[s] = s % 3 == 0 ? (std::int64_t{1} << octave(random)) + (s % 7) : linear(random);
      previous_linear[s] = static_cast<std::int32_t>(s % 5 == 0 ? -(linear(random) / 8) : linear(random));
      if (s % 11 == 0) wanted[s] = previous_linear[s] = 0;
      if (s % 13 == 0) wanted[s] = one, previous_linear[s] = static_cast<std::int32_t>(one);
      // Now and then a stored x_{t-1} at and past the composed kernel's bound (+-2^29: within it the sum, 2 M^gamma -
      // x_{t-1} and the shortfall stay within 32 bits), as a long run of contributed shortfalls could leave, and
      // far past it either way; and an x_t at the bound (the kernels take any 32-bit line).
      constexpr std::int32_t kBound = std::int32_t{1} << 29;
      const std::array<std::int32_t, 8> edges = {kBound - 1, kBound, -(kBound - 1), -kBound, std::int32_t{1} << 30,
                                                 -(std::int32_t{1} << 30), INT32_MIN + 1, INT32_MAX};
      if (s % 997 == 0) previous_linear[s] = edges[(s / 997) % edges.size()];
      if (s % 991 == 0) {  // both at once: the sum of two 2^30 wraps in 32 bits, and so does a shortfall at -2^30
        const std::array<std::pair<std::int32_t, std::int32_t>, 4> both = {
            std::pair{kBound - 1, kBound - 1}, std::pair{kBound, kBound - 1}, std::pair{std::int32_t{1} << 30, std::int32_t{1} << 30},
            std::pair{-(std::int32_t{1} << 30), -(std::int32_t{1} << 30)}};
        wanted[s] = both[(s / 991) % both.size()].first;
        previous_linear[s] = both[(s / 991) % both.size()].second;
      }
      previous_code[s] = static_cast<std::uint8_t>(random() % 256);
    }
    std::vector<std::uint16_t> expected_codes(kSamples);
    std::vector<std::uint8_t> expected_store_code(previous_code);
    std::vector<std::int32_t> expected_store_linear(previous_linear);
    std::vector<std::int64_t> expected_shortfall(kSamples);
    std::uint64_t expected_unreachable = 0;
    for (std::size_t s = 0; s < kSamples; ++s) {
      const fixed_detail::LcdSample sample =
          kernels.lcd_drive(wanted[s], previous_linear[s], previous_code[s], held, false);
      expected_codes[s] = sample.code;
      expected_shortfall[s] = sample.shortfall;
      expected_unreachable += sample.unreachable ? 1 : 0;
      expected_store_code[s] = static_cast<std::uint8_t>(sample.code);
      expected_store_linear[s] = static_cast<std::int32_t>(history == LcdHistory::Contributed ? sample.contributed : wanted[s]);
    }
    EXPECT_GT(expected_unreachable, 0u) << "the operands reach the unreachable ends";
    ASSERT_FALSE(plan->index.empty()) << "the per-row index is built";
    ASSERT_FALSE(plan->composed.empty()) << "the composed table is built";
    fixed_detail::LcdPlan indexed = *plan;  // the per-row index, where no composed table is built
    indexed.composed.clear();
    fixed_detail::LcdPlan binary = indexed;  // the binary search of the merge table, where neither is
    binary.index.clear();
    const std::vector<std::int32_t> wanted32(wanted.begin(), wanted.end());  // the 32-bit line (narrow_lines)
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
     for (const bool narrow : {false, true}) {
      for (const fixed_detail::LcdPlan* searched : {&*plan, static_cast<const fixed_detail::LcdPlan*>(&indexed),
                                                    static_cast<const fixed_detail::LcdPlan*>(&binary)}) {
        const TargetMock mock(target);
        const std::string where = std::string(hwy::TargetName(target)) +
                                  (history == LcdHistory::Contributed ? " contributed" : " wanted") + " F=" +
                                  std::to_string(linear_frac_bits) + (held ? " held" : "") +
                                  (searched == &binary ? " binary search" : searched == &indexed ? " index" : " composed") +
                                  (narrow ? " 32-bit line" : " 64-bit line");
        std::vector<std::uint8_t> store_code(previous_code);
        std::vector<std::uint16_t> codes(kSamples);
        std::vector<std::int32_t> store_linear(previous_linear);
        std::vector<std::int64_t> shortfall(kSamples);
        const std::uint64_t unreachable =
            narrow ? fixed_detail::lines::lcd_drive(wanted32.data(), kSamples, *searched, kernels, store_code.data(),
                                                    store_linear.data(), held, codes.data(), shortfall.data())
                   : fixed_detail::lines::lcd_drive(wanted.data(), kSamples, *searched, kernels, store_code.data(),
                                                    store_linear.data(), held, codes.data(), shortfall.data());
        EXPECT_EQ(unreachable, expected_unreachable) << where;
        for (std::size_t s = 0; s < kSamples; ++s) {
          ASSERT_EQ(codes[s], expected_codes[s]) << where << " sample " << s << " wanted " << wanted[s];
          ASSERT_EQ(shortfall[s], expected_shortfall[s]) << where << " sample " << s;
          ASSERT_EQ(store_code[s], expected_store_code[s]) << where << " sample " << s;
          ASSERT_EQ(store_linear[s], expected_store_linear[s]) << where << " sample " << s;
        }
      }
     }
    }
  }
}

// The LCD drive through the composed table (LcdPlan::composed) against FixedKernels::lcd_drive at every code step of
// every row v_{t-1}: the least sum x_t + x_{t-1} whose stage code reaches k, found by bisection of the stage function
// itself, and the sums one below and one above it, on every instruction set; at the default F and at F = 20.
TEST(FixedLines, LcdComposedTableGivesTheStageCodesAtEveryStep) {
  for (const int linear_frac_bits : {28, 20}) {
    const fixed_detail::FixedKernels kernels(lcd_config_at(linear_frac_bits));
    ASSERT_TRUE(kernels.line_plans().lcd.has_value());
    const fixed_detail::LcdPlan& plan = *kernels.line_plans().lcd;
    ASSERT_FALSE(plan.composed.empty()) << "F = " << linear_frac_bits;
    const std::int64_t one = kernels.one();
    const auto stage_code = [&](std::int64_t sum, int row) {
      const std::int64_t wanted = sum / 2;
      return kernels.lcd_drive(wanted, sum - wanted, static_cast<std::uint16_t>(row), false, false).code;
    };
    std::vector<std::int32_t> wanted;
    std::vector<std::int32_t> previous_linear;
    std::vector<std::uint8_t> previous_code;
    std::size_t steps = 0;
    for (int row = 0; row <= plan.top; ++row) {
      for (int k = 1; k <= plan.top; ++k) {
        if (stage_code(2 * one, row) < k) continue;  // the row never reaches k
        std::int64_t lo = 0;
        std::int64_t hi = 2 * one;
        while (lo < hi) {
          const std::int64_t mid = lo + (hi - lo) / 2;
          if (stage_code(mid, row) >= k) {
            hi = mid;
          } else {
            lo = mid + 1;
          }
        }
        ++steps;
        for (const std::int64_t sum : {lo - 1, lo, lo + 1}) {
          if (sum < 0 || sum > 2 * one) continue;
          wanted.push_back(static_cast<std::int32_t>(sum / 2));
          previous_linear.push_back(static_cast<std::int32_t>(sum - sum / 2));
          previous_code.push_back(static_cast<std::uint8_t>(row));
        }
      }
    }
    EXPECT_GT(steps, 255u * 200u) << "most rows step through most codes";
    std::vector<std::uint16_t> expected(wanted.size());
    for (std::size_t s = 0; s < wanted.size(); ++s) {
      expected[s] = kernels.lcd_drive(wanted[s], previous_linear[s], previous_code[s], false, false).code;
    }
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      std::vector<std::uint8_t> store_code(previous_code);
      std::vector<std::int32_t> store_linear(previous_linear);
      std::vector<std::uint16_t> codes(wanted.size());
      fixed_detail::lines::lcd_drive(wanted.data(), wanted.size(), plan, kernels, store_code.data(),
                                     store_linear.data(), false, codes.data(), nullptr);
      for (std::size_t s = 0; s < wanted.size(); ++s) {
        ASSERT_EQ(codes[s], expected[s]) << hwy::TargetName(target) << " F=" << linear_frac_bits << " row "
                                         << int{previous_code[s]} << " sum " << wanted[s] + previous_linear[s];
      }
    }
  }
}

// The LCD search through the per-row index against the binary search of the merge table, at every threshold of every
// row (v_{t-1} = 0 .. 255 and the held row) and one target either side, at 0 and at one, on every instruction set;
// at the default F and at F = 20.
TEST(FixedLines, LcdIndexGivesTheBinarySearchCodesAtEveryThreshold) {
  for (const int linear_frac_bits : {28, 20}) {
    const fixed_detail::FixedKernels kernels(lcd_config_at(linear_frac_bits));
    ASSERT_TRUE(kernels.line_plans().lcd.has_value());
    const fixed_detail::LcdPlan& indexed = *kernels.line_plans().lcd;
    ASSERT_FALSE(indexed.index.empty()) << "F = " << linear_frac_bits;
    fixed_detail::LcdPlan binary = indexed;
    binary.index.clear();
    const auto scale = static_cast<std::int64_t>(indexed.scale);
    std::vector<std::int64_t> targets;
    std::vector<std::int64_t> rows;
    for (std::int64_t r = 0; r <= indexed.width; ++r) {
      for (std::int64_t k = 1; k <= indexed.top; ++k) {
        const std::int64_t u = (indexed.merge[static_cast<std::size_t>(r * indexed.width + k)] + scale - 1) / scale;
        for (const std::int64_t t : {u - 1, u, u + 1}) {
          targets.push_back(std::clamp<std::int64_t>(t, 0, indexed.one));
          rows.push_back(r);
        }
      }
      for (const std::int64_t t : {std::int64_t{0}, indexed.one}) {
        targets.push_back(t);
        rows.push_back(r);
      }
    }
    targets.push_back(indexed.one / 3);  // a tail
    rows.push_back(7);
    // The binary search on scalars (no vector at all: n below one vector) gives the expected codes.
    std::vector<std::uint16_t> expected(targets.size());
    for (std::size_t i = 0; i < targets.size(); ++i) {
      fixed_detail::lines::lcd_search(&targets[i], &rows[i], 1, binary, &expected[i]);
    }
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
      const TargetMock mock(target);
      for (const fixed_detail::LcdPlan* plan : {&indexed, static_cast<const fixed_detail::LcdPlan*>(&binary)}) {
        std::vector<std::uint16_t> codes(targets.size());
        fixed_detail::lines::lcd_search(targets.data(), rows.data(), targets.size(), *plan, codes.data());
        for (std::size_t i = 0; i < targets.size(); ++i) {
          ASSERT_EQ(codes[i], expected[i]) << hwy::TargetName(target) << " F=" << linear_frac_bits
                                           << (plan == &indexed ? " index" : " binary") << " row " << rows[i]
                                           << " target " << targets[i];
        }
      }
    }
  }
}

// The formats the kernels take: the defaults at an 8-bit link (U's sums in 32-bit lanes) and an OLED drive; a 10-bit
// link's U sums exceed 32 bits and an LCD drive is the merge search, so those keep the per-sample steps.
TEST(FixedLines, PlansCoverTheDefaultFormatsAndStepAsideOtherwise) {
  const auto plans_of = [](const FixedDecoderConfig& c) {
    return fixed_detail::FixedLinePlans::build(fixed_detail::FixedKernels(c));
  };
  const FixedDecoderConfig oled = fixed_config(link_config(0.5), "vive");
  EXPECT_TRUE(plans_of(oled).eotf.has_value());
  EXPECT_TRUE(plans_of(oled).drive.has_value());
  EXPECT_TRUE(plans_of(oled).drive_value.has_value());
  EXPECT_TRUE(plans_of(oled).motion.has_value());
  EXPECT_TRUE(plans_of(oled).gaussian.has_value());
  EXPECT_FALSE(plans_of(oled).drive->packed32.empty()) << "the OLED drive search in one lookup at 8 bits";
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5, 0, false, 10), "vive")).gaussian.has_value());
  FixedDecoderConfig still = oled;
  still.decoder.sensitivity = 0.0;  // w = 1 everywhere: the stage function's shortcut
  EXPECT_FALSE(plans_of(still).motion.has_value());
  FixedDecoderConfig octave_exp = oled;
  octave_exp.exp_entries = 1000;  // a segment step that is no power of two
  EXPECT_FALSE(plans_of(octave_exp).motion.has_value());
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5, 0, false, 10), "vive")).eotf.has_value());
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5), "lcd")).drive.has_value());
  EXPECT_TRUE(plans_of(fixed_config(link_config(0.5), "lcd")).lcd.has_value());
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5), "lcd", 10)).lcd.has_value()) << "no merge table at 10 bits";
  EXPECT_FALSE(plans_of(oled).lcd.has_value());
  EXPECT_FALSE(plans_of(with_kernels(oled, false, true)).eotf.has_value());
  FixedDecoderConfig narrow_shift = oled;
  narrow_shift.bilinear_weight_frac_bits = 16;  // 2W = U: U's blend is not rounded, only padded
  EXPECT_FALSE(plans_of(narrow_shift).eotf.has_value());
}

}  // namespace
}  // namespace trm
