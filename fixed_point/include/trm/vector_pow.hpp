// std::pow over arrays, a SIMD vector at a time, giving the C library's doubles bit for bit.
//
// The double reference decoder and the transfer functions call pow twice per sample (the EOTF of U's output and the
// panel's x^(1/γ)); libm computes it one call at a time. On x86-64 with FMA and AVX2 glibc's pow is the FMA build of
// Arm's algorithm (a 128-entry log table in extended precision, then a 128-entry exp table). The kernel here runs
// that algorithm operation for operation in Highway vectors — the same tables, the same roundings, fused exactly
// where glibc's FMA build fuses — so every lane is the double std::pow returns. Lanes on glibc's special paths (x
// zero, subnormal, negative, infinite or NaN; y outside [2^-65, 2^63); x^y within 2^-54 of 1 or beyond 2^±512) and
// every element on CPUs without FMA (where glibc takes its other build) are computed by std::pow itself, except the
// two a decoder meets on every black or full-light sample, pow(+0, y > 0) = +0 and pow(1, y) = 1, set in the vector.
//
// Each instruction set's first call checks its kernel against std::pow on 16384 inputs at four exponents and uses
// std::pow alone if one differs (a C library whose pow is another algorithm). tests/fixed_point/vector_pow_test.cpp
// holds the kernel to std::pow over millions of inputs on every instruction set the CPU runs, which is what finds a
// rare one-bit difference.
#pragma once

#include <cstddef>
#include <span>

namespace trm {

// out[k] = std::pow(x[k], y) for every k; out may be x. Throws std::invalid_argument if the sizes differ.
void pow_elements(std::span<const double> x, double y, std::span<double> out);
// out[k] = std::pow(x[k], y[k]).
void pow_elements(std::span<const double> x, std::span<const double> y, std::span<double> out);

// Where the elements are computed: the Highway target's name ("AVX3_DL", "AVX2", ...) when the kernel is in use,
// "libm" when std::pow computes them all.
const char* pow_elements_path();

// out[k] = std::exp(x[k]) for every k, bit for bit (out may be x): glibc's exp (__exp_fma) is the same algorithm as the
// last step of its pow, and runs here as that step without pow's low word, its special lanes (|x| < 2^-54, |x| >= 512,
// inf and NaN) by std::exp; std::exp computes every element where the pow kernel is not used. The reference decoder's
// motion weights w = exp(-s c). Throws std::invalid_argument if the sizes differ.
void exp_elements(std::span<const double> x, std::span<double> out);
const char* exp_elements_path();

}  // namespace trm
