// The per-pixel stage arithmetic of the fixed-point decoder (DESIGN §4-5), integer only, one function per stage;
// both schedules call these.
#include "fixed_kernels.hpp"
#include "fixed_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace trm::fixed_detail {

Raw FixedKernels::gaussian_horizontal(const std::uint16_t* codes_row, const PolyphaseTaps& taps, int ch) const {
  if (linear_space_) {
    Raw acc = 0;  // uQ1.P x uQ0.T
    for (std::size_t i = 0; i < taps.weight.size(); ++i) {
      acc += taps.weight[i] * resample_rom_[codes_row[3 * taps.index[i] + ch]];
    }
    return fx::rounded_shift(acc, config_.linear_gaussian_tap_frac_bits, fx::Quant::Rnd);  // uQ1.P
  }
  Raw acc = 0;  // codes x uQ0.T
  for (std::size_t i = 0; i < taps.weight.size(); ++i) acc += taps.weight[i] * codes_row[3 * taps.index[i] + ch];
  // uQb.L, half to even: rows a, b with a + b an integer (255 - pattern) keep a + b exact, so an exact half-code
  // tie of the vertical sum stays exact and rounds up as the encoder rounds it.
  const int shift = config_.gaussian_tap_frac_bits - config_.gaussian_line_frac_bits;
  return fx::rounded_shift(acc, shift, fx::Quant::RndConv);
}

template <typename Line>
std::uint16_t FixedKernels::gaussian_vertical(const Line* const* rows, const PolyphaseTaps& taps, int sample) const {
  Raw acc = 0;  // uQb.(L + T); linear space uQ1.(P + T)
  for (std::size_t j = 0; j < taps.weight.size(); ++j) acc += taps.weight[j] * static_cast<Raw>(rows[j][sample]);
  if (linear_space_) return encode_linear(fx::rounded_shift(acc, config_.linear_gaussian_tap_frac_bits, fx::Quant::Rnd));
  // Q_b: the nearest code, exact half-code ties up, as the encoder's quantise_reduced (which counts a double D within
  // its rounding noise of a half as the half); taps sum to 1, so no clamp is needed.
  return static_cast<std::uint16_t>(fx::rounded_shift(acc, config_.gaussian_tap_frac_bits + config_.gaussian_line_frac_bits, fx::Quant::Rnd));
}

template <typename Line>
void FixedKernels::gaussian_horizontal_line(const std::uint16_t* codes_row, const Geometry& g, Line* out,
                                            bool grey) const {
  const int columns = g.reduced.width;
  if (linear_space_) {  // through the resample ROM: the per-sample path
    for (int k = 0; k < columns; ++k) {
      const PolyphaseTaps& taps = g.gauss_cols[static_cast<std::size_t>(k)];
      for (int ch = 0; ch < 3; ++ch) {
        out[3 * k + ch] = grey && ch > 0 ? out[3 * k] : static_cast<Line>(gaussian_horizontal(codes_row, taps, ch));
      }
    }
    return;
  }
  if (line_plans_.gaussian && g.gauss_columns.samples == 3 * static_cast<std::size_t>(columns)) {
    lines::gaussian_columns(codes_row, 3 * static_cast<std::size_t>(g.full.width), g.gauss_columns,
                            line_plans_.gaussian->horizontal_shift, out);
    return;
  }
  const int shift = config_.gaussian_tap_frac_bits - config_.gaussian_line_frac_bits;
  for (int k = 0; k < columns; ++k) {
    const PolyphaseTaps& taps = g.gauss_cols[static_cast<std::size_t>(k)];
    const int* index = taps.index.data();
    const Raw* weight = taps.weight.data();
    const std::size_t count = taps.weight.size();
    Line* o = out + 3 * k;
    if (grey) {
      Raw acc = 0;
      for (std::size_t i = 0; i < count; ++i) acc += weight[i] * codes_row[3 * index[i]];
      o[0] = o[1] = o[2] = static_cast<Line>(fx::rounded_shift(acc, shift, fx::Quant::RndConv));
      continue;
    }
    Raw acc0 = 0, acc1 = 0, acc2 = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint16_t* pixel = codes_row + 3 * index[i];
      acc0 += weight[i] * pixel[0];
      acc1 += weight[i] * pixel[1];
      acc2 += weight[i] * pixel[2];
    }
    o[0] = static_cast<Line>(fx::rounded_shift(acc0, shift, fx::Quant::RndConv));
    o[1] = static_cast<Line>(fx::rounded_shift(acc1, shift, fx::Quant::RndConv));
    o[2] = static_cast<Line>(fx::rounded_shift(acc2, shift, fx::Quant::RndConv));
  }
}

