// Fault injection: reproducibility, measured rates, bursts, bad parameters.
#include "trm/faults.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

namespace trm::link {
namespace {

std::uint64_t count_flipped_bits(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(a[i] ^ b[i])));
  return n;
}

// Runs `packets` packets of `bytes` zero bytes through the injector; returns total flipped bits seen.
std::uint64_t run(FaultInjector& f, int packets, std::size_t bytes) {
  std::uint64_t flipped = 0;
  const std::vector<std::uint8_t> zero(bytes, 0);
  for (int i = 0; i < packets; ++i) {
    std::vector<std::uint8_t> p = zero;
    if (f.apply(p)) flipped += count_flipped_bits(p, zero);
  }
  return flipped;
}

TEST(Faults, SameSeedSameFaultsOtherSeedOtherFaults) {
  auto trace = [](std::uint64_t seed) {
    FaultInjector f({1e-3, {1e-4, 16}, 0.05, seed});
    std::vector<std::vector<std::uint8_t>> out;
    for (int i = 0; i < 200; ++i) {
      std::vector<std::uint8_t> p(500, 0xA5);
      if (f.apply(p)) out.push_back(p);
      else out.emplace_back();
    }
    return out;
  };
  EXPECT_EQ(trace(7), trace(7));
  EXPECT_NE(trace(7), trace(8));
}

TEST(Faults, MeasuredBitErrorRateMatches) {
  for (double ber : {1e-6, 1e-4, 1e-3}) {
    FaultInjector f({ber, {}, 0.0, 3});
    const std::uint64_t flipped = run(f, 2000, 5000);  // 8e7 bits
    const double expected = ber * 8e7, sigma = std::sqrt(expected);
    EXPECT_NEAR(static_cast<double>(flipped), expected, 5 * sigma + 1) << ber;
    EXPECT_EQ(flipped, f.counters().random_bit_errors);
    EXPECT_EQ(f.counters().bits_delivered, 80'000'000u);
  }
}

TEST(Faults, ExtremeRates) {
  FaultInjector none({0.0, {}, 0.0, 1});
  EXPECT_EQ(run(none, 100, 100), 0u);
  EXPECT_EQ(none.counters().packets_damaged, 0u);
  FaultInjector all({1.0, {}, 0.0, 1});
  EXPECT_EQ(run(all, 10, 100), 8000u);  // every bit flips
  FaultInjector drop_all({0.0, {}, 1.0, 1});
  EXPECT_EQ(run(drop_all, 10, 100), 0u);
  EXPECT_EQ(drop_all.counters().packets_dropped, 10u);
  EXPECT_EQ(drop_all.counters().bits_delivered, 0u);
}

TEST(Faults, DropRateMatches) {
  FaultInjector f({0.0, {}, 0.1, 11});
  run(f, 20000, 4);
  EXPECT_NEAR(static_cast<double>(f.counters().packets_dropped), 2000.0, 5 * std::sqrt(1800.0));
}

TEST(Faults, BurstsFlipFirstAndLastBitAndSpanPackets) {
  FaultInjector single({0.0, {1e-3, 1}, 0.0, 5});
  const std::uint64_t flipped = run(single, 1000, 1000);  // 8e6 bits, ~8000 bursts of one bit
  EXPECT_EQ(flipped, single.counters().bursts);
  EXPECT_NEAR(static_cast<double>(single.counters().bursts), 8000.0, 5 * std::sqrt(8000.0));

  FaultInjector wide({0.0, {1e-4, 64}, 0.0, 5});
  const std::uint64_t wide_flipped = run(wide, 1000, 1000);
  const std::uint64_t bursts = wide.counters().bursts;
  EXPECT_GT(bursts, 0u);
  EXPECT_EQ(wide_flipped, wide.counters().burst_bit_errors);
  // Each burst flips 2 + Binomial(62, 1/2) bits: mean 33 (a burst cut off at the end of the run flips fewer).
  EXPECT_GE(wide_flipped + 64, 2 * bursts);
  EXPECT_NEAR(static_cast<double>(wide_flipped) / static_cast<double>(bursts), 33.0, 2.0);

  // Bursts longer than a packet carry on into the next one.
  FaultInjector spanning({0.0, {1e-3, 4000}, 0.0, 9});
  run(spanning, 100, 100);
  EXPECT_GT(spanning.counters().packets_damaged, spanning.counters().bursts);
}

TEST(Faults, BadParametersAreRejected) {
  EXPECT_THROW(FaultInjector({-1e-6, {}, 0.0, 1}), std::invalid_argument);
  EXPECT_THROW(FaultInjector({1.5, {}, 0.0, 1}), std::invalid_argument);
  EXPECT_THROW(FaultInjector({std::numeric_limits<double>::quiet_NaN(), {}, 0.0, 1}), std::invalid_argument);
  EXPECT_THROW(FaultInjector({0.0, {}, 2.0, 1}), std::invalid_argument);
  EXPECT_THROW(FaultInjector({0.0, {0.1, 0}, 0.0, 1}), std::invalid_argument);
  const BurstConfig b = parse_burst("1e-7:64");
  EXPECT_DOUBLE_EQ(b.rate, 1e-7);
  EXPECT_EQ(b.length_bits, 64);
  for (const char* bad : {"", "1e-7", "1e-7:", ":64", "x:64", "1e-7:6x", "2:64", "1e-7:0", "1e-7:-5", "1e-7:99999999999"})
    EXPECT_THROW(parse_burst(bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace trm::link
