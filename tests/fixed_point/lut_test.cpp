// Every LUT function swept over every representable input against the std:: function; the bounds
// are the measured errors of docs/fixed_point.md, so a change in accuracy is a deliberate one.
#include "lut_reference.hpp"

#include "trm/lut.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace trm::fx {
namespace {

using testing::measure;
using testing::reference_functions;

struct Bound {
  const char* label;
  int octaves;            // 0: uniform
  std::int64_t max_lsb;   // max |lut − Q(f)| in output LSB, 257 entries, 16-bit in, 16-bit out
};

// The 257-entry rows of the table in docs/fixed_point.md.
constexpr Bound kBounds257[] = {
    {"sRGB EOTF", 0, 1},          {"sRGB EOTF", 16, 24},
    {"sRGB inverse EOTF", 0, 115}, {"sRGB inverse EOTF", 16, 7},
    {"x^2.2", 0, 1},              {"x^2.2", 16, 21},
    {"x^(1/2.2)", 0, 1490},       {"x^(1/2.2)", 16, 6},
    {"exp(-x), x in [0,16), Q4.12 in", 0, 31}, {"exp(-x), x in [0,16), Q4.12 in", 16, 16},
    {"1/x, x in [1,2), uQ1.15 out", 0, 1},     {"1/x, x in [1,2), uQ1.15 out", 16, 3},
    {"sqrt(x)", 0, 1024},         {"sqrt(x)", 16, 6},
};

TEST(Lut, EveryFunctionStaysWithinItsDocumentedBoundOverEveryInput) {
  int checked = 0;
  for (const auto& function : reference_functions()) {
    for (const Bound& bound : kBounds257) {
      if (function.label != bound.label) continue;
      LutShape shape;
      shape.entries = 257;
      shape.octaves = bound.octaves;
      shape.output_bits = function.output_bits;
      shape.output_frac_bits = function.output_frac_bits;
      const InterpolatedLut lut = function.make(shape);
      const testing::LutError e = measure(lut, function.exact, function.direction);
      EXPECT_EQ(e.codes, 1 << 16);
      EXPECT_LE(e.max_lsb_vs_quantised, bound.max_lsb) << function.label << ", octaves " << bound.octaves;
      EXPECT_TRUE(e.monotonic) << function.label << ", octaves " << bound.octaves;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 14);
}

// With enough entries interpolation error vanishes below the rounding of the output: at most the
// two roundings (ROM word, interpolated result) remain.
TEST(Lut, LargeTablesReachOneLsb) {
  LutShape shape;
  shape.entries = 1025;
  shape.octaves = 16;
  const auto& functions = reference_functions();
  for (const char* label : {"sRGB inverse EOTF", "x^(1/2.2)", "sqrt(x)"}) {
    for (const auto& f : functions) {
      if (f.label != label) continue;
      EXPECT_LE(measure(f.make(shape), f.exact, f.direction).max_lsb_vs_quantised, 1) << label;
    }
  }
}

// Direct mode: one ROM word per link code (8 and 10 bit, full-range codes q/(2^b − 1)): exactly the
// rounded function, no interpolation.
TEST(Lut, DirectSrgbEotfTablesAreExactlyTheRoundedFunction) {
  for (const int bits : {8, 10}) {
    LutShape shape;
    shape.entries = 1 << bits;
    shape.input_bits = bits;
    shape.input_scale = InputScale::FullRange;
    const InterpolatedLut lut = make_srgb_eotf_lut(shape);
    EXPECT_TRUE(lut.is_direct());
    EXPECT_EQ(lut.position_of((1u << bits) - 1u), 1.0);
    const auto e = measure(lut, testing::srgb_eotf_exact, testing::Monotonic::Increasing);
    EXPECT_EQ(e.max_lsb_vs_quantised, 0) << bits << "-bit";
    EXPECT_TRUE(e.monotonic);
    EXPECT_EQ(lut.rom_size().bits(), (std::int64_t{1} << bits) * 16);
  }
}

// Full-range interpolated input: nodes sit at non-integer codes and the segment position comes from
// the rounded constant K; the error stays at the rounding level.
TEST(Lut, FullRangeInterpolatedInputReachesBothEnds) {
  LutShape shape;
  shape.entries = 129;
  shape.input_bits = 10;
  shape.input_scale = InputScale::FullRange;
  shape.output_bits = 16;
  shape.output_frac_bits = 15;  // uQ1.15: 1.0 representable
  const InterpolatedLut lut = make_gamma_lut(2.2, shape);
  EXPECT_FALSE(lut.is_direct());
  EXPECT_EQ(lut.evaluate_raw(0), 0);
  EXPECT_EQ(lut.evaluate_raw(1023), 1 << 15);
  const auto e = measure(lut, [](double t) { return std::pow(t, 2.2); }, testing::Monotonic::Increasing);
  EXPECT_LE(e.max_lsb_vs_quantised, 4);
  EXPECT_TRUE(e.monotonic);
}

TEST(Lut, ExpClampsBeyondItsRange) {
  LutShape shape;
  shape.input_bits = 16;  // Q4.12 codes cover [0, 16), the table only [0, 10]
  const InterpolatedLut lut = make_exp_neg_lut(10.0, 12, shape);
  const std::int64_t tail = lut.rom().back();
  EXPECT_EQ(lut.evaluate_raw(10u << 12), tail);
  EXPECT_EQ(lut.evaluate_raw(65535), tail);
  EXPECT_EQ(lut.evaluate_raw(0), 65535);  // exp(0) = 1 saturates in uQ0.16
  const auto e = measure(lut, [](double t) { return std::exp(-10.0 * std::min(t, 1.0)); },
                         testing::Monotonic::Decreasing);
  EXPECT_LE(e.max_lsb_vs_quantised, 13);
  EXPECT_TRUE(e.monotonic);
}

TEST(Lut, ReportsItsRomSize) {
  LutShape shape;
  shape.entries = 65;
  shape.output_bits = 12;
  shape.output_frac_bits = 12;
  const InterpolatedLut lut = make_sqrt_lut(shape);
  EXPECT_EQ(lut.rom_size().entries, 65);
  EXPECT_EQ(lut.rom_size().word_bits, 12);
  EXPECT_EQ(lut.rom_size().bits(), 65 * 12);
  EXPECT_EQ(lut.name(), "sqrt");
}

TEST(Lut, ReciprocalOfAnyPositiveValueThroughNormalisation) {
  LutShape shape;
  shape.entries = 257;
  shape.output_bits = 16;
  shape.output_frac_bits = 15;
  const InterpolatedLut lut = make_reciprocal_lut(shape);
  std::mt19937_64 rng(5);
  double worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t value = (rng() >> (rng() % 63)) | 1u;
    const int frac_bits = static_cast<int>(rng() % 40);
    const NormalisedReciprocal r = reciprocal_normalised(lut, value, frac_bits);
    const double ours = std::ldexp(static_cast<double>(r.mantissa_raw), -15 - r.exponent);
    const double exact = 1.0 / std::ldexp(static_cast<double>(value), -frac_bits);
    worst = std::max(worst, std::abs(ours / exact - 1.0));
  }
  // Relative error: the LUT's 1.032 LSB of Q1.15 (docs table) on a result >= 0.5 is 1.032·2^-14,
  // plus up to 2^-16 from truncating the mantissa to the LUT's 16 input bits.
  EXPECT_LT(worst, 1.04 / 16384 + 1.0 / 65536);
  EXPECT_GT(worst, 0.0);
  EXPECT_THROW(reciprocal_normalised(lut, 0, 0), std::invalid_argument);
}

TEST(Lut, InvalidConfigurationsThrowWithAClearMessage) {
  const auto message_of = [](auto&& make) {
    try {
      make();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const auto with = [](auto change) {
    LutShape s;
    change(s);
    return s;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.entries = 1; })); }).find("entries"), std::string::npos);
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.entries = 65537; })); }).find("entries"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.output_bits = 33; })); }).find("output_bits"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.output_bits = 0; })); }).find("output_bits"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.input_bits = 25; })); }).find("input_bits"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.octaves = 5; })); }).find("octaves"),
            std::string::npos);  // 256 segments are not 5·2^k
  EXPECT_NE(message_of([&] { make_sqrt_lut(with([](LutShape& s) { s.octaves = -1; })); }).find("octaves"),
            std::string::npos);
  for (const double bad : {0.0, -1.0, nan, inf}) {
    EXPECT_NE(message_of([&] { make_exp_neg_lut(bad, 12, LutShape{}); }).find("xmax"), std::string::npos) << bad;
    EXPECT_NE(message_of([&] { make_gamma_lut(bad, LutShape{}); }).find("gamma"), std::string::npos) << bad;
    EXPECT_NE(message_of([&] { make_inverse_gamma_lut(bad, LutShape{}); }).find("gamma"), std::string::npos) << bad;
    EXPECT_NE(message_of([&] { make_power_lut(bad, LutShape{}); }).find("exponent"), std::string::npos) << bad;
  }
  EXPECT_EQ(message_of([&] { make_sqrt_lut(LutShape{}); }), "accepted");
}

// The ROM contents are a function of the configuration only; pin one table so that an unintended
// change of generator or rounding shows up here (DESIGN §6: golden vectors change deliberately).
TEST(Lut, GeneratedRomIsStable) {
  LutShape shape;
  shape.entries = 17;
  const InterpolatedLut lut = make_srgb_eotf_lut(shape);
  const std::vector<std::int64_t> expected = {0,     338,   940,   1923,  3334,  5215,  7603,  10530, 14027,
                                              18122, 22840, 28206, 34244, 40975, 48421, 56601, 65535};
  EXPECT_EQ(lut.rom(), expected);
}

}  // namespace
}  // namespace trm::fx