template <typename Line>
void FixedKernels::gaussian_vertical_row(const Line* const* rows, const PolyphaseTaps& taps, int samples,
                                         std::uint16_t* out, bool grey) const {
  if (linear_space_) {  // re-encoded through the threshold ROM: the per-sample path
    for (int i = 0; i < samples; ++i) out[i] = grey && i % 3 > 0 ? out[i - i % 3] : gaussian_vertical(rows, taps, i);
    return;
  }
  const std::size_t count = taps.weight.size();
  constexpr std::size_t kMaxLineTaps = 64;
  if (line_plans_.gaussian && count <= kMaxLineTaps) {
    std::array<std::uint32_t, kMaxLineTaps> narrow{};
    for (std::size_t j = 0; j < count; ++j) narrow[j] = static_cast<std::uint32_t>(taps.weight[j]);
    lines::gaussian_rows(rows, narrow.data(), count, static_cast<std::size_t>(samples),
                         line_plans_.gaussian->vertical_shift, line_plans_.gaussian->fold_rows, out);
    return;
  }
  const int shift = config_.gaussian_tap_frac_bits + config_.gaussian_line_frac_bits;
  const Raw* weight = taps.weight.data();
  const int step = grey ? 3 : 1;
  for (int i = 0; i < samples; i += step) {
    Raw acc = 0;
    for (std::size_t j = 0; j < count; ++j) acc += weight[j] * static_cast<Raw>(rows[j][i]);
    out[i] = static_cast<std::uint16_t>(fx::rounded_shift(acc, shift, fx::Quant::Rnd));
    if (grey) out[i + 1] = out[i + 2] = out[i];
  }
}

template std::uint16_t FixedKernels::gaussian_vertical(const Raw* const*, const PolyphaseTaps&, int) const;
template std::uint16_t FixedKernels::gaussian_vertical(const std::uint32_t* const*, const PolyphaseTaps&, int) const;
template void FixedKernels::gaussian_horizontal_line(const std::uint16_t*, const Geometry&, Raw*, bool) const;
template void FixedKernels::gaussian_horizontal_line(const std::uint16_t*, const Geometry&, std::uint32_t*, bool) const;
template void FixedKernels::gaussian_vertical_row(const Raw* const*, const PolyphaseTaps&, int, std::uint16_t*,
                                                  bool) const;
template void FixedKernels::gaussian_vertical_row(const std::uint32_t* const*, const PolyphaseTaps&, int,
                                                  std::uint16_t*, bool) const;

std::uint16_t FixedKernels::encode_linear(Raw x) const {
  // Binary search over the threshold ROM: b comparisons per reduced sample.
  return threshold_search(encode_thresholds_, x);
}

Raw FixedKernels::blend_linear(Raw top_left, Raw top_right, Raw bottom_left, Raw bottom_right, Raw col_upper,
                               Raw row_upper) const {
  const Raw unit = Raw{1} << config_.bilinear_weight_frac_bits;
  // U on linear light: the four codes through the I ROM (uQ1.F), result uQ1.F. The exact sum has 1 + F + 2W bits
  // (77 at the defaults): a 128-bit accumulator.
  using Wide = fx::detail::int128;
  const Wide top = (unit - col_upper) * code_rom_[static_cast<std::size_t>(top_left)] +
                   col_upper * code_rom_[static_cast<std::size_t>(top_right)];
  const Wide bottom = (unit - col_upper) * code_rom_[static_cast<std::size_t>(bottom_left)] +
                      col_upper * code_rom_[static_cast<std::size_t>(bottom_right)];
  const int shift = 2 * config_.bilinear_weight_frac_bits;
  return static_cast<Raw>(fx::rounded_shift((unit - row_upper) * top + row_upper * bottom, shift, fx::Quant::Rnd));
}

