// pow_elements and exp_elements (trm/vector_pow.hpp): glibc's pow and exp a vector at a time, compiled once per x86
// instruction set by Highway's foreach_target and chosen at run time. The order of operations and the fused multiply-adds follow the
// FMA build of glibc 2.36's pow (__ieee754_pow_fma, its disassembly read operation by operation): a fusion more or
// less than glibc's changes the last bit of about one result in three. Hence this file compiles with
// -ffp-contract=off (fixed_point/CMakeLists.txt): only hn::MulAdd / hn::MulSub fuse.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "vector_pow.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

// Compiled once, before the per-target code.
#ifndef TRM_VECTOR_POW_SHARED
#define TRM_VECTOR_POW_SHARED
namespace trm::vector_pow_detail {

inline void libm_elements(const double* x, const double* y, std::size_t y_step, double* out, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) out[k] = std::pow(x[k], y[k * y_step]);
}
inline void libm_exp_elements(const double* x, double* out, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) out[k] = std::exp(x[k]);
}

// What a target's kernel is checked on before its first use: x across (0, 2], half of it pseudo-random (a 64-bit
// linear congruential generator's top 52 bits as a mantissa), half with dense samples near 0, near 1 and at the
// exponent boundaries of the tables. It catches a C library whose pow is another algorithm (most results differ); an
// operation fused where glibc's is not can change as few as one result in a million, which is for the tests'
// millions of inputs (tests/fixed_point/vector_pow_test.cpp) to find.
constexpr std::size_t kCheckCount = 16384;
inline std::array<double, kCheckCount> check_inputs() {
  std::array<double, kCheckCount> x{};
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  for (std::size_t k = 0; k < kCheckCount; ++k) {
    const double t = (static_cast<double>(k) + 0.5) / kCheckCount;
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double random = std::ldexp(static_cast<double>(state >> 12), -52);  // [0, 1)
    x[k] = k % 2 == 0   ? 2.0 * random + 0x1p-30
           : k % 8 == 1 ? t * t * t
           : k % 8 == 3 ? 1.0 - std::ldexp(t, -static_cast<int>(k % 40))
           : k % 8 == 5 ? std::ldexp(1.0 + t, -static_cast<int>(k % 64))
                        : 2.0 * t;
  }
  return x;
}
// The exponents trm uses most: sRGB 2.4 and 1/2.4, gamma 2.2 and 1/2.2.
constexpr std::array<double, 4> kCheckExponents{2.4, 1.0 / 2.4, 2.2, 1.0 / 2.2};

}  // namespace trm::vector_pow_detail
#endif

HWY_BEFORE_NAMESPACE();
namespace trm::vector_pow_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET <= HWY_AVX2 && HWY_NATIVE_FMA
#include "vector_pow_tables.inc"

// kLogTable with a fourth, unused double per entry, so that an entry is one aligned 4-lane load.
alignas(32) constexpr std::array<double, 128 * 4> kLogTable4 = [] {
  std::array<double, 128 * 4> table{};
  for (std::size_t entry = 0; entry < 128; ++entry) {
    for (std::size_t j = 0; j < 3; ++j) table[4 * entry + j] = kLogTable[3 * entry + j];
  }
  return table;
}();

