// The std:: references for the LUT functions and the sweep that measures a table against them,
// shared by lut_test.cpp and the lut_accuracy table generator.
#pragma once

#include "trm/fixed_runtime.hpp"
#include "trm/lut.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace trm::fx::testing {

enum class Monotonic { Increasing, Decreasing };

struct ReferenceFunction {
  std::string label;
  std::function<InterpolatedLut(const LutShape&)> make;
  std::function<double(double)> exact;  // of the domain position t in [0, 1] (LUT's position_of)
  Monotonic direction;
  int output_bits = 16;
  int output_frac_bits = 16;
};

inline double srgb_eotf_exact(double x) { return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4); }
inline double srgb_inverse_eotf_exact(double x) {
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

constexpr double kExpRange = 16.0;  // exp(−x) over [0, 16) with a Q4.12 input: the code is the raw value

inline std::vector<ReferenceFunction> reference_functions() {
  return {
      {"sRGB EOTF", make_srgb_eotf_lut, srgb_eotf_exact, Monotonic::Increasing},
      {"sRGB inverse EOTF", make_srgb_inverse_eotf_lut, srgb_inverse_eotf_exact, Monotonic::Increasing},
      {"x^2.2", [](const LutShape& s) { return make_gamma_lut(2.2, s); },
       [](double t) { return std::pow(t, 2.2); }, Monotonic::Increasing},
      {"x^(1/2.2)", [](const LutShape& s) { return make_inverse_gamma_lut(2.2, s); },
       [](double t) { return std::pow(t, 1.0 / 2.2); }, Monotonic::Increasing},
      {"exp(-x), x in [0,16), Q4.12 in", [](const LutShape& s) { return make_exp_neg_lut(kExpRange, 12, s); },
       [](double t) { return std::exp(-kExpRange * std::min(t, 1.0)); }, Monotonic::Decreasing},
      {"1/x, x in [1,2), uQ1.15 out", make_reciprocal_lut, [](double t) { return 1.0 / (1.0 + t); },
       Monotonic::Decreasing, 16, 15},
      {"sqrt(x)", make_sqrt_lut, [](double t) { return std::sqrt(t); }, Monotonic::Increasing},
  };
}

struct LutError {
  std::int64_t max_lsb_vs_quantised = 0;  // max |lut − Q(f)|, output LSB (Q: the LUT's rounding, saturating)
  double max_lsb_vs_exact = 0.0;          // max |lut − f|, output LSB, f clamped to the output range
  int error_free_bits = 0;                // floor(−log2(max |lut − f|)), absolute units
  bool monotonic = true;                  // in the function's direction, non-strict
  std::int64_t codes = 0;                 // number of inputs swept
};

// Sweeps every input code of `lut`.
inline LutError measure(const InterpolatedLut& lut, const std::function<double(double)>& exact,
                        Monotonic direction) {
  const LutShape& s = lut.shape();
  const RuntimeFormat out{s.output_bits - s.output_frac_bits, s.output_frac_bits, s.output_signed, s.rounding,
                          Overflow::Sat};
  const double lsb = std::ldexp(1.0, -s.output_frac_bits);
  const double lowest = to_double(out.min_raw(), out);
  const double highest = to_double(out.max_raw(), out);
  LutError e;
  std::int64_t previous = 0;
  for (std::uint32_t code = 0; code < (std::uint32_t{1} << s.input_bits); ++code) {
    const std::int64_t y = lut.evaluate_raw(code);
    const double f = exact(lut.position_of(code));
    e.max_lsb_vs_quantised = std::max(e.max_lsb_vs_quantised, static_cast<std::int64_t>(std::llabs(y - quantise_double(f, out))));
    const double clamped = std::clamp(f, lowest, highest);
    e.max_lsb_vs_exact = std::max(e.max_lsb_vs_exact, std::abs(static_cast<double>(y) * lsb - clamped) / lsb);
    if (code > 0 && (direction == Monotonic::Increasing ? y < previous : y > previous)) e.monotonic = false;
    previous = y;
    ++e.codes;
  }
  const double max_abs = e.max_lsb_vs_exact * lsb;
  e.error_free_bits = max_abs > 0 ? static_cast<int>(std::floor(-std::log2(max_abs))) : 64;
  return e;
}

}  // namespace trm::fx::testing
