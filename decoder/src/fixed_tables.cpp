// The tables the configuration check and the ROM construction share (fixed_tables.hpp).
#include "fixed_tables.hpp"

#include "trm/encoder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <stdexcept>

namespace trm::fixed_detail {

[[noreturn]] void reject_config(const std::string& stage, const std::string& why) {
  throw std::invalid_argument("FixedDecoderConfig: " + stage + ": " + why);
}

fx::RuntimeFormat lcd_coefficient_format(int linear_frac_bits) {
  return fx::RuntimeFormat{7, linear_frac_bits, true, fx::Quant::Rnd, fx::Overflow::Sat};
}

std::uint16_t threshold_search_generic(const std::vector<std::int64_t>& thresholds, std::int64_t x) {
  int lo = 0;
  int hi = static_cast<int>(thresholds.size()) - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (x >= thresholds[static_cast<std::size_t>(mid)]) lo = mid; else hi = mid - 1;
  }
  return static_cast<std::uint16_t>(lo);
}

ThresholdIndex::ThresholdIndex(std::vector<std::int64_t> thresholds, int value_bits)
    : thresholds_(std::move(thresholds)), value_bits_(value_bits) {
  if (value_bits <= kMantissaBits || value_bits > 40 || thresholds_.empty()) return;
  const std::size_t buckets = static_cast<std::size_t>(value_bits - kMantissaBits + 1) << kMantissaBits;
  base_.resize(buckets);
  int steps = 0;
  for (std::size_t b = 0; b < buckets; ++b) {
    const BucketRange range = bucket_range(b);
    const std::int64_t lo = range.lo;
    const std::int64_t hi = range.lo + range.width - 1;
    base_[b] = threshold_search(thresholds_, lo);
    steps = std::max(steps, static_cast<int>(threshold_search(thresholds_, hi)) - static_cast<int>(base_[b]));
  }
  if (steps > kMaxSteps) {
    base_.clear();
    return;
  }
  padded_ = thresholds_;
  padded_.insert(padded_.end(), kMaxSteps + 1, std::numeric_limits<std::int64_t>::max());
  steps_ = std::max(steps, 1);
}

std::vector<std::int64_t> integer_weights(const std::vector<double>& weights, int frac_bits, const char* stage) {
  const std::size_t n = weights.size();
  double weight_sum = 0.0;
  for (double w : weights) {
    if (!std::isfinite(w) || w < 0.0 || w > 1.0) {
      reject_config(stage, "weight " + std::to_string(w) + " is not a finite number in [0, 1]");
    }
    weight_sum += w;
  }
  if (n == 0 || !(weight_sum > 0.5 && weight_sum < 1.5)) reject_config(stage, "the weights do not sum to 1");
  const double scale = std::ldexp(1.0, frac_bits);
  std::vector<std::int64_t> out(n);
  std::vector<double> remainder(n);
  std::int64_t total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double scaled = weights[i] * scale;
    out[i] = static_cast<std::int64_t>(std::floor(scaled));
    remainder[i] = scaled - static_cast<double>(out[i]);
    total += out[i];
  }
  bool symmetric = true;
  for (std::size_t i = 0; i < n / 2; ++i) symmetric = symmetric && weights[i] == weights[n - 1 - i];
  // Groups of taps that receive units together: {i, mirror(i)} when symmetric, else single taps.
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < (symmetric ? (n + 1) / 2 : n); ++i) {
    if (symmetric && i != n - 1 - i) groups.push_back({i, n - 1 - i}); else groups.push_back({i});
  }
  std::stable_sort(groups.begin(), groups.end(), [&](const auto& a, const auto& b) {
    return remainder[a.front()] > remainder[b.front()];
  });
  std::int64_t missing = (std::int64_t{1} << frac_bits) - total;
  while (missing > 0) {
    const std::int64_t before = missing;
    for (const auto& group : groups) {
      if (static_cast<std::int64_t>(group.size()) > missing) continue;
      for (std::size_t i : group) ++out[i];
      missing -= static_cast<std::int64_t>(group.size());
      if (missing == 0) break;
    }
    if (missing == before) {  // cannot happen for symmetric lists (parity); keeps termination obvious
      ++out[groups.front().front()];
      --missing;
    }
  }
  for (std::size_t k = 0; missing < 0; k = (k + 1) % n) {  // only if the doubles summed above 1
    if (out[k] > 0) {
      --out[k];
      ++missing;
    }
  }
  return out;
}

std::vector<std::int64_t> link_code_thresholds(int bits, Transfer transfer, int frac_bits) {
  const int top = (1 << bits) - 1;
  const auto code_of_grid = [&](std::int64_t g) {
    return static_cast<int>(quantise_reduced(to_encoded(std::ldexp(static_cast<double>(g), -frac_bits), transfer), bits));
  };
  std::vector<std::int64_t> t(static_cast<std::size_t>(top) + 1, 0);
  for (int k = 1; k <= top; ++k) {
    auto g = static_cast<std::int64_t>(std::ceil(std::ldexp(to_linear((k - 0.5) / top, transfer), frac_bits)));
    while (g > 0 && code_of_grid(g - 1) >= k) --g;
    while (code_of_grid(g) < k) ++g;
    t[static_cast<std::size_t>(k)] = g;
  }
  return t;
}

}  // namespace trm::fixed_detail
