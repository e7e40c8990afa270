// Throughput of the fixed-point model's hot paths: a quantised multiply-accumulate (a 16-tap filter
// as in the decoder's resampling stages) against the same filter in double, run-time-format
// quantisation, and LUT evaluation in each table mode. Items are MACs, conversions or lookups.
#include "trm/fixed.hpp"
#include "trm/fixed_runtime.hpp"
#include "trm/lut.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

namespace {

using namespace trm::fx;

constexpr int kTaps = 16;
constexpr int kSamples = 4096;

using Pixel = Fixed<0, 16, false>;                            // linear light uQ0.16
using Tap = Fixed<2, 14, true>;                               // filter weight sQ2.14
using Accumulator = Fixed<7, 30, true>;                       // 16 exact products (2^4 growth) plus headroom
using Output = Fixed<2, 14, true, Quant::Rnd, Overflow::Sat>; // β-like result sQ2.14

std::vector<std::uint64_t> random_bits(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint64_t> v(n);
  for (auto& x : v) x = rng();
  return v;
}

void BM_FixedMacQuantised(benchmark::State& state) {
  std::vector<Pixel> pixels;
  for (const auto b : random_bits(kSamples + kTaps, 1)) pixels.push_back(Pixel::from_raw(b));
  std::vector<Tap> taps;
  for (int k = 0; k < kTaps; ++k) taps.push_back(Tap::from_double(1.0 / kTaps + 0.01 * (k - kTaps / 2)));
  std::vector<Output> out(kSamples);
  for (auto _ : state) {
    for (int i = 0; i < kSamples; ++i) {
      Accumulator acc{};
      for (int k = 0; k < kTaps; ++k) acc = acc + pixels[i + k] * taps[k];  // exact
      out[i] = acc;                                                        // one rounding + saturation
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kSamples * kTaps);
}
BENCHMARK(BM_FixedMacQuantised);

void BM_DoubleMac(benchmark::State& state) {
  std::vector<double> pixels;
  for (const auto b : random_bits(kSamples + kTaps, 1)) pixels.push_back(static_cast<double>(b & 0xffff) / 65536.0);
  std::vector<double> taps;
  for (int k = 0; k < kTaps; ++k) taps.push_back(1.0 / kTaps + 0.01 * (k - kTaps / 2));
  std::vector<double> out(kSamples);
  for (auto _ : state) {
    for (int i = 0; i < kSamples; ++i) {
      double acc = 0.0;
      for (int k = 0; k < kTaps; ++k) acc += pixels[i + k] * taps[k];
      out[i] = acc;
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kSamples * kTaps);
}
BENCHMARK(BM_DoubleMac);

void BM_RuntimeQuantiseRaw(benchmark::State& state) {
  const RuntimeFormat residual{2, 8, true, Quant::Rnd, Overflow::Sat};
  std::vector<std::int64_t> in;
  for (const auto b : random_bits(kSamples, 2)) in.push_back(static_cast<std::int64_t>(b >> 44) - (1 << 19));
  std::vector<std::int64_t> out(kSamples);
  SaturationCounter counter;
  for (auto _ : state) {
    for (int i = 0; i < kSamples; ++i) out[i] = quantise_raw(in[i], 16, residual, &counter);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
}
BENCHMARK(BM_RuntimeQuantiseRaw);

// Arg: 0 = 257 uniform segments, 1 = 257 entries in 16 octaves, 2 = direct 1024-entry (10-bit codes).
void BM_LutEvaluate(benchmark::State& state) {
  LutShape shape;
  if (state.range(0) == 1) shape.octaves = 16;
  if (state.range(0) == 2) {
    shape.entries = 1024;
    shape.input_bits = 10;
    shape.input_scale = InputScale::FullRange;
  }
  const InterpolatedLut lut = make_srgb_eotf_lut(shape);
  std::vector<std::uint32_t> codes;
  const std::uint64_t mask = (std::uint64_t{1} << shape.input_bits) - 1u;
  for (const auto b : random_bits(kSamples, 3)) codes.push_back(static_cast<std::uint32_t>(b & mask));
  std::vector<std::int64_t> out(kSamples);
  for (auto _ : state) {
    for (int i = 0; i < kSamples; ++i) out[i] = lut.evaluate_raw(codes[i]);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
  state.SetLabel(state.range(0) == 0 ? "uniform 257" : state.range(0) == 1 ? "16 octaves 257" : "direct 1024");
}
BENCHMARK(BM_LutEvaluate)->Arg(0)->Arg(1)->Arg(2);

}  // namespace
