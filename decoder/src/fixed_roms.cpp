// The ROM contents and tap tables of the fixed-point decoder (DESIGN §5), generated from the double-precision
// functions at construction; evaluation (fixed_stages.cpp) is integer only.
#include "fixed_kernels.hpp"
#include "fixed_tables.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace trm::fixed_detail {

FixedKernels::FixedKernels(const FixedDecoderConfig& config) : config_(config) {
  config_.validate();
  const EncoderConfig& link = config_.decoder.link;
  const int F = config_.linear_frac_bits;
  const fx::RuntimeFormat linear_format{1, F, false, fx::Quant::Rnd, fx::Overflow::Sat};
  linear_lsb_ = std::ldexp(1.0, -F);
  drive_lsb_ = std::ldexp(1.0, -config_.drive_frac_bits);
  residual_lsb_ = std::ldexp(1.0, -config_.residual.frac_bits);

  // I = lin(E): one ROM word per link code.
  code_rom_.resize(static_cast<std::size_t>(max_code()) + 1);
  for (int code = 0; code <= max_code(); ++code) {
    code_rom_[static_cast<std::size_t>(code)] =
        fx::quantise_double(to_linear(static_cast<double>(code) / max_code(), link.transfer), linear_format);
  }

  linear_space_ = link.resample_space == ResampleSpace::Linear;
  if (linear_space_) {
    // D in linear light: lin(E) at D's precision, and the thresholds that re-encode D's result to link codes.
    const fx::RuntimeFormat resample_format{1, config_.linear_resample_frac_bits, false, fx::Quant::Rnd,
                                            fx::Overflow::Sat};
    resample_rom_.resize(static_cast<std::size_t>(max_code()) + 1);
    for (int code = 0; code <= max_code(); ++code) {
      resample_rom_[static_cast<std::size_t>(code)] =
          fx::quantise_double(to_linear(static_cast<double>(code) / max_code(), link.transfer), resample_format);
    }
    encode_thresholds_ = link_code_thresholds(link.bits, link.transfer, config_.linear_resample_frac_bits);
  }

  // L = lin(U(d)): the address is U's output in codes uQb.U; segments aligned to code steps make the segment
  // index and weight plain bit fields of the address. (Encoded space only: in linear space U outputs linear light.)
  fx::LutShape eotf_shape;
  eotf_shape.entries = (max_code() << config_.eotf_segments_per_code_log2) + 1;
  eotf_shape.input_bits = link.bits + config_.eotf_segments_per_code_log2;  // the ROM address (node index)
  eotf_shape.output_bits = 1 + F;
  eotf_shape.output_frac_bits = F;
  const Transfer transfer = link.transfer;
  if (!linear_space_) {
    eotf_ = std::make_unique<fx::InterpolatedLut>(
        "eotf", eotf_shape, std::ldexp(static_cast<double>(max_code()), config_.eotf_segments_per_code_log2),
        [transfer](double t) { return to_linear(t, transfer); });
  }

  // Eq. 5: Rec. 709 weights summing exactly to 2^W; 1/x through the normalised reciprocal LUT (uQ2.24 holds 1.0).
  const std::vector<std::int64_t> luma =
      integer_weights({0.2126, 0.7152, 0.0722}, config_.luma_weight_frac_bits, "motion contrast (luma)");
  std::copy(luma.begin(), luma.end(), luma_weights_.begin());
  fx::LutShape reciprocal_shape;
  reciprocal_shape.entries = config_.reciprocal_entries;
  reciprocal_shape.input_bits = 24;
  reciprocal_shape.output_bits = 26;
  reciprocal_shape.output_frac_bits = 24;
  reciprocal_ = std::make_unique<fx::InterpolatedLut>(fx::make_reciprocal_lut(reciprocal_shape));

  // Eq. 6: exp(-x) = exp(-floor x) exp(-frac x).
  const double s = config_.decoder.sensitivity;
  sensitivity_infinite_ = std::isinf(s);
  if (!sensitivity_infinite_) {
    sensitivity_raw_ = fx::quantise_double(s, {8, config_.sensitivity_frac_bits, false, fx::Quant::Rnd, fx::Overflow::Sat});
  }
  exp_integer_rom_.resize(16);
  for (int i = 0; i < 16; ++i) exp_integer_rom_[static_cast<std::size_t>(i)] = fx::quantise_double(std::exp(-i), linear_format);
  fx::LutShape exp_shape;
  exp_shape.entries = config_.exp_entries;
  exp_shape.input_bits = config_.exp_input_frac_bits;
  exp_shape.output_bits = 1 + F;
  exp_shape.output_frac_bits = F;
  exp_fraction_ = std::make_unique<fx::InterpolatedLut>("exp_neg_fraction", exp_shape,
                                                        std::ldexp(1.0, config_.exp_input_frac_bits),
                                                        [](double t) { return std::exp(-t); });

  const int top = max_output_code();
  drive_lut_shift_ = std::max(0, F - 24);
  const int drive_address_bits = F - drive_lut_shift_;
  emission_.emplace(config_.decoder.panel, config_.decoder.output_bits);
  lcd_ = config_.decoder.panel.has_history();
  if (lcd_) {
    // LCD (Eq. 7 inverse): coefficients sQ7.F, the target LUT x^(1/gamma) and the clamped-drive luminance ROMs.
    const LcdPanel& lcd = config_.decoder.panel.lcd;
    const fx::RuntimeFormat coefficient = lcd_coefficient_format(F);
    lcd_coefficients_ = {fx::quantise_double(lcd.p1, coefficient), fx::quantise_double(lcd.p2, coefficient),
                         fx::quantise_double(lcd.p3, coefficient), fx::quantise_double(lcd.p4, coefficient)};
    lcd_held_coefficients_ = {2 * lcd_coefficients_[0] + lcd_coefficients_[1], 0, 2 * lcd_coefficients_[2],
                              lcd_coefficients_[3]};
    const int address_bits = std::min(24, F + 1);
    fx::LutShape target_shape;
    target_shape.input_bits = address_bits;
    target_shape.octaves = address_bits;
    target_shape.entries = address_bits * config_.lcd_segments_per_octave + 1;
    target_shape.output_bits = 1 + F;
    target_shape.output_frac_bits = F;
    lcd_target_lut_ = std::make_unique<fx::InterpolatedLut>(fx::make_inverse_gamma_lut(lcd.gamma, target_shape));
    lcd_target_shift_ = F + 1 - address_bits;
    const fx::RuntimeFormat luminance{4, F, true, fx::Quant::Rnd, fx::Overflow::Sat};
    for (int end = 0; end < 2; ++end) {
      std::vector<Raw>& rom = lcd_end_luminance_[static_cast<std::size_t>(end)];
      rom.resize(static_cast<std::size_t>(top) + 1);
      for (int j = 0; j <= top; ++j) {
        rom[static_cast<std::size_t>(j)] =
            fx::quantise_double(lcd.emitted(static_cast<double>(end), static_cast<double>(j) / top), luminance);
      }
    }
    // The threshold merges the drive search compares against, once per (v_{t-1}, k) instead of per step: the
    // same integers, so the same codes. 8-bit output: 2^16 words; wider outputs compute them per step.
    if (top <= kLcdMergeTableMaxCode) {
      const std::size_t width = static_cast<std::size_t>(top) + 1;
      lcd_merge_table_.resize(width * (width + 1));
      for (std::size_t row = 0; row <= width; ++row) {
        // Rows 0..top: v_{t-1} = row with the merge coefficients; the last row: the held merge M(v, v).
        const bool held_row = row == width;
        const std::array<Raw, 4>& p = held_row ? lcd_held_coefficients_ : lcd_coefficients_;
        const Raw j = held_row ? 0 : static_cast<Raw>(row);
        for (std::size_t k = 1; k < width; ++k) {
          lcd_merge_table_[row * width + k] = scaled_merge(p, 2 * static_cast<Raw>(k) - 1, j);
        }
      }
    }
    line_plans_ = FixedLinePlans::build(*this);
    return;
  }
  // OLED drive: thresholds T_k = ((k - 1/2) / (2^o - 1))^gamma, the light of the drive half a code below k, rounded
  // up onto the linear grid, so that x >= T_k on the grid is exactly x^(1/gamma) (2^o - 1) + 1/2 >= k.
  const Panel& panel = config_.decoder.panel;
  for (int ch = 0; ch < 3; ++ch) {
    const double gamma = panel.channel_gammas()[static_cast<std::size_t>(ch)];
    std::vector<Raw>& t = thresholds_[static_cast<std::size_t>(ch)];
    t.resize(static_cast<std::size_t>(top) + 1);
    t[0] = 0;
    for (int k = 1; k <= top; ++k) {
      t[static_cast<std::size_t>(k)] =
          static_cast<Raw>(std::ceil(std::ldexp(panel.linear_from_drive((k - 0.5) / top, ch), F)));
    }
    drive_index_[static_cast<std::size_t>(ch)] = ThresholdIndex(t, F + 1);  // x in [0, 1] is uQ1.F
    fx::LutShape drive_shape;
    drive_shape.input_bits = drive_address_bits;
    drive_shape.octaves = drive_address_bits;
    drive_shape.entries = drive_address_bits * config_.drive_segments_per_octave + 1;
    drive_shape.output_bits = 1 + config_.drive_frac_bits;
    drive_shape.output_frac_bits = config_.drive_frac_bits;
    drive_luts_[static_cast<std::size_t>(ch)] =
        std::make_unique<fx::InterpolatedLut>(fx::make_inverse_gamma_lut(gamma, drive_shape));
  }
  line_plans_ = FixedLinePlans::build(*this);
}