// The table values of each lane's entry. With four lanes (AVX2) the entries are loaded whole and transposed: on the
// CPUs measured a gather of four doubles costs several times as much as four loads and the shuffles.
template <class D>
HWY_INLINE void LookupLog(D d, hn::Vec<hn::RebindToSigned<D>> entry, hn::Vec<D>& invc, hn::Vec<D>& logc,
                          hn::Vec<D>& logctail) {
  const hn::RebindToSigned<D> di;
  if constexpr (hn::MaxLanes(d) == 4) {
    HWY_ALIGN std::int64_t e[4];
    hn::Store(entry, di, e);
    const hn::Vec<D> v0 = hn::Load(d, kLogTable4.data() + 4 * e[0]);
    const hn::Vec<D> v1 = hn::Load(d, kLogTable4.data() + 4 * e[1]);
    const hn::Vec<D> v2 = hn::Load(d, kLogTable4.data() + 4 * e[2]);
    const hn::Vec<D> v3 = hn::Load(d, kLogTable4.data() + 4 * e[3]);
    const hn::Vec<D> t0 = hn::InterleaveLower(d, v0, v1);  // invc0 invc1 | tail0 tail1
    const hn::Vec<D> t1 = hn::InterleaveUpper(d, v0, v1);  // logc0 logc1 | pad
    const hn::Vec<D> t2 = hn::InterleaveLower(d, v2, v3);
    const hn::Vec<D> t3 = hn::InterleaveUpper(d, v2, v3);
    invc = hn::ConcatLowerLower(d, t2, t0);
    logc = hn::ConcatLowerLower(d, t3, t1);
    logctail = hn::ConcatUpperUpper(d, t2, t0);
  } else {
    const auto index = hn::ShiftLeft<2>(entry);
    invc = hn::GatherIndex(d, kLogTable4.data(), index);
    logc = hn::GatherIndex(d, kLogTable4.data() + 1, index);
    logctail = hn::GatherIndex(d, kLogTable4.data() + 2, index);
  }
}

// The bits of exp's table pair (tail, scale word) of each lane's slot (an even word index).
template <class DI>
HWY_INLINE void LookupExp(DI di, hn::Vec<DI> slot, hn::Vec<DI>& tail, hn::Vec<DI>& scale) {
  const auto* words = reinterpret_cast<const std::int64_t*>(kExpTable);
  if constexpr (hn::MaxLanes(di) == 4) {
    HWY_ALIGN std::int64_t s[4];
    hn::Store(slot, di, s);
    const hn::Half<DI> dh;
    const hn::Vec<DI> pairs02 = hn::Combine(di, hn::LoadU(dh, words + s[2]), hn::LoadU(dh, words + s[0]));
    const hn::Vec<DI> pairs13 = hn::Combine(di, hn::LoadU(dh, words + s[3]), hn::LoadU(dh, words + s[1]));
    tail = hn::InterleaveLower(di, pairs02, pairs13);
    scale = hn::InterleaveUpper(di, pairs02, pairs13);
  } else {
    tail = hn::GatherIndex(di, words, slot);
    scale = hn::GatherIndex(di, words + 1, slot);
  }
}

// exp(ehi + elo) as glibc's exp_inline (pow's last step) computes it, or exp(ehi) as its exp (__exp_fma, the same
// operations without elo; elo null): 2^(k/128) exp(r), r = ehi - k ln2/128 (+ elo), from the same table and
// polynomial. Lanes on its special paths, |ehi| < 2^-54 (the result rounds to 1 +- ulp) or >= 512 (over- and
// underflow, and inf and NaN), are marked in `special` and must be recomputed by libm.
template <class D>
HWY_INLINE hn::Vec<D> ExpVector(D d, hn::Vec<D> ehi, const hn::Vec<D>* elo,
                                hn::Mask<hn::RebindToSigned<D>>& special) {
  const hn::RebindToSigned<D> di;
  const hn::RebindToUnsigned<D> du;
  using VD = hn::Vec<D>;
  using VI = hn::Vec<decltype(di)>;
  const VI abstop = hn::BitCast(di, hn::And(hn::ShiftRight<52>(hn::BitCast(du, ehi)), hn::Set(du, 0x7ff)));
  special = hn::Or(hn::Lt(abstop, hn::Set(di, 0x3c9)), hn::Gt(abstop, hn::Set(di, 0x407)));
  const VD shifted = hn::MulAdd(ehi, hn::Set(d, kInvLn2N), hn::Set(d, kShift));
  const VI ki = hn::BitCast(di, shifted);
  const VD ke = hn::Sub(shifted, hn::Set(d, kShift));
  const VD r_hi = hn::MulAdd(ke, hn::Set(d, kNegLn2LoN), hn::MulAdd(ke, hn::Set(d, kNegLn2HiN), ehi));
  const VD re = elo != nullptr ? hn::Add(*elo, r_hi) : r_hi;
  const VI slot = hn::ShiftLeft<1>(hn::And(ki, hn::Set(di, 127)));
  VI tail_bits, scale_bits;
  LookupExp(di, slot, tail_bits, scale_bits);
  const VD tail = hn::BitCast(d, tail_bits);
  const VD scale = hn::BitCast(d, hn::Add(scale_bits, hn::ShiftLeft<45>(ki)));
  const VD c23 = hn::MulAdd(re, hn::Set(d, kExpPoly[1]), hn::Set(d, kExpPoly[0]));
  const VD tail_r = hn::Add(re, tail);
  const VD r2 = hn::Mul(re, re);
  const VD c45 = hn::MulAdd(re, hn::Set(d, kExpPoly[3]), hn::Set(d, kExpPoly[2]));
  const VD sum = hn::MulAdd(c45, hn::Mul(r2, r2), hn::MulAdd(c23, r2, tail_r));
  return hn::MulAdd(sum, scale, scale);
}

