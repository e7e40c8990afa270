// Fixed-point formats chosen at run time (configuration), with exactly the semantics of the
// compile-time type trm::fx::Fixed (both call the same core in trm/fx_quantise.hpp).
//
// A decoder whose residual width is a command-line option cannot make it a template argument; it
// keeps raw integers and a RuntimeFormat instead:
//
//   const RuntimeFormat residual{.int_bits = 2, .frac_bits = bits - 2, .is_signed = true,
//                                .quant = Quant::Rnd, .overflow = Overflow::Sat};
//   residual.validate();                                   // once, at configuration time
//   std::int64_t r = quantise_raw(beta_raw, 14, residual, &clip_counter);
//
// Raw values are std::int64_t, so a run-time format is at most 64 bits signed or 63 bits unsigned.
#pragma once

#include "trm/fixed.hpp"
#include "trm/fx_quantise.hpp"

#include <cstdint>
#include <string>

namespace trm::fx {

struct RuntimeFormat {
  int int_bits = 1;  // includes the sign bit for signed formats (as sc_fixed's I)
  int frac_bits = 15;
  bool is_signed = true;
  Quant quant = Quant::Trn;
  Overflow overflow = Overflow::Wrap;

  constexpr int width() const { return int_bits + frac_bits; }
  constexpr bool is_valid() const {
    return width() >= 1 && width() <= (is_signed ? 64 : 63) && frac_bits >= -kMaxFracBitsMagnitude &&
           frac_bits <= kMaxFracBitsMagnitude;
  }
  // Throws std::invalid_argument naming the problem (width 0, too wide, frac bits out of range).
  void validate() const;

  constexpr std::int64_t min_raw() const { return static_cast<std::int64_t>(detail::min_raw(width(), is_signed)); }
  constexpr std::int64_t max_raw() const { return static_cast<std::int64_t>(detail::max_raw(width(), is_signed)); }

  // e.g. "sQ2.14 Rnd Sat", "uQ0.16 Trn Wrap".
  std::string to_string() const;

  constexpr detail::Target target() const { return {width(), frac_bits, is_signed, quant, overflow}; }

  friend constexpr bool operator==(const RuntimeFormat&, const RuntimeFormat&) = default;
};

// The run-time description of a compile-time type, e.g. format_of<Fixed<2, 14, true>>().
template <FixedPoint T>
constexpr RuntimeFormat format_of() {
  return {T::int_bits, T::frac_bits, T::is_signed, T::quant, T::overflow};
}

[[noreturn]] void throw_invalid_format(const RuntimeFormat& format);

// The value raw_in * 2^-in_frac_bits converted into `out`: quantised with out.quant, then
// overflowed with out.overflow. Returns out's raw value. Throws std::invalid_argument if `out` is
// not valid or |in_frac_bits| > 1024.
constexpr std::int64_t quantise_raw(std::int64_t raw_in, int in_frac_bits, const RuntimeFormat& out,
                                    SaturationCounter* counter = nullptr) {
  if (!out.is_valid() || in_frac_bits < -kMaxFracBitsMagnitude || in_frac_bits > kMaxFracBitsMagnitude) {
    throw_invalid_format(out);
  }
  return static_cast<std::int64_t>(detail::convert(raw_in, in_frac_bits, out.target(), counter));
}

constexpr std::int64_t quantise_raw(std::int64_t raw_in, const RuntimeFormat& in, const RuntimeFormat& out,
                                    SaturationCounter* counter = nullptr) {
  return quantise_raw(raw_in, in.frac_bits, out, counter);
}

// Exact product of two raw values (value scale 2^-(a_frac + b_frac)) converted into `out`. The
// product is formed in 128 bits, so any two int64 raw values are accepted.
constexpr std::int64_t multiply_raw(std::int64_t a, int a_frac_bits, std::int64_t b, int b_frac_bits,
                                    const RuntimeFormat& out, SaturationCounter* counter = nullptr) {
  if (!out.is_valid() || a_frac_bits < -512 || a_frac_bits > 512 || b_frac_bits < -512 || b_frac_bits > 512) {
    throw_invalid_format(out);
  }
  const detail::int128 product = static_cast<detail::int128>(a) * b;
  return static_cast<std::int64_t>(detail::convert(product, a_frac_bits + b_frac_bits, out.target(), counter));
}

// `value` converted exactly, then quantised into `out`. Throws std::invalid_argument for NaN, ±Inf
// or an invalid format.
std::int64_t quantise_double(double value, const RuntimeFormat& out, SaturationCounter* counter = nullptr);

// raw * 2^-frac_bits as a double (rounded to nearest if raw has more than 53 significant bits).
double to_double(std::int64_t raw, const RuntimeFormat& format);

}  // namespace trm::fx
