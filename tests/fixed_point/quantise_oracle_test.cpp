// Conversion between formats, bit for bit against SystemC sc_fixed, for all 7 x 4 quantisation /
// overflow mode pairs: exhaustively for 16-bit sources, and on random values for 48- and 64-bit
// sources.
#include "sc_oracle.hpp"

#include "trm/fixed.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>

namespace trm::fx {
namespace {

using testing::for_each_mode_pair;
using testing::raw_bits;
using testing::sc_raw_bits;
using testing::ScOf;
using testing::to_sc_value;

template <FixedPoint T>
std::string describe() {
  return std::string(T::is_signed ? "s" : "u") + "Q" + std::to_string(T::int_bits) + "." +
         std::to_string(T::frac_bits) + " " + to_string(T::quant) + "/" + to_string(T::overflow);
}

// Converts `source` into Dst with our type and with sc_fixed; returns whether the bits agree and
// reports the first few disagreements.
template <FixedPoint Dst, FixedPoint Src>
bool agrees_with_systemc(const Src& source, int& mismatches) {
  const Dst ours = source;
  const ScOf<Dst> theirs = to_sc_value(source);
  if (raw_bits(ours) == sc_raw_bits(theirs)) return true;
  if (++mismatches <= 5) {
    ADD_FAILURE() << describe<Src>() << " raw " << static_cast<long long>(source.raw()) << " -> " << describe<Dst>()
                  << ": ours " << raw_bits(ours) << ", sc_fixed " << sc_raw_bits(theirs);
  }
  return false;
}

// Every one of the 2^16 source bit patterns, into Dst with every mode pair.
template <FixedPoint Src, int DstInt, int DstFrac, bool DstSigned>
void expect_every_source_matches() {
  static_assert(Src::width == 16);
  for_each_mode_pair([]<Quant Q, Overflow O>() {
    using Dst = Fixed<DstInt, DstFrac, DstSigned, Q, O>;
    int mismatches = 0;
    int checked = 0;
    for (std::uint32_t bits = 0; bits < (1u << 16); ++bits) {
      agrees_with_systemc<Dst>(Src::from_raw(static_cast<typename Src::raw_type>(bits)), mismatches);
      ++checked;
    }
    EXPECT_EQ(mismatches, 0) << describe<Src>() << " -> " << describe<Dst>();
    EXPECT_EQ(checked, 1 << 16);
  });
}

using SignedQ4_12 = Fixed<4, 12, true>;
using UnsignedQ4_12 = Fixed<4, 12, false>;

// Targets: fewer frac and fewer int bits (Q2.6), fewer frac and more int bits (Q6.2), 12-bit Q3.9,
// more frac bits than the source with a negative int part, negative frac bits (Q13.-1).
TEST(QuantiseExhaustive, SignedSourceInto8BitTargets) {
  expect_every_source_matches<SignedQ4_12, 2, 6, true>();
  expect_every_source_matches<SignedQ4_12, 2, 6, false>();
  expect_every_source_matches<SignedQ4_12, 6, 2, true>();
  expect_every_source_matches<SignedQ4_12, 6, 2, false>();
}

TEST(QuantiseExhaustive, SignedSourceInto12BitTargets) {
  expect_every_source_matches<SignedQ4_12, 3, 9, true>();
  expect_every_source_matches<SignedQ4_12, 3, 9, false>();
  expect_every_source_matches<SignedQ4_12, -1, 13, true>();
  expect_every_source_matches<SignedQ4_12, 13, -1, false>();
}

TEST(QuantiseExhaustive, UnsignedSourceInto8BitTargets) {
  expect_every_source_matches<UnsignedQ4_12, 2, 6, true>();
  expect_every_source_matches<UnsignedQ4_12, 2, 6, false>();
  expect_every_source_matches<UnsignedQ4_12, 6, 2, true>();
  expect_every_source_matches<UnsignedQ4_12, 6, 2, false>();
}

TEST(QuantiseExhaustive, UnsignedSourceInto12BitTargets) {
  expect_every_source_matches<UnsignedQ4_12, 3, 9, true>();
  expect_every_source_matches<UnsignedQ4_12, 3, 9, false>();
  expect_every_source_matches<UnsignedQ4_12, -1, 13, false>();
  expect_every_source_matches<UnsignedQ4_12, 13, -1, true>();
}

// ---- Wide sources, random values --------------------------------------------------------------

// Random raw patterns that reach every interesting case, not just uniform bits (which would almost
// always overflow a narrower target): the magnitude's bit length is uniform over [0, W], and in a
// quarter of the draws the `dropped_bits` low bits are forced to an exact tie (1000…0), in an
// eighth to exactly representable (000…0).
class RawGenerator {
 public:
  explicit RawGenerator(std::uint64_t seed) : rng_(seed) {}