// x^y for one vector; lanes on glibc's special paths are marked in `special` and must be recomputed by std::pow.
template <class D>
HWY_INLINE hn::Vec<D> PowVector(D d, hn::Vec<D> x, hn::Vec<D> y, hn::Mask<hn::RebindToSigned<D>>& special) {
  const hn::RebindToSigned<D> di;
  using VD = hn::Vec<D>;
  using VI = hn::Vec<decltype(di)>;
  const VI ix = hn::BitCast(di, x);
  // Logical shifts where a mask follows (AVX2 has no 64-bit arithmetic shift).
  const hn::RebindToUnsigned<D> du;
  const VI top_y = hn::BitCast(di, hn::And(hn::ShiftRight<52>(hn::BitCast(du, y)), hn::Set(du, 0x7ff)));
  // glibc: top12(x) - 1 >= 0x7fe (x <= 0 or subnormal, inf, NaN, or negative), |y| outside [2^-65, 2^63) or NaN.
  special = hn::Or(hn::Lt(ix, hn::Set(di, std::int64_t{0x0010000000000000})),
                   hn::Gt(ix, hn::Set(di, std::int64_t{0x7fefffffffffffff})));
  special = hn::Or(special, hn::Or(hn::Lt(top_y, hn::Set(di, 0x3be)), hn::Gt(top_y, hn::Set(di, 0x43d))));

  // log_inline: x = 2^k z with z in [0x1.6955p-1, 0x1.6955p0), log x = k ln2 + log c + log1p(z / c - 1).
  const VI tmp = hn::Sub(ix, hn::Set(di, std::int64_t{0x3fe6955500000000}));
#if HWY_TARGET == HWY_AVX2
  // AVX2 has no 64-bit arithmetic shift nor int64 -> double conversion (Highway emulates them in 5 and 7 operations).
  // The entry's bits by a logical shift; k = tmp >> 52 (arithmetic) exactly, as the top 12 bits in offset binary
  // (k + 2048) placed in a double's mantissa at exponent 52 and that double less 2^52 + 2048.
  const VI entry = hn::BitCast(di, hn::And(hn::ShiftRight<45>(hn::BitCast(du, tmp)), hn::Set(du, 127)));
  const VD kd = hn::Sub(hn::BitCast(d, hn::Xor(hn::ShiftRight<52>(hn::BitCast(du, tmp)),
                                               hn::Set(du, std::uint64_t{0x4330000000000800}))),
                        hn::Set(d, 0x1.00000000008p52));
#else
  const VI entry = hn::And(hn::ShiftRight<45>(tmp), hn::Set(di, 127));
  const VD kd = hn::ConvertTo(d, hn::ShiftRight<52>(tmp));  // arithmetic shift: k
#endif
  const VD z = hn::BitCast(d, hn::Sub(ix, hn::And(tmp, hn::Set(di, static_cast<std::int64_t>(0xfffULL << 52)))));
  VD invc, logc, logctail;
  LookupLog(d, entry, invc, logc, logctail);
  const VD r = hn::MulAdd(z, invc, hn::Set(d, -1.0));
  const VD t1 = hn::MulAdd(kd, hn::Set(d, kLn2Hi), logc);
  const VD t2 = hn::Add(t1, r);
  const VD lo1 = hn::MulAdd(kd, hn::Set(d, kLn2Lo), logctail);
  const VD lo2 = hn::Add(hn::Sub(t1, t2), r);
  const VD ar = hn::Mul(r, hn::Set(d, kLogPoly[0]));
  const VD ar2 = hn::Mul(r, ar);
  const VD ar3 = hn::Mul(r, ar2);
  const VD hi = hn::Add(t2, ar2);
  const VD lo3 = hn::MulSub(ar, r, ar2);
  const VD lo4 = hn::Add(hn::Sub(t2, hi), ar2);
  const VD a12 = hn::MulAdd(r, hn::Set(d, kLogPoly[2]), hn::Set(d, kLogPoly[1]));
  const VD a34 = hn::MulAdd(r, hn::Set(d, kLogPoly[4]), hn::Set(d, kLogPoly[3]));
  const VD a56 = hn::MulAdd(r, hn::Set(d, kLogPoly[6]), hn::Set(d, kLogPoly[5]));
  const VD poly = hn::MulAdd(ar2, hn::MulAdd(a56, ar2, a34), a12);
  const VD lo = hn::MulAdd(ar3, poly, hn::Add(hn::Add(hn::Add(lo1, lo2), lo3), lo4));
  const VD log_hi = hn::Add(hi, lo);
  const VD log_lo = hn::Add(hn::Sub(hi, log_hi), lo);

  // y log x as ehi + elo.
  const VD ehi = hn::Mul(y, log_hi);
  const VD elo = hn::MulAdd(y, log_lo, hn::MulSub(log_hi, y, ehi));
  hn::Mask<decltype(di)> exp_special;
  const VD result = ExpVector(d, ehi, &elo, exp_special);
  special = hn::Or(special, exp_special);
  return result;
}

