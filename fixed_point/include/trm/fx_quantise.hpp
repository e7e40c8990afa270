// Quantisation and overflow handling shared by the compile-time type (trm/fixed.hpp) and the
// run-time formats (trm/fixed_runtime.hpp). Semantics are SystemC's sc_fixed / ac_types' ac_fixed:
// an exact value is first quantised to the target's LSB (Quant), then brought into the target's
// range (Overflow). Both steps happen only when a value is converted into a narrower format.
//
// Everything here works on raw integers: a value is `raw * 2^-frac_bits`. Exact intermediate values
// are held in a signed 128-bit integer, which covers every value the library produces (at most a
// 64-bit source shifted, or a 66-bit sum), so nothing here can overflow or shift out of range.
#pragma once

#include <bit>
#include <cstdint>

namespace trm::fx {

// Quantisation (rounding) modes; SystemC name in brackets. "Tie" means the dropped bits are exactly
// one half LSB of the target.
enum class Quant {
  Trn,        // floor, toward −∞ (SC_TRN): drop the bits
  TrnZero,    // toward zero (SC_TRN_ZERO)
  Rnd,        // nearest, tie toward +∞ (SC_RND)
  RndZero,    // nearest, tie toward zero (SC_RND_ZERO)
  RndInf,     // nearest, tie away from zero (SC_RND_INF)
  RndMinInf,  // nearest, tie toward −∞ (SC_RND_MIN_INF)
  RndConv,    // nearest, tie to even (SC_RND_CONV)
};

// Overflow modes, applied after quantisation.
enum class Overflow {
  Wrap,     // keep the low W bits, two's complement for signed targets (SC_WRAP, n_bits = 0)
  Sat,      // clamp to the target's min / max (SC_SAT)
  SatZero,  // any overflow gives 0 (SC_SAT_ZERO)
  SatSym,   // clamp to ±max, so a signed result is never the asymmetric minimum (SC_SAT_SYM)
};

inline constexpr Quant kAllQuantModes[] = {Quant::Trn,    Quant::TrnZero,   Quant::Rnd,    Quant::RndZero,
                                           Quant::RndInf, Quant::RndMinInf, Quant::RndConv};
inline constexpr Overflow kAllOverflowModes[] = {Overflow::Wrap, Overflow::Sat, Overflow::SatZero,
                                                 Overflow::SatSym};

constexpr const char* to_string(Quant q) {
  switch (q) {
    case Quant::Trn: return "Trn";
    case Quant::TrnZero: return "TrnZero";
    case Quant::Rnd: return "Rnd";
    case Quant::RndZero: return "RndZero";
    case Quant::RndInf: return "RndInf";
    case Quant::RndMinInf: return "RndMinInf";
    case Quant::RndConv: return "RndConv";
  }
  return "?";
}

constexpr const char* to_string(Overflow o) {
  switch (o) {
    case Overflow::Wrap: return "Wrap";
    case Overflow::Sat: return "Sat";
    case Overflow::SatZero: return "SatZero";
    case Overflow::SatSym: return "SatSym";
  }
  return "?";
}

// Optional event counter a caller passes to conversions so a pipeline can report how often it
// clipped. Counting is opt-in (a null pointer costs one predictable branch).
struct SaturationCounter {
  // Conversions whose overflow stage changed the quantised value: a saturation, a zeroing, a wrap,
  // or SatSym's move of the signed minimum to −max.
  std::uint64_t overflows = 0;
  // divide() calls with a zero divisor (their result is defined, see trm/fixed.hpp).
  std::uint64_t divisions_by_zero = 0;

