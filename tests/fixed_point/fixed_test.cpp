// The compile-time type beyond plain conversion: construction from double, raw access, shifts,
// comparisons, overflow counting and division.
#include "sc_oracle.hpp"

#include "trm/fixed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

namespace trm::fx {
namespace {

using testing::for_each_mode_pair;
using testing::raw_bits;
using testing::sc_raw_bits;
using testing::ScOf;
using testing::to_sc_value;

using Q2_14 = Fixed<2, 14, true>;
using UQ0_16 = Fixed<0, 16, false>;

// ---- constexpr use: formats are checked at compile time ----------------------------------------
static_assert(Q2_14::from_double(1.5).raw() == 24576);
static_assert(Q2_14::from_double(-2.0).raw() == -32768);
static_assert(UQ0_16::max().raw() == 65535 && UQ0_16::min().raw() == 0);
static_assert(Q2_14::min().raw() == -32768 && Q2_14::max().raw() == 32767);
static_assert(std::is_same_v<ProductType<UQ0_16, Q2_14>, Fixed<2, 30, true>>);
static_assert((UQ0_16::from_double(0.5) * Q2_14::from_double(-1.25)).to_double() == -0.625);
static_assert(Fixed<2, 14, true, Quant::Rnd, Overflow::Sat>(Q2_14::from_double(1.5) * Q2_14::from_double(1.5)) ==
              Q2_14::max());
static_assert(Q2_14::from_double(0.25) < UQ0_16::from_double(0.5));
static_assert(Q2_14::from_double(0.5) == UQ0_16::from_double(0.5));
static_assert(shift_exact<-2>(Q2_14::from_double(1.0)).to_double() == 0.25);

TEST(FixedFromDouble, RejectsNanAndInfinity) {
  EXPECT_THROW(Q2_14::from_double(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(Q2_14::from_double(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(UQ0_16::from_double(-std::numeric_limits<double>::infinity()), std::invalid_argument);
}

// Doubles of every magnitude (subnormal to 1e300) quantised into a 20-bit target, against
// sc_fixed's construction from double.
TEST(FixedFromDouble, MatchesSystemCForAllModePairs) {
  for_each_mode_pair([]<Quant Q, Overflow O>() {
    std::mt19937_64 rng(static_cast<std::uint64_t>(Q) * 8 + static_cast<std::uint64_t>(O));
    std::uniform_real_distribution<double> mantissa(-2.0, 2.0);
    std::uniform_int_distribution<int> exponent(-30, 30);
    int mismatches = 0;
    const auto check = [&]<FixedPoint T>(T, double v) {
      const T ours = T::from_double(v);
      const ScOf<T> theirs(v);
      if (raw_bits(ours) != sc_raw_bits(theirs) && ++mismatches <= 5) {
        ADD_FAILURE() << "value " << v << ": ours " << raw_bits(ours) << ", sc_fixed " << sc_raw_bits(theirs);
      }
    };
    for (int i = 0; i < 4000; ++i) {
      const double v = std::ldexp(mantissa(rng), exponent(rng));
      check(Fixed<6, 14, true, Q, O>{}, v);
      check(Fixed<6, 14, false, Q, O>{}, v);
    }
    for (const double v : {0.0, -0.0, 1e-310, -1e-310, 1e300, -1e300, 0.5, -0.5, 31.999, -32.0}) {
      check(Fixed<6, 14, true, Q, O>{}, v);
      check(Fixed<6, 14, false, Q, O>{}, v);
    }
    EXPECT_EQ(mismatches, 0) << to_string(Q) << "/" << to_string(O);
  });
}

TEST(FixedRaw, FromRawKeepsTheLowWidthBits) {
  EXPECT_EQ(Q2_14::from_raw(0x1'8000).raw(), -32768);  // bit 15 set: sign-extended
  EXPECT_EQ(Q2_14::from_raw(-1).raw(), -1);
  EXPECT_EQ(UQ0_16::from_raw(0x1'2345).raw(), 0x2345u);
  EXPECT_EQ(Q2_14::from_raw(Q2_14::from_double(-1.75).raw()).to_double(), -1.75);
}

// x << n and x >> n stay in x's type and apply its modes, as sc_fixed's <<= and >>=.
TEST(FixedShift, MatchesSystemCShiftAssignment) {
  for_each_mode_pair([]<Quant Q, Overflow O>() {
    using T = Fixed<4, 8, true, Q, O>;
    int mismatches = 0;
    for (std::int64_t raw = -2048; raw < 2048; raw += 7) {
      for (int n = -14; n <= 14; ++n) {
        const T x = T::from_raw(raw);
        ScOf<T> left = to_sc_value(x);
        left <<= n;
        ScOf<T> right = to_sc_value(x);
        right >>= n;
        if ((raw_bits(x << n) != sc_raw_bits(left) || raw_bits(x >> n) != sc_raw_bits(right)) && ++mismatches <= 5) {
          ADD_FAILURE() << "raw " << raw << " shift " << n;
        }
      }
    }
    EXPECT_EQ(mismatches, 0) << to_string(Q) << "/" << to_string(O);
  });
}

TEST(FixedShift, HugeShiftCountsAreDefined) {
  using Sat = Fixed<4, 8, true, Quant::Trn, Overflow::Sat>;
  const Sat x = Sat::from_double(1.5);
  EXPECT_EQ((x << 1'000'000).raw(), Sat::max().raw());
  EXPECT_EQ((x >> 1'000'000).raw(), 0);
  EXPECT_EQ((x << std::numeric_limits<int>::min()).raw(), 0);
  EXPECT_EQ((Sat::from_double(-1.5) >> std::numeric_limits<int>::max()).raw(), -1);  // floor of a tiny negative
  EXPECT_EQ((Fixed<4, 8, true>::from_double(1.5) << 4096).raw(), 0);                 // wrap: every bit shifted out
}

TEST(FixedCompare, AgreesWithDoubleAcrossFormats) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 20000; ++i) {
    const auto a = Fixed<5, 11, true>::from_raw(static_cast<std::int64_t>(rng()));
    const auto b = Fixed<3, 20, false>::from_raw(rng());
    const double da = a.to_double();
    const double db = b.to_double();
    ASSERT_EQ(a == b, da == db);
    ASSERT_EQ(a < b, da < db);
    ASSERT_EQ(a > b, da > db);
    ASSERT_EQ(b <= a, db <= da);
  }
  using S = Fixed<5, 11, true>;
  using U = Fixed<3, 20, false>;
  EXPECT_TRUE(S::from_double(2.5) == U::from_double(2.5));
}

TEST(FixedArithmetic, CompoundAssignmentQuantisesIntoTheLeftType) {
  using Acc = Fixed<2, 14, true, Quant::Rnd, Overflow::Sat>;
  Acc acc = Acc::from_double(1.0);
  acc += UQ0_16::from_double(0.75);  // 1.75
  EXPECT_EQ(acc.to_double(), 1.75);
  acc += UQ0_16::from_double(0.75);  // 2.5 saturates
  EXPECT_EQ(acc.raw(), Acc::max().raw());
  acc *= Q2_14::from_double(-0.5);
  EXPECT_EQ(acc.raw(), -16383);  // (2 − 2^-14)·(−0.5) = −16383.5 LSB: a tie, Rnd goes toward +∞
  acc -= Q2_14::from_double(1.0);
  EXPECT_EQ(acc.raw(), -16383 - 16384);
}

// ---- Overflow counting --------------------------------------------------------------------------

TEST(SaturationCounter, CountsEveryConversionTheOverflowStageChanged) {
  SaturationCounter counter;
  using Sat8 = Fixed<8, 0, true, Quant::Trn, Overflow::Sat>;
  using Sym8 = Fixed<8, 0, true, Quant::Trn, Overflow::SatSym>;
  using Wrap8 = Fixed<8, 0, true, Quant::Trn, Overflow::Wrap>;
  const auto big = Fixed<16, 0, true>::from_integer(300);
  const auto small = Fixed<16, 0, true>::from_integer(100);
  const auto minimum = Fixed<16, 0, true>::from_integer(-128);
  EXPECT_EQ(convert<Sat8>(big, &counter).raw(), 127);
  EXPECT_EQ(convert<Sat8>(small, &counter).raw(), 100);  // in range: not counted
  EXPECT_EQ(convert<Wrap8>(big, &counter).raw(), 300 - 256);
  EXPECT_EQ(convert<Sym8>(minimum, &counter).raw(), -127);  // SatSym moves the minimum: counted
  EXPECT_EQ(convert<Sat8>(minimum, &counter).raw(), -128);  // plain Sat keeps it: not counted
  EXPECT_EQ(Sat8::from_double(-1000.0, &counter).raw(), -128);
  EXPECT_EQ(counter.overflows, 4u);
  EXPECT_EQ(counter.divisions_by_zero, 0u);
  counter.reset();
  EXPECT_EQ(counter.overflows, 0u);
}

// ---- Division -----------------------------------------------------------------------------------

// Independent reference: the exact quotient n/d (d > 0) as floor and the comparison of the
// remainder with one half, found by search rather than by integer division, then rounded by the
// mode's definition written out directly.
std::int64_t reference_rounded_quotient(std::int64_t n, std::int64_t d, Quant q) {
  auto floor_q = static_cast<std::int64_t>(std::floor(static_cast<double>(n) / static_cast<double>(d)));
  while (floor_q * d > n) --floor_q;
  while ((floor_q + 1) * d <= n) ++floor_q;
  const std::int64_t twice_rem = 2 * (n - floor_q * d);  // in [0, 2d)
  const bool exact = twice_rem == 0;
  const bool above_half = twice_rem > d;
  const bool tie = twice_rem == d;
  const bool negative = n < 0;
  switch (q) {
    case Quant::Trn: return floor_q;
    case Quant::TrnZero: return (negative && !exact) ? floor_q + 1 : floor_q;
    case Quant::Rnd: return (above_half || tie) ? floor_q + 1 : floor_q;
    case Quant::RndZero: return (above_half || (tie && negative)) ? floor_q + 1 : floor_q;
    case Quant::RndInf: return (above_half || (tie && !negative)) ? floor_q + 1 : floor_q;
    case Quant::RndMinInf: return above_half ? floor_q + 1 : floor_q;
    case Quant::RndConv: return (above_half || (tie && (floor_q & 1) != 0)) ? floor_q + 1 : floor_q;
  }
  return floor_q;
}

TEST(FixedDivide, RoundsTheExactQuotientWithTheResultMode) {
  for_each_mode_pair([]<Quant Q, Overflow O>() {
    using A = Fixed<4, 8, true>;
    using B = Fixed<3, 6, false>;
    using R = Fixed<5, 7, true, Q, O>;  // raw quotient = (ra · 2^(7 + 6 − 8)) / rb = ra·32 / rb
    using Wide = Fixed<40, 7, true>;    // the reference quotient before overflow handling
    int mismatches = 0;
    for (std::int64_t ra = -2048; ra < 2048; ra += 3) {
      for (std::int64_t rb = 1; rb < 512; rb += 5) {
        const std::int64_t q = reference_rounded_quotient(ra * 32, rb, Q);
        const R expected = Wide::from_raw(q);  // the overflow stage, by conversion
        const R ours = divide<R>(A::from_raw(ra), B::from_raw(static_cast<std::uint64_t>(rb)));
        if (ours.raw() != expected.raw() && ++mismatches <= 5) {
          ADD_FAILURE() << ra << " / " << rb << ": ours " << ours.raw() << ", expected " << expected.raw();
        }
      }
    }
    EXPECT_EQ(mismatches, 0) << to_string(Q) << "/" << to_string(O);
  });
}

TEST(FixedDivide, NegativeDivisorAndTiesFollowTheMode) {
  using A = Fixed<8, 0, true>;
  using Conv = Fixed<8, 0, true, Quant::RndConv>;
  using Inf = Fixed<8, 0, true, Quant::RndInf>;
  EXPECT_EQ(divide<Conv>(A::from_integer(5), A::from_integer(-2)).raw(), -2);  // −2.5 → even
  EXPECT_EQ(divide<Inf>(A::from_integer(5), A::from_integer(-2)).raw(), -3);   // −2.5 → away from 0
  EXPECT_EQ(divide<Conv>(A::from_integer(-7), A::from_integer(-2)).raw(), 4);  // 3.5 → even
  // 1/3 in Q0.16 rounds to nearest: 21845.33 → 21845.
  EXPECT_EQ((divide<Fixed<1, 16, true, Quant::Rnd>>(A::from_integer(1), A::from_integer(3))).raw(), 21845);
}

TEST(FixedDivide, ZeroDivisorIsDefinedAndCounted) {
  using A = Fixed<4, 8, true>;
  using Wrap = Fixed<4, 8, true>;
  using Sym = Fixed<4, 8, true, Quant::Trn, Overflow::SatSym>;
  SaturationCounter counter;
  EXPECT_EQ(divide<Wrap>(A::from_double(1.0), A{}, &counter).raw(), Wrap::max().raw());
  EXPECT_EQ(divide<Wrap>(A::from_double(-1.0), A{}, &counter).raw(), Wrap::min().raw());
  EXPECT_EQ(divide<Sym>(A::from_double(-1.0), A{}, &counter).raw(), -Sym::max().raw());
  EXPECT_EQ(divide<Wrap>(A{}, A{}, &counter).raw(), 0);
  EXPECT_EQ(counter.divisions_by_zero, 4u);
  EXPECT_THROW(divide_checked<Wrap>(A::from_double(1.0), A{}), std::domain_error);
  EXPECT_EQ(divide_checked<Wrap>(A::from_double(1.0), A::from_double(2.0)).to_double(), 0.5);
}

}  // namespace
}  // namespace trm::fx
