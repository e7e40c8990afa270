// FixedDecoderConfig::validate: every format, LUT size and ROM of the fixed-point decoder checked before anything is
// built, naming the stage that a bad setting belongs to.
#include "fixed_tables.hpp"

#include "trm/fixed_decoder.hpp"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

namespace trm {
namespace {

using fixed_detail::lcd_coefficient_format;
using fixed_detail::link_code_thresholds;

[[noreturn]] void reject(const std::string& stage, const std::string& why) { fixed_detail::reject_config(stage, why); }

void require_range(const std::string& stage, const char* what, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    reject(stage, std::string(what) + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                      std::to_string(value));
  }
}

}  // namespace

void FixedDecoderConfig::validate() const {
  decoder.validate();
  const EncoderConfig& link = decoder.link;
  if (decoder.panel.has_history()) {
    // The panel itself is valid (decoder.validate); what the sQ7.F coefficient registers hold must still be a
    // merge increasing in v_t, or the threshold search has no answer (a p3 below half an LSB rounds to 0).
    const LcdPanel& lcd = decoder.panel.lcd;
    const fx::RuntimeFormat coefficient = lcd_coefficient_format(linear_frac_bits);
    LcdPanel held_in_registers = lcd;
    double* registers[] = {&held_in_registers.p1, &held_in_registers.p2, &held_in_registers.p3, &held_in_registers.p4};
    for (double* p : registers) *p = std::ldexp(static_cast<double>(fx::quantise_double(*p, coefficient)), -linear_frac_bits);
    Panel quantised = decoder.panel;
    quantised.lcd = held_in_registers;
    try {
      quantised.validate("");
    } catch (const std::invalid_argument& e) {
      reject("LCD drive (merge coefficients " + coefficient.to_string() + ")",
             std::string("the coefficients as the registers hold them break a rule: ") + e.what() +
                 "; these coefficients are not supported in fixed point");
    }
    if (lcd_segments_per_octave < 1 || lcd_segments_per_octave > 2048 ||
        !std::has_single_bit(static_cast<unsigned>(lcd_segments_per_octave))) {
      reject("LCD drive (target LUT)", "lcd_segments_per_octave must be a power of two in [1, 2048]");
    }
  }
  require_range("linear light", "linear_frac_bits", linear_frac_bits, 8, 28);
  require_range("execution", "threads", threads, 1, kMaxDecoderThreads);
  if (link.resample_space == ResampleSpace::Linear) {
    const std::string stage = "D (linear resample space)";
    require_range(stage, "linear_resample_frac_bits", linear_resample_frac_bits, 16, 40);
    require_range(stage, "linear_gaussian_tap_frac_bits", linear_gaussian_tap_frac_bits, 8, 30);
    if (linear_resample_frac_bits + linear_gaussian_tap_frac_bits > 62) {
      reject(stage, "lin(E) x taps accumulator exceeds 62 bits (linear_resample_frac_bits + "
                    "linear_gaussian_tap_frac_bits > 62)");
    }
    const std::vector<std::int64_t> t = link_code_thresholds(link.bits, link.transfer, linear_resample_frac_bits);
    for (std::size_t k = 1; k < t.size(); ++k) {
      if (t[k] <= t[k - 1]) {
        reject(stage, "uQ1." + std::to_string(linear_resample_frac_bits) + " is too narrow to re-encode " +
                          std::to_string(link.bits) + "-bit " + to_string(link.transfer) + " codes: the thresholds of "
                          "codes " + std::to_string(k - 1) + " and " + std::to_string(k) + " collapse");
      }
    }
  }
  require_range("D (Gaussian taps)", "gaussian_tap_frac_bits", gaussian_tap_frac_bits, 8, 30);
  require_range("D (line buffer)", "gaussian_line_frac_bits", gaussian_line_frac_bits, 0, 30);
  if (link.bits + gaussian_line_frac_bits + gaussian_tap_frac_bits > 62) {
    reject("D (line buffer)", "codes x taps accumulator exceeds 62 bits (bits + line + tap fraction bits)");
  }
  require_range("U (bilinear weights)", "bilinear_weight_frac_bits", bilinear_weight_frac_bits, 4, 24);
  require_range("EOTF LUT", "eotf_segments_per_code_log2", eotf_segments_per_code_log2, 0, 12);
  require_range("U (output)", "upsample_frac_bits", upsample_frac_bits, eotf_segments_per_code_log2, 32);
  if ((static_cast<std::int64_t>((1 << link.bits) - 1) << eotf_segments_per_code_log2) + 1 > 65536) {
    reject("EOTF LUT", "(2^bits - 1) 2^k + 1 entries exceed the 65536-word ROM limit");
  }
  if (!residual.is_signed) reject("residual store", "the residual format must be signed (rho is in [-1, 1])");
  if (!residual.is_valid() || residual.width() > 32 || residual.int_bits < 1 || residual.frac_bits < 1 ||
      residual.frac_bits > linear_frac_bits) {
    reject("residual store", "format " + residual.to_string() +
                                 " must have <= 32 bits, >= 1 integer bit and 1..linear_frac_bits fraction bits");
  }
  require_range("motion contrast (luma)", "luma_weight_frac_bits", luma_weight_frac_bits, 8, 30);
  require_range("motion contrast (reciprocal LUT)", "reciprocal_entries", reciprocal_entries, 65, 65536);
  require_range("motion weight", "sensitivity_frac_bits", sensitivity_frac_bits, 4, 24);
  require_range("motion weight (exp LUT)", "exp_input_frac_bits", exp_input_frac_bits, 8, 24);
  require_range("motion weight (exp LUT)", "exp_entries", exp_entries, 65, 65536);
  require_range("OLED drive", "drive_frac_bits", drive_frac_bits, 8, 30);
  if (drive_segments_per_octave < 1 || drive_segments_per_octave > 1024 ||
      !std::has_single_bit(static_cast<unsigned>(drive_segments_per_octave))) {
    reject("OLED drive (value LUT)", "drive_segments_per_octave must be a power of two in [1, 1024]");
  }
  // The threshold ROM must tell every drive code apart: T_1 < T_2 < ... on the linear grid.
  const int top = (1 << decoder.output_bits) - 1;
  for (double gamma : decoder.panel.channel_gammas()) {
    const double t1 = std::ceil(std::ldexp(std::pow(0.5 / top, gamma), linear_frac_bits));
    const double t2 = std::ceil(std::ldexp(std::pow(1.5 / top, gamma), linear_frac_bits));
    if (!(t1 >= 1.0 && t2 > t1)) {
      reject("OLED/LCD drive (linear light)", "uQ1." + std::to_string(linear_frac_bits) +
                                              " is too narrow for " + std::to_string(decoder.output_bits) +
                                              "-bit drive at gamma " + std::to_string(gamma) +
                                              ": thresholds of codes 0, 1, 2 collapse");
    }
  }
}

}  // namespace trm