  constexpr void reset() { *this = SaturationCounter{}; }
};

// Formats are limited so every shift amount computed from them stays a small int.
inline constexpr int kMaxFormatWidth = 64;
inline constexpr int kMaxFracBitsMagnitude = 1024;

namespace detail {

__extension__ typedef __int128 int128;
__extension__ typedef unsigned __int128 uint128;

// Left shift without ever shifting a negative number (done on the unsigned bit pattern).
// Callers guarantee the mathematical result fits in 127 bits.
constexpr int128 shift_left(int128 x, int s) { return static_cast<int128>(static_cast<uint128>(x) << s); }

// floor(x / 2^s) for 0 <= s < 128, without shifting a negative number: for x < 0, ~x = −x − 1 >= 0
// and floor(x / 2^s) = ~(~x >> s).
constexpr int128 floor_shift_right(int128 x, int s) { return x >= 0 ? (x >> s) : ~((~x) >> s); }

// floor((part 2^shift + floor(denominator / 2)) / denominator): part 2^shift / denominator rounded half up, for
// denominator > 0, 0 <= shift < 128 and a result below 2^64. Where part and the denominator fit 64 bits, shift <= 30
// and the quotient q is below 2^50, their doubles give q within 3 q 2^-53 + ulp(q) / 2 < 1/2, so that the estimate
// is the result or one either side of it, which two exact products settle: a few instructions where the 128-bit
// division is a library call.
inline std::uint64_t rounded_quotient(uint128 part, int shift, uint128 denominator) {
  const uint128 rounded = (part << shift) + denominator / 2;
  constexpr uint128 k64 = uint128{1} << 64;
  if (part >= k64 || denominator >= k64 || shift > 30 || (part >> (50 - shift)) >= denominator) {
    return static_cast<std::uint64_t>(rounded / denominator);
  }
  const double scale = static_cast<double>(std::uint64_t{1} << shift);
  auto quotient = static_cast<std::uint64_t>(static_cast<double>(static_cast<std::uint64_t>(part)) * scale /
                                                 static_cast<double>(static_cast<std::uint64_t>(denominator)) +
                                             0.5);
  if (quotient * denominator > rounded) {
    --quotient;
  } else if ((quotient + 1) * denominator <= rounded) {
    ++quotient;
  }
  return quotient;
}

// Number of significant bits of |x| (0 for x = 0).
constexpr int magnitude_bits(int128 x) {
  const uint128 m = x >= 0 ? static_cast<uint128>(x) : static_cast<uint128>(~x) + 1u;
  const auto hi = static_cast<std::uint64_t>(m >> 64);
  const auto lo = static_cast<std::uint64_t>(m);
  return hi != 0 ? 128 - std::countl_zero(hi) : 64 - std::countl_zero(lo);
}

// The rounding decision, as in ac_types: from the sign of the exact value, the lowest kept bit,
// the first dropped bit and the OR of the remaining dropped bits, decide whether to add one LSB to
// the floor.
constexpr bool round_up(Quant q, bool negative, bool kept_lsb, bool first_dropped, bool rest_dropped) {
  switch (q) {
    case Quant::Trn: return false;
    case Quant::TrnZero: return negative && (first_dropped || rest_dropped);
    case Quant::Rnd: return first_dropped;
    case Quant::RndZero: return first_dropped && (rest_dropped || negative);
    case Quant::RndInf: return first_dropped && (rest_dropped || !negative);
    case Quant::RndMinInf: return first_dropped && rest_dropped;
    case Quant::RndConv: return first_dropped && (rest_dropped || kept_lsb);
  }
  return false;
}

// Target format of a conversion, in the form the core needs.
struct Target {
  int width;  // 1..64
  int frac_bits;
  bool is_signed;
  Quant quant;
  Overflow overflow;
};

constexpr int128 min_raw(int width, bool is_signed) {
  return is_signed ? -shift_left(1, width - 1) : 0;
}
constexpr int128 max_raw(int width, bool is_signed) {
  return shift_left(1, is_signed ? width - 1 : width) - 1;
}

// Result of the quantisation stage: floor plus rounding increment. A value of 2^65 target LSBs or
// more overflows every target of <= 64 bits; it is marked `huge` and `raw` then holds only its low
// 128 bits (all that wrapping needs).
struct Quantised {
  int128 raw;
  bool huge;
  bool huge_negative;
};

constexpr Quantised quantise_only(int128 raw_in, int in_frac_bits, int out_frac_bits, Quant q) {
  const int shift = in_frac_bits - out_frac_bits;  // > 0: bits are dropped
  if (raw_in == 0) return {0, false, false};
  if (shift <= 0) {
    const int up = -shift;
    // |raw_in| < 2^bits, so |raw_in << up| >= 2^(bits - 1 + up); beyond 2^65 every target overflows.
    const int128 low_bits = up < 128 ? shift_left(raw_in, up) : 0;
    if (magnitude_bits(raw_in) + up > 66) return {low_bits, true, raw_in < 0};
    return {low_bits, false, false};
  }
  const bool negative = raw_in < 0;
  int128 kept;
  bool first_dropped;
  bool rest_dropped;
  if (shift >= 127 || magnitude_bits(raw_in) < shift - 1) {
    // |raw_in| < 2^(shift-1): the floor is 0 or −1. For x >= 0 the first dropped bit is 0 and the
    // rest is x; for x < 0 the dropped part 2^shift + x exceeds one half, with a non-zero rest.
    kept = negative ? -1 : 0;
    first_dropped = negative;
    rest_dropped = true;  // raw_in != 0 here
  } else {
    kept = floor_shift_right(raw_in, shift);
    const int128 dropped = raw_in - shift_left(kept, shift);  // in [0, 2^shift)
    first_dropped = ((dropped >> (shift - 1)) & 1) != 0;
    rest_dropped = (dropped & (shift_left(1, shift - 1) - 1)) != 0;
  }
  const bool up = round_up(q, negative, (kept & 1) != 0, first_dropped, rest_dropped);
  return {kept + (up ? 1 : 0), false, false};
}

// Overflow stage: brings an exact quantised raw value into the target range.
constexpr int128 apply_overflow(const Quantised& v, const Target& t, SaturationCounter* counter) {
  const int128 lo = min_raw(t.width, t.is_signed);
  const int128 hi = max_raw(t.width, t.is_signed);
  const bool above = v.huge ? !v.huge_negative : v.raw > hi;
  const bool below = v.huge ? v.huge_negative : v.raw < lo;
  // SatSym on a signed target never yields the minimum: that value is also replaced by −max.
  const bool sym_min = t.overflow == Overflow::SatSym && t.is_signed && !v.huge && v.raw == lo;
  if (!above && !below && !sym_min) return v.raw;
  if (counter != nullptr) ++counter->overflows;
  switch (t.overflow) {
    case Overflow::Wrap: {
      const uint128 mask = (static_cast<uint128>(1) << t.width) - 1u;
      const uint128 bits = static_cast<uint128>(v.raw) & mask;
      if (t.is_signed && ((bits >> (t.width - 1)) & 1u) != 0) {
        return -static_cast<int128>((mask - bits) + 1u);
      }
      return static_cast<int128>(bits);
    }
    case Overflow::Sat: return above ? hi : lo;
    case Overflow::SatZero: return 0;
    case Overflow::SatSym:
      if (above) return hi;
      return t.is_signed ? -hi : lo;
  }
  return v.raw;
}

// The whole conversion: value raw_in * 2^-in_frac_bits into target t. Returns the target raw value.
constexpr int128 convert(int128 raw_in, int in_frac_bits, const Target& t, SaturationCounter* counter) {
  return apply_overflow(quantise_only(raw_in, in_frac_bits, t.frac_bits, t.quant), t, counter);
}

}  // namespace detail

// raw * 2^-shift rounded to an integer with q, without an overflow stage: for an accumulator brought back onto its
// result's LSB where the result format holds every value by construction. It is the quantisation step of every
// conversion above, so arithmetic that rounds with it rounds exactly as the Fixed types and quantise_raw do.
constexpr detail::int128 rounded_shift(detail::int128 raw, int shift, Quant q) {
  return detail::quantise_only(raw, shift, 0, q).raw;
}
constexpr std::int64_t rounded_shift(std::int64_t raw, int shift, Quant q) {
  // The two modes the decoder's hot stages use, on the 64-bit value itself: the floor is an arithmetic shift, the
  // first dropped bit is bit shift - 1 of the two's complement pattern, the rest the bits below it (exactly as
  // quantise_only decides, without its 128-bit detour).
  if (shift >= 1 && shift <= 63 && (q == Quant::Rnd || q == Quant::RndConv)) {
    const std::int64_t kept = raw >> shift;
    const bool first_dropped = ((raw >> (shift - 1)) & 1) != 0;
    if (q == Quant::Rnd) return kept + (first_dropped ? 1 : 0);
    const bool rest_dropped = (raw & ((std::int64_t{1} << (shift - 1)) - 1)) != 0;
    return kept + (first_dropped && (rest_dropped || (kept & 1) != 0) ? 1 : 0);
  }
  return static_cast<std::int64_t>(rounded_shift(static_cast<detail::int128>(raw), shift, q));
}

}  // namespace trm::fx

