// The OLED's drive codes of linear values, q = quantise(OledPanel::drive(x, c), 2^bits - 1), found from the
// values where each code begins instead of a pow per sample: the same integers as the pow (what the double reference
// decoder returns when it keeps no drive plane).
#pragma once

#include "trm/panel.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace trm {

class OledDriveCodes {
 public:
  // bits in [1, 16]; the panel as OledPanel::validate accepts it. Costs a few pows per code and distinct gamma.
  OledDriveCodes(const OledPanel& panel, int bits);

  // The code of x (not NaN) on channel 0, 1 or 2.
  std::uint16_t code(double x, int channel) const;
  // The codes of interleaved RGB samples (channel = index % 3; the sizes must match). A NaN sample gets code 0 and
  // makes the call return false, as OledPanel::drive gives it no drive value.
  bool codes(std::span<const double> x, std::span<std::uint16_t> out) const;

  // Where x lies within this many units in the last place of a code's first value, the code is computed by the pow
  // itself. The proof that this is enough is in the source.
  static constexpr std::uint64_t kGuardUlps = 256;

 private:
  // One channel's gamma: the bit patterns of the first double of each code k = 1 .. top (begins[k]; begins[0] = 0
  // and begins[top + 1] = the largest pattern, as sentinels), and per bucket of doubles (the exponent and the top
  // bucket_bits bits of the fraction) the code at the bucket's lower end.
  struct Table {
    double exponent = 1.0;  // 1 / gamma, as OledPanel::drive computes it
    std::vector<std::uint64_t> begins;
    std::uint64_t lowest = 0;        // the lowest pattern looked up (more than the guard below code 1's first)
    std::uint64_t first_bucket = 0;  // its bucket
    std::vector<std::uint16_t> code_at_bucket;
  };
  struct LookupFields;
  Table build(double exponent) const;
  std::uint16_t exact(double x, const Table& t) const;
  LookupFields fields_of(const Table& t) const;
  static int look_up(double x, const LookupFields& t);

  int top_;
  int bucket_shift_;
  std::vector<Table> tables_;         // one per distinct gamma
  std::array<std::size_t, 3> of_channel_{};  // the table of each channel
};

}  // namespace trm