StoredResidual FixedKernels::store_nonzero_residual(Raw rho) const {
  StoredResidual out;
  fx::SaturationCounter saturation;
  out.value = fx::quantise_raw(rho, config_.linear_frac_bits, config_.residual, &saturation);
  out.saturated = saturation.overflows != 0;
  out.rounded = !out.saturated && fx::rounded_shift(out.value, config_.residual.frac_bits - config_.linear_frac_bits, fx::Quant::Rnd) != rho;
  return out;
}

Raw FixedKernels::scaled_merge(const std::array<Raw, 4>& p, Raw t, Raw j) const {
  // M(T, vp) with T = t / (2 Mx), vp = 2 j / (2 Mx), times (2 Mx)^2: every term is an exact integer.
  const Raw two_top = 2 * static_cast<Raw>(max_output_code());
  const Raw vp2 = 2 * j;
  return p[0] * (t * t + vp2 * vp2) + p[1] * (t * vp2) + p[2] * (two_top * (t + vp2)) + p[3] * (two_top * two_top);
}

Raw FixedKernels::lcd_drive_value(const std::array<Raw, 4>& p, Raw target_scaled, int code, Raw j) const {
  // v between the thresholds around `code`, interpolated linearly in M (reports only; the code is exact).
  const Raw two_top = 2 * static_cast<Raw>(max_output_code());
  const Raw t_lo = std::max<Raw>(0, 2 * code - 1);
  const Raw t_hi = std::min<Raw>(two_top, 2 * code + 1);
  const Raw m_lo = scaled_merge(p, t_lo, j);
  const Raw m_hi = scaled_merge(p, t_hi, j);
  const fx::detail::int128 span = m_hi - m_lo;
  if (span <= 0) return (t_lo << config_.drive_frac_bits) / two_top;  // coefficients quantised to a flat merge
  const fx::detail::int128 offset = std::clamp<fx::detail::int128>(target_scaled - m_lo, 0, span);
  // v = round(2^D (t_lo span + offset dt) / (span 2 Mx)), half up: every operand is non-negative.
  return static_cast<Raw>(
      fx::detail::rounded_quotient(static_cast<fx::detail::uint128>(t_lo * span + offset * (t_hi - t_lo)),
                                   config_.drive_frac_bits, static_cast<fx::detail::uint128>(span * two_top)));
}

LcdSample FixedKernels::lcd_drive(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                                   bool drive_value) const {
  return lcd_solve(wanted, previous_wanted, previous_code, held, std::nullopt, drive_value);
}

LcdSample FixedKernels::lcd_report(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                                   std::uint16_t code) const {
  return lcd_solve(wanted, previous_wanted, previous_code, held, code, true);
}

LcdSample FixedKernels::lcd_solve(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                                  std::optional<std::uint16_t> code, bool drive_value) const {
  const int top = max_output_code();
  LcdSample out;
  const Raw sum = held ? 2 * wanted : wanted + previous_wanted;
  const Raw target_scaled = lcd_target_scaled(sum);
  // First frame of the eye: the pixel is taken as held at x_t (M(v, v) = x_t^(1/gamma), the same m).
  const Raw j = held ? lcd_held_code(target_scaled) : previous_code;
  const Raw x_previous = held ? wanted : previous_wanted;
  out.previous_code = static_cast<std::uint16_t>(j);
  out.contributed = wanted;
  const int end = lcd_clamped_end(sum, j);
  if (end >= 0) {
    // No root in [0, 1]: v clamps to the nearer end; frame t contributes x_eff = 2 M(v, v_prev)^gamma - x_{t-1}.
    const bool above = end == 1;
    out.unreachable = true;
    out.code = static_cast<std::uint16_t>(above ? top : 0);
    out.drive = lcd_clamped_drive(above);
    const Raw x_effective = 2 * lcd_end_luminance_[static_cast<std::size_t>(end)][static_cast<std::size_t>(j)] -
                            x_previous;
    out.shortfall = wanted - x_effective;
    out.contributed = x_effective;
    return out;
  }
  out.code = code ? *code
                  : static_cast<std::uint16_t>(lcd_search(lcd_coefficients_, j, target_scaled,
                                                          lcd_merge_row(static_cast<std::size_t>(j))));
  if (drive_value) out.drive = lcd_drive_value(lcd_coefficients_, target_scaled, out.code, j);
  return out;
}

