// The 64-bit shortcuts of the hot paths against the 128-bit quantiser they stand in for: rounded_shift on int64 at the
// extremes of the range and every shift, and LUT interpolation at every weight width, in tables whose words and
// steps make the shortcut apply, stop applying, or never apply (rounding other than half up); and the rounded
// quotient's double estimate against the 128-bit division.
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

// rounded_quotient against the division it stands in for: quotients a half away from an integer and either side of
// it (where an estimate off by one must be corrected, in both directions), quotients either side of the estimate's
// bound 2^50 and operands either side of 2^64 (the division itself), at every shift of the fast path and beyond.
TEST(FastPath, RoundedQuotientIsTheDivisionsQuotient) {
  using detail::uint128;
  std::mt19937_64 rng(43);
  std::uint64_t checked = 0;
  std::uint64_t estimates_high = 0;
  std::uint64_t estimates_low = 0;
  const auto check = [&](uint128 part, int shift, uint128 denominator) {
    if (denominator == 0) return;
    const uint128 expected = ((part << shift) + denominator / 2) / denominator;
    if ((expected >> 64) != 0) return;
    constexpr uint128 k64 = uint128{1} << 64;
    if (part < k64 && denominator < k64 && shift <= 30 && (part >> (50 - shift)) < denominator) {
      // The estimate rounded_quotient starts from, where it takes it: how often the products must settle it.
      const double part_value = static_cast<double>(static_cast<std::uint64_t>(part));
      const double denominator_value = static_cast<double>(static_cast<std::uint64_t>(denominator));
      const auto estimate =
          static_cast<std::uint64_t>(part_value * std::ldexp(1.0, shift) / denominator_value + 0.5);
      estimates_high += estimate > expected ? 1 : 0;
      estimates_low += estimate < expected ? 1 : 0;
    }
    ASSERT_EQ(detail::rounded_quotient(part, shift, denominator), static_cast<std::uint64_t>(expected))
        << "part " << static_cast<std::uint64_t>(part) << " (high " << static_cast<std::uint64_t>(part >> 64)
        << ") shift " << shift << " denominator " << static_cast<std::uint64_t>(denominator) << " (high "
        << static_cast<std::uint64_t>(denominator >> 64) << ")";
    ++checked;
  };
  for (int shift = 0; shift <= 34; ++shift) {
    for (int i = 0; i < 4000; ++i) {
      // An odd denominator 2d + 1 and q + 1/2 = (part 2^shift + d) / (2d + 1) + 1/2: part 2^shift = q (2d + 1) + d
      // + delta sits delta / (2d + 1) from the half (delta in [-2, 2]); part is its multiple of 2^shift at or below,
      // and the next.
      const int denominator_bits = 1 + static_cast<int>(rng() % 63);
      const uint128 denominator = (rng() >> (64 - denominator_bits)) | 1;
      const int quotient_bits = static_cast<int>(rng() % 52);
      const uint128 q = quotient_bits == 0 ? 0 : rng() >> (64 - quotient_bits);
      for (int delta = -2; delta <= 2; ++delta) {
        const uint128 scaled =
            q * denominator + denominator / 2 + static_cast<uint128>(static_cast<std::int64_t>(delta));
        check(scaled >> shift, shift, denominator);
        check((scaled >> shift) + 1, shift, denominator);
      }
      // Random operands, the largest part first.
      check(rng(), shift, rng() >> (rng() % 64));
      check(rng() >> (rng() % 64), shift, (rng() >> (rng() % 64)) + 1);
    }
    // The estimate's bound: quotients 2^50 - 1, 2^50, 2^50 + 1 before rounding.
    for (const std::uint64_t denominator :
         {std::uint64_t{1}, std::uint64_t{3}, std::uint64_t{1} << 13, (std::uint64_t{1} << 13) + 1}) {
      for (const std::int64_t d : {-1, 0, 1}) {
        const uint128 target = (uint128{1} << 50) + static_cast<uint128>(d);
        check((target * denominator) >> shift, shift, denominator);
      }
    }
    // Operands at and past 64 bits.
    const uint128 k64 = uint128{1} << 64;
    for (const uint128 part : {k64 - 1, k64, k64 + 1}) {
      for (const uint128 denominator : {k64 - 1, k64, k64 + 1, uint128{1} << 80}) check(part, shift, denominator);
    }
  }
  EXPECT_GT(checked, 34u * 4000u * 10u);
  EXPECT_GT(estimates_high, 100u) << "estimates above the quotient";
  EXPECT_GT(estimates_low, 100u) << "estimates below the quotient";
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
