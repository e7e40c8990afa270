// Configuration checks, ROM generation and the per-pixel stage functions of the fixed-point decoder
// (DESIGN §4-5). ROM contents are generated here from the double-precision functions; evaluation is integer only.
#include "fixed_kernels.hpp"
#include "lost_view.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace trm {
namespace {

// The largest code k with x >= T_k in an increasing threshold ROM (T_0 = 0, one word per code): the quantiser of a
// threshold ROM, by binary search (log2 of the ROM size comparisons).
std::uint16_t threshold_search(const std::vector<std::int64_t>& thresholds, std::int64_t x) {
  int lo = 0;
  int hi = static_cast<int>(thresholds.size()) - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (x >= thresholds[static_cast<std::size_t>(mid)]) lo = mid; else hi = mid - 1;
  }
  return static_cast<std::uint16_t>(lo);
}

// The LCD merge coefficient registers: sQ7.F (|p| <= kMaxLcdCoefficient = 16 with the sign), F the linear-light
// fraction bits.
fx::RuntimeFormat lcd_coefficient_format(int linear_frac_bits) {
  return fx::RuntimeFormat{7, linear_frac_bits, true, fx::Quant::Rnd, fx::Overflow::Sat};
}

[[noreturn]] void reject(const std::string& stage, const std::string& why) {
  throw std::invalid_argument("FixedDecoderConfig: " + stage + ": " + why);
}

void require_range(const std::string& stage, const char* what, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    reject(stage, std::string(what) + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                      std::to_string(value));
  }
}

// Largest-remainder rounding of non-negative weights (summing to ~1) to integers summing exactly to 2^frac_bits.
// A mirror-symmetric weight list (taps centred on an integer or half-integer position) stays exactly symmetric:
// mirror pairs receive their extra units together, an odd unit goes to the centre tap. Exact symmetry keeps the
// exact half-code ties of symmetric content (a Nyquist checkerboard at r = 1/2) exact, so that they round up as the
// encoder's quantise_reduced rounds them (see FixedKernels::gaussian_vertical). Otherwise ties go to the lower index,
// so the result is deterministic.
// Weights that are not finite and non-negative with a positive sum (a degenerate Gaussian) are rejected, naming the
// stage: converting NaN to an integer is undefined.
std::vector<std::int64_t> integer_weights(const std::vector<double>& weights, int frac_bits, const char* stage) {
  const std::size_t n = weights.size();
  double weight_sum = 0.0;
  for (double w : weights) {
    if (!std::isfinite(w) || w < 0.0 || w > 1.0) {
      reject(stage, "weight " + std::to_string(w) + " is not a finite number in [0, 1]");
    }
    weight_sum += w;
  }
  if (n == 0 || !(weight_sum > 0.5 && weight_sum < 1.5)) reject(stage, "the weights do not sum to 1");
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

// The linear resample space's re-encoding thresholds on the uQ1.frac_bits grid: T_k is the smallest grid value g
// whose link code under the encoder's reduced-frame quantiser, quantise_reduced(enc(g 2^-f)) (round half up, within
// its tie tolerance), is k or more (T_0 = 0). The code of any grid value x is then the largest k with x >= T_k,
// exactly as the encoder quantises that value.
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

}  // namespace