Raw FixedKernels::lcd_search(const std::array<Raw, 4>& p, Raw j, Raw target_scaled, const Raw* row) const {
  return merge_search(max_output_code(), target_scaled, [&](int k) {  // M(T_k, vp) increases with T
    return row != nullptr ? row[k] : scaled_merge(p, 2 * static_cast<Raw>(k) - 1, j);
  });
}

Raw FixedKernels::lcd_held_code(Raw target_scaled) const {
  const auto held_row = static_cast<std::size_t>(max_output_code()) + 1;
  return lcd_search(lcd_held_coefficients_, 0, target_scaled, lcd_merge_row(held_row));
}

const Raw* FixedKernels::lcd_merge_row(std::size_t row) const {
  const std::size_t width = static_cast<std::size_t>(max_output_code()) + 1;
  return lcd_merge_table_.empty() ? nullptr : lcd_merge_table_.data() + row * width;
}

template <typename Linear>
void FixedKernels::lcd_reports(const Linear* wanted, const std::int32_t* previous_wanted,
                               const std::uint8_t* previous_code, const std::uint16_t* codes, std::size_t n, bool held,
                               Raw* drive, std::uint16_t* previous) const {
  const std::optional<LcdPlan>& plan = line_plans_.lcd;
  if (!plan) {
    for (std::size_t s = 0; s < n; ++s) {
      const LcdSample sample = lcd_report(wanted[s], previous_wanted[s], previous_code[s], held, codes[s]);
      drive[s] = sample.drive;
      previous[s] = sample.previous_code;
    }
    return;
  }
  // lcd_solve's steps, the code given, a chunk at a time: the targets by the target ROM's kernel, and on the eye's
  // first frame (x_{t-1} = x_t) v_{t-1} by the search of the merge table's held row (lcd_held_code).
  constexpr std::size_t kChunk = 3 * 128;  // FixedDecoderCore::drive_lcd_line's chunk, whole
  std::array<Raw, kChunk> sums;
  std::array<Raw, kChunk> targets;
  std::array<Raw, kChunk> held_row;
  std::array<std::uint16_t, kChunk> rows;
  if (held) held_row.fill(plan->width);
  for (std::size_t start = 0; start < n; start += kChunk) {
    const std::size_t count = std::min(kChunk, n - start);
    for (std::size_t i = 0; i < count; ++i) {
      const Raw x = wanted[start + i];
      sums[i] = held ? 2 * x : x + previous_wanted[start + i];
    }
    lines::lcd_targets(sums.data(), count, *plan, *this, targets.data());
    if (held) {
      lines::lcd_search(targets.data(), held_row.data(), count, *plan, rows.data());
    } else {
      std::copy_n(previous_code + start, count, rows.data());
    }
    lines::lcd_drive_values(sums.data(), targets.data(), rows.data(), codes + start, count, *plan, *this,
                            drive + start);
    std::copy_n(rows.data(), count, previous + start);
  }
}

template void FixedKernels::lcd_reports(const std::int32_t*, const std::int32_t*, const std::uint8_t*,
                                        const std::uint16_t*, std::size_t, bool, Raw*, std::uint16_t*) const;
template void FixedKernels::lcd_reports(const Raw*, const std::int32_t*, const std::uint8_t*, const std::uint16_t*,
                                        std::size_t, bool, Raw*, std::uint16_t*) const;

Raw FixedKernels::luma(const Raw* rgb) const {
  const Raw sum = luma_weights_[0] * rgb[0] + luma_weights_[1] * rgb[1] + luma_weights_[2] * rgb[2];
  return fx::rounded_shift(sum, config_.luma_weight_frac_bits, fx::Quant::Rnd);  // uQ1.F
}

