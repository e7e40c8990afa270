// Compile-time Q-format fixed-point type with SystemC sc_fixed / ac_types ac_fixed semantics.
//
//   Fixed<IntBits, FracBits, Signed, Q, O>
//
// holds raw * 2^-FracBits in W = IntBits + FracBits bits; for a signed type the sign bit is one of
// the IntBits (as sc_fixed's I). Examples: linear light Q0.16 is Fixed<0, 16, false>, the
// compensated frame β in Q2.14 is Fixed<2, 14, true> (range [-2, 2)).
//
// * Arithmetic (+, -, *, unary -) is exact: the result type is wide enough to hold every possible
//   value (ProductType, SumType, DifferenceType, NegationType below, as ac_types' rt<>); it uses
//   the default modes, which never act because nothing is dropped.
// * Quantisation (Q) then overflow (O) happen only when a value is converted into a type: the
//   implicit converting constructor (`Fixed<2, 14, true, Quant::Rnd, Overflow::Sat> y = a * b;`),
//   convert<T>(x, &counter), from_double, and the same-type shifts << and >>.
// * Results and operands are limited to 64 bits. A product or sum that would need more does not
//   compile: narrow an operand first (that is a design decision the hardware has to make too).
// * Division has no natural exact result type, so it is a named function, divide<R>(a, b): the
//   exact quotient is rounded with R's quantisation mode and brought into range with R's overflow
//   mode. A zero divisor gives R's max for a > 0, R's min for a < 0 (−max under SatSym) and 0 for
//   a == 0, whatever R's overflow mode, and is counted in SaturationCounter::divisions_by_zero;
//   divide_checked<R> throws std::domain_error instead.
// * from_double is exact before quantisation (a double is a 53-bit integer times a power of two);
//   NaN and ±Inf are rejected with std::invalid_argument.
#pragma once

#include "trm/fx_quantise.hpp"

#include <algorithm>
#include <compare>
#include <cstdint>
#include <stdexcept>
#include <type_traits>

namespace trm::fx {

template <int IntBits, int FracBits, bool Signed, Quant Q = Quant::Trn, Overflow O = Overflow::Wrap>
class Fixed;

template <class T>
struct IsFixed : std::false_type {};
template <int I, int F, bool S, Quant Q, Overflow O>
struct IsFixed<Fixed<I, F, S, Q, O>> : std::true_type {};

template <class T>
concept FixedPoint = IsFixed<std::remove_cvref_t<T>>::value;

namespace detail {
struct RawTag {};
}  // namespace detail

template <int IntBits, int FracBits, bool Signed, Quant Q, Overflow O>
class Fixed {
 public:
  static constexpr int int_bits = IntBits;
  static constexpr int frac_bits = FracBits;
  static constexpr int width = IntBits + FracBits;
  static constexpr bool is_signed = Signed;
  static constexpr Quant quant = Q;
  static constexpr Overflow overflow = O;

  static_assert(width >= 1, "trm::fx::Fixed: total width IntBits + FracBits must be at least 1 bit");
  static_assert(width <= kMaxFormatWidth, "trm::fx::Fixed: total width IntBits + FracBits must be at most 64 bits");
  static_assert(FracBits >= -kMaxFracBitsMagnitude && FracBits <= kMaxFracBitsMagnitude,
                "trm::fx::Fixed: FracBits must lie in [-1024, 1024]");

  // Raw bits as an integer: sign-extended for signed types, zero-extended for unsigned ones.
  using raw_type = std::conditional_t<Signed, std::int64_t, std::uint64_t>;

  static constexpr detail::Target target() { return {width, FracBits, Signed, Q, O}; }

  constexpr Fixed() = default;

  // Conversion from any other fixed-point type: quantise with Q, then overflow with O (as
  // assigning one sc_fixed to another). Implicit on purpose: `Narrow y = a * b;` reads like the
  // hardware it models.
  template <int I2, int F2, bool S2, Quant Q2, Overflow O2>
  constexpr Fixed(const Fixed<I2, F2, S2, Q2, O2>& other)  // NOLINT(google-explicit-constructor)
      : raw_(narrow(detail::convert(other.raw(), F2, target(), nullptr))) {}

