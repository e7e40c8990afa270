// The per-pixel arithmetic of the fixed-point decoder, one function per stage, shared by the frame-at-a-time and
// the streaming schedules (so they can differ only in scheduling). What the schedules keep per eye and per frame is
// in fixed_core.hpp.
// Raw values are integers; each function states its Q formats. F = linear_frac_bits throughout.
#pragma once

#include "fixed_lines.hpp"
#include "fixed_tables.hpp"

#include "trm/fixed_decoder.hpp"
#include "trm/lut.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace trm::fixed_detail {

using Raw = std::int64_t;

// D taps of one reduced sample along one axis: indices clamped (replicate), weights uQ0.T summing to 2^T.
struct PolyphaseTaps {
  std::vector<int> index;
  std::vector<Raw> weight;
  int first() const { return index.front(); }  // indices are non-decreasing
  int last() const { return index.back(); }
};

// U along one axis for one full-resolution sample: weight of i1 in uQ0.W; i0 gets 2^W - upper.
struct BilinearWeights {
  int i0 = 0;
  int i1 = 0;
  Raw upper = 0;
};

// Everything that depends on the view size: taps per axis.
struct Geometry {
  cv::Size full;
  cv::Size reduced;
  std::vector<PolyphaseTaps> gauss_cols;  // reduced.width entries
  std::vector<PolyphaseTaps> gauss_rows;  // reduced.height entries
  std::vector<BilinearWeights> bilinear_cols;  // full.width entries
  std::vector<BilinearWeights> bilinear_rows;  // full.height entries
  ColumnBlendPlan column_blend;                // U's column taps per output sample, for the line kernels
  GaussianColumnsPlan gauss_columns;           // D's horizontal taps as slots, for the line kernels
};

// Result of Eq. 2 and the split for one channel sample of a full frame.
struct CompensatedSample {
  Raw shown = 0;  // clamp(beta, 0, 1), uQ1.F
  Raw rho = 0;    // beta - shown, sQ2.F (before the residual store)
  bool clipped = false;
};

// rho (plus any LCD shortfall) as the residual frame store holds it.
struct StoredResidual {
  Raw value = 0;  // residual store format
  bool saturated = false;
  bool rounded = false;
};

// What the residual store adds to the frame's tally (FixedStageCounts::residual_saturated and residual_rounded,
// FrameTally::residual_abs_sum and residual_abs_max), sample by sample or a line at a time.
struct ResidualTally {
  std::uint64_t saturated = 0;
  std::uint64_t rounded = 0;
  Raw abs_sum = 0;
  Raw abs_max = 0;

  void add(const StoredResidual& stored) {
    saturated += stored.saturated ? 1 : 0;
    rounded += stored.rounded ? 1 : 0;
    const Raw magnitude = stored.value < 0 ? -stored.value : stored.value;
    abs_sum += magnitude;
    abs_max = std::max(abs_max, magnitude);
  }
};

// LCD drive of one channel sample (Eq. 7 inverse).
struct LcdSample {
  std::uint16_t code = 0;
  std::uint16_t previous_code = 0;  // v_{t-1} the merge was solved against (the held code on the first frame)
  Raw drive = 0;        // v, uQ1.drive_frac_bits (reports)
  Raw shortfall = 0;    // x_t - x_t_eff where unreachable, sQ.F
  Raw contributed = 0;  // x_t, or x_t_eff where unreachable, sQ.F
  bool unreachable = false;
};

struct WeightedSample {
  Raw alpha_prime = 0;  // clamp(alpha + w rho, 0, 1), uQ1.F
  Raw dropped = 0;      // |alpha + w rho - alpha'|, uQ2.F
  bool clipped = false;
};

class FixedKernels {
 public:
  explicit FixedKernels(const FixedDecoderConfig& config);

