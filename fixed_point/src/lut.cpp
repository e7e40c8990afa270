#include "trm/lut.hpp"

#include "trm/fixed_runtime.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace trm::fx {
namespace {

constexpr int kMaxEntries = 1 << 16;
constexpr int kMaxInputBits = 24;
constexpr int kMaxOutputBits = 32;
constexpr int kSegmentFracBits = InterpolatedLut::kSegmentFracBits;

[[noreturn]] void reject(const std::string& name, const std::string& why) {
  throw std::invalid_argument("trm::fx LUT '" + name + "': " + why);
}

void validate_shape(const std::string& name, const LutShape& s) {
  if (s.entries < 2 || s.entries > kMaxEntries) {
    reject(name, "entries must be in [2, 65536], got " + std::to_string(s.entries));
  }
  if (s.input_bits < 1 || s.input_bits > kMaxInputBits) {
    reject(name, "input_bits must be in [1, 24], got " + std::to_string(s.input_bits));
  }
  if (s.octaves < 0) reject(name, "octaves must be >= 0, got " + std::to_string(s.octaves));
  if (s.output_bits < 1 || s.output_bits > kMaxOutputBits) {
    reject(name, "output_bits must be in [1, 32], got " + std::to_string(s.output_bits));
  }
  if (s.output_frac_bits < -kMaxOutputBits || s.output_frac_bits > 2 * kMaxOutputBits) {
    reject(name, "output_frac_bits must be in [-32, 64], got " + std::to_string(s.output_frac_bits));
  }
}

RuntimeFormat output_format(const LutShape& s) {
  return {s.output_bits - s.output_frac_bits, s.output_frac_bits, s.output_signed, s.rounding, Overflow::Sat};
}

double input_span_of(const LutShape& s) {
  const double codes = std::ldexp(1.0, s.input_bits);
  return s.input_scale == InputScale::Binary ? codes : codes - 1.0;
}

}  // namespace

InterpolatedLut::InterpolatedLut(std::string name, const LutShape& shape, double input_span,
                                 const std::function<double(double)>& function)
    : name_(std::move(name)),
      shape_(shape),
      input_span_(input_span),
      direct_(false),
      segment_step_(0),
      segments_per_octave_log2_(0),
      bottom_region_bits_(0) {
  validate_shape(name_, shape_);
  if (!(input_span > 0.0) || !std::isfinite(input_span)) {
    reject(name_, "input span must be a positive finite number of codes");
  }
  const RuntimeFormat out = output_format(shape_);
  const std::int64_t codes = std::int64_t{1} << shape_.input_bits;
  direct_ = shape_.entries == codes;

  auto rom_word = [&](double t) {
    const double y = function(t);
    if (!std::isfinite(y)) reject(name_, "function is not finite at t = " + std::to_string(t));
    return quantise_double(y, out);
  };

  rom_.resize(static_cast<std::size_t>(shape_.entries));
  if (direct_) {
    // One word per code: rom[u] = f(x(u)), positions past the end of the domain clamp to it.
    for (std::int64_t u = 0; u < codes; ++u) {
      rom_[static_cast<std::size_t>(u)] = rom_word(std::min(static_cast<double>(u) / input_span_, 1.0));
    }
    set_fast_weight_bits();
    return;
  }
  const int segments = shape_.entries - 1;
  if (shape_.octaves > 0) {
    const int octaves = shape_.octaves;
    if (octaves > shape_.input_bits) {
      reject(name_, "octaves must be in [1, input_bits], got " + std::to_string(octaves));
    }
    const int per_octave = segments / octaves;
    if (per_octave * octaves != segments || !std::has_single_bit(static_cast<unsigned>(per_octave))) {
      reject(name_, "octave segmentation needs entries = octaves * 2^k + 1, got " + std::to_string(shape_.entries) +
                        " entries for " + std::to_string(octaves) + " octaves");
    }
    segments_per_octave_log2_ = std::countr_zero(static_cast<unsigned>(per_octave));
    bottom_region_bits_ = shape_.input_bits - octaves + 1;
    // Node j of region r (r = 0: bottom region, r >= 1: octave starting at 2^(bottom + r − 1)):
    // code = region start + j·(region length)/S. Region r ends where region r + 1 starts.
    for (int r = 0; r < octaves; ++r) {
      const double region_start = r == 0 ? 0.0 : std::ldexp(1.0, bottom_region_bits_ + r - 1);
      const double region_length = std::ldexp(1.0, bottom_region_bits_ + (r == 0 ? 0 : r - 1));
      for (int j = (r == 0 ? 0 : 1); j <= per_octave; ++j) {
        const double code = region_start + region_length * j / per_octave;
        rom_[static_cast<std::size_t>(r * per_octave + j)] = rom_word(code / input_span_);
      }
    }
    set_fast_weight_bits();
    return;
  }
  for (int j = 0; j <= segments; ++j) {
    rom_[static_cast<std::size_t>(j)] = rom_word(static_cast<double>(j) / segments);
  }
  // K = (N − 1)·2^32 / span, rounded to an integer once here; evaluation is then integer-only.
  const double step = std::round(std::ldexp(static_cast<double>(segments), kSegmentFracBits) / input_span_);
  if (step < 1.0 || step > std::ldexp(1.0, 62)) {
    reject(name_, "input span too wide or too narrow for the table size");
  }
  segment_step_ = static_cast<std::uint64_t>(step);
  set_fast_weight_bits();
}

