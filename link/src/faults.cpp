#include "trm/faults.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace trm::link {

namespace {

constexpr int kMaxBurstBits = 1000000;
// Gaps are capped here: at p = 1e-18 a gap of 2^62 bits is still longer than any simulated run.
constexpr double kMaxGap = 4.6e18;

void check_probability(double p, const char* what) {
  if (!(p >= 0.0 && p <= 1.0))  // also rejects NaN
    throw std::invalid_argument(std::string(what) + " must be in [0, 1]");
}

}  // namespace

BurstConfig parse_burst(const std::string& text) {
  const std::size_t colon = text.find(':');
  auto bad = [&] {
    return std::invalid_argument("--burst '" + text + "': expected RATE:LENGTH (bursts per bit, burst length in bits), e.g. 1e-7:64");
  };
  if (colon == std::string::npos) throw bad();
  const std::string rate_text = text.substr(0, colon), length_text = text.substr(colon + 1);
  if (rate_text.empty() || length_text.empty()) throw bad();
  errno = 0;
  char* end = nullptr;
  const double rate = std::strtod(rate_text.c_str(), &end);
  if (end != rate_text.c_str() + rate_text.size() || errno == ERANGE) throw bad();
  const long length = std::strtol(length_text.c_str(), &end, 10);
  if (end != length_text.c_str() + length_text.size() || errno == ERANGE) throw bad();
  BurstConfig burst{rate, static_cast<int>(std::clamp<long>(length, -1, kMaxBurstBits + 1))};
  check_probability(burst.rate, "burst rate");
  if (burst.length_bits < 1 || burst.length_bits > kMaxBurstBits)
    throw std::invalid_argument("--burst '" + text + "': burst length must be 1.." + std::to_string(kMaxBurstBits) + " bits");
  return burst;
}

void FaultConfig::validate() const {
  check_probability(bit_error_rate, "bit error rate (--ber)");
  check_probability(drop_probability, "packet drop probability (--drop)");
  check_probability(burst.rate, "burst rate");
  if (burst.rate > 0.0 && (burst.length_bits < 1 || burst.length_bits > kMaxBurstBits))
    throw std::invalid_argument("burst length must be 1.." + std::to_string(kMaxBurstBits) + " bits");
}

FaultInjector::FaultInjector(FaultConfig config) : config_(config), rng_(config.seed) {
  config_.validate();
  if (config_.bit_error_rate > 0.0) bits_to_next_error_ = geometric_gap(config_.bit_error_rate);
  if (config_.burst.enabled()) bits_to_next_burst_ = geometric_gap(config_.burst.rate);
}

double FaultInjector::uniform01() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

std::uint64_t FaultInjector::geometric_gap(double p) {
  // Skip sampling: with independent errors of probability p per bit, the number of error-free bits before
  // the next error is geometric, floor(ln U / ln(1 - p)) with U uniform in (0, 1]. One draw per error
  // instead of one per bit, so a BER of 1e-9 over gigabits costs nothing.
  if (p >= 1.0) return 0;
  const double u = 1.0 - uniform01();  // (0, 1]
  const double gap = std::floor(std::log(u) / std::log1p(-p));
  return gap >= kMaxGap ? static_cast<std::uint64_t>(kMaxGap) : static_cast<std::uint64_t>(gap);
}

bool FaultInjector::apply(std::vector<std::uint8_t>& packet) {
  ++counters_.packets_seen;
  if (config_.drop_probability > 0.0 && uniform01() < config_.drop_probability) {
    ++counters_.packets_dropped;
    return false;
  }
  const std::uint64_t bits = static_cast<std::uint64_t>(packet.size()) * 8u;
  counters_.bits_delivered += bits;
  auto flip = [&](std::uint64_t bit) { packet[bit / 8] ^= static_cast<std::uint8_t>(0x80u >> (bit % 8)); };
  bool damaged = false;

  if (config_.bit_error_rate > 0.0) {
    std::uint64_t position = 0;  // next bit of this packet the BER process has not passed yet
    while (bits - position > bits_to_next_error_) {
      position += bits_to_next_error_;
      flip(position);
      ++counters_.random_bit_errors;
      damaged = true;
      ++position;
      bits_to_next_error_ = geometric_gap(config_.bit_error_rate);
    }
    bits_to_next_error_ -= bits - position;
  }

  if (config_.burst.enabled()) {
    const std::uint64_t length = static_cast<std::uint64_t>(config_.burst.length_bits);
    std::uint64_t position = 0;
    while (position < bits) {
      if (burst_bits_left_ > 0) {
        // Inside a burst: its first and last bit always flip, the others with probability 1/2.
        const bool first = burst_bits_left_ == length, last = burst_bits_left_ == 1;
        if (first || last || uniform01() < 0.5) {
          flip(position);
          ++counters_.burst_bit_errors;
          damaged = true;
        }
        --burst_bits_left_;
        ++position;
        if (burst_bits_left_ == 0) bits_to_next_burst_ = geometric_gap(config_.burst.rate);
        continue;
      }
      if (bits - position <= bits_to_next_burst_) {
        bits_to_next_burst_ -= bits - position;
        break;
      }
      position += bits_to_next_burst_;
      bits_to_next_burst_ = 0;
      burst_bits_left_ = length;
      ++counters_.bursts;
    }
  }

  if (damaged) ++counters_.packets_damaged;
  return true;
}

}  // namespace trm::link