namespace trm::fx::detail {

// A finite double as an exact integer mantissa and binary point: value = mantissa * 2^-frac_bits.
struct DecodedDouble {
  int128 mantissa;
  int frac_bits;
  bool finite;
};

constexpr DecodedDouble decode_double(double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  const bool negative = (bits >> 63) != 0;
  const int biased_exponent = static_cast<int>((bits >> 52) & 0x7ffu);
  const std::uint64_t fraction = bits & ((std::uint64_t{1} << 52) - 1u);
  if (biased_exponent == 0x7ff) return {0, 0, false};  // Inf or NaN
  // Normal: (2^52 + fraction) * 2^(e - 1075); subnormal: fraction * 2^-1074.
  const std::uint64_t magnitude = biased_exponent == 0 ? fraction : (fraction | (std::uint64_t{1} << 52));
  const int frac_bits = biased_exponent == 0 ? 1074 : 1075 - biased_exponent;
  const auto m = static_cast<int128>(magnitude);
  return {negative ? -m : m, frac_bits, true};
}

// 2^e as a double, exact for -1074 <= e <= 1023 (0 below, +Inf above).
constexpr double pow2(int e) {
  double result = 1.0;
  const double step = e >= 0 ? 2.0 : 0.5;
  for (int i = 0; i < (e >= 0 ? e : -e); ++i) result *= step;
  return result;
}

}  // namespace trm::fx::detail