// `result` with the lanes marked in `special` recomputed one at a time by libm: lane(xs, j) for lane j, with xs the
// vector x stored (from the vectors, not from the input array: out may be the input).
template <class D, class Lane>
HWY_INLINE hn::Vec<D> WithLibmLanes(D d, hn::Mask<hn::RebindToSigned<D>> special, hn::Vec<D> x, hn::Vec<D> result,
                                    Lane lane) {
  const hn::RebindToSigned<D> di;
  HWY_ALIGN std::int64_t marked[hn::MaxLanes(di)];
  HWY_ALIGN double xs[hn::MaxLanes(d)];
  HWY_ALIGN double rs[hn::MaxLanes(d)];
  hn::Store(hn::VecFromMask(di, special), di, marked);
  hn::Store(x, d, xs);
  hn::Store(result, d, rs);
  for (std::size_t j = 0; j < hn::Lanes(d); ++j) {
    if (marked[j] != 0) rs[j] = lane(xs, j);
  }
  return hn::Load(d, rs);
}

// One vector of x^y into out.
template <class D>
HWY_INLINE void PowStore(D d, hn::Vec<D> vx, hn::Vec<D> vy, double* out) {
  const hn::RebindToSigned<D> di;
  hn::Mask<decltype(di)> special;
  auto result = PowVector(d, vx, vy, special);
  if (HWY_UNLIKELY(!hn::AllFalse(di, special))) {
    // The special operands a decoder meets most, black and full light, exactly as pow gives them:
    // pow(+0, y) = +0 for y > 0 and pow(1, y) = 1 for every y.
    const auto bits = hn::BitCast(di, vx);
    const auto zero_base = hn::And(hn::Eq(bits, hn::Zero(di)),
                                   hn::RebindMask(di, hn::And(hn::Gt(vy, hn::Zero(d)), hn::IsFinite(vy))));
    const auto one_base = hn::RebindMask(di, hn::Eq(vx, hn::Set(d, 1.0)));
    result = hn::IfThenElse(hn::RebindMask(d, zero_base), hn::Zero(d), result);
    result = hn::IfThenElse(hn::RebindMask(d, one_base), hn::Set(d, 1.0), result);
    special = hn::AndNot(hn::Or(zero_base, one_base), special);
  }
  if (HWY_UNLIKELY(!hn::AllFalse(di, special))) {
    HWY_ALIGN double ys[hn::MaxLanes(d)];
    hn::Store(vy, d, ys);
    result = WithLibmLanes(d, special, vx, result,
                           [&ys](const double* xs, std::size_t j) { return std::pow(xs[j], ys[j]); });
  }
  hn::StoreU(result, d, out);
}