const Geometry& FixedKernels::geometry(cv::Size full) {
  const auto key = std::make_pair(full.width, full.height);
  const auto found = geometries_.find(key);
  if (found != geometries_.end()) return found->second;
  const EncoderConfig& link = config_.decoder.link;
  Geometry g;
  g.full = full;
  g.reduced = cv::Size(reduced_size(full.width, link.reduction), reduced_size(full.height, link.reduction));
  const double sigma = link.effective_sigma();
  const int tap_bits = linear_space_ ? config_.linear_gaussian_tap_frac_bits : config_.gaussian_tap_frac_bits;
  const auto gauss_axis = [&](int full_n, int reduced_n) {
    std::vector<PolyphaseTaps> axis(static_cast<std::size_t>(reduced_n));
    for (int k = 0; k < reduced_n; ++k) {
      const GaussianTaps taps = gaussian_taps(k, full_n, reduced_n, sigma);
      PolyphaseTaps& out = axis[static_cast<std::size_t>(k)];
      out.weight = integer_weights(taps.weights, tap_bits, "D (Gaussian taps)");
      for (std::size_t i = 0; i < taps.weights.size(); ++i) {
        out.index.push_back(std::clamp(taps.first_index + static_cast<int>(i), 0, full_n - 1));
      }
    }
    return axis;
  };
  const auto bilinear_axis = [&](int full_n, int reduced_n) {
    std::vector<BilinearWeights> axis(static_cast<std::size_t>(full_n));
    const fx::RuntimeFormat weight{1, config_.bilinear_weight_frac_bits, false, fx::Quant::Rnd, fx::Overflow::Sat};
    for (int x = 0; x < full_n; ++x) {
      const BilinearTap tap = bilinear_tap(x, full_n, reduced_n);
      axis[static_cast<std::size_t>(x)] = {tap.i0, tap.i1, fx::quantise_double(tap.frac, weight)};
    }
    return axis;
  };
  g.gauss_cols = gauss_axis(full.width, g.reduced.width);
  g.gauss_rows = gauss_axis(full.height, g.reduced.height);
  g.bilinear_cols = bilinear_axis(full.width, g.reduced.width);
  g.bilinear_rows = bilinear_axis(full.height, g.reduced.height);
  if (line_plans_.eotf) g.column_blend = column_blend_plan(g, line_plans_.eotf->unit);
  if (line_plans_.gaussian) g.gauss_columns = gaussian_columns_plan(g);
  return geometries_.emplace(key, std::move(g)).first->second;
}

}  // namespace trm::fixed_detail
