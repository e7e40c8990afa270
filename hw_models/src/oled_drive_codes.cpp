#include "trm/oled_drive_codes.hpp"

#include "trm/transfer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace trm {

// Why a guard of kGuardUlps makes the lookup exact. Let p(x) = x^e (e = 1 / gamma) and P(x) the pow computed: glibc's
// pow, which pow_elements gives bit for bit, is within 0.54 ulp of p (sysdeps/ieee754/dbl-64/e_pow.c), so within
// p 2^-52.1 for a normal result. quantise is monotone in P (a clamp, a product by a positive constant and a sum, each
// correctly rounded). begins[k] = b is a double with code(b) >= k whose predecessor b- has code(b-) < k (a bisection
// finds one whatever P does elsewhere). A double x at least G ulps above b is above b (1 + G 2^-53), so
// p(x) >= p(b) (1 + G 2^-53)^e with e >= 1/4 (gamma <= 4); at G = 256 that factor exceeds 1 + 2^-47, far above the
// (1 + 2^-52.1) / (1 - 2^-52.1) the two errors can take back: P(x) >= P(b) and code(x) >= k. A double at least G ulps
// below b- is below b- (1 - G 2^-54) (the ulps halve below a power of two), so p(x) <= p(b-) (1 - 2^-48) and likewise
// P(x) <= P(b-) and code(x) < k. So a double at least G ulps from every begins[k] has the code of the number of begins
// at or below it. The results there are at least (1/2) / (2^16 - 1), normal.
namespace {

constexpr std::uint64_t kOneBits = 0x3FF0000000000000ULL;  // the pattern of 1.0
static_assert(kMaxPanelGamma <= 4.0, "the guard's proof takes gamma <= 4: widen kGuardUlps for larger gammas");

std::uint64_t bits_of(double x) { return std::bit_cast<std::uint64_t>(x); }
double from_bits(std::uint64_t u) { return std::bit_cast<double>(u); }

}  // namespace

OledDriveCodes::OledDriveCodes(const OledPanel& panel, int bits) {
  panel.validate("OledDriveCodes: ");
  if (bits < 1 || bits > 16) {
    throw std::invalid_argument("OledDriveCodes: bits must be in [1, 16], got " + std::to_string(bits));
  }
  top_ = (1 << bits) - 1;
  // Buckets two bits finer than the codes near 1, where their first values lie closest (relatively gamma / top apart):
  // up to 12 bits a bucket holds the first value of at most about one code (a few at 13-16 bits, where the table's
  // size stops the refinement and the lookup steps more).
  bucket_shift_ = 52 - std::min(bits + 2, 14);
  for (std::size_t c = 0; c < 3; ++c) {
    const double exponent = 1.0 / panel.gamma[c];
    const auto same = std::find_if(tables_.begin(), tables_.end(), [&](const Table& t) { return t.exponent == exponent; });
    if (same != tables_.end()) {
      of_channel_[c] = static_cast<std::size_t>(same - tables_.begin());
      continue;
    }
    of_channel_[c] = tables_.size();
    tables_.push_back(build(exponent));
  }
}

std::uint16_t OledDriveCodes::exact(double x, const Table& t) const {
  return quantise(std::pow(std::clamp(x, 0.0, 1.0), t.exponent), top_);
}