// y_step 0: y[0] for every element; 1: y[k].
void KernelElements(const double* x, const double* y, std::size_t y_step, double* out, std::size_t n) {
  const hn::ScalableTag<double> d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes) {
    PowStore(d, hn::LoadU(d, x + k), y_step == 0 ? hn::Set(d, y[0]) : hn::LoadU(d, y + k), out + k);
  }
  if (k == n) return;
  // The tail as one more vector, its unused lanes 2^1 (no special path).
  HWY_ALIGN double xs[hn::MaxLanes(d)];
  HWY_ALIGN double ys[hn::MaxLanes(d)];
  HWY_ALIGN double rs[hn::MaxLanes(d)];
  for (std::size_t j = 0; j < lanes; ++j) {
    xs[j] = k + j < n ? x[k + j] : 2.0;
    ys[j] = k + j < n ? y[(k + j) * y_step] : 1.0;
  }
  PowStore(d, hn::Load(d, xs), hn::Load(d, ys), rs);
  for (std::size_t j = 0; k + j < n; ++j) out[k + j] = rs[j];
}

// Each target checks its own kernel against std::pow at its first use (the C library might not be glibc 2.36's).
bool UseKernel() {
  static const bool agrees = [] {
    const std::array<double, kCheckCount> x = check_inputs();
    std::array<double, kCheckCount> fast{};
    std::array<double, kCheckCount> exact{};
    for (const double y : kCheckExponents) {
      KernelElements(x.data(), &y, 0, fast.data(), kCheckCount);
      libm_elements(x.data(), &y, 0, exact.data(), kCheckCount);
      if (std::memcmp(fast.data(), exact.data(), sizeof fast) != 0) return false;
    }
    return true;
  }();
  return agrees;
}

void PowElements(const double* x, const double* y, std::size_t y_step, double* out, std::size_t n) {
  if (UseKernel()) {
    KernelElements(x, y, y_step, out, n);
  } else {
    libm_elements(x, y, y_step, out, n);
  }
}

const char* Path() { return UseKernel() ? hwy::TargetName(HWY_TARGET) : "libm"; }

