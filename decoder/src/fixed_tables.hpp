// What the configuration check and the ROM construction of the fixed-point decoder both derive from a configuration:
// the coefficient register format, the re-encoding thresholds, the integer tap weights, and the threshold-ROM search.
#pragma once

#include "trm/fixed_runtime.hpp"
#include "trm/transfer.hpp"

#include <bit>
#include <cstdint>
#include <string>
#include <vector>

namespace trm::fixed_detail {

// Throws std::invalid_argument "FixedDecoderConfig: <stage>: <why>".
[[noreturn]] void reject_config(const std::string& stage, const std::string& why);

// The LCD merge coefficient registers: sQ7.F (|p| <= kMaxLcdCoefficient = 16 with the sign), F the linear-light
// fraction bits.
fx::RuntimeFormat lcd_coefficient_format(int linear_frac_bits);

// The largest code k with x >= T_k in an increasing threshold ROM (T_0 = 0, one word per code): the quantiser of a
// threshold ROM, by binary search (log2 of the ROM size comparisons).
// A ROM of 2^n words (every drive and link code ROM) is searched without branches: n halving steps, each adding its
// step where x >= T, give the same k for a non-decreasing ROM (the generic search is kept for other sizes).
std::uint16_t threshold_search_generic(const std::vector<std::int64_t>& thresholds, std::int64_t x);
inline std::uint16_t threshold_search(const std::vector<std::int64_t>& thresholds, std::int64_t x) {
  const std::size_t n = thresholds.size();
  if ((n & (n - 1)) != 0) return threshold_search_generic(thresholds, x);
  const std::int64_t* t = thresholds.data();
  std::size_t k = 0;
  for (std::size_t step = n / 2; step != 0; step /= 2) k += x >= t[k + step] ? step : 0;
  return static_cast<std::uint16_t>(k);
}

// threshold_search's result, found faster for the simulation (the modelled hardware still searches the ROM; its
// report is unchanged): a small index addressed like a float, by the leading-one position of x and the kMantissaBits
// bits below it, gives the code at the lower end of x's bucket; the few thresholds inside the bucket (at most
// kMaxSteps, checked at construction) are then compared in turn. Values outside [0, 2^value_bits) and ROMs whose
// buckets hold more thresholds fall back to threshold_search.
class ThresholdIndex {
 public:
  static constexpr int kMantissaBits = 7;
  static constexpr int kMaxSteps = 4;
  ThresholdIndex() = default;
  ThresholdIndex(std::vector<std::int64_t> thresholds, int value_bits);
  std::uint16_t search(std::int64_t x) const {
    const auto u = static_cast<std::uint64_t>(x);
    if (steps_ == 0 || (u >> value_bits_) != 0) return threshold_search(thresholds_, x);
    std::size_t k = base_[bucket_of(u)];
    for (int i = 0; i < steps_; ++i) k += x >= padded_[k + 1] ? 1 : 0;
    return static_cast<std::uint16_t>(k);
  }
  // The values bucket b covers: [lo, lo + width) (width 1 below 2^kMantissaBits, where x is its own bucket).
  struct BucketRange {
    std::int64_t lo = 0;
    std::int64_t width = 1;
  };
  static BucketRange bucket_range(std::size_t b) {
    if (b < (std::size_t{1} << kMantissaBits)) return {static_cast<std::int64_t>(b), 1};
    const int lead = static_cast<int>(b >> kMantissaBits) + kMantissaBits - 1;
    const auto mantissa = static_cast<std::int64_t>(b & ((std::size_t{1} << kMantissaBits) - 1));
    return {((std::int64_t{1} << kMantissaBits) + mantissa) << (lead - kMantissaBits),
            std::int64_t{1} << (lead - kMantissaBits)};
  }
  // The index itself, for the vectorised search (fixed_lines.hpp); steps() == 0: not usable.
  int steps() const { return steps_; }
  int value_bits() const { return value_bits_; }
  const std::vector<std::uint16_t>& base() const { return base_; }
  const std::vector<std::int64_t>& padded() const { return padded_; }

 private:
  static std::size_t bucket_of(std::uint64_t u) {
    const int lead = static_cast<int>(std::bit_width(u)) - 1;
    if (lead < kMantissaBits) return static_cast<std::size_t>(u);
    const std::size_t octave = static_cast<std::size_t>(lead - kMantissaBits + 1);
    return (octave << kMantissaBits) + static_cast<std::size_t>((u >> (lead - kMantissaBits)) & ((1u << kMantissaBits) - 1));
  }
  std::vector<std::int64_t> thresholds_;
  std::vector<std::int64_t> padded_;  // the thresholds, then kMaxSteps words that no x reaches
  std::vector<std::uint16_t> base_;   // code at each bucket's lower end
  int value_bits_ = 0;
  int steps_ = 0;                     // 0: not usable
};

// Largest-remainder rounding of non-negative weights (summing to ~1) to integers summing exactly to 2^frac_bits.
// A mirror-symmetric weight list (taps centred on an integer or half-integer position) stays exactly symmetric:
// mirror pairs receive their extra units together, an odd unit goes to the centre tap. Exact symmetry keeps the
// exact half-code ties of symmetric content (a Nyquist checkerboard at r = 1/2) exact, so that they round up as the
// encoder's quantise_reduced rounds them (see FixedKernels::gaussian_vertical). Otherwise ties go to the lower index,
// so the result is deterministic.
// Weights that are not finite and non-negative with a positive sum (a degenerate Gaussian) are rejected, naming the
// stage: converting NaN to an integer is undefined.
std::vector<std::int64_t> integer_weights(const std::vector<double>& weights, int frac_bits, const char* stage);

// The linear resample space's re-encoding thresholds on the uQ1.frac_bits grid: T_k is the smallest grid value g
// whose link code under the encoder's reduced-frame quantiser, quantise_reduced(enc(g 2^-f)) (round half up, within
// its tie tolerance), is k or more (T_0 = 0). The code of any grid value x is then the largest k with x >= T_k,
// exactly as the encoder quantises that value.
std::vector<std::int64_t> link_code_thresholds(int bits, Transfer transfer, int frac_bits);

}  // namespace trm::fixed_detail
