// The 64-bit shortcuts of the hot paths against the 128-bit quantiser they stand in for: rounded_shift on int64 at the
// extremes of the range and every shift, and LUT interpolation at every weight width, in tables whose words and
// steps make the shortcut apply, stop applying, or never apply (rounding other than half up).
#include "trm/fixed_runtime.hpp"
#include "trm/lut.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace trm::fx {
namespace {

TEST(FastPath, RoundedShiftOnInt64MatchesTheWideQuantiserAtTheExtremes) {
  std::mt19937_64 rng(31);
  const std::int64_t edges[] = {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::min() + 1,
                                -1, 0, 1, std::numeric_limits<std::int64_t>::max() - 1,
                                std::numeric_limits<std::int64_t>::max()};
  for (const Quant q : kAllQuantModes) {
    for (int shift = 1; shift <= 63; ++shift) {
      for (int i = 0; i < 64; ++i) {
        const std::int64_t raw = i < 7 ? edges[i] : static_cast<std::int64_t>(rng());
        EXPECT_EQ(rounded_shift(raw, shift, q),
                  static_cast<std::int64_t>(rounded_shift(static_cast<detail::int128>(raw), shift, q)))
            << to_string(q) << " " << raw << " >> " << shift;
      }
    }
  }
}

// y0 + (y1 - y0) w / 2^bits rounded by the table's own mode, exactly (the definition interpolate implements).
std::int64_t exact_interpolation(const InterpolatedLut& lut, std::size_t node, std::uint64_t weight, int bits) {
  const auto& rom = lut.rom();
  if (node >= rom.size() - 1) return rom.back();
  const detail::int128 exact = detail::shift_left(rom[node], bits) +
                               static_cast<detail::int128>(rom[node + 1] - rom[node]) * static_cast<std::int64_t>(weight);
  const LutShape& s = lut.shape();
  return static_cast<std::int64_t>(
      detail::convert(exact, bits, {s.output_bits, 0, s.output_signed, s.rounding, Overflow::Sat}, nullptr));
}

TEST(FastPath, InterpolationMatchesTheExactRoundingAtEveryWeightWidth) {
  std::mt19937_64 rng(47);
  for (const Quant rounding : {Quant::Rnd, Quant::RndConv, Quant::Trn}) {
    for (const bool is_signed : {false, true}) {
      for (const int output_bits : {12, 29, 32}) {
        LutShape shape;
        shape.entries = 65;
        shape.input_bits = 16;
        shape.output_bits = output_bits;
        shape.output_frac_bits = output_bits - (is_signed ? 2 : 1);
        shape.output_signed = is_signed;
        shape.rounding = rounding;
        // A steep signed function exercises negative words and large steps.
        const InterpolatedLut lut("test", shape, 65536.0,
                                  [is_signed](double t) { return is_signed ? std::sin(9.0 * t) : t * t; });
        for (int bits = 1; bits <= 62; ++bits) {
          for (int i = 0; i < 40; ++i) {
            const std::size_t node = static_cast<std::size_t>(rng() % 66);
            const std::uint64_t weight = i == 0 ? 0 : i == 1 ? (std::uint64_t{1} << bits) - 1 : rng() >> (64 - bits);
            EXPECT_EQ(lut.interpolate(node, weight, bits), exact_interpolation(lut, node, weight, bits))
                << to_string(rounding) << " out " << output_bits << (is_signed ? "s" : "u") << " bits " << bits
                << " node " << node << " weight " << weight;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace trm::fx