  // Same conversion, reporting overflow events.
  template <FixedPoint Src>
  static constexpr Fixed convert_from(const Src& source, SaturationCounter* counter) {
    return Fixed(detail::RawTag{}, narrow(detail::convert(source.raw(), Src::frac_bits, target(), counter)));
  }

  // Takes the low `width` bits of `bits` (sign-extending for signed types): the register view.
  static constexpr Fixed from_raw(raw_type bits) {
    const detail::Quantised as_is{static_cast<detail::int128>(bits), false, false};
    constexpr detail::Target wrap{width, FracBits, Signed, Quant::Trn, Overflow::Wrap};
    return Fixed(detail::RawTag{}, narrow(detail::apply_overflow(as_is, wrap, nullptr)));
  }

  // Exact value of `value`, quantised with Q and overflowed with O. Throws std::invalid_argument
  // for NaN and ±Inf (a pipeline input must be checked before it reaches fixed-point hardware).
  static constexpr Fixed from_double(double value, SaturationCounter* counter = nullptr) {
    const detail::DecodedDouble d = detail::decode_double(value);
    if (!d.finite) throw std::invalid_argument("trm::fx::Fixed::from_double: NaN or infinite input");
    return Fixed(detail::RawTag{}, narrow(detail::convert(d.mantissa, d.frac_bits, target(), counter)));
  }

  static constexpr Fixed from_integer(std::int64_t value, SaturationCounter* counter = nullptr) {
    return Fixed(detail::RawTag{}, narrow(detail::convert(value, 0, target(), counter)));
  }

  static constexpr Fixed max() {
    return Fixed(detail::RawTag{}, narrow(detail::max_raw(width, Signed)));
  }
  static constexpr Fixed min() {
    return Fixed(detail::RawTag{}, narrow(detail::min_raw(width, Signed)));
  }
  // One unit in the last place, 2^-FracBits (the smallest positive value).
  static constexpr Fixed lsb() { return Fixed(detail::RawTag{}, 1); }

  constexpr raw_type raw() const { return raw_; }

  // Exact when the raw value has at most 53 significant bits; otherwise rounded to nearest double.
  constexpr double to_double() const { return static_cast<double>(raw_) * kLsbValue; }

  // Internal: wraps an exact, in-range raw value (used by the arithmetic operators).
  constexpr Fixed(detail::RawTag, raw_type bits) : raw_(bits) {}

  template <FixedPoint Other>
  constexpr Fixed& operator+=(const Other& rhs);
  template <FixedPoint Other>
  constexpr Fixed& operator-=(const Other& rhs);
  template <FixedPoint Other>
  constexpr Fixed& operator*=(const Other& rhs);
  constexpr Fixed& operator<<=(int n) { return *this = *this << n; }
  constexpr Fixed& operator>>=(int n) { return *this = *this >> n; }

 private:
  static constexpr double kLsbValue = detail::pow2(-FracBits);

  // The argument is already in range (convert / apply_overflow guarantee it).
  static constexpr raw_type narrow(detail::int128 v) { return static_cast<raw_type>(v); }