// One vector of exp(x) into out, special lanes by std::exp.
template <class D>
HWY_INLINE void ExpStore(D d, hn::Vec<D> vx, double* out) {
  const hn::RebindToSigned<D> di;
  hn::Mask<decltype(di)> special;
  auto result = ExpVector(d, vx, nullptr, special);
  if (HWY_UNLIKELY(!hn::AllFalse(di, special))) {
    result = WithLibmLanes(d, special, vx, result, [](const double* xs, std::size_t j) { return std::exp(xs[j]); });
  }
  hn::StoreU(result, d, out);
}
void ExpKernelElements(const double* x, double* out, std::size_t n) {
  const hn::ScalableTag<double> d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes) ExpStore(d, hn::LoadU(d, x + k), out + k);
  if (k == n) return;
  // The tail as one more vector, its unused lanes 1 (no special path).
  HWY_ALIGN double xs[hn::MaxLanes(d)];
  HWY_ALIGN double rs[hn::MaxLanes(d)];
  for (std::size_t j = 0; j < lanes; ++j) xs[j] = k + j < n ? x[k + j] : 1.0;
  ExpStore(d, hn::Load(d, xs), rs);
  for (std::size_t j = 0; k + j < n; ++j) out[k + j] = rs[j];
}
// As UseKernel: each target checks its exp against std::exp at its first use, on x across (-40, 40].
bool UseExpKernel() {
  static const bool agrees = [] {
    const std::array<double, kCheckCount> unit = check_inputs();  // (0, 2]
    std::array<double, kCheckCount> x{};
    for (std::size_t k = 0; k < kCheckCount; ++k) x[k] = (unit[k] - 1.0) * 40.0;
    std::array<double, kCheckCount> fast{};
    std::array<double, kCheckCount> exact{};
    ExpKernelElements(x.data(), fast.data(), kCheckCount);
    libm_exp_elements(x.data(), exact.data(), kCheckCount);
    return std::memcmp(fast.data(), exact.data(), sizeof fast) == 0;
  }();
  return agrees;
}
void ExpElements(const double* x, double* out, std::size_t n) {
  if (UseExpKernel()) {
    ExpKernelElements(x, out, n);
  } else {
    libm_exp_elements(x, out, n);
  }
}
const char* ExpPath() { return UseExpKernel() ? hwy::TargetName(HWY_TARGET) : "libm"; }
#else
// No FMA (glibc's pow takes its other build there), or not x86: libm itself.
void PowElements(const double* x, const double* y, std::size_t y_step, double* out, std::size_t n) {
  libm_elements(x, y, y_step, out, n);
}
const char* Path() { return "libm"; }
void ExpElements(const double* x, double* out, std::size_t n) { libm_exp_elements(x, out, n); }
const char* ExpPath() { return "libm"; }
#endif

}  // namespace HWY_NAMESPACE
}  // namespace trm::vector_pow_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "trm/vector_pow.hpp"

#include <stdexcept>

namespace trm {
namespace vector_pow_detail {

HWY_EXPORT(PowElements);
HWY_EXPORT(Path);
HWY_EXPORT(ExpElements);
HWY_EXPORT(ExpPath);

void elements(const double* x, const double* y, std::size_t y_step, double* out, std::size_t n) {
  HWY_DYNAMIC_DISPATCH(PowElements)(x, y, y_step, out, n);
}
const char* path() { return HWY_DYNAMIC_DISPATCH(Path)(); }
void exp_elements(const double* x, double* out, std::size_t n) { HWY_DYNAMIC_DISPATCH(ExpElements)(x, out, n); }
const char* exp_path() { return HWY_DYNAMIC_DISPATCH(ExpPath)(); }

}  // namespace vector_pow_detail

void pow_elements(std::span<const double> x, double y, std::span<double> out) {
  if (x.size() != out.size()) throw std::invalid_argument("pow_elements: x and out differ in size");
  vector_pow_detail::elements(x.data(), &y, 0, out.data(), x.size());
}

void pow_elements(std::span<const double> x, std::span<const double> y, std::span<double> out) {
  if (x.size() != out.size() || y.size() != x.size()) {
    throw std::invalid_argument("pow_elements: x, y and out differ in size");
  }
  vector_pow_detail::elements(x.data(), y.data(), 1, out.data(), x.size());
}

const char* pow_elements_path() { return vector_pow_detail::path(); }
void exp_elements(std::span<const double> x, std::span<double> out) {
  if (x.size() != out.size()) throw std::invalid_argument("exp_elements: x and out differ in size");
  vector_pow_detail::exp_elements(x.data(), out.data(), x.size());
}
const char* exp_elements_path() { return vector_pow_detail::exp_path(); }

}  // namespace trm
#endif
