// Run-time formats: the same semantics as the compile-time type, checked against both Fixed and
// SystemC's run-time-parameterised sc_fix / sc_ufix.
#include "sc_oracle.hpp"

#include "trm/fixed.hpp"
#include "trm/fixed_runtime.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

namespace trm::fx {
namespace {

using testing::for_each_mode_pair;
using testing::low_bits;

TEST(RuntimeFormat, MatchesTheCompileTimeTypeForAllModePairs) {
  for_each_mode_pair([]<Quant Q, Overflow O>() {
    std::mt19937_64 rng(static_cast<std::uint64_t>(Q) * 8 + static_cast<std::uint64_t>(O) + 100);
    using Src = Fixed<12, 20, true>;
    using SignedDst = Fixed<3, 9, true, Q, O>;
    using UnsignedDst = Fixed<14, -2, false, Q, O>;
    int mismatches = 0;
    for (int i = 0; i < 20000; ++i) {
      const Src src = Src::from_raw(static_cast<std::int64_t>(rng() >> (rng() % 40)));
      const SignedDst a = src;
      const UnsignedDst b = src;
      const std::int64_t ra = quantise_raw(src.raw(), Src::frac_bits, format_of<SignedDst>());
      const std::int64_t rb = quantise_raw(src.raw(), format_of<Src>(), format_of<UnsignedDst>());
      if ((ra != a.raw() || rb != static_cast<std::int64_t>(b.raw())) && ++mismatches <= 5) {
        ADD_FAILURE() << "raw " << src.raw();
      }
    }
    EXPECT_EQ(mismatches, 0) << to_string(Q) << "/" << to_string(O);
  });
}

// Random source and target formats (widths 1..63/64, binary points on either side of the word),
// random mode pairs, against sc_fix / sc_ufix with the same run-time parameters.
TEST(RuntimeFormat, MatchesSystemCWithRandomFormats) {
  std::mt19937_64 rng(2024);
  constexpr int kCases = 200000;
  int mismatches = 0;
  for (int i = 0; i < kCases; ++i) {
    const bool in_signed = (rng() & 1u) != 0;
    const int in_width = 1 + static_cast<int>(rng() % (in_signed ? 64 : 63));
    const int in_frac = static_cast<int>(rng() % 97) - 24;
    const RuntimeFormat out{0, static_cast<int>(rng() % 81) - 20, (rng() & 1u) != 0,
                            kAllQuantModes[rng() % 7], kAllOverflowModes[rng() % 4]};
    RuntimeFormat target = out;
    target.int_bits = 1 + static_cast<int>(rng() % (target.is_signed ? 64 : 63)) - target.frac_bits;
    const int length = static_cast<int>(rng() % (in_width + 1));
    std::uint64_t bits = length == 0 ? 0 : (rng() & (length >= 64 ? ~0ULL : ((1ULL << length) - 1u)));
    if (in_signed && (rng() & 1u) != 0) bits = ~bits;
    bits = low_bits(bits, in_width);
    std::int64_t raw_in = static_cast<std::int64_t>(bits);
    if (in_signed && in_width < 64 && ((bits >> (in_width - 1)) & 1u) != 0) {
      raw_in = static_cast<std::int64_t>(bits | ~((1ULL << in_width) - 1u));  // sign-extend
    }

    std::uint64_t theirs;
    const int in_int = in_width - in_frac;
    const auto q = testing::to_sc(target.quant);
    const auto o = testing::to_sc(target.overflow);
    auto assign_into = [&](const auto& source) {
      if (target.is_signed) {
        sc_dt::sc_fix dst(target.width(), target.int_bits, q, o);
        dst = source;
        return low_bits(dst.range(target.width() - 1, 0).to_uint64(), target.width());
      }
      sc_dt::sc_ufix dst(target.width(), target.int_bits, q, o);
      dst = source;
      return low_bits(dst.range(target.width() - 1, 0).to_uint64(), target.width());
    };
    if (in_signed) {
      sc_dt::sc_fix src(in_width, in_int);
      src.range(in_width - 1, 0) = static_cast<sc_dt::uint64>(bits);
      theirs = assign_into(src);
    } else {
      sc_dt::sc_ufix src(in_width, in_int);
      src.range(in_width - 1, 0) = static_cast<sc_dt::uint64>(bits);
      theirs = assign_into(src);
    }
    const std::uint64_t ours = low_bits(static_cast<std::uint64_t>(quantise_raw(raw_in, in_frac, target)), target.width());
    if (ours != theirs && ++mismatches <= 5) {
      ADD_FAILURE() << "raw " << raw_in << " (w " << in_width << ", f " << in_frac << ") -> " << target.to_string()
                    << ": ours " << ours << ", sc_fix " << theirs;
    }
  }
  EXPECT_EQ(mismatches, 0) << "of " << kCases;
}

TEST(RuntimeFormat, MultiplyRawMatchesTheCompileTimeProduct) {
  std::mt19937_64 rng(7);
  using A = Fixed<2, 14, true>;
  using B = Fixed<0, 16, false>;
  using Dst = Fixed<2, 14, true, Quant::Rnd, Overflow::Sat>;
  SaturationCounter counter;
  for (int i = 0; i < 100000; ++i) {
    const A a = A::from_raw(static_cast<std::int64_t>(rng()));
    const B b = B::from_raw(rng());
    const Dst expected = a * b;
    ASSERT_EQ(multiply_raw(a.raw(), 14, static_cast<std::int64_t>(b.raw()), 16, format_of<Dst>(), &counter),
              expected.raw());
  }
  EXPECT_EQ(counter.overflows, 0u);  // |a·b| < 2: Q2.14 never overflows, even with rounding up
  // The product of two int64 extremes is formed exactly (in 128 bits) before saturating.
  const RuntimeFormat sat32{32, 0, true, Quant::Trn, Overflow::Sat};
  EXPECT_EQ(multiply_raw(std::numeric_limits<std::int64_t>::min(), 0, std::numeric_limits<std::int64_t>::min(), 0,
                         sat32, &counter),
            sat32.max_raw());
  EXPECT_EQ(counter.overflows, 1u);
}

TEST(RuntimeFormat, QuantiseDoubleMatchesFixedAndRejectsNonFinite) {
  const RuntimeFormat q2_14{2, 14, true, Quant::RndConv, Overflow::SatSym};
  using T = Fixed<2, 14, true, Quant::RndConv, Overflow::SatSym>;
  for (const double v : {0.0, 1.0 / 3.0, -1.9999, -2.5, 7.0, 2.0 / 32768.0, 3.0 / 32768.0}) {
    EXPECT_EQ(quantise_double(v, q2_14), T::from_double(v).raw()) << v;
  }
  EXPECT_EQ(to_double(quantise_double(0.75, q2_14), q2_14), 0.75);
  EXPECT_THROW(quantise_double(std::numeric_limits<double>::quiet_NaN(), q2_14), std::invalid_argument);
  EXPECT_THROW(quantise_double(-std::numeric_limits<double>::infinity(), q2_14), std::invalid_argument);
}

// rounded_shift is the quantisation step alone: for values whose result fits, it is quantise_raw into an integer
// format wide enough that no overflow occurs, in every rounding mode, for every sign, tie and shift (including
// shifts <= 0, which are exact).
TEST(RuntimeFormat, RoundedShiftIsTheQuantisationStep) {
  std::mt19937_64 rng(2718);
  const RuntimeFormat integer{64, 0, true, Quant::Trn, Overflow::Wrap};
  for (const Quant q : kAllQuantModes) {
    RuntimeFormat out = integer;
    out.quant = q;
    for (int shift = -4; shift <= 40; ++shift) {
      for (int i = 0; i < 200; ++i) {
        std::int64_t raw = static_cast<std::int64_t>(rng() >> 20) - (std::int64_t{1} << 43);
        if (i % 4 == 0 && shift > 0) raw = (raw >> shift << shift) | (std::int64_t{1} << (shift - 1));  // exact tie
        EXPECT_EQ(rounded_shift(raw, shift, q), quantise_raw(raw, shift, out))
            << to_string(q) << " " << raw << " >> " << shift;
        const detail::int128 wide = static_cast<detail::int128>(raw) << 40;
        EXPECT_EQ(static_cast<std::int64_t>(rounded_shift(wide, shift + 40, q)), quantise_raw(raw, shift, out));
      }
    }
  }
  // Round half up and half to even, the two the decoder uses, on ties of both signs.
  EXPECT_EQ(rounded_shift(std::int64_t{5}, 1, Quant::Rnd), 3);
  EXPECT_EQ(rounded_shift(std::int64_t{-5}, 1, Quant::Rnd), -2);
  EXPECT_EQ(rounded_shift(std::int64_t{5}, 1, Quant::RndConv), 2);
  EXPECT_EQ(rounded_shift(std::int64_t{7}, 1, Quant::RndConv), 4);
  EXPECT_EQ(rounded_shift(std::int64_t{-5}, 1, Quant::RndConv), -2);
  EXPECT_EQ(rounded_shift(std::int64_t{-3}, 0, Quant::Rnd), -3);
  EXPECT_EQ(rounded_shift(std::int64_t{-3}, -2, Quant::Rnd), -12);
}

TEST(RuntimeFormat, InvalidFormatsAreRejectedWithAReason) {
  const auto message_of = [](const RuntimeFormat& f) {
    try {
      f.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message_of({0, 0, true}).find("at least 1"), std::string::npos);
  EXPECT_NE(message_of({2, -4, false}).find("at least 1"), std::string::npos);
  EXPECT_NE(message_of({33, 32, true}).find("at most 64"), std::string::npos);
  EXPECT_NE(message_of({0, 64, false}).find("at most 63"), std::string::npos);
  EXPECT_NE(message_of({-2000, 2010, true}).find("[-1024, 1024]"), std::string::npos);
  EXPECT_EQ(message_of({1, 63, true}), "accepted");
  EXPECT_EQ(message_of({0, 63, false}), "accepted");
  EXPECT_THROW(quantise_raw(1, 0, RuntimeFormat{0, 0, true}), std::invalid_argument);
  EXPECT_THROW(quantise_raw(1, 5000, RuntimeFormat{}), std::invalid_argument);
  EXPECT_EQ(RuntimeFormat({2, 14, true, Quant::Rnd, Overflow::Sat}).to_string(), "sQ2.14 Rnd Sat");
}

}  // namespace
}  // namespace trm::fx