  raw_type raw_ = 0;
};

// Explicit conversion with overflow counting: convert<Narrow>(wide, &counter).
template <FixedPoint To, FixedPoint From>
constexpr To convert(const From& value, SaturationCounter* counter = nullptr) {
  return To::convert_from(value, counter);
}

// ---- Exact result types (ac_types rt<>::mult / plus / minus) ---------------------------------

template <FixedPoint A, FixedPoint B>
using ProductType = Fixed<A::int_bits + B::int_bits, A::frac_bits + B::frac_bits, A::is_signed || B::is_signed>;

namespace detail {
// An unsigned operand added to a signed one needs one more integer bit to keep its top bit.
template <class A, class B>
inline constexpr int sum_int_bits = std::max(A::int_bits + (B::is_signed && !A::is_signed ? 1 : 0),
                                             B::int_bits + (A::is_signed && !B::is_signed ? 1 : 0)) + 1;
}  // namespace detail

template <FixedPoint A, FixedPoint B>
using SumType = Fixed<detail::sum_int_bits<A, B>, std::max(A::frac_bits, B::frac_bits), A::is_signed || B::is_signed>;

template <FixedPoint A, FixedPoint B>
using DifferenceType = Fixed<detail::sum_int_bits<A, B>, std::max(A::frac_bits, B::frac_bits), true>;

template <FixedPoint A>
using NegationType = Fixed<A::int_bits + 1, A::frac_bits, true>;

namespace detail {
// Raw value of `x` with its binary point moved to `frac_bits` (>= x's), exactly.
template <FixedPoint X>
constexpr int128 aligned_raw(const X& x, int frac_bits) {
  return shift_left(static_cast<int128>(x.raw()), frac_bits - X::frac_bits);
}
}  // namespace detail

template <FixedPoint A, FixedPoint B>
constexpr ProductType<A, B> operator*(const A& a, const B& b) {
  using R = ProductType<A, B>;
  // |a| < 2^(Wa - Sa), |b| < 2^(Wb - Sb): the product fits R's width; compute it in 128 bits.
  const detail::int128 p = static_cast<detail::int128>(a.raw()) * static_cast<detail::int128>(b.raw());
  return R(detail::RawTag{}, static_cast<typename R::raw_type>(p));
}

template <FixedPoint A, FixedPoint B>
constexpr SumType<A, B> operator+(const A& a, const B& b) {
  using R = SumType<A, B>;
  const detail::int128 s = detail::aligned_raw(a, R::frac_bits) + detail::aligned_raw(b, R::frac_bits);
  return R(detail::RawTag{}, static_cast<typename R::raw_type>(s));
}

template <FixedPoint A, FixedPoint B>
constexpr DifferenceType<A, B> operator-(const A& a, const B& b) {
  using R = DifferenceType<A, B>;
  const detail::int128 d = detail::aligned_raw(a, R::frac_bits) - detail::aligned_raw(b, R::frac_bits);
  return R(detail::RawTag{}, static_cast<typename R::raw_type>(d));
}

template <FixedPoint A>
constexpr NegationType<A> operator-(const A& a) {
  using R = NegationType<A>;
  return R(detail::RawTag{}, static_cast<typename R::raw_type>(-static_cast<detail::int128>(a.raw())));
}

template <int I, int F, bool S, Quant Q, Overflow O>
template <FixedPoint Other>
constexpr Fixed<I, F, S, Q, O>& Fixed<I, F, S, Q, O>::operator+=(const Other& rhs) {
  return *this = *this + rhs;
}
template <int I, int F, bool S, Quant Q, Overflow O>
template <FixedPoint Other>
constexpr Fixed<I, F, S, Q, O>& Fixed<I, F, S, Q, O>::operator-=(const Other& rhs) {
  return *this = *this - rhs;
}
template <int I, int F, bool S, Quant Q, Overflow O>
template <FixedPoint Other>
constexpr Fixed<I, F, S, Q, O>& Fixed<I, F, S, Q, O>::operator*=(const Other& rhs) {
  return *this = *this * rhs;
}

// ---- Comparisons: exact, across formats --------------------------------------------------------

namespace detail {
template <FixedPoint A, FixedPoint B>
constexpr int common_frac_bits() {
  constexpr int f = std::max(A::frac_bits, B::frac_bits);
  static_assert(A::width + (f - A::frac_bits) <= 126 && B::width + (f - B::frac_bits) <= 126,
                "trm::fx: comparing formats whose binary points are more than ~60 bits apart");
  return f;
}
}  // namespace detail

template <FixedPoint A, FixedPoint B>
constexpr bool operator==(const A& a, const B& b) {
  constexpr int f = detail::common_frac_bits<A, B>();
  return detail::aligned_raw(a, f) == detail::aligned_raw(b, f);
}

template <FixedPoint A, FixedPoint B>
constexpr std::strong_ordering operator<=>(const A& a, const B& b) {
  constexpr int f = detail::common_frac_bits<A, B>();
  return detail::aligned_raw(a, f) <=> detail::aligned_raw(b, f);
}

// ---- Shifts -------------------------------------------------------------------------------------

// x << n: the value x * 2^n brought back into x's own type with its Q and O modes (as sc_fixed's
// `x <<= n`): bits shifted out at the top overflow, bits shifted out at the bottom are quantised.
// n may be negative (then it shifts right). Any int is accepted.
template <FixedPoint A>
constexpr A operator<<(const A& a, int n) {
  // Beyond ±4096 the outcome no longer changes (every bit has left a <= 64-bit value).
  const int clamped = std::clamp(n, -4096, 4096);
  return A(detail::RawTag{}, static_cast<typename A::raw_type>(
                                 detail::convert(a.raw(), A::frac_bits - clamped, A::target(), nullptr)));
}

template <FixedPoint A>
constexpr A operator>>(const A& a, int n) {
  return a << -std::clamp(n, -4096, 4096);
}

// Exact shift: multiplies by 2^N by moving the binary point; the raw bits are unchanged (free in
// hardware: it is wiring). shift_exact<-2>(Q2.14) is Q0.16 holding a quarter of the value.
template <int N, FixedPoint A>
constexpr auto shift_exact(const A& a) {
  using R = Fixed<A::int_bits + N, A::frac_bits - N, A::is_signed, A::quant, A::overflow>;
  return R(detail::RawTag{}, a.raw());
}

// ---- Division -----------------------------------------------------------------------------------

// a / b rounded with R's quantisation mode and brought into R's range with its overflow mode (the
// exact quotient, not a truncated intermediate). Zero divisor: see the header comment.
template <FixedPoint R, FixedPoint A, FixedPoint B>
constexpr R divide(const A& a, const B& b, SaturationCounter* counter = nullptr) {
  using detail::int128;
  // a/b * 2^Fr = (ra * 2^(Fr + Fb - Fa)) / rb: scale whichever side keeps both integers exact.
  constexpr int k = R::frac_bits + B::frac_bits - A::frac_bits;
  static_assert(A::width + std::max(k, 0) <= 125 && B::width + std::max(-k, 0) <= 125,
                "trm::fx::divide: result binary point too far from the operands' (exceeds 125-bit intermediate)");
  if (b.raw() == 0) {
    if (counter != nullptr) ++counter->divisions_by_zero;
    if (a.raw() == 0) return R{};
    if (a.raw() > 0) return R::max();
    return (R::overflow == Overflow::SatSym && R::is_signed) ? R::from_raw(-R::max().raw()) : R::min();
  }
  int128 numerator = k >= 0 ? detail::shift_left(a.raw(), std::max(k, 0)) : static_cast<int128>(a.raw());
  int128 denominator = k < 0 ? detail::shift_left(b.raw(), std::max(-k, 0)) : static_cast<int128>(b.raw());
  if (denominator < 0) {
    numerator = -numerator;
    denominator = -denominator;
  }
  int128 quotient = numerator / denominator;  // truncates toward zero
  int128 remainder = numerator % denominator;
  if (remainder < 0) {  // make it floor division, remainder in [0, denominator)
    quotient -= 1;
    remainder += denominator;
  }
  const bool first_dropped = 2 * remainder >= denominator;
  const bool rest_dropped = first_dropped ? 2 * remainder > denominator : remainder > 0;
  const bool up = detail::round_up(R::quant, numerator < 0, (quotient & 1) != 0, first_dropped, rest_dropped);
  const detail::Quantised q{quotient + (up ? 1 : 0), false, false};
  return R(detail::RawTag{}, static_cast<typename R::raw_type>(detail::apply_overflow(q, R::target(), counter)));
}

template <FixedPoint R, FixedPoint A, FixedPoint B>
constexpr R divide_checked(const A& a, const B& b, SaturationCounter* counter = nullptr) {
  if (b.raw() == 0) throw std::domain_error("trm::fx::divide_checked: division by zero");
  return divide<R>(a, b, counter);
}

}  // namespace trm::fx