  const FixedDecoderConfig& config() const { return config_; }
  int linear_frac_bits() const { return config_.linear_frac_bits; }
  Raw one() const { return Raw{1} << config_.linear_frac_bits; }
  int max_code() const { return (1 << config_.decoder.link.bits) - 1; }
  int max_output_code() const { return (1 << config_.decoder.output_bits) - 1; }

  // The taps for a view size (built once per size and cached).
  const Geometry& geometry(cv::Size full);

  // I = lin(E): direct ROM indexed by the link code; uQ1.F.
  Raw linear_of_code(std::uint16_t code) const { return code_rom_[code]; }

  bool linear_space() const { return linear_space_; }
  // D, horizontal half: sum_i w_i E_i over one row of codes (channel ch of interleaved RGB), uQb.L (L = line bits).
  // Linear space: sum_i w_i lin(E_i), uQ1.P.
  Raw gaussian_horizontal(const std::uint16_t* codes_row, const PolyphaseTaps& taps, int ch) const;
  // D, vertical half, and Q_b: d = round(sum_j w_j h_j) where rows[j] is the line buffer row of tap j, a link code;
  // an exact half-code tie rounds up, as the encoder's quantise_reduced does. Linear space: the sum rounded to uQ1.P
  // and re-encoded through the threshold ROM (thresholds from quantise_reduced).
  template <typename Line>
  std::uint16_t gaussian_vertical(const Line* const* rows, const PolyphaseTaps& taps, int sample) const;
  // D's two halves over a line, as the schedules run them: out[3k + ch] = gaussian_horizontal(codes_row,
  // g.gauss_cols[k], ch) for every reduced column k; out[i] = gaussian_vertical(rows, taps, i) for i < samples. A
  // grey line (every pixel R = G = B, the chroma skip) computes channel 0 and copies it. The same bits as the
  // per-sample functions (one accumulation per sample, all three channels in one pass over the taps). The line
  // buffer's words are Raw, or 32 bits where narrow_gaussian_lines says they hold every value.
  template <typename Line>
  void gaussian_horizontal_line(const std::uint16_t* codes_row, const Geometry& g, Line* out, bool grey) const;
  template <typename Line>
  void gaussian_vertical_row(const Line* const* rows, const PolyphaseTaps& taps, int samples, std::uint16_t* out,
                             bool grey) const;
  // D's line buffer in 32-bit words: the encoded space with the line kernels' plan (every horizontal sum below 2^32).
  bool narrow_gaussian_lines() const { return !linear_space_ && line_plans_.gaussian.has_value(); }
  // Linear space: the link code the encoder gives linear value x (uQ1.P): the largest k with x >= T_k.
  std::uint16_t encode_linear(Raw x) const;

