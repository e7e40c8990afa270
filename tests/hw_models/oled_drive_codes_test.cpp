// OledDriveCodes against its definition, quantise(OledPanel::drive(x, c), 2^bits - 1) a pow per sample: on every
// double within 300 ulps (the guard is 256) of each code's crossing, where the guard hands over to the pow and back;
// on random values over and beyond [0, 1]; on the special values; for even and uneven gammas at the ends of their
// range.
#include "trm/oled_drive_codes.hpp"

#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace trm {
namespace {

OledPanel oled_with(std::array<double, 3> gamma) {
  OledPanel panel;
  panel.gamma = gamma;
  return panel;
}

std::uint16_t code_by_pow(const OledPanel& panel, double x, int channel, int bits) {
  return quantise(panel.drive(x, channel), (1 << bits) - 1);
}

// Every double from `span` ulps below to `span` ulps above each code's exact crossing ((k - 1/2) / top)^gamma, every
// `code_step`-th code, on each channel: one at a time (code) and as a row with the value at its channel's places
// (codes, what the decoders call).
void expect_exact_around_crossings(const OledPanel& panel, int bits, std::int64_t span, int code_step) {
  const OledDriveCodes codes(panel, bits);
  const int top = (1 << bits) - 1;
  for (int channel = 0; channel < 3; ++channel) {
    const double gamma = panel.gamma[static_cast<std::size_t>(channel)];
    std::vector<double> row;
    for (int k = 1; k <= top; k += code_step) {
      const auto centre = std::bit_cast<std::int64_t>(std::pow((k - 0.5) / top, gamma));
      for (std::int64_t d = -span; d <= span; ++d) {
        const double x = std::bit_cast<double>(centre + d);
        ASSERT_EQ(codes.code(x, channel), code_by_pow(panel, x, channel, bits))
            << "bits " << bits << " gamma " << gamma << " code " << k << " x " << x << " (" << d << " ulps)";
        for (int c = 0; c < 3; ++c) row.push_back(c == channel ? x : 0.5);
      }
    }
    std::vector<std::uint16_t> out(row.size());
    ASSERT_TRUE(codes.codes(row, out));
    for (std::size_t i = static_cast<std::size_t>(channel); i < row.size(); i += 3) {
      ASSERT_EQ(out[i], code_by_pow(panel, row[i], channel, bits)) << "bits " << bits << " gamma " << gamma << " x " << row[i];
    }
    EXPECT_GT(row.size(), std::size_t{0});
  }
}

const std::array<std::array<double, 3>, 3> kGammas{{{2.2, 2.2, 2.2}, {kMinPanelGamma, 1.0, kMaxPanelGamma}, {1.8, 2.2, 2.6}}};

TEST(OledDriveCodes, EveryDoubleNearEachCodesCrossingHasThePowsCode) {
  for (const auto& gamma : kGammas) {
    const OledPanel panel = oled_with(gamma);
    for (const int bits : {1, 2, 8}) expect_exact_around_crossings(panel, bits, 300, 1);
    expect_exact_around_crossings(panel, 10, 300, 3);
    expect_exact_around_crossings(panel, 12, 300, 29);
    expect_exact_around_crossings(panel, 16, 300, 1021);
  }
}

TEST(OledDriveCodes, RandomAndSpecialValuesHaveThePowsCode) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> special{0.0,  -0.0, std::numeric_limits<double>::denorm_min(), 1e-300, 1e-12, 0.5,
                                    std::nextafter(1.0, 0.0), 1.0, std::nextafter(1.0, 2.0), 2.0, -1e-12, -1.0,
                                    inf, -inf};
  std::mt19937_64 rng(20261207);
  std::uniform_real_distribution<double> wide(-0.1, 1.1);
  std::uniform_real_distribution<double> octave(-40.0, 0.0);  // log2 x: the dark end, where codes lie far apart
  for (const auto& gamma : kGammas) {
    const OledPanel panel = oled_with(gamma);
    for (const int bits : {1, 8, 10, 16}) {
      const OledDriveCodes codes(panel, bits);
      std::vector<double> x = special;
      for (int i = 0; i < 30000; ++i) x.push_back(i % 2 == 0 ? wide(rng) : std::exp2(octave(rng)));
      std::vector<std::uint16_t> row(x.size());
      ASSERT_TRUE(codes.codes(x, row));
      for (std::size_t i = 0; i < x.size(); ++i) {
        const int channel = static_cast<int>(i % 3);
        ASSERT_EQ(row[i], code_by_pow(panel, x[i], channel, bits)) << "bits " << bits << " x " << x[i] << " channel " << channel;
        ASSERT_EQ(codes.code(x[i], channel), row[i]);
      }
    }
  }
}

TEST(OledDriveCodes, NanGivesCodeZeroAndIsReported) {
  const OledDriveCodes codes(oled_with({2.2, 2.2, 2.2}), 8);
  const std::vector<double> x{0.25, std::numeric_limits<double>::quiet_NaN(), 1.0};
  std::vector<std::uint16_t> out(3, 7);
  EXPECT_FALSE(codes.codes(x, out));
  EXPECT_EQ(out[1], 0);
  EXPECT_EQ(out[0], code_by_pow(oled_with({2.2, 2.2, 2.2}), 0.25, 0, 8));
  EXPECT_EQ(out[2], 255);
  const std::vector<double> clean{0.25, 0.5, 1.0};
  EXPECT_TRUE(codes.codes(clean, out));
}

TEST(OledDriveCodes, RefusesWhatItCannotServe) {
  const OledPanel panel = oled_with({2.2, 2.2, 2.2});
  EXPECT_THROW(OledDriveCodes(panel, 0), std::invalid_argument);
  EXPECT_THROW(OledDriveCodes(panel, 17), std::invalid_argument);
  EXPECT_THROW(OledDriveCodes(oled_with({2.2, 9.0, 2.2}), 8), std::invalid_argument);
  const OledDriveCodes codes(panel, 8);
  EXPECT_THROW(codes.code(0.5, 3), std::invalid_argument);
  std::vector<std::uint16_t> shorter(2);
  EXPECT_THROW(codes.codes(std::vector<double>(3, 0.5), shorter), std::invalid_argument);
}

}  // namespace
}  // namespace trm