Raw FixedKernels::motion_weight(Raw luma_previous, Raw luma_alpha, bool& underflow) const {
  underflow = false;
  const int F = config_.linear_frac_bits;
  const Raw sum = luma_previous + luma_alpha;  // uQ2.F
  const Raw difference = luma_previous > luma_alpha ? luma_previous - luma_alpha : luma_alpha - luma_previous;
  if (difference == 0) return one();  // c = 0 (including a zero sum): w = 1 exactly, for every s
  if (sensitivity_infinite_) return 0;
  if (config_.decoder.sensitivity == 0.0) return one();
  const Raw contrast = contrast_of(difference, sum);
  // Eq. 6: x = s c in uQ5.X, w = exp(-i) exp(-f).
  const Raw x = fx::rounded_shift(sensitivity_raw_ * contrast,
                            config_.sensitivity_frac_bits + F - config_.exp_input_frac_bits, fx::Quant::Rnd);
  const Raw integer_part = x >> config_.exp_input_frac_bits;
  if (integer_part >= 16) {
    underflow = true;
    return 0;
  }
  const Raw fraction = x & ((Raw{1} << config_.exp_input_frac_bits) - 1);
  const Raw e_fraction = exp_fraction_->evaluate_raw(static_cast<std::uint32_t>(fraction));
  return fx::rounded_shift(exp_integer_rom_[static_cast<std::size_t>(integer_part)] * e_fraction, F, fx::Quant::Rnd);
}

Raw FixedKernels::contrast_of(Raw difference, Raw sum) const {
  // Eq. 5: c = difference / sum = difference * mantissa 2^-24 2^-e, uQ1.F (clamped to 1 against LUT error).
  const fx::NormalisedReciprocal reciprocal =
      fx::reciprocal_normalised(*reciprocal_, static_cast<std::uint64_t>(sum), config_.linear_frac_bits);
  const int shift = reciprocal_->shape().output_frac_bits + reciprocal.exponent;
  Raw narrow = 0;
  if (!__builtin_mul_overflow(difference, reciprocal.mantissa_raw, &narrow)) {
    // The exact product fits in 64 bits (at the default formats always: 30 x 26 bits); the rounding is the same.
    return std::min(fx::rounded_shift(narrow, shift, fx::Quant::Rnd), one());
  }
  const fx::detail::int128 product = static_cast<fx::detail::int128>(difference) * reciprocal.mantissa_raw;
  const fx::detail::int128 c128 = fx::rounded_shift(product, shift, fx::Quant::Rnd);
  return static_cast<Raw>(std::min<fx::detail::int128>(c128, one()));
}

Raw FixedKernels::motion_contrast(Raw luma_previous, Raw luma_alpha) const {
  const Raw difference = luma_previous > luma_alpha ? luma_previous - luma_alpha : luma_alpha - luma_previous;
  return difference == 0 ? 0 : contrast_of(difference, luma_previous + luma_alpha);
}

WeightedSample FixedKernels::add_weighted_residual(Raw alpha, Raw weight, Raw residual) const {
  WeightedSample out;
  // Eq. 4: alpha' = clamp(alpha + w rho, 0, 1); w rho is uQ1.F x sQ.R, rounded to F fraction bits.
  const Raw sum = alpha + fx::rounded_shift(weight * residual, config_.residual.frac_bits, fx::Quant::Rnd);
  out.alpha_prime = std::clamp(sum, Raw{0}, one());
  out.clipped = out.alpha_prime != sum;
  out.dropped = sum > out.alpha_prime ? sum - out.alpha_prime : out.alpha_prime - sum;
  return out;
}

WeightedSample FixedKernels::clamp_alpha(Raw alpha) const {
  WeightedSample out;
  out.alpha_prime = std::clamp(alpha, Raw{0}, one());
  out.clipped = out.alpha_prime != alpha;
  out.dropped = alpha > out.alpha_prime ? alpha - out.alpha_prime : out.alpha_prime - alpha;
  return out;
}

std::uint8_t FixedKernels::compare_line(const std::uint16_t* stored, const std::uint16_t* received, int samples) {
  return std::equal(stored, stored + samples, received) ? kLineStatic : std::uint8_t{0};
}

Raw FixedKernels::drive_value(Raw linear, int ch) const {
  if (linear >= one()) return Raw{1} << config_.drive_frac_bits;
  return drive_luts_[static_cast<std::size_t>(ch)]->evaluate_raw(static_cast<std::uint32_t>(linear >> drive_lut_shift_));
}

}  // namespace trm::fixed_detail