  // The U functions return U's output: in the encoded space codes uQb.U (linear_of_upsampled applies the EOTF LUT);
  // in the linear space linear light uQ1.F, blended from lin(code) (linear_of_upsampled passes it through).
  // U: bilinear blend of reduced codes rows row0 (i0) and row1 (i1) at full column x, channel ch; codes uQb.U.
  // (The per-sample stages are defined here, inline in the schedules' loops; the rest is in fixed_stages.cpp.)
  Raw upsample(const std::uint16_t* row0, const std::uint16_t* row1, const BilinearWeights& col, Raw row_upper,
               int ch) const {
    return blend(row0[3 * col.i0 + ch], row0[3 * col.i1 + ch], row1[3 * col.i0 + ch], row1[3 * col.i1 + ch],
                 col.upper, row_upper);
  }
  // U and lin() over an output line: out[3x + ch] = linear_of_upsampled(upsample(row0, row1, g.bilinear_cols[x],
  // row_upper, ch)); a grey line computes channel 0 and copies it.
  void upsample_line(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, Raw row_upper, Raw* out,
                     bool grey) const {
    const int width = g.full.width;
    for (int x = 0; x < width; ++x) {
      const BilinearWeights& col = g.bilinear_cols[static_cast<std::size_t>(x)];
      Raw* o = out + 3 * x;
      o[0] = linear_of_upsampled(upsample(row0, row1, col, row_upper, 0));
      if (grey) {
        o[1] = o[2] = o[0];
        continue;
      }
      o[1] = linear_of_upsampled(upsample(row0, row1, col, row_upper, 1));
      o[2] = linear_of_upsampled(upsample(row0, row1, col, row_upper, 2));
    }
  }
  // The bilinear arithmetic itself: four codes, weights uQ0.W, result uQb.U (Rnd); linear space: four codes through
  // the I ROM, result uQ1.F (Rnd).
  Raw blend(Raw top_left, Raw top_right, Raw bottom_left, Raw bottom_right, Raw col_upper, Raw row_upper) const {
    if (linear_space_) return blend_linear(top_left, top_right, bottom_left, bottom_right, col_upper, row_upper);
    const Raw unit = Raw{1} << config_.bilinear_weight_frac_bits;
    const Raw top = (unit - col_upper) * top_left + col_upper * top_right;  // uQb.W
    const Raw bottom = (unit - col_upper) * bottom_left + col_upper * bottom_right;
    const Raw blended = (unit - row_upper) * top + row_upper * bottom;  // uQb.2W
    return fx::rounded_shift(blended, 2 * config_.bilinear_weight_frac_bits - config_.upsample_frac_bits,
                             fx::Quant::Rnd);  // uQb.U
  }
  // lin() of U's encoded output through the interpolated EOTF LUT; uQ1.F. Linear space: U's output as it is.
  Raw linear_of_upsampled(Raw upsampled) const {
    if (linear_space_) return upsampled;
    // The top bits of U's output address the ROM node, the rest weigh the step to the next node (wider than the
    // table's own input code, which stops at 24 bits).
    const int weight_bits = config_.upsample_frac_bits - config_.eotf_segments_per_code_log2;
    return eotf_->interpolate(static_cast<std::size_t>(upsampled >> weight_bits),
                              static_cast<std::uint64_t>(upsampled & ((Raw{1} << weight_bits) - 1)), weight_bits);
  }

  // Eq. 2: beta = 2 I - L (sQ3.F), shown = clamp(beta, 0, 1), rho = beta - shown.
  CompensatedSample compensate(Raw full_linear, Raw low_linear) const { return split(2 * full_linear - low_linear); }
  // shown = clamp(beta, 0, 1), rho = beta - shown. A concealed (lost) line of a full frame splits beta = L.
  CompensatedSample split(Raw beta) const {
    CompensatedSample out;
    out.shown = std::clamp(beta, Raw{0}, one());
    out.clipped = out.shown != beta;
    out.rho = beta - out.shown;  // sQ2.F in [-1, 1]
    return out;
  }
  // rho (sQ.F) into the residual store format (its rounding and overflow modes).
  StoredResidual store_residual(Raw rho) const {
    if (rho == 0) return StoredResidual{};  // zero in every format (the common case: beta within [0, 1])
    return store_nonzero_residual(rho);
  }

