// pow_elements against std::pow and exp_elements against std::exp, bit for bit, on every instruction set this CPU runs.
#include "trm/vector_pow.hpp"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

// Restricts Highway's dispatch to one target for the test's lifetime.
struct TargetMock {
  explicit TargetMock(std::int64_t target) { hwy::SetSupportedTargetsForTest(target); }
  ~TargetMock() { hwy::SetSupportedTargetsForTest(0); }
  TargetMock(const TargetMock&) = delete;
  TargetMock& operator=(const TargetMock&) = delete;
};

// Highway's targets this CPU runs and this build compiled, best first.
std::vector<std::int64_t> supported_targets() { return hwy::SupportedAndGeneratedTargets(); }

std::uint64_t bits_of(double v) {
  std::uint64_t out = 0;
  std::memcpy(&out, &v, sizeof out);
  return out;
}

// The first index where `got` differs from std::pow in any bit, or -1.
long first_difference(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& got) {
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (bits_of(got[k]) != bits_of(std::pow(x[k], y[k]))) return static_cast<long>(k);
  }
  return -1;
}

// Inputs of the kinds the decoder and the transfer functions see, and the ones that are hardest for the algorithm:
// uniform in [0, 1] (codes, linear light), 2^-60..1 (dark samples), 1 - 2^-50..1 (near white: log x near 0),
// (0, 4], 0 and 1 scattered among them, and per-element exponents.
std::vector<double> sample_inputs(std::mt19937_64& rng, int kind, std::size_t n) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> x(n);
  for (double& v : x) {
    switch (kind) {
      case 0: v = unit(rng); break;
      case 1: v = std::ldexp(unit(rng), -static_cast<int>(rng() % 60)); break;
      case 2: v = 1.0 - std::ldexp(unit(rng), -static_cast<int>(rng() % 50)); break;
      default: v = 4.0 * unit(rng); break;
    }
    if (rng() % 61 == 0) v = rng() % 2 == 0 ? 0.0 : 1.0;
  }
  return x;
}

TEST(VectorPow, EveryElementIsStdPowOnEveryTarget) {
  const double exponents[] = {2.4, 1.0 / 2.4, 2.2, 1.0 / 2.2, 1.8, 2.6, 0.5, 3.0, -1.5};
  for (const std::int64_t target : supported_targets()) {
    TargetMock mock(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target) + ", kernel path " + trm::pow_elements_path());
    std::mt19937_64 rng(static_cast<std::uint64_t>(target));
    for (int kind = 0; kind < 4; ++kind) {
      // 1021 * 256 + 3: not a multiple of any vector length, so the padded tail vector runs too.
      const std::vector<double> x = sample_inputs(rng, kind, 1021 * 256 + 3);
      for (const double exponent : exponents) {
        const std::vector<double> y(x.size(), exponent);
        std::vector<double> got(x.size());
        trm::pow_elements(x, exponent, got);
        EXPECT_EQ(first_difference(x, y, got), -1) << "x kind " << kind << ", y = " << exponent;
      }
      std::vector<double> y(x.size());
      for (std::size_t k = 0; k < y.size(); ++k) y[k] = exponents[(k * 7 + rng() % 3) % std::size(exponents)];
      std::vector<double> got(x.size());
      trm::pow_elements(x, y, got);
      EXPECT_EQ(first_difference(x, y, got), -1) << "x kind " << kind << ", exponents per element";
    }
  }
}

TEST(VectorPow, SpecialOperandsTakeLibmsPaths) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double specials[] = {0.0,   -0.0, 1.0,  -1.0, 2.0,   -2.0, inf, -inf, nan, 4.9e-324, 2.2e-308, 1e-300,
                              1e300, 0.5,  1e-5, 1.0 - 1e-16, 1.0 + 2.2e-16, 1.7976931348623157e308};
  const double exponents[] = {2.4, -2.4, 0.0, -0.0, 1.0, 2.0, 3.0, 0.5, inf, -inf, nan, 1e-20, 1e20, 1e-300, 700.0};
  std::vector<double> x;
  std::vector<double> y;
  for (const double a : specials) {
    for (const double b : exponents) {
      x.push_back(a);
      y.push_back(b);
    }
  }
  for (const std::int64_t target : supported_targets()) {
    TargetMock mock(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target));
    std::vector<double> got(x.size());
    trm::pow_elements(x, y, got);
    const long k = first_difference(x, y, got);
    EXPECT_EQ(k, -1) << "pow(" << (k >= 0 ? x[static_cast<std::size_t>(k)] : 0.0) << ", "
                     << (k >= 0 ? y[static_cast<std::size_t>(k)] : 0.0) << ")";
  }
}