  template <FixedPoint T>
  T next(int dropped_bits) {
    const int length = static_cast<int>(rng_() % (T::width + 1));
    std::uint64_t bits = length == 0 ? 0 : (length >= 64 ? rng_() : rng_() & ((std::uint64_t{1} << length) - 1u));
    const std::uint64_t pick = rng_() % 8;
    if (dropped_bits > 0 && dropped_bits < 64 && pick < 3) {
      const std::uint64_t low_mask = (std::uint64_t{1} << dropped_bits) - 1u;
      bits = (bits & ~low_mask) | (pick < 2 ? std::uint64_t{1} << (dropped_bits - 1) : 0);
    }
    if (T::is_signed && (rng_() & 1u) != 0) bits = ~bits;  // negative values of every length
    return T::from_raw(static_cast<typename T::raw_type>(bits));
  }

 private:
  std::mt19937_64 rng_;
};

// Per source-format family: 2 targets x 28 mode pairs x 18 000 values = 1 008 000 conversions
// (at least 10^6 per family, spread evenly over the mode pairs to keep the suite fast).
constexpr int kRandomPerTargetAndModePair = 18000;

template <FixedPoint Src, int DstInt, int DstFrac, bool DstSigned>
void expect_random_sources_match(std::uint64_t seed) {
  for_each_mode_pair([seed]<Quant Q, Overflow O>() {
    using Dst = Fixed<DstInt, DstFrac, DstSigned, Q, O>;
    RawGenerator generator(seed + static_cast<std::uint64_t>(Q) * 16 + static_cast<std::uint64_t>(O));
    int mismatches = 0;
    for (int i = 0; i < kRandomPerTargetAndModePair; ++i) {
      agrees_with_systemc<Dst>(generator.next<Src>(Src::frac_bits - DstFrac), mismatches);
    }
    EXPECT_EQ(mismatches, 0) << describe<Src>() << " -> " << describe<Dst>();
  });
}

TEST(QuantiseRandom, Signed64BitInto32Bit) {
  expect_random_sources_match<Fixed<16, 48, true>, 10, 22, true>(1);
  expect_random_sources_match<Fixed<16, 48, true>, 20, 12, false>(2);
}

TEST(QuantiseRandom, Unsigned64BitInto32Bit) {
  expect_random_sources_match<Fixed<20, 44, false>, 10, 22, true>(3);
  expect_random_sources_match<Fixed<20, 44, false>, 24, 8, false>(4);
}

TEST(QuantiseRandom, Signed48BitInto32Bit) {
  expect_random_sources_match<Fixed<8, 40, true>, 4, 28, true>(5);
  expect_random_sources_match<Fixed<8, 40, true>, 2, 30, false>(6);
}

TEST(QuantiseRandom, Unsigned48BitInto32Bit) {
  expect_random_sources_match<Fixed<12, 36, false>, 6, 26, true>(7);
  expect_random_sources_match<Fixed<12, 36, false>, 16, 16, false>(8);
}

// ---- Exact products, sums and differences, quantised on assignment ------------------------------

// Per arithmetic family: 28 mode pairs x 2 targets x 18 000 = 1 008 000 random operand pairs.
template <FixedPoint A, FixedPoint B, int DstInt, int DstFrac, bool DstSigned, class Op, class ScOp>
void expect_random_operations_match(std::uint64_t seed, Op op, ScOp sc_op) {
  for_each_mode_pair([&]<Quant Q, Overflow O>() {
    using Dst = Fixed<DstInt, DstFrac, DstSigned, Q, O>;
    RawGenerator generator(seed * 1000 + static_cast<std::uint64_t>(Q) * 16 + static_cast<std::uint64_t>(O));
    int mismatches = 0;
    for (int i = 0; i < kRandomPerTargetAndModePair; ++i) {
      const A a = generator.next<A>(A::frac_bits - DstFrac);
      const B b = generator.next<B>(B::frac_bits - DstFrac);
      const auto exact = op(a, b);
      const Dst ours = exact;
      const ScOf<Dst> theirs = sc_op(to_sc_value(a), to_sc_value(b));
      // The wide result is exact: it equals SystemC's arbitrary-precision result (<= 53 bits here).
      static_assert(decltype(exact)::width <= 53);
      const bool exact_ok = exact.to_double() == sc_op(to_sc_value(a), to_sc_value(b)).to_double();
      if ((raw_bits(ours) != sc_raw_bits(theirs) || !exact_ok) && ++mismatches <= 5) {
        ADD_FAILURE() << "a raw " << static_cast<long long>(a.raw()) << ", b raw " << static_cast<long long>(b.raw())
                      << " -> " << describe<Dst>() << ": ours " << raw_bits(ours) << ", sc_fixed "
                      << sc_raw_bits(theirs) << (exact_ok ? "" : " (wide result differs)");
      }
    }
    EXPECT_EQ(mismatches, 0) << describe<A>() << " op " << describe<B>() << " -> " << describe<Dst>();
  });
}

using Q4_20 = Fixed<4, 20, true>;
using UQ2_22 = Fixed<2, 22, false>;

TEST(ArithmeticOracle, ProductsQuantisedToNarrowerTargets) {
  const auto multiply = [](const auto& a, const auto& b) { return a * b; };
  const auto sc_multiply = [](const auto& a, const auto& b) { return sc_dt::sc_fxval(a * b); };
  static_assert(std::is_same_v<ProductType<Q4_20, UQ2_22>, Fixed<6, 42, true>>);
  expect_random_operations_match<Q4_20, UQ2_22, 3, 13, true>(11, multiply, sc_multiply);
  expect_random_operations_match<Q4_20, UQ2_22, 2, 14, false>(12, multiply, sc_multiply);
}

TEST(ArithmeticOracle, SumsQuantisedToNarrowerTargets) {
  const auto add = [](const auto& a, const auto& b) { return a + b; };
  const auto sc_add = [](const auto& a, const auto& b) { return sc_dt::sc_fxval(a + b); };
  static_assert(std::is_same_v<SumType<Q4_20, UQ2_22>, Fixed<5, 22, true>>);
  expect_random_operations_match<Q4_20, UQ2_22, 3, 9, true>(13, add, sc_add);
  expect_random_operations_match<UQ2_22, Fixed<8, 16, false>, 4, 12, false>(14, add, sc_add);
}

TEST(ArithmeticOracle, DifferencesQuantisedToNarrowerTargets) {
  const auto subtract = [](const auto& a, const auto& b) { return a - b; };
  const auto sc_subtract = [](const auto& a, const auto& b) { return sc_dt::sc_fxval(a - b); };
  static_assert(std::is_same_v<DifferenceType<UQ2_22, UQ2_22>, Fixed<3, 22, true>>);
  expect_random_operations_match<UQ2_22, UQ2_22, 2, 10, true>(15, subtract, sc_subtract);
  expect_random_operations_match<Q4_20, UQ2_22, 3, 9, false>(16, subtract, sc_subtract);
}

}  // namespace
}  // namespace trm::fx
