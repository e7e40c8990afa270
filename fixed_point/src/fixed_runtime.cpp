#include "trm/fixed_runtime.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace trm::fx {

std::string RuntimeFormat::to_string() const {
  return std::string(is_signed ? "sQ" : "uQ") + std::to_string(int_bits) + "." + std::to_string(frac_bits) + " " +
         fx::to_string(quant) + " " + fx::to_string(overflow);
}

void throw_invalid_format(const RuntimeFormat& format) {
  std::string why;
  if (format.width() < 1) {
    why = "total width int_bits + frac_bits must be at least 1";
  } else if (format.width() > (format.is_signed ? 64 : 63)) {
    why = format.is_signed ? "signed width must be at most 64 bits" : "unsigned width must be at most 63 bits (raw values are int64)";
  } else if (format.frac_bits < -kMaxFracBitsMagnitude || format.frac_bits > kMaxFracBitsMagnitude) {
    why = "frac_bits must lie in [-1024, 1024]";
  } else {
    why = "source frac_bits out of range [-1024, 1024]";
  }
  throw std::invalid_argument("trm::fx: invalid fixed-point format " + format.to_string() + ": " + why);
}

void RuntimeFormat::validate() const {
  if (!is_valid()) throw_invalid_format(*this);
}

std::int64_t quantise_double(double value, const RuntimeFormat& out, SaturationCounter* counter) {
  out.validate();
  const detail::DecodedDouble d = detail::decode_double(value);
  if (!d.finite) throw std::invalid_argument("trm::fx::quantise_double: NaN or infinite input");
  return static_cast<std::int64_t>(detail::convert(d.mantissa, d.frac_bits, out.target(), counter));
}

double to_double(std::int64_t raw, const RuntimeFormat& format) {
  return std::ldexp(static_cast<double>(raw), -format.frac_bits);
}

}  // namespace trm::fx