TEST(VectorPow, InPlaceAndSizeChecks) {
  std::vector<double> values{0.25, 0.5, 0.75, 1.0, 0.0, 0.125, 0.9, 0.3, 0.6, 0.01};
  const std::vector<double> original = values;
  trm::pow_elements(values, 2.4, values);
  for (std::size_t k = 0; k < values.size(); ++k) EXPECT_EQ(bits_of(values[k]), bits_of(std::pow(original[k], 2.4)));
  std::vector<double> shorter(values.size() - 1);
  EXPECT_THROW(trm::pow_elements(values, 2.4, shorter), std::invalid_argument);
  const std::vector<double> exponents(values.size() + 1, 2.4);
  std::vector<double> out(values.size());
  EXPECT_THROW(trm::pow_elements(values, exponents, out), std::invalid_argument);
}

// exp_elements against std::exp: the motion test's range (-s c, s up to 255, c in (0, 1]), the whole finite range with
// its over- and underflow ends, arguments near 0 (the special path below 2^-54 and the first ones above it), and the
// special values; on every instruction set.
TEST(VectorExp, EveryElementIsStdExpOnEveryTarget) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (const std::int64_t target : supported_targets()) {
    TargetMock mock(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target) + ", kernel path " + trm::exp_elements_path());
    std::mt19937_64 rng(static_cast<std::uint64_t>(target) + 7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int kind = 0; kind < 4; ++kind) {
      std::vector<double> x(1021 * 256 + 3);
      for (double& v : x) {
        switch (kind) {
          case 0: v = -255.0 * unit(rng); break;
          case 1: v = -750.0 + 1465.0 * unit(rng); break;
          case 2: v = (rng() % 2 == 0 ? 1.0 : -1.0) * std::ldexp(unit(rng), -static_cast<int>(rng() % 64)); break;
          default: v = -10.0 * unit(rng); break;
        }
      }
      std::vector<double> got(x.size());
      trm::exp_elements(x, got);
      long first = -1;
      for (std::size_t k = 0; k < x.size() && first < 0; ++k) {
        if (bits_of(got[k]) != bits_of(std::exp(x[k]))) first = static_cast<long>(k);
      }
      EXPECT_EQ(first, -1) << "x kind " << kind << ", exp(" << (first >= 0 ? x[static_cast<std::size_t>(first)] : 0.0)
                           << ")";
    }
    std::vector<double> specials{0.0, -0.0, inf, -inf, std::numeric_limits<double>::quiet_NaN(), 0x1p-54, -0x1p-54,
                                 0x1p-55, 511.9, 512.0, 709.78, 709.79, -708.0, -745.2, -746.0, 1e-300, -1e-300};
    std::vector<double> got(specials.size());
    trm::exp_elements(specials, got);
    for (std::size_t k = 0; k < specials.size(); ++k) {
      EXPECT_EQ(bits_of(got[k]), bits_of(std::exp(specials[k]))) << "exp(" << specials[k] << ")";
    }
    trm::exp_elements(specials, specials);  // in place
    for (std::size_t k = 0; k < specials.size(); ++k) EXPECT_EQ(bits_of(specials[k]), bits_of(got[k]));
  }
  std::vector<double> shorter(2);
  EXPECT_THROW(trm::exp_elements(std::vector<double>(3, 0.5), shorter), std::invalid_argument);
}

// On a CPU with FMA and AVX2 (the CI machines) the kernel must be the one in use on every such target the CPU runs
// (AVX2, and AVX-512 where it has it): each target's first-use check against std::pow passed. Elsewhere std::pow
// computes every element, which the tests above cover as well.
TEST(VectorPow, KernelIsInUseWhereTheCpuHasFma) {
  const std::int64_t best = supported_targets().front();
  if (best > HWY_AVX2) GTEST_SKIP() << "this CPU's best target is " << hwy::TargetName(best) << " (no FMA)";
  for (const std::int64_t target : supported_targets()) {
    if (target > HWY_AVX2) continue;
    TargetMock mock(target);
    EXPECT_STREQ(trm::pow_elements_path(), hwy::TargetName(target));
    EXPECT_STREQ(trm::exp_elements_path(), hwy::TargetName(target));
  }
}

}  // namespace