  bool lcd() const { return lcd_; }
  // LCD (Eq. 7 inverse): the drive code whose merge with v_{t-1} = previous_code reaches m = ((x_t + x_{t-1})/2)^(1/g).
  // held: the eye's first frame, x_{t-1} = x_t and the pixel held (M(v, v)); returns the held code. drive_value:
  // also the report drive value v (else LcdSample::drive stays 0).
  LcdSample lcd_drive(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                      bool drive_value = true) const;
  // The LCD drive's target m = ((x_t + x_{t-1}) / 2)^(1/gamma) of sum = x_t + x_{t-1} (the average in uQ1.(F+1); the
  // LUT takes its top bits), uQ1.F.
  Raw lcd_target(Raw sum) const {
    if (sum >= (Raw{1} << (config_.linear_frac_bits + 1))) return one();
    return sum > 0 ? lcd_target_lut_->evaluate_raw(static_cast<std::uint32_t>(sum >> lcd_target_shift_)) : 0;
  }
  // The same sample's report where its code is known (the LCD drive kernel's): lcd_drive's v_{t-1} and drive value
  // without the search.
  LcdSample lcd_report(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                       std::uint16_t code) const;
  // lcd_report's drive value of a sample whose x_t + x_{t-1} = sum, whose target m = lcd_target(sum), v_{t-1} = j and
  // code `code`: the clamped end's where the sum is unreachable, else v between the code's thresholds.
  Raw lcd_report_drive(Raw sum, Raw target, Raw j, std::uint16_t code) const {
    const int end = lcd_clamped_end(sum, j);
    return end >= 0 ? lcd_clamped_drive(end == 1)
                    : lcd_drive_value(lcd_coefficients_, scale_lcd_target(target), code, j);
  }
  // lcd_report of the n samples of a line whose codes the LCD drive kernel gave: drive[s] and previous[s] are
  // lcd_report(wanted[s], previous_wanted[s], previous_code[s], held, codes[s])'s drive and previous_code.
  template <typename Linear>
  void lcd_reports(const Linear* wanted, const std::int32_t* previous_wanted, const std::uint8_t* previous_code,
                   const std::uint16_t* codes, std::size_t n, bool held, Raw* drive, std::uint16_t* previous) const;
  // lcd_drive's search: the largest k in [0, top] with merge_at(k) <= target_scaled (merge_at(k) = M(T_k, v_{t-1})
  // scaled, increasing in k; k = 0 is not read), by binary comparison.
  template <typename MergeAt>
  static int merge_search(int top, Raw target_scaled, MergeAt merge_at) {
    int lo = 0;
    int hi = top;
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (target_scaled >= merge_at(mid)) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  // Rec. 709 luma of linear RGB (uQ1.F each); uQ1.F.
  Raw luma(const Raw* rgb) const;
  // Eqs. 5-6: c = |Yp - Ya| / (Yp + Ya) (0 where the sum is 0), w = exp(-s c); uQ1.F. Sets underflow when s c >= 16.
  Raw motion_weight(Raw luma_previous, Raw luma_alpha, bool& underflow) const;
  // Eq. 5 alone (the c that motion_weight computes, for test vectors): uQ1.F, 0 where Yp = Ya.
  Raw motion_contrast(Raw luma_previous, Raw luma_alpha) const;
  // Eq. 4: alpha' = clamp(alpha + w rho, 0, 1).
  WeightedSample add_weighted_residual(Raw alpha, Raw weight, Raw residual) const;
  // Eq. 4 on a line with no residual (DESIGN §7 skip): alpha' = clamp(alpha, 0, 1), what add_weighted_residual gives
  // for rho = 0.
  WeightedSample clamp_alpha(Raw alpha) const;

  // The line comparator of the static skip (DESIGN §7): a received reduced line i(k) against the stored d_{t-1} row
  // k, `samples` channel samples. kLineStatic: every code equals the stored one (so U of the two is the same).
  static constexpr std::uint8_t kLineStatic = 1;
  static std::uint8_t compare_line(const std::uint16_t* stored, const std::uint16_t* received, int samples);
  // The grey detector of the chroma skip (DESIGN §7): R = G = B at every one of `pixels` interleaved pixels. Blocks of
  // pixels are ORed without a branch (which the compiler vectorises) and the comparator stops after the first block
  // with a coloured pixel.
  template <typename T>
  static bool grey_line(const T* rgb, int pixels) {
    constexpr int kBlock = 64;
    for (int start = 0; start < pixels; start += kBlock) {
      const int end = std::min(pixels, start + kBlock);
      T difference = 0;
      for (int x = start; x < end; ++x) difference |= (rgb[3 * x] ^ rgb[3 * x + 1]) | (rgb[3 * x] ^ rgb[3 * x + 2]);
      if (difference != 0) return false;
    }
    return true;
  }

  // OLED drive code: the largest k with x >= T_k (binary search of the threshold ROM).
  std::uint16_t drive_code(Raw linear, int ch) const {
    return drive_index_[static_cast<std::size_t>(ch)].search(linear);  // o comparisons per sample in hardware
  }
  // Drive value v = x^(1/gamma) for reports, uQ1.drive_frac_bits.
  Raw drive_value(Raw linear, int ch) const;
  // The light drive code `code` emits after `previous_code` (read only for a panel with history).
  double emitted(std::uint16_t code, std::uint16_t previous_code, int ch) const {
    return (*emission_)(code, previous_code, ch);
  }

  // The ROMs themselves, for the line kernels' plans (fixed_lines.hpp).
  const std::vector<Raw>& code_rom() const { return code_rom_; }
  const fx::InterpolatedLut* eotf_lut() const { return eotf_.get(); }
  const ThresholdIndex& drive_index(int ch) const { return drive_index_[static_cast<std::size_t>(ch)]; }
  // The line kernels' tables for this configuration (empty where its formats do not fit their lanes).
  const FixedLinePlans& line_plans() const { return line_plans_; }

  // Every ROM of this configuration (name, words, word bits, copies).
  std::vector<FixedRomReport> roms() const;
  // The operator table of the per-pixel stages at the geometry's sizes (see the table in fixed_resources.cpp).
  std::vector<FixedArithmeticReport> arithmetic(const Geometry& g) const;

  // Exact conversions (the raw values have at most 53 significant bits; the scales are powers of two).
  double linear_to_double(Raw v) const { return static_cast<double>(v) * linear_lsb_; }
  double drive_to_double(Raw v) const { return static_cast<double>(v) * drive_lsb_; }
  double residual_to_double(Raw v) const { return static_cast<double>(v) * residual_lsb_; }

 private:
  friend struct FixedLinePlans;  // the line kernels' plans copy the motion test's ROMs and constants
  FixedDecoderConfig config_;
  std::vector<Raw> code_rom_;
  std::unique_ptr<fx::InterpolatedLut> eotf_;  // encoded space only
  // Linear resample space: D's input lin(E) (uQ1.P) and the re-encoding thresholds T_k (uQ1.P, T_0 = 0).
  bool linear_space_ = false;
  std::vector<Raw> resample_rom_;
  std::vector<Raw> encode_thresholds_;
  std::unique_ptr<fx::InterpolatedLut> reciprocal_;
  std::unique_ptr<fx::InterpolatedLut> exp_fraction_;
  std::vector<Raw> exp_integer_rom_;  // exp(-i), i = 0..15, uQ1.F
  std::array<Raw, 3> luma_weights_{};
  Raw sensitivity_raw_ = 0;
  bool sensitivity_infinite_ = false;
  std::array<std::vector<Raw>, 3> thresholds_;  // T_k, k = 0..2^o - 1 (T_0 = 0)
  std::array<ThresholdIndex, 3> drive_index_;   // the same search over thresholds_, faster
  std::array<std::unique_ptr<fx::InterpolatedLut>, 3> drive_luts_;
  int drive_lut_shift_ = 0;  // linear LSBs dropped to address the drive LUT (24 address bits at most)
  std::optional<PanelEmission> emission_;  // built once the configuration is valid
  double linear_lsb_ = 0.0;
  double drive_lsb_ = 0.0;
  double residual_lsb_ = 0.0;
  std::map<std::pair<int, int>, Geometry> geometries_;
  FixedLinePlans line_plans_;
  // LCD: merge coefficients in sQ.kLcdCoefficientBits, x^(1/gamma) LUT for m, and M(0, vp)^gamma, M(1, vp)^gamma
  // ROMs (uQ/sQ.F) for the shortfall at the two clamped drives.
  bool lcd_ = false;
  std::array<Raw, 4> lcd_coefficients_{};       // p1..p4
  std::array<Raw, 4> lcd_held_coefficients_{};  // M(v, v): 2 p1 + p2, 0, 2 p3, p4
  std::unique_ptr<fx::InterpolatedLut> lcd_target_lut_;
  int lcd_target_shift_ = 0;  // the sum's bits below the target LUT's input
  // scaled_merge(p, 2k - 1, j) for every code k >= 1 and v_{t-1} = j (rows 0..2^o - 1), then the held row
  // (lcd_held_coefficients_, j = 0); empty above kLcdMergeTableMaxCode.
  static constexpr int kLcdMergeTableMaxCode = 255;
  std::vector<Raw> lcd_merge_table_;
  std::array<std::vector<Raw>, 2> lcd_end_luminance_;
  // The merge scaled to an integer: (2 Mx)^2 2^P M(t / (2 Mx), j / Mx).
  Raw scaled_merge(const std::array<Raw, 4>& p, Raw t, Raw j) const;
  // c = difference / sum through the reciprocal LUT, clamped to 1; difference > 0.
  Raw contrast_of(Raw difference, Raw sum) const;
  Raw lcd_drive_value(const std::array<Raw, 4>& p, Raw target_scaled, int code, Raw j) const;
  // lcd_drive and lcd_report: the code searched for, or the one given.
  LcdSample lcd_solve(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held,
                      std::optional<std::uint16_t> code, bool drive_value) const;
  // lcd_solve's steps. The target m = ((x_t + x_{t-1}) / 2)^(1/gamma) scaled as scaled_merge: m (2 Mx)^2 2^F.
  Raw lcd_target_scaled(Raw sum) const { return scale_lcd_target(lcd_target(sum)); }
  Raw scale_lcd_target(Raw target) const {
    const Raw two_top = 2 * static_cast<Raw>(max_output_code());
    return target * (two_top * two_top);
  }
  // Reachability is decided in linear light, on the sum x_t + x_{t-1} against 2 M(0|1, v_{t-1} = j)^gamma from the
  // same ROMs the shortfall uses: 0 where the sum lies below the dark end, 1 above the bright end, -1 between them.
  // The exact ends of the range are met exactly: white after white (the ROM holds 1.0), black after black, and with
  // LcdHistory::Contributed the next target, which is built from the ROM value itself. (In m, the 1/gamma power and
  // the quantised coefficients would blur these ends by many LSB near black.)
  int lcd_clamped_end(Raw sum, Raw j) const {
    const auto row = static_cast<std::size_t>(j);
    if (sum < 2 * lcd_end_luminance_[0][row]) return 0;
    return sum > 2 * lcd_end_luminance_[1][row] ? 1 : -1;
  }
  // The drive value of a clamped (unreachable) sample: 0 or 1.
  Raw lcd_clamped_drive(bool above) const { return above ? Raw{1} << config_.drive_frac_bits : 0; }
  // The largest code k whose threshold merge with v_{t-1} = j (coefficients p; row: lcd_merge_table_'s row, or null:
  // computed per step) is at or below target_scaled.
  Raw lcd_search(const std::array<Raw, 4>& p, Raw j, Raw target_scaled, const Raw* row) const;
  // v_{t-1} of the eye's first frame: the code whose held merge M(v, v) reaches the target.
  Raw lcd_held_code(Raw target_scaled) const;
  // lcd_merge_table_'s row (v_{t-1} = row; row 2^o: the held merge), or null where the table is not built.
  const Raw* lcd_merge_row(std::size_t row) const;
  Raw blend_linear(Raw top_left, Raw top_right, Raw bottom_left, Raw bottom_right, Raw col_upper, Raw row_upper) const;
  StoredResidual store_nonzero_residual(Raw rho) const;
};

}  // namespace trm::fixed_detail