void FixedDecoderConfig::validate() const {
  decoder.validate();
  const EncoderConfig& link = decoder.link;
  if (decoder.panel.kind == PanelKind::Lcd) {
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
      validate_panel(quantised, "");
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
  const std::array<double, 3> gammas = decoder.panel.kind == PanelKind::Oled
                                           ? decoder.panel.oled.gamma
                                           : std::array<double, 3>{decoder.panel.lcd.gamma, decoder.panel.lcd.gamma,
                                                                   decoder.panel.lcd.gamma};
  for (double gamma : gammas) {
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

namespace fixed_detail {

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
  lcd_ = config_.decoder.panel.kind == PanelKind::Lcd;
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
    const fx::RuntimeFormat luminance{4, F, true, fx::Quant::Rnd, fx::Overflow::Sat};
    for (int end = 0; end < 2; ++end) {
      std::vector<Raw>& rom = lcd_end_luminance_[static_cast<std::size_t>(end)];
      rom.resize(static_cast<std::size_t>(top) + 1);
      for (int j = 0; j <= top; ++j) {
        const double merged = lcd.merge(static_cast<double>(end), static_cast<double>(j) / top);
        rom[static_cast<std::size_t>(j)] = fx::quantise_double(std::pow(std::max(merged, 0.0), lcd.gamma), luminance);
      }
    }
    return;
  }
  // OLED drive: thresholds T_k = ((k - 1/2) / (2^o - 1))^gamma rounded up onto the linear grid, so that x >= T_k on
  // the grid is exactly x^(1/gamma) (2^o - 1) + 1/2 >= k.
  for (int ch = 0; ch < 3; ++ch) {
    const double gamma = config_.decoder.panel.oled.gamma[static_cast<std::size_t>(ch)];
    std::vector<Raw>& t = thresholds_[static_cast<std::size_t>(ch)];
    t.resize(static_cast<std::size_t>(top) + 1);
    t[0] = 0;
    for (int k = 1; k <= top; ++k) {
      t[static_cast<std::size_t>(k)] =
          static_cast<Raw>(std::ceil(std::ldexp(std::pow((k - 0.5) / top, gamma), F)));
    }
    fx::LutShape drive_shape;
    drive_shape.input_bits = drive_address_bits;
    drive_shape.octaves = drive_address_bits;
    drive_shape.entries = drive_address_bits * config_.drive_segments_per_octave + 1;
    drive_shape.output_bits = 1 + config_.drive_frac_bits;
    drive_shape.output_frac_bits = config_.drive_frac_bits;
    drive_luts_[static_cast<std::size_t>(ch)] =
        std::make_unique<fx::InterpolatedLut>(fx::make_inverse_gamma_lut(gamma, drive_shape));
    std::vector<double>& e = emission_[static_cast<std::size_t>(ch)];
    e.resize(static_cast<std::size_t>(top) + 1);
    for (int code = 0; code <= top; ++code) {
      e[static_cast<std::size_t>(code)] = config_.decoder.panel.linear_from_drive(static_cast<double>(code) / top, ch);
    }
  }
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
    const double scale = std::ldexp(1.0, config_.bilinear_weight_frac_bits);
    for (int x = 0; x < full_n; ++x) {
      const BilinearTap tap = bilinear_tap(x, full_n, reduced_n);
      // frac = num / 2W exactly; 2W <= 2^31 and the scale is a power of two, so the rounding is exact.
      axis[static_cast<std::size_t>(x)] = {tap.i0, tap.i1, static_cast<Raw>(std::floor(tap.frac * scale + 0.5))};
    }
    return axis;
  };
  g.gauss_cols = gauss_axis(full.width, g.reduced.width);
  g.gauss_rows = gauss_axis(full.height, g.reduced.height);
  g.bilinear_cols = bilinear_axis(full.width, g.reduced.width);
  g.bilinear_rows = bilinear_axis(full.height, g.reduced.height);
  return geometries_.emplace(key, std::move(g)).first->second;
}

Raw FixedKernels::gaussian_horizontal(const std::uint16_t* codes_row, const PolyphaseTaps& taps, int ch) const {
  if (linear_space_) {
    Raw acc = 0;  // uQ1.P x uQ0.T
    for (std::size_t i = 0; i < taps.weight.size(); ++i) {
      acc += taps.weight[i] * resample_rom_[codes_row[3 * taps.index[i] + ch]];
    }
    return round_shift(acc, config_.linear_gaussian_tap_frac_bits);  // uQ1.P
  }
  Raw acc = 0;  // codes x uQ0.T
  for (std::size_t i = 0; i < taps.weight.size(); ++i) acc += taps.weight[i] * codes_row[3 * taps.index[i] + ch];
  // uQb.L, half to even: rows a, b with a + b an integer (255 - pattern) keep a + b exact, so an exact half-code
  // tie of the vertical sum stays exact and rounds up as the encoder rounds it.
  const int shift = config_.gaussian_tap_frac_bits - config_.gaussian_line_frac_bits;
  return shift > 0 ? round_convergent_shift(acc, shift) : round_shift(acc, shift);
}

std::uint16_t FixedKernels::gaussian_vertical(const Raw* const* rows, const PolyphaseTaps& taps, int sample) const {
  Raw acc = 0;  // uQb.(L + T); linear space uQ1.(P + T)
  for (std::size_t j = 0; j < taps.weight.size(); ++j) acc += taps.weight[j] * rows[j][sample];
  if (linear_space_) return encode_linear(round_shift(acc, config_.linear_gaussian_tap_frac_bits));
  // Q_b: the nearest code, exact half-code ties up, as the encoder's quantise_reduced (which counts a double D within
  // its rounding noise of a half as the half); taps sum to 1, so no clamp is needed.
  return static_cast<std::uint16_t>(round_shift(acc, config_.gaussian_tap_frac_bits + config_.gaussian_line_frac_bits));
}

std::uint16_t FixedKernels::encode_linear(Raw x) const {
  // Binary search over the threshold ROM: b comparisons per reduced sample.
  return threshold_search(encode_thresholds_, x);
}

Raw FixedKernels::blend(Raw top_left, Raw top_right, Raw bottom_left, Raw bottom_right, Raw col_upper,
                        Raw row_upper) const {
  const Raw unit = Raw{1} << config_.bilinear_weight_frac_bits;
  if (linear_space_) {
    // U on linear light: the four codes through the I ROM (uQ1.F), result uQ1.F. The exact sum has 1 + F + 2W bits
    // (77 at the defaults): a 128-bit accumulator.
    using Wide = fx::detail::int128;
    const Wide top = (unit - col_upper) * code_rom_[static_cast<std::size_t>(top_left)] +
                     col_upper * code_rom_[static_cast<std::size_t>(top_right)];
    const Wide bottom = (unit - col_upper) * code_rom_[static_cast<std::size_t>(bottom_left)] +
                        col_upper * code_rom_[static_cast<std::size_t>(bottom_right)];
    const int shift = 2 * config_.bilinear_weight_frac_bits;
    return static_cast<Raw>(((unit - row_upper) * top + row_upper * bottom + (Wide{1} << (shift - 1))) >> shift);
  }
  const Raw top = (unit - col_upper) * top_left + col_upper * top_right;            // uQb.W
  const Raw bottom = (unit - col_upper) * bottom_left + col_upper * bottom_right;
  const Raw blended = (unit - row_upper) * top + row_upper * bottom;               // uQb.2W
  return round_shift(blended, 2 * config_.bilinear_weight_frac_bits - config_.upsample_frac_bits);  // uQb.U
}

Raw FixedKernels::upsample(const std::uint16_t* row0, const std::uint16_t* row1, const BilinearWeights& col,
                           Raw row_upper, int ch) const {
  return blend(row0[3 * col.i0 + ch], row0[3 * col.i1 + ch], row1[3 * col.i0 + ch], row1[3 * col.i1 + ch], col.upper,
               row_upper);
}

Raw FixedKernels::linear_of_upsampled(Raw upsampled) const {
  if (linear_space_) return upsampled;
  // The top bits of U's output address the ROM node, the rest weigh the step to the next node (wider than the
  // table's own input code, which stops at 24 bits).
  const int weight_bits = config_.upsample_frac_bits - config_.eotf_segments_per_code_log2;
  return eotf_->interpolate(static_cast<std::size_t>(upsampled >> weight_bits),
                            static_cast<std::uint64_t>(upsampled & ((Raw{1} << weight_bits) - 1)), weight_bits);
}

CompensatedSample FixedKernels::split(Raw beta) const {
  CompensatedSample out;
  out.shown = std::clamp(beta, Raw{0}, one());
  out.clipped = out.shown != beta;
  out.rho = beta - out.shown;  // sQ2.F in [-1, 1]
  return out;
}

StoredResidual FixedKernels::store_residual(Raw rho) const {
  StoredResidual out;
  if (rho == 0) return out;  // zero in every format (the common case: beta within [0, 1])
  fx::SaturationCounter saturation;
  out.value = fx::quantise_raw(rho, config_.linear_frac_bits, config_.residual, &saturation);
  out.saturated = saturation.overflows != 0;
  out.rounded = !out.saturated && round_shift(out.value, config_.residual.frac_bits - config_.linear_frac_bits) != rho;
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
  const fx::detail::int128 numerator = (static_cast<fx::detail::int128>(t_lo) * span + offset * (t_hi - t_lo))
                                       << config_.drive_frac_bits;
  const fx::detail::int128 denominator = span * two_top;
  return static_cast<Raw>((numerator + denominator / 2) / denominator);
}

LcdSample FixedKernels::lcd_drive(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held) const {
  const int F = config_.linear_frac_bits;
  const int top = max_output_code();
  const Raw two_top = 2 * static_cast<Raw>(top);
  LcdSample out;
  // m = ((x_t + x_{t-1}) / 2)^(1/gamma): the sum is the average in uQ1.(F+1); the LUT takes its top 24 bits.
  const Raw sum = held ? 2 * wanted : wanted + previous_wanted;
  Raw target = 0;
  if (sum >= (Raw{1} << (F + 1))) {
    target = one();
  } else if (sum > 0) {
    const int shift = F + 1 - lcd_target_lut_->shape().input_bits;
    target = lcd_target_lut_->evaluate_raw(static_cast<std::uint32_t>(sum >> shift));
  }
  const Raw target_scaled = target * (two_top * two_top);  // m (2 Mx)^2 2^F, as scaled_merge
  const auto search = [&](const std::array<Raw, 4>& p, Raw j) {
    int lo = 0;
    int hi = top;
    while (lo < hi) {  // the largest k with M(T_k, vp) <= m (M increases with T)
      const int mid = (lo + hi + 1) / 2;
      if (target_scaled >= scaled_merge(p, 2 * static_cast<Raw>(mid) - 1, j)) lo = mid; else hi = mid - 1;
    }
    return lo;
  };
  // First frame of the eye: the pixel is taken as held at x_t (M(v, v) = x_t^(1/gamma), the same m).
  const Raw j = held ? search(lcd_held_coefficients_, 0) : previous_code;
  const Raw x_previous = held ? wanted : previous_wanted;
  out.previous_code = static_cast<std::uint16_t>(j);
  out.contributed = wanted;
  // Reachability is decided in linear light, on the sum x_t + x_{t-1} against 2 M(0|1, v_{t-1})^gamma from the same
  // ROMs the shortfall uses. The exact ends of the range are met exactly: white after white (the ROM holds 1.0),
  // black after black, and with LcdHistory::Contributed the next target, which is built from the ROM value itself.
  // (In m, the 1/gamma power and the quantised coefficients would blur these ends by many LSB near black.)
  const bool below = sum < 2 * lcd_end_luminance_[0][static_cast<std::size_t>(j)];
  const bool above = sum > 2 * lcd_end_luminance_[1][static_cast<std::size_t>(j)];
  if (below || above) {
    // No root in [0, 1]: v clamps to the nearer end; frame t contributes x_eff = 2 M(v, v_prev)^gamma - x_{t-1}.
    out.unreachable = true;
    out.code = static_cast<std::uint16_t>(above ? top : 0);
    out.drive = above ? Raw{1} << config_.drive_frac_bits : 0;
    const Raw x_effective = 2 * lcd_end_luminance_[above ? 1 : 0][static_cast<std::size_t>(j)] - x_previous;
    out.shortfall = wanted - x_effective;
    out.contributed = x_effective;
    return out;
  }
  out.code = static_cast<std::uint16_t>(search(lcd_coefficients_, j));
  out.drive = lcd_drive_value(lcd_coefficients_, target_scaled, out.code, j);
  return out;
}

double FixedKernels::lcd_emitted(std::uint16_t code, std::uint16_t previous_code) const {
  const LcdPanel& lcd = config_.decoder.panel.lcd;
  const double top = max_output_code();
  return std::pow(std::max(lcd.merge(code / top, previous_code / top), 0.0), lcd.gamma);
}

Raw FixedKernels::luma(const Raw* rgb) const {
  const Raw sum = luma_weights_[0] * rgb[0] + luma_weights_[1] * rgb[1] + luma_weights_[2] * rgb[2];
  return round_shift(sum, config_.luma_weight_frac_bits);  // uQ1.F
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
  const Raw x = round_shift(sensitivity_raw_ * contrast,
                            config_.sensitivity_frac_bits + F - config_.exp_input_frac_bits);
  const Raw integer_part = x >> config_.exp_input_frac_bits;
  if (integer_part >= 16) {
    underflow = true;
    return 0;
  }
  const Raw fraction = x & ((Raw{1} << config_.exp_input_frac_bits) - 1);
  const Raw e_fraction = exp_fraction_->evaluate_raw(static_cast<std::uint32_t>(fraction));
  return round_shift(exp_integer_rom_[static_cast<std::size_t>(integer_part)] * e_fraction, F);
}

Raw FixedKernels::contrast_of(Raw difference, Raw sum) const {
  // Eq. 5: c = difference / sum = difference * mantissa 2^-24 2^-e, uQ1.F (clamped to 1 against LUT error).
  const fx::NormalisedReciprocal reciprocal =
      fx::reciprocal_normalised(*reciprocal_, static_cast<std::uint64_t>(sum), config_.linear_frac_bits);
  const fx::detail::int128 product = static_cast<fx::detail::int128>(difference) * reciprocal.mantissa_raw;
  const int shift = reciprocal_->shape().output_frac_bits + reciprocal.exponent;
  const fx::detail::int128 c128 = shift >= 0 ? (product + (static_cast<fx::detail::int128>(1) << shift >> 1)) >> shift
                                             : product << -shift;
  return static_cast<Raw>(std::min<fx::detail::int128>(c128, one()));
}

Raw FixedKernels::motion_contrast(Raw luma_previous, Raw luma_alpha) const {
  const Raw difference = luma_previous > luma_alpha ? luma_previous - luma_alpha : luma_alpha - luma_previous;
  return difference == 0 ? 0 : contrast_of(difference, luma_previous + luma_alpha);
}

WeightedSample FixedKernels::add_weighted_residual(Raw alpha, Raw weight, Raw residual) const {
  WeightedSample out;
  // Eq. 4: alpha' = clamp(alpha + w rho, 0, 1); w rho is uQ1.F x sQ.R, rounded to F fraction bits.
  const Raw sum = alpha + round_shift(weight * residual, config_.residual.frac_bits);
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

std::uint16_t FixedKernels::drive_code(Raw linear, int ch) const {
  // Binary search over the threshold ROM: o comparisons per sample.
  return threshold_search(thresholds_[static_cast<std::size_t>(ch)], linear);
}

Raw FixedKernels::drive_value(Raw linear, int ch) const {
  if (linear >= one()) return Raw{1} << config_.drive_frac_bits;
  return drive_luts_[static_cast<std::size_t>(ch)]->evaluate_raw(static_cast<std::uint32_t>(linear >> drive_lut_shift_));
}

std::vector<FixedRomReport> FixedKernels::roms() const {
  const auto lut = [](const std::string& name, const fx::InterpolatedLut& table, int count = 1) {
    const fx::RomSize size = table.rom_size();
    return FixedRomReport{name, size.entries, size.word_bits, count};
  };
  const int F = config_.linear_frac_bits;
  const int top = max_output_code();
  std::vector<FixedRomReport> out;
  if (linear_space_) {
    const int P = config_.linear_resample_frac_bits;
    const int b = config_.decoder.link.bits;
    out.push_back({"I = lin(E), lin(d|i) for U: direct ROM per code (uQ1." + std::to_string(F) + ")",
                   static_cast<int>(code_rom_.size()), 1 + F, 1});
    out.push_back({"D input lin(E): direct ROM per link code (uQ1." + std::to_string(P) + ")",
                   static_cast<int>(resample_rom_.size()), 1 + P, 1});
    out.push_back({"D re-encoding to " + std::to_string(b) + "-bit link codes: thresholds T_k (uQ1." +
                       std::to_string(P) + ")",
                   static_cast<int>(encode_thresholds_.size()), 1 + P, 1});
  } else {
    out.push_back({"I = lin(E): direct ROM per link code (uQ1." + std::to_string(F) + ")",
                   static_cast<int>(code_rom_.size()), 1 + F, 1});
    out.push_back(lut("L, alpha = lin(U(.)): interpolated EOTF LUT", *eotf_));
  }
  out.push_back(lut("Eq. 5 1/(Yp + Ya): normalised reciprocal LUT", *reciprocal_));
  out.push_back({"Eq. 6 exp(-i), i = 0..15", static_cast<int>(exp_integer_rom_.size()), 1 + F, 1});
  out.push_back(lut("Eq. 6 exp(-f), f in [0, 1): interpolated LUT", *exp_fraction_));
  if (lcd_) {
    out.push_back(lut("LCD target m = x^(1/gamma): octave-segmented LUT", *lcd_target_lut_));
    out.push_back({"LCD M(0|1, v_{t-1})^gamma: clamped-drive luminance ROMs (sQ4." + std::to_string(F) + ")",
                   top + 1, 4 + F, 2});
  } else {
    // The drive value LUT (DecodedFrame::drive) feeds reports only; the drive codes come from the thresholds.
    out.push_back({"OLED drive thresholds T_k per channel (uQ1." + std::to_string(F) + ")", top + 1, 1 + F, 3});
  }
  return out;
}

// Operators per evaluation of each stage, counted from the functions above (worst case per evaluation; a
// rounding "+ half LSB" before a shift counts as an adder, a clamp as two comparators, a shift or a bit-field
// extraction as nothing). A rare path is left out: the LCD held first frame (a second search).
//
// | stage                          | per            | adders            | multipliers | comparators | ROM reads |
// |--------------------------------|----------------|-------------------|-------------|-------------|-----------|
// | I = lin(E)                     | sample         | 0                 | 0           | 0           | 1         |
// | D horizontal (n_h taps)        | reduced sample | n_h               | n_h         | 1 (RndConv) | 0         |
// | D vertical + Q_b (n_v taps)    | reduced sample | n_v               | n_v         | 0           | 0         |
// | U bilinear (blend)             | sample         | 6                 | 6           | 0           | 0         |
// | EOTF LUT (interpolated)        | sample         | 3                 | 1           | 0           | 2         |
// | Eq. 2 beta, clamp, rho         | sample         | 2                 | 0           | 2           | 0         |
// | residual store (round, sat.)   | sample         | 1                 | 0           | 2           | 0         |
// | luma of L_{t-1} and alpha      | pixel          | 6                 | 6           | 0           | 0         |
// | Eq. 5 contrast c               | pixel          | 6                 | 2           | 3           | 2         |
// | Eq. 6 weight w                 | pixel          | 5                 | 3           | 1           | 3         |
// | Eq. 4 alpha'                   | sample         | 2                 | 1           | 2           | 0         |
// | OLED drive code (search)       | sample         | 0                 | 0           | o           | o         |
// | LCD drive code (Eq. 7 inverse) | sample         | 4 + 6 o           | 2 + 8 o     | 2 + o       | 4         |
//
// In the linear resample space D reads lin(E) from a ROM per tap and re-encodes through the threshold ROM, U reads
// lin(code) from the I ROM per corner, and there is no EOTF LUT:
//
// | D horizontal on lin(E) (n_h)   | reduced sample | n_h               | n_h         | 0           | n_h       |
// | D vertical + re-encoding (n_v) | reduced sample | n_v               | n_v         | b           | b         |
// | U bilinear of lin(.)           | sample         | 6                 | 6           | 0           | 4         |
std::vector<FixedArithmeticReport> FixedKernels::arithmetic(const Geometry& g) const {
  const auto widest = [](const std::vector<PolyphaseTaps>& axis) {
    std::size_t n = 0;
    for (const auto& taps : axis) n = std::max(n, taps.weight.size());
    return static_cast<int>(n);
  };
  const int n_h = widest(g.gauss_cols);
  const int n_v = widest(g.gauss_rows);
  const int o = config_.decoder.output_bits;
  const std::int64_t pixels = static_cast<std::int64_t>(g.full.width) * g.full.height;
  const std::int64_t samples = 3 * pixels;
  const std::int64_t horizontal = 3 * static_cast<std::int64_t>(g.reduced.width) * g.full.height;
  const std::int64_t vertical = 3 * static_cast<std::int64_t>(g.reduced.width) * g.reduced.height;
  std::vector<FixedArithmeticReport> out;
  if (linear_space_) {
    const int b = config_.decoder.link.bits;
    out = {
        {"I = lin(E)", "full", "channel sample", samples, 0, 0, 0, 1},
        {"D horizontal on lin(E) (" + std::to_string(n_h) + " taps)", "full", "reduced-width sample per input line",
         horizontal, n_h, n_h, 0, n_h},
        {"D vertical + re-encode (" + std::to_string(n_v) + " taps, " + std::to_string(b) + " steps)", "full",
         "reduced sample", vertical, n_v, n_v, b, b},
        {"U bilinear of lin(d_t): L", "full", "channel sample", samples, 6, 6, 0, 4},
        {"Eq. 2 beta = 2I - L, shown, rho", "full", "channel sample", samples, 2, 0, 2, 0},
        {"residual store (round, saturate)", "full", "channel sample", samples, 1, 0, 2, 0},
        {"U bilinear of lin(i): alpha", "reduced", "channel sample", samples, 6, 6, 0, 4},
        {"U bilinear of lin(d_{t-1}): L_{t-1}", "reduced", "channel sample", samples, 6, 6, 0, 4},
        {"luma of L_{t-1} and alpha", "reduced", "pixel", pixels, 6, 6, 0, 0},
        {"Eq. 5 motion contrast c", "reduced", "pixel", pixels, 6, 2, 3, 2},
        {"Eq. 6 weight w = exp(-s c)", "reduced", "pixel", pixels, 5, 3, 1, 3},
        {"Eq. 4 alpha' = clamp(alpha + w rho)", "reduced", "channel sample", samples, 2, 1, 2, 0},
    };
  } else {
    out = {
        {"I = lin(E)", "full", "channel sample", samples, 0, 0, 0, 1},
        {"D horizontal (" + std::to_string(n_h) + " taps)", "full", "reduced-width sample per input line", horizontal,
         n_h, n_h, 1, 0},
        {"D vertical + Q_b (" + std::to_string(n_v) + " taps)", "full", "reduced sample", vertical, n_v, n_v, 0, 0},
        {"U bilinear of d_t", "full", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: L = lin(U(d_t))", "full", "channel sample", samples, 3, 1, 0, 2},
        {"Eq. 2 beta = 2I - L, shown, rho", "full", "channel sample", samples, 2, 0, 2, 0},
        {"residual store (round, saturate)", "full", "channel sample", samples, 1, 0, 2, 0},
        {"U bilinear of i", "reduced", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: alpha = lin(U(i))", "reduced", "channel sample", samples, 3, 1, 0, 2},
        {"U bilinear of d_{t-1}", "reduced", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: L_{t-1} = lin(U(d_{t-1}))", "reduced", "channel sample", samples, 3, 1, 0, 2},
        {"luma of L_{t-1} and alpha", "reduced", "pixel", pixels, 6, 6, 0, 0},
        {"Eq. 5 motion contrast c", "reduced", "pixel", pixels, 6, 2, 3, 2},
        {"Eq. 6 weight w = exp(-s c)", "reduced", "pixel", pixels, 5, 3, 1, 3},
        {"Eq. 4 alpha' = clamp(alpha + w rho)", "reduced", "channel sample", samples, 2, 1, 2, 0},
    };
  }
  if (lcd_) {
    out.push_back({"LCD drive code (Eq. 7 inverse, " + std::to_string(o) + "-step search)", "both", "channel sample",
                   samples, 4 + 6 * o, 2 + 8 * o, 2 + o, 4});
  } else {
    out.push_back({"OLED drive code (" + std::to_string(o) + "-step threshold search)", "both", "channel sample",
                   samples, 0, 0, o, o});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------

FixedDecoderCore::FixedDecoderCore(FixedDecoderConfig config) : kernels_(config) {}

namespace {

std::string size_text(int width, int height) { return std::to_string(width).append("x").append(std::to_string(height)); }

}  // namespace

EyeState& FixedDecoderCore::begin(const LinkFrame& frame, const char* who) {
  const FixedDecoderConfig& config = kernels_.config();
  const FrameMeta& meta = frame.meta;
  std::string what = who;
  what.append(": ")
      .append(to_string(meta.parity))
      .append(" frame t=")
      .append(std::to_string(meta.index))
      .append(" eye=")
      .append(std::to_string(meta.eye))
      .append(": ");
  check_view_meta(meta, what);
  if (meta.bits != config.decoder.link.bits) throw std::invalid_argument(what + "link bits do not match the decoder");
  if (meta.transfer != config.decoder.link.transfer) {
    throw std::invalid_argument(what + "transfer does not match the decoder");
  }
  if (frame.codes.empty() || frame.codes.type() != CV_16UC3) {
    throw std::invalid_argument(what + "codes must be a non-empty CV_16UC3 image");
  }
  // The codes against their own metadata first (a mismatch there is named as such), then against the view size:
  // both before the geometry of the view is built, so a frame claiming a view it cannot be part of allocates nothing.
  const std::string codes_size = size_text(frame.codes.cols, frame.codes.rows);
  if (frame.codes.cols != meta.width || frame.codes.rows != meta.height) {
    throw std::invalid_argument(what + "codes are " + codes_size + " but the metadata says " +
                                size_text(meta.width, meta.height));
  }
  const cv::Size full(meta.full_width, meta.full_height);
  const double r = config.decoder.link.reduction;
  const cv::Size expected = meta.parity == Parity::Full
                                ? full
                                : cv::Size(reduced_size(full.width, r), reduced_size(full.height, r));
  if (frame.codes.size() != expected) {
    throw std::invalid_argument(what + "codes are " + codes_size + " but a " + to_string(meta.parity) +
                                " frame of a " + size_text(full.width, full.height) + " view at r=" +
                                std::to_string(r) + " must be " + size_text(expected.width, expected.height));
  }
  double highest = 0.0;
  cv::minMaxLoc(frame.codes.reshape(1), nullptr, &highest);
  if (highest > kernels_.max_code()) throw std::invalid_argument(what + "code exceeds the link bit depth");
  EyeState& eye = eyes_[meta.eye];
  if (eye.full_size != full) {
    eye = EyeState();
    eye.full_size = full;
  }
  return eye;
}

FrameOutput FixedDecoderCore::start_output(const LinkFrame& frame) const {
  FrameOutput out;
  const cv::Size full(frame.meta.full_width, frame.meta.full_height);
  out.frame.meta = frame.meta;
  out.frame.meta.width = full.width;
  out.frame.meta.height = full.height;
  out.frame.wanted_linear.create(full, CV_64FC3);
  out.frame.drive.create(full, CV_64FC3);
  out.frame.drive_codes.create(full, CV_16UC3);
  out.frame.emitted_linear.create(full, CV_64FC3);
  return out;
}

void FixedDecoderCore::begin_lcd(FrameOutput& out, EyeState& eye) const {
  if (!kernels_.lcd()) return;
  out.lcd_held = eye.lcd_previous_drive.empty();
  if (out.lcd_held) {
    // Not read on the held frame (lcd_drive takes x_{t-1} = x_t and the held code); zeroed to stay defined.
    eye.lcd_previous_drive = cv::Mat::zeros(eye.full_size, CV_16UC3);
    eye.lcd_previous_linear = cv::Mat::zeros(eye.full_size, CV_32SC3);
  }
}

Raw FixedDecoderCore::emit(FrameOutput& out, EyeState& eye, int y, int x, int ch, Raw wanted) const {
  const int k = 3 * x + ch;
  out.frame.wanted_linear.ptr<double>(y)[k] = kernels_.linear_to_double(wanted);
  if (!kernels_.lcd()) {
    const std::uint16_t code = kernels_.drive_code(wanted, ch);
    out.frame.drive.ptr<double>(y)[k] = kernels_.drive_to_double(kernels_.drive_value(wanted, ch));
    out.frame.drive_codes.ptr<std::uint16_t>(y)[k] = code;
    out.frame.emitted_linear.ptr<double>(y)[k] = kernels_.emitted_of_code(code, ch);
    return 0;
  }
  // LCD frame stores: v_{t-1} and x_{t-1} at this sample are read, then replaced by this frame's.
  std::uint16_t& previous_code = eye.lcd_previous_drive.ptr<std::uint16_t>(y)[k];
  std::int32_t& previous_linear = eye.lcd_previous_linear.ptr<std::int32_t>(y)[k];
  const LcdSample s = kernels_.lcd_drive(wanted, previous_linear, previous_code, out.lcd_held);
  out.frame.drive.ptr<double>(y)[k] = kernels_.drive_to_double(s.drive);
  out.frame.drive_codes.ptr<std::uint16_t>(y)[k] = s.code;
  out.tally.counts.lcd_unreachable += s.unreachable ? 1 : 0;
  const bool contributed = config().decoder.lcd_history == LcdHistory::Contributed;
  out.frame.emitted_linear.ptr<double>(y)[k] = kernels_.lcd_emitted(s.code, s.previous_code);
  previous_code = s.code;
  previous_linear = static_cast<std::int32_t>(contributed ? s.contributed : wanted);
  return out.full ? s.shortfall : 0;
}

void FixedDecoderCore::full_pixel(FrameOutput& out, EyeState& eye, const Geometry& g, int y, int x,
                                  const std::uint16_t* codes_row, const std::uint16_t* low0,
                                  const std::uint16_t* low1, std::int32_t* residual_row, bool lost) const {
  const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
  const BilinearWeights& col = g.bilinear_cols[static_cast<std::size_t>(x)];
  FrameTally& t = out.tally;
  for (int ch = 0; ch < 3; ++ch) {
    const Raw low_linear = kernels_.linear_of_upsampled(kernels_.upsample(low0, low1, col, row.upper, ch));  // L_t
    const Raw full_linear = kernels_.linear_of_code(codes_row[3 * x + ch]);                                  // I_t
    // Eq. 2; a lost line has no trustworthy beta and shows L_t (within [0, 1], so its rho is 0).
    const CompensatedSample s = lost ? kernels_.split(low_linear) : kernels_.compensate(full_linear, low_linear);
    if (out.taps != nullptr) {
      tap(out, FixedStage::Linear, y, x, ch, full_linear);
      tap(out, FixedStage::LowPass, y, x, ch, low_linear);
      tap(out, FixedStage::Beta, y, x, ch, s.shown + s.rho);
      tap(out, FixedStage::Shown, y, x, ch, s.shown);
    }
    t.clipped += s.clipped ? 1 : 0;
    t.counts.beta_clipped += s.clipped ? 1 : 0;
    // LCD: an unreachable drive's shortfall joins rho (Sec. 4.4) before the residual store.
    const Raw shortfall = emit(out, eye, y, x, ch, s.shown);
    const StoredResidual stored = kernels_.store_residual(s.rho + shortfall);
    residual_row[3 * x + ch] = static_cast<std::int32_t>(stored.value);
    tap(out, FixedStage::Residual, y, x, ch, stored.value);
    t.counts.residual_saturated += stored.saturated ? 1 : 0;
    t.counts.residual_rounded += stored.rounded ? 1 : 0;
    const Raw magnitude = stored.value < 0 ? -stored.value : stored.value;
    t.residual_abs_sum += magnitude;
    t.residual_abs_max = std::max(t.residual_abs_max, magnitude);
  }
}

void FixedDecoderCore::end_full_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* residual_row) const {
  if (!skipping()) return;
  const int height = eye.full_size.height;
  if (y == 0) eye.residual_nonzero.assign(static_cast<std::size_t>(height), 0);
  // The OR of the line's residual samples, accumulated as they are produced (one flip-flop) and kept as the line's
  // flag: a line held all zero is not written to the store.
  const int samples = 3 * eye.full_size.width;
  const bool nonzero = std::any_of(residual_row, residual_row + samples, [](std::int32_t v) { return v != 0; });
  eye.residual_nonzero[static_cast<std::size_t>(y)] = nonzero ? 1 : 0;
  out.tally.counts.residual_write_lines_skipped += nonzero ? 0 : 1;
}

void FixedDecoderCore::reduced_pixel(FrameOutput& out, EyeState& eye, const Geometry& g, int y, int x, const std::uint16_t* in0,
                                     const std::uint16_t* in1, const std::uint16_t* prev0, const std::uint16_t* prev1,
                                     const std::int32_t* residual_row, const ReducedLineGate* gate) const {
  const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
  const BilinearWeights& col = g.bilinear_cols[static_cast<std::size_t>(x)];
  Raw alpha[3];
  for (int ch = 0; ch < 3; ++ch) {
    alpha[ch] = kernels_.linear_of_upsampled(kernels_.upsample(in0, in1, col, row.upper, ch));  // Eq. 1
    tap(out, FixedStage::Alpha, y, x, ch, alpha[ch]);
  }
  const bool motion_static = gate != nullptr && gate->motion_static;
  const bool residual_zero = gate != nullptr && gate->residual_zero;
  if (residual_row == nullptr && !residual_zero) {
    // No full frame just before: alpha alone (U of codes stays within [0, 1]; the clamp only guards).
    for (int ch = 0; ch < 3; ++ch) {
      const Raw shown = std::clamp(alpha[ch], Raw{0}, kernels_.one());
      tap(out, FixedStage::AlphaPrime, y, x, ch, shown);
      emit(out, eye, y, x, ch, shown);
    }
    return;
  }
  // L_{t-1} for the motion test, from the stored d_{t-1}: the low-pass the full frame compensated against, bit for
  // bit (d_t rounds exact ties up, as the encoder's reduced frame does, so for static content it is the received i).
  Raw previous[3];
  for (int ch = 0; ch < 3; ++ch) {
    // Static line (DESIGN §7): the d_{t-1} rows equal the received ones, so U of them is alpha.
    previous[ch] = motion_static ? alpha[ch]
                                 : kernels_.linear_of_upsampled(kernels_.upsample(prev0, prev1, col, row.upper, ch));
  }
  FrameTally& t = out.tally;
  bool underflow = false;
  const Raw weight = motion_static ? kernels_.one()  // c = 0: w = 1 exactly (DESIGN §4)
                                   : kernels_.motion_weight(kernels_.luma(previous), kernels_.luma(alpha), underflow);
  if (out.taps != nullptr) {
    for (int ch = 0; ch < 3; ++ch) tap(out, FixedStage::PreviousLowPass, y, x, ch, previous[ch]);
    tap(out, FixedStage::Contrast, y, x, 0, kernels_.motion_contrast(kernels_.luma(previous), kernels_.luma(alpha)));
    tap(out, FixedStage::Weight, y, x, 0, weight);
  }
  t.weight_sum += weight;
  t.counts.weight_underflow += underflow ? 1 : 0;
  for (int ch = 0; ch < 3; ++ch) {
    const Raw residual = residual_zero ? 0 : residual_row[3 * x + ch];
    const WeightedSample s = residual_zero ? kernels_.clamp_alpha(alpha[ch])
                                           : kernels_.add_weighted_residual(alpha[ch], weight, residual);  // Eq. 4
    t.clipped += s.clipped ? 1 : 0;
    t.counts.alpha_clipped += s.clipped ? 1 : 0;
    t.dropped_sum += s.dropped;
    const Raw magnitude = residual < 0 ? -residual : residual;
    t.residual_abs_sum += magnitude;
    t.residual_abs_max = std::max(t.residual_abs_max, magnitude);
    tap(out, FixedStage::AlphaPrime, y, x, ch, s.alpha_prime);
    emit(out, eye, y, x, ch, s.alpha_prime);
  }
}

void FixedDecoderCore::start_taps(FrameOutput& out, FixedStageTaps& taps, const Geometry& g, bool full,
                                  bool residual) const {
  const FixedDecoderConfig& c = config();
  const int F = c.linear_frac_bits;
  const int b = c.decoder.link.bits;
  const std::string linear = "uQ1." + std::to_string(F);
  taps = FixedStageTaps();
  const auto add = [&](FixedStage stage, const char* name, const std::string& format, int bits, bool is_signed,
                       cv::Size size, int channels) {
    FixedStagePlane& p = taps[stage];
    p.present = true;
    p.name = name;
    p.format = format;
    p.bits = bits;
    p.is_signed = is_signed;
    p.size = size;
    p.channels = channels;
    p.values.assign(static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height) * static_cast<std::size_t>(channels), 0);
  };
  const std::string code = "uQ" + std::to_string(b) + ".0";
  add(FixedStage::Codes, "codes", code, b, false, full ? g.full : g.reduced, 3);
  if (full) {
    add(FixedStage::Linear, "I", linear, 1 + F, false, g.full, 3);
    add(FixedStage::Reduced, "d", code, b, false, g.reduced, 3);
    add(FixedStage::LowPass, "L", linear, 1 + F, false, g.full, 3);
    add(FixedStage::Beta, "beta", "sQ3." + std::to_string(F), 3 + F, true, g.full, 3);
    add(FixedStage::Shown, "shown", linear, 1 + F, false, g.full, 3);
    add(FixedStage::Residual, "rho",
        std::string("sQ") + std::to_string(c.residual.int_bits) + "." + std::to_string(c.residual.frac_bits),
        c.residual.width(), true, g.full, 3);
  } else {
    add(FixedStage::Alpha, "alpha", linear, 1 + F, false, g.full, 3);
    if (residual) {
      add(FixedStage::PreviousLowPass, "L_prev", linear, 1 + F, false, g.full, 3);
      add(FixedStage::Contrast, "c", linear, 1 + F, false, g.full, 1);
      add(FixedStage::Weight, "w", linear, 1 + F, false, g.full, 1);
    }
    add(FixedStage::AlphaPrime, "alpha_prime", linear, 1 + F, false, g.full, 3);
  }
  const int o = c.decoder.output_bits;
  add(FixedStage::Drive, "drive", "uQ" + std::to_string(o) + ".0", o, false, g.full, 3);
  out.taps = &taps;
}

DecodedFrame FixedDecoderCore::finish(FrameOutput&& out, EyeState& eye, bool full, bool residual_applied) {
  const FrameTally& t = out.tally;
  const double samples = 3.0 * static_cast<double>(out.frame.wanted_linear.total());
  FrameStats& stats = out.frame.stats;
  stats.concealed_lines = out.concealed_lines;
  stats.clipped_fraction = static_cast<double>(t.clipped) / samples;
  if (full || residual_applied) {
    stats.residual_mean_abs = kernels_.residual_to_double(t.residual_abs_sum) / samples;
    stats.residual_max_abs = kernels_.residual_to_double(t.residual_abs_max);
  }
  if (residual_applied) {
    stats.residual_applied = true;
    stats.dropped_sum = kernels_.linear_to_double(t.dropped_sum);
    stats.mean_motion_weight = kernels_.linear_to_double(t.weight_sum) / (samples / 3.0);
  }
  stats.lcd_unreachable_fraction = static_cast<double>(t.counts.lcd_unreachable) / samples;
  last_counts_ = t.counts;
  eye.last_output = out.frame;  // the held-output store (drive codes), shared, as the reference keeps it
  return std::move(out.frame);
}

FixedDecoderCore::Arrival FixedDecoderCore::classify(const LinkFrame& frame, std::span<const std::uint8_t> line_intact,
                                                     Concealment& out, const char* who) {
  if (line_intact.empty()) return Arrival::Whole;
  if (line_intact.size() != static_cast<std::size_t>(frame.codes.rows)) {
    throw std::invalid_argument(std::string(who) + ": line mask has " + std::to_string(line_intact.size()) +
                                " entries for a view of " + std::to_string(frame.codes.rows) + " lines");
  }
  out = Concealment();
  out.intact = line_intact;
  out.first_intact = -1;
  for (int y = 0; y < frame.codes.rows; ++y) {
    if (out.lost(y)) {
      ++out.lost_lines;
    } else if (out.first_intact < 0) {
      out.first_intact = y;
    }
  }
  if (out.first_intact < 0) return Arrival::Lost;
  if (out.lost_lines == 0) return Arrival::Whole;
  // The reference looks at the eye's d_t before a change of view size resets the eye; so does this.
  const auto found = eyes_.find(frame.meta.eye);
  if (frame.meta.parity == Parity::Reduced && found != eyes_.end() && found->second.have_residual &&
      found->second.previous_low.size() == frame.codes.size()) {
    out.substitute = found->second.previous_low;
  }
  return Arrival::Partial;
}

cv::Mat FixedDecoderCore::concealed_codes(const cv::Mat& codes, const Concealment& c) {
  cv::Mat out = codes.clone();
  const int samples = 3 * codes.cols;
  for (int y = 0; y < codes.rows; ++y) {
    if (!c.lost(y)) continue;
    std::uint16_t* row = out.ptr<std::uint16_t>(y);
    if (!c.substitute.empty()) {
      const std::uint16_t* stored = c.substitute.ptr<std::uint16_t>(y);
      std::copy(stored, stored + samples, row);
      continue;
    }
    // The nearest intact line above, else (lines above the first intact one) below. Lines above y are already
    // concealed, so the line just above holds the nearest intact line above.
    const std::uint16_t* source = out.ptr<std::uint16_t>(y < c.first_intact ? c.first_intact : y - 1);
    std::copy(source, source + samples, row);
  }
  return out;
}

DecodedFrame FixedDecoderCore::decode_lost(const FrameMeta& meta, const char* who) {
  check_view_meta(meta, std::string(who).append(": lost view: "));
  last_counts_ = FixedStageCounts();
  return detail::hold_lost_view(eyes_[meta.eye], meta);
}

}  // namespace fixed_detail
}  // namespace trm
