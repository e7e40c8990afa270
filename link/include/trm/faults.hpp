// Seeded link faults: random bit errors at a bit error rate, burst errors, dropped packets.
//
// Reproducible across compilers and platforms: the generator is std::mt19937_64 (its output is fixed
// by the C++ standard) and every draw is converted to a double by our own code, never through the
// implementation-defined std:: distributions.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace trm::link {

// Bursts start at random bit positions (a burst starts at any given bit with probability `rate`).
// A burst of `length_bits` flips its first and last bit and each bit in between with probability 1/2
// (the usual definition of a burst error of length L). Bursts may span packets.
struct BurstConfig {
  double rate = 0.0;
  int length_bits = 0;
  bool enabled() const { return rate > 0.0 && length_bits > 0; }
};

// "RATE:LENGTH", e.g. "1e-7:64". Throws std::invalid_argument with a clear message.
BurstConfig parse_burst(const std::string& text);

struct FaultConfig {
  double bit_error_rate = 0.0;      // independent bit flips, probability per bit, [0, 1]
  BurstConfig burst;
  double drop_probability = 0.0;    // each packet lost whole with this probability, [0, 1]
  std::uint64_t seed = 1;

  bool any() const { return bit_error_rate > 0.0 || burst.enabled() || drop_probability > 0.0; }
  void validate() const;  // throws std::invalid_argument: NaN, negative, > 1, burst length < 1 or > 1e6
};

struct FaultCounters {
  std::uint64_t packets_seen = 0;
  std::uint64_t packets_dropped = 0;
  std::uint64_t packets_damaged = 0;    // delivered with at least one flipped bit
  std::uint64_t bits_delivered = 0;     // bits of delivered packets (the ones bit errors act on)
  std::uint64_t random_bit_errors = 0;  // flips from the BER process
  std::uint64_t bursts = 0;             // bursts started
  std::uint64_t burst_bit_errors = 0;   // flips from bursts
};

class FaultInjector {
 public:
  explicit FaultInjector(FaultConfig config);
  const FaultConfig& config() const { return config_; }

  // Applies the faults to one packet in transmission order. Returns false when the packet is dropped
  // (its bytes are then irrelevant and the bit-error processes do not advance over it); otherwise the
  // packet is delivered, possibly with flipped bits.
  bool apply(std::vector<std::uint8_t>& packet);

  const FaultCounters& counters() const { return counters_; }

 private:
  double uniform01();                       // [0, 1), 53 bits
  std::uint64_t geometric_gap(double p);    // error-free bits before the next event, P(event) = p per bit

  FaultConfig config_;
  std::mt19937_64 rng_;
  FaultCounters counters_;
  std::uint64_t bits_to_next_error_ = 0;    // BER process: skip sampling, carried across packets
  std::uint64_t bits_to_next_burst_ = 0;
  std::uint64_t burst_bits_left_ = 0;       // bits of the current burst still to come
};

}  // namespace trm::link
