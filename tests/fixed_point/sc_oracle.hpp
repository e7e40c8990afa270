// SystemC sc_fixed as the independent oracle for trm::fx (STYLE.md "Fixed-point arithmetic").
#pragma once

#define SC_INCLUDE_FX
#include <systemc>

#include "trm/fixed.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

namespace trm::fx::testing {

constexpr sc_dt::sc_q_mode to_sc(Quant q) {
  switch (q) {
    case Quant::Trn: return sc_dt::SC_TRN;
    case Quant::TrnZero: return sc_dt::SC_TRN_ZERO;
    case Quant::Rnd: return sc_dt::SC_RND;
    case Quant::RndZero: return sc_dt::SC_RND_ZERO;
    case Quant::RndInf: return sc_dt::SC_RND_INF;
    case Quant::RndMinInf: return sc_dt::SC_RND_MIN_INF;
    case Quant::RndConv: return sc_dt::SC_RND_CONV;
  }
  return sc_dt::SC_TRN;
}

constexpr sc_dt::sc_o_mode to_sc(Overflow o) {
  switch (o) {
    case Overflow::Wrap: return sc_dt::SC_WRAP;
    case Overflow::Sat: return sc_dt::SC_SAT;
    case Overflow::SatZero: return sc_dt::SC_SAT_ZERO;
    case Overflow::SatSym: return sc_dt::SC_SAT_SYM;
  }
  return sc_dt::SC_WRAP;
}

// The SystemC type with the same format and modes as Fixed<I, F, S, Q, O>.
template <int I, int F, bool S, Quant Q = Quant::Trn, Overflow O = Overflow::Wrap>
using ScFixed = std::conditional_t<S, sc_dt::sc_fixed<I + F, I, to_sc(Q), to_sc(O)>,
                                   sc_dt::sc_ufixed<I + F, I, to_sc(Q), to_sc(O)>>;

template <FixedPoint T>
using ScOf = ScFixed<T::int_bits, T::frac_bits, T::is_signed, T::quant, T::overflow>;

// The low `width` bits, as the register would hold them (sign extension removed).
constexpr std::uint64_t low_bits(std::uint64_t bits, int width) {
  return width >= 64 ? bits : bits & ((std::uint64_t{1} << width) - 1u);
}

template <class Sc>
std::uint64_t sc_raw_bits(const Sc& v) {
  const int w = v.wl();
  return low_bits(v.range(w - 1, 0).to_uint64(), w);
}

template <FixedPoint T>
std::uint64_t raw_bits(const T& v) {
  return low_bits(static_cast<std::uint64_t>(v.raw()), T::width);
}

// An sc_fixed holding exactly the value of `v` (set through its bits, so 64-bit values are exact).
template <FixedPoint T>
ScOf<T> to_sc_value(const T& v) {
  ScOf<T> s;
  s.range(T::width - 1, 0) = static_cast<sc_dt::uint64>(raw_bits(v));
  return s;
}

// The same SystemC arithmetic through its run-time-parameterised types (sc_fix / sc_ufix, which sc_fixed and
// sc_ufixed only fix at compile time), so the oracle side of a test compiles once however many formats and
// mode pairs it covers. Defined in sc_oracle.cpp.
struct ScFormat {
  int int_bits = 0;
  int frac_bits = 0;
  bool is_signed = true;
  int width() const { return int_bits + frac_bits; }
};

template <FixedPoint T>
constexpr ScFormat sc_format_of() {
  return {T::int_bits, T::frac_bits, T::is_signed};
}

// `raw` (the low source.width() bits) read in `source`, assigned to `target` with modes q / o: the target's bits.
std::uint64_t sc_convert_bits(std::uint64_t raw, ScFormat source, ScFormat target, Quant q, Overflow o);

enum class ScOp { Add, Subtract, Multiply };
struct ScBinaryResult {
  std::uint64_t bits = 0;  // the exact result assigned to the target
  double exact = 0.0;      // the exact (arbitrary-precision) result
};
ScBinaryResult sc_binary_bits(ScOp op, std::uint64_t a_raw, ScFormat a, std::uint64_t b_raw, ScFormat b,
                              ScFormat target, Quant q, Overflow o);

// "sQ4.12 RND/SAT"-style label for failure messages.
std::string describe(ScFormat format, Quant q, Overflow o);

// Calls f.template operator()<Q, O>() for each of the 7 x 4 quantisation / overflow pairs.
template <class F>
void for_each_mode_pair(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f.template operator()<kAllQuantModes[I / 4], kAllOverflowModes[I % 4]>(), ...);
  }(std::make_index_sequence<28>{});
}

}  // namespace trm::fx::testing
