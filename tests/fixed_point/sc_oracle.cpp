#include "sc_oracle.hpp"

namespace trm::fx::testing {
namespace {

// A value of `format` holding exactly the bits `raw` (set through its bits, so 64-bit values are exact).
sc_dt::sc_fxval value_of(std::uint64_t raw, ScFormat format) {
  const int w = format.width();
  if (format.is_signed) {
    sc_dt::sc_fix value(w, format.int_bits, sc_dt::SC_TRN, sc_dt::SC_WRAP);
    value.range(w - 1, 0) = static_cast<sc_dt::uint64>(low_bits(raw, w));
    return value.value();
  }
  sc_dt::sc_ufix value(w, format.int_bits, sc_dt::SC_TRN, sc_dt::SC_WRAP);
  value.range(w - 1, 0) = static_cast<sc_dt::uint64>(low_bits(raw, w));
  return value.value();
}

std::uint64_t assigned_bits(const sc_dt::sc_fxval& value, ScFormat target, Quant q, Overflow o) {
  if (target.is_signed) {
    const sc_dt::sc_fix assigned(value, target.width(), target.int_bits, to_sc(q), to_sc(o));
    return sc_raw_bits(assigned);
  }
  const sc_dt::sc_ufix assigned(value, target.width(), target.int_bits, to_sc(q), to_sc(o));
  return sc_raw_bits(assigned);
}

}  // namespace

std::uint64_t sc_convert_bits(std::uint64_t raw, ScFormat source, ScFormat target, Quant q, Overflow o) {
  return assigned_bits(value_of(raw, source), target, q, o);
}

ScBinaryResult sc_binary_bits(ScOp op, std::uint64_t a_raw, ScFormat a, std::uint64_t b_raw, ScFormat b,
                              ScFormat target, Quant q, Overflow o) {
  const sc_dt::sc_fxval x = value_of(a_raw, a);
  const sc_dt::sc_fxval y = value_of(b_raw, b);
  sc_dt::sc_fxval exact;
  switch (op) {
    case ScOp::Add: exact = x + y; break;
    case ScOp::Subtract: exact = x - y; break;
    case ScOp::Multiply: exact = x * y; break;
  }
  return {assigned_bits(exact, target, q, o), exact.to_double()};
}

std::string describe(ScFormat format, Quant q, Overflow o) {
  return std::string(format.is_signed ? "s" : "u") + "Q" + std::to_string(format.int_bits) + "." +
         std::to_string(format.frac_bits) + " " + to_string(q) + "/" + to_string(o);
}

}  // namespace trm::fx::testing
