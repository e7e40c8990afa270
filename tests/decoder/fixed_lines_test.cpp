// The line kernels (FixedDecoderConfig::line_kernels, decoder/src/fixed_lines.hpp) against the per-sample stage
// functions they replace: the same drive codes, report planes, statistics and counters, on every instruction set
// Highway compiled them for that this CPU runs (the scalar target included), with line widths that leave vector
// tails.
#include "fixed_decoder_test_support.hpp"
#include "fixed_kernels.hpp"
#include "fixed_lines.hpp"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdint>
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

// Restores the CPU's own targets when a test ends.
struct TargetMock {
  explicit TargetMock(std::int64_t target) { hwy::SetSupportedTargetsForTest(target); }
  ~TargetMock() { hwy::SetSupportedTargetsForTest(0); }
  TargetMock(const TargetMock&) = delete;
  TargetMock& operator=(const TargetMock&) = delete;
};

FixedDecoderConfig with_kernels(FixedDecoderConfig config, bool kernels, bool planes) {
  config.line_kernels = kernels;
  config.report_planes = planes;
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
  };
  // 67 pixels: 201 samples per line, a tail after every vector width; r = 0.4 gives non-dyadic U weights.
  const std::vector<Case> cases = {
      {"panorama", 0.5, "vive", 8, false, true},  {"discs", 0.4, "rift", 10, false, true},
      {"checker", 0.5, "vive", 8, true, false},   {"text", 0.75, "vive", 8, false, true},
      {"zoneplate", 0.25, "rift", 8, false, true}, {"flash", 0.5, "vive", 10, false, true},
      {"jitter", 0.5, "vive", 8, false, false},
  };
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  for (const std::int64_t target : targets) {
    const TargetMock mock(target);
    ASSERT_STREQ(fixed_detail::lines::target_name(), hwy::TargetName(target)) << "the dispatch follows the mock";
    for (const Case& c : cases) {
      const EncoderConfig link = link_config(c.r, 0, c.stereo);
      const auto frames = encode_sequence(scene_images(c.scene, 67, 46, 6), link);
      FixedDecoderConfig config = fixed_config(link, c.panel, c.output_bits);
      config.skip_unneeded = c.skip;
      for (const bool planes : {true, false}) {
        expect_kernels_identical(frames, config, planes,
                                 std::string(hwy::TargetName(target)) + " " + c.scene + " r=" + std::to_string(c.r) +
                                     " " + c.panel + " " + std::to_string(c.output_bits) + "-bit");
        if (HasFatalFailure()) return;
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
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5, 0, false, 10), "vive")).eotf.has_value());
  EXPECT_FALSE(plans_of(fixed_config(link_config(0.5), "lcd")).drive.has_value());
  EXPECT_FALSE(plans_of(with_kernels(oled, false, true)).eotf.has_value());
  FixedDecoderConfig narrow_shift = oled;
  narrow_shift.bilinear_weight_frac_bits = 16;  // 2W = U: U's blend is not rounded, only padded
  EXPECT_FALSE(plans_of(narrow_shift).eotf.has_value());
}

}  // namespace
}  // namespace trm