void InterpolatedLut::set_fast_weight_bits() {
  if (shape_.rounding != Quant::Rnd) return;
  // |y0| < 2^M and |y1 - y0| < 2^D: y0 2^w and (y1 - y0) w stay below 2^(max(M, D) + w) <= 2^61, their sum and the
  // rounding half below 2^63.
  const auto bits_of = [](std::int64_t v) { return static_cast<int>(std::bit_width(static_cast<std::uint64_t>(v < 0 ? -v : v))); };
  int widest = 0;
  for (std::size_t i = 0; i < rom_.size(); ++i) {
    widest = std::max(widest, bits_of(rom_[i]));
    if (i + 1 < rom_.size()) widest = std::max(widest, bits_of(rom_[i + 1] - rom_[i]));
  }
  fast_weight_bits_ = 61 - widest;
}

std::int64_t InterpolatedLut::interpolate_wide(std::size_t node, std::uint64_t weight, int weight_bits) const {
  const std::size_t last = rom_.size() - 1;
  if (node >= last) return rom_[last];
  // y = rom[i] + (rom[i+1] − rom[i])·w, exact in units of 2^-weight_bits output LSB, then rounded once.
  const detail::Target out{shape_.output_bits, 0, shape_.output_signed, shape_.rounding, Overflow::Sat};
  const std::int64_t y0 = rom_[node];
  const std::int64_t y1 = rom_[node + 1];
  const detail::int128 exact =
      detail::shift_left(y0, weight_bits) + static_cast<detail::int128>(y1 - y0) * static_cast<std::int64_t>(weight);
  return static_cast<std::int64_t>(detail::convert(exact, weight_bits, out, nullptr));
}

double InterpolatedLut::evaluate(std::uint32_t code) const {
  return std::ldexp(static_cast<double>(evaluate_raw(code)), -shape_.output_frac_bits);
}

// ---- The functions ------------------------------------------------------------------------------

namespace {

double srgb_eotf(double x) { return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4); }
double srgb_inverse_eotf(double x) {
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

void require_positive_finite(const std::string& name, const char* what, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    reject(name, std::string(what) + " must be positive and finite, got " + std::to_string(v));
  }
}

}  // namespace

InterpolatedLut make_srgb_eotf_lut(const LutShape& shape) {
  return InterpolatedLut("srgb_eotf", shape, input_span_of(shape), srgb_eotf);
}

InterpolatedLut make_srgb_inverse_eotf_lut(const LutShape& shape) {
  return InterpolatedLut("srgb_inverse_eotf", shape, input_span_of(shape), srgb_inverse_eotf);
}

InterpolatedLut make_power_lut(double exponent, const LutShape& shape) {
  require_positive_finite("power", "exponent", exponent);
  return InterpolatedLut("power(" + std::to_string(exponent) + ")", shape, input_span_of(shape),
                         [exponent](double t) { return std::pow(t, exponent); });
}

InterpolatedLut make_gamma_lut(double gamma, const LutShape& shape) {
  require_positive_finite("gamma", "gamma", gamma);
  return make_power_lut(gamma, shape);
}

InterpolatedLut make_inverse_gamma_lut(double gamma, const LutShape& shape) {
  require_positive_finite("inverse_gamma", "gamma", gamma);
  return make_power_lut(1.0 / gamma, shape);
}

InterpolatedLut make_exp_neg_lut(double xmax, int input_frac_bits, const LutShape& shape) {
  require_positive_finite("exp_neg", "xmax", xmax);
  if (input_frac_bits < -kMaxInputBits || input_frac_bits > 2 * kMaxInputBits) {
    reject("exp_neg", "input_frac_bits must be in [-24, 48], got " + std::to_string(input_frac_bits));
  }
  return InterpolatedLut("exp_neg(xmax=" + std::to_string(xmax) + ")", shape, std::ldexp(xmax, input_frac_bits),
                         [xmax](double t) { return std::exp(-xmax * t); });
}

InterpolatedLut make_reciprocal_lut(const LutShape& shape) {
  // The code is the fraction of a normalised mantissa, so the scale is always binary: x = 1 + u/2^B.
  LutShape binary = shape;
  binary.input_scale = InputScale::Binary;
  return InterpolatedLut("reciprocal", binary, input_span_of(binary), [](double t) { return 1.0 / (1.0 + t); });
}

InterpolatedLut make_sqrt_lut(const LutShape& shape) {
  return InterpolatedLut("sqrt", shape, input_span_of(shape), [](double t) { return std::sqrt(t); });
}

NormalisedReciprocal reciprocal_normalised(const InterpolatedLut& reciprocal_lut, std::uint64_t value,
                                           int value_frac_bits) {
  if (value == 0) throw std::invalid_argument("trm::fx::reciprocal_normalised: reciprocal of zero");
  const int leading_one = 63 - std::countl_zero(value);
  const int bits = reciprocal_lut.shape().input_bits;
  const std::uint64_t below_leading_one = value & ((std::uint64_t{1} << leading_one) - 1u);
  // Align the fraction bits of m to the LUT's input code (truncating any extra low bits).
  const std::uint64_t code = leading_one >= bits ? below_leading_one >> (leading_one - bits)
                                                 : below_leading_one << (bits - leading_one);
  return {reciprocal_lut.evaluate_raw(static_cast<std::uint32_t>(code)), leading_one - value_frac_bits};
}

}  // namespace trm::fx