OledDriveCodes::Table OledDriveCodes::build(double exponent) const {
  Table t;
  t.exponent = exponent;
  const auto top = static_cast<std::size_t>(top_);
  t.begins.assign(top + 2, 0);
  t.begins[top + 1] = std::numeric_limits<std::uint64_t>::max();
  const auto code_at = [&](std::uint64_t u) { return exact(from_bits(u), t); };
  for (std::size_t k = 1; k <= top; ++k) {
    // From the exact crossing ((k - 1/2) / top)^gamma, a few ulps from the computed one: doubling steps out to a
    // bracket (code 0 at 0, top at 1), then bisection of the patterns, which order positive doubles as their values.
    const double guess = std::pow((static_cast<double>(k) - 0.5) / top_, 1.0 / exponent);
    std::uint64_t lo = std::min(bits_of(guess), kOneBits);
    std::uint64_t hi = lo;
    for (std::uint64_t step = 1; code_at(lo) >= k; step *= 2) lo = lo > step ? lo - step : 0;
    for (std::uint64_t step = 1; code_at(hi) < k; step *= 2) hi = std::min(hi + step, kOneBits);
    while (hi - lo > 1) {
      const std::uint64_t mid = lo + (hi - lo) / 2;
      (code_at(mid) >= k ? hi : lo) = mid;
    }
    t.begins[k] = hi;
  }
  // The lookup takes the first values in order and more than two guards apart (for gammas in [1/2, 4] and 16 bits at
  // most they are billions of ulps apart).
  for (std::size_t k = 1; k <= top; ++k) {
    if (t.begins[k] <= t.begins[k - 1] + 2 * kGuardUlps + 1) {
      throw std::logic_error("OledDriveCodes: the first values of codes " + std::to_string(k - 1) + " and " +
                             std::to_string(k) + " lie within two guards of each other");
    }
  }
  // Patterns below `lowest` are looked up as `lowest`: code 0, more than the guard below code 1's first value.
  t.lowest = t.begins[1] - kGuardUlps - 1;
  t.first_bucket = t.lowest >> bucket_shift_;
  const std::uint64_t last_bucket = kOneBits >> bucket_shift_;
  t.code_at_bucket.resize(static_cast<std::size_t>(last_bucket - t.first_bucket + 1));
  std::size_t k = 0;
  for (std::uint64_t b = t.first_bucket; b <= last_bucket; ++b) {
    while (k < top && t.begins[k + 1] <= b << bucket_shift_) ++k;
    t.code_at_bucket[static_cast<std::size_t>(b - t.first_bucket)] = static_cast<std::uint16_t>(k);
  }
  return t;
}

// A table's fields for the lookup, held in registers over a row.
struct OledDriveCodes::LookupFields {
  const std::uint64_t* begins;
  const std::uint16_t* code_at_bucket;
  std::uint64_t lowest;
  std::uint64_t first_bucket;
  int shift;
};

// The code of x (not NaN), or -1 where x lies within the guard of a code's first value (the pow decides). Without a
// branch on x's value in the common case: x clamped to [0, 1] (a maximum and a minimum instruction; -0 becomes +0),
// its pattern raised to `lowest`; the code at its bucket's lower end, plus one where the bucket's next code begins at
// or below it (the buckets are fine enough that a second step is rare).
inline int OledDriveCodes::look_up(double x, const LookupFields& t) {
  const double above_zero = x > 0.0 ? x : 0.0;
  const std::uint64_t u = std::max(bits_of(above_zero < 1.0 ? above_zero : 1.0), t.lowest);
  std::size_t k = t.code_at_bucket[static_cast<std::size_t>((u >> t.shift) - t.first_bucket)];
  k += u >= t.begins[k + 1] ? 1 : 0;
  while (u >= t.begins[k + 1]) [[unlikely]] ++k;
  if ((u - t.begins[k] < kGuardUlps) | (t.begins[k + 1] - u <= kGuardUlps)) [[unlikely]] {
    return -1;
  }
  return static_cast<int>(k);
}

OledDriveCodes::LookupFields OledDriveCodes::fields_of(const Table& t) const {
  return LookupFields{t.begins.data(), t.code_at_bucket.data(), t.lowest, t.first_bucket, bucket_shift_};
}

std::uint16_t OledDriveCodes::code(double x, int channel) const {
  if (channel < 0 || channel > 2) throw std::invalid_argument("OledDriveCodes: channel must be 0, 1 or 2");
  const Table& t = tables_[of_channel_[static_cast<std::size_t>(channel)]];
  const int k = look_up(x, fields_of(t));
  return k >= 0 ? static_cast<std::uint16_t>(k) : exact(x, t);
}

bool OledDriveCodes::codes(std::span<const double> x, std::span<std::uint16_t> out) const {
  if (x.size() != out.size()) throw std::invalid_argument("OledDriveCodes::codes: x and out differ in size");
  const std::array<const Table*, 3> table{&tables_[of_channel_[0]], &tables_[of_channel_[1]], &tables_[of_channel_[2]]};
  const std::array<LookupFields, 3> fields{fields_of(*table[0]), fields_of(*table[1]), fields_of(*table[2])};
  bool nan = false;
  const auto one = [&](std::size_t i, std::size_t channel) {
    const double v = x[i];
    if (std::isnan(v)) [[unlikely]] {
      nan = true;
      out[i] = 0;
      return;
    }
    const int k = look_up(v, fields[channel]);
    out[i] = k >= 0 ? static_cast<std::uint16_t>(k) : exact(v, *table[channel]);
  };
  std::size_t i = 0;
  for (; i + 3 <= x.size(); i += 3) {
    one(i, 0);
    one(i + 1, 1);
    one(i + 2, 2);
  }
  for (; i < x.size(); ++i) one(i, i % 3);
  return !nan;
}

}  // namespace trm
