// The per-pixel arithmetic of the fixed-point decoder, one function per stage, shared by the frame-at-a-time and
// the streaming schedules (so they can differ only in scheduling), plus the state both keep per eye.
// Raw values are integers; each function states its Q formats. F = linear_frac_bits throughout.
#pragma once

#include "trm/fixed_decoder.hpp"
#include "trm/lut.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace trm::fixed_detail {

using Raw = std::int64_t;

// Round half up (SC_RND) of v / 2^shift; C++20 >> on negative values is arithmetic, so this holds for any sign.
inline Raw round_shift(Raw v, int shift) { return shift <= 0 ? v * (Raw{1} << -shift) : (v + (Raw{1} << (shift - 1))) >> shift; }

// Round half to even (SC_RND_CONV) of v / 2^shift, shift >= 1. Used where two values that sum to an integer must
// still do so after rounding (complementary rows of a Nyquist pattern in the D line buffer).
inline Raw round_convergent_shift(Raw v, int shift) {
  const Raw floor = v >> shift;
  const Raw rest = v - (floor << shift);
  const Raw half = Raw{1} << (shift - 1);
  return floor + ((rest > half || (rest == half && (floor & 1) != 0)) ? 1 : 0);
}

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

// Order-independent accumulators of one frame (integers, so both schedules report identical statistics).
struct FrameTally {
  FixedStageCounts counts;
  std::uint64_t clipped = 0;     // samples for FrameStats::clipped_fraction
  Raw dropped_sum = 0;           // uQ.F
  Raw weight_sum = 0;            // uQ.F over pixels
  Raw residual_abs_sum = 0;      // in residual format LSBs
  Raw residual_abs_max = 0;
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
  std::uint16_t gaussian_vertical(const Raw* const* rows, const PolyphaseTaps& taps, int sample) const;
  // Linear space: the link code the encoder gives linear value x (uQ1.P): the largest k with x >= T_k.
  std::uint16_t encode_linear(Raw x) const;

  // The U functions return U's output: in the encoded space codes uQb.U (linear_of_upsampled applies the EOTF LUT);
  // in the linear space linear light uQ1.F, blended from lin(code) (linear_of_upsampled passes it through).
  // U: bilinear blend of reduced codes rows row0 (i0) and row1 (i1) at full column x, channel ch; codes uQb.U.
  Raw upsample(const std::uint16_t* row0, const std::uint16_t* row1, const BilinearWeights& col, Raw row_upper,
               int ch) const;
  // The bilinear arithmetic itself: four codes, weights uQ0.W, result uQb.U (Rnd); linear space: four codes through
  // the I ROM, result uQ1.F (Rnd).
  Raw blend(Raw top_left, Raw top_right, Raw bottom_left, Raw bottom_right, Raw col_upper, Raw row_upper) const;
  // lin() of U's encoded output through the interpolated EOTF LUT; uQ1.F. Linear space: U's output as it is.
  Raw linear_of_upsampled(Raw upsampled) const;

  // Eq. 2: beta = 2 I - L (sQ3.F), shown = clamp(beta, 0, 1), rho = beta - shown.
  CompensatedSample compensate(Raw full_linear, Raw low_linear) const { return split(2 * full_linear - low_linear); }
  // shown = clamp(beta, 0, 1), rho = beta - shown. A concealed (lost) line of a full frame splits beta = L.
  CompensatedSample split(Raw beta) const;
  // rho (sQ.F) into the residual store format (its rounding and overflow modes).
  StoredResidual store_residual(Raw rho) const;

  bool lcd() const { return lcd_; }
  // LCD (Eq. 7 inverse): the drive code whose merge with v_{t-1} = previous_code reaches m = ((x_t + x_{t-1})/2)^(1/g).
  // held: the eye's first frame, x_{t-1} = x_t and the pixel held (M(v, v)); returns the held code.
  LcdSample lcd_drive(Raw wanted, Raw previous_wanted, std::uint16_t previous_code, bool held) const;
  double lcd_emitted(std::uint16_t code, std::uint16_t previous_code) const;

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

  // OLED drive code: the largest k with x >= T_k (binary search of the threshold ROM).
  std::uint16_t drive_code(Raw linear, int ch) const;
  // Drive value v = x^(1/gamma) for reports, uQ1.drive_frac_bits.
  Raw drive_value(Raw linear, int ch) const;
  double emitted_of_code(std::uint16_t code, int ch) const { return emission_[ch][code]; }

  // Every ROM of this configuration (name, words, word bits, copies).
  std::vector<FixedRomReport> roms() const;
  // The operator table of the per-pixel stages at the geometry's sizes (see the table in fixed_kernels.cpp).
  std::vector<FixedArithmeticReport> arithmetic(const Geometry& g) const;

  // Exact conversions (the raw values have at most 53 significant bits; the scales are powers of two).
  double linear_to_double(Raw v) const { return static_cast<double>(v) * linear_lsb_; }
  double drive_to_double(Raw v) const { return static_cast<double>(v) * drive_lsb_; }
  double residual_to_double(Raw v) const { return static_cast<double>(v) * residual_lsb_; }

 private:
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
  std::array<std::unique_ptr<fx::InterpolatedLut>, 3> drive_luts_;
  int drive_lut_shift_ = 0;  // linear LSBs dropped to address the drive LUT (24 address bits at most)
  std::array<std::vector<double>, 3> emission_;
  double linear_lsb_ = 0.0;
  double drive_lsb_ = 0.0;
  double residual_lsb_ = 0.0;
  std::map<std::pair<int, int>, Geometry> geometries_;
  // LCD: merge coefficients in sQ.kLcdCoefficientBits, x^(1/gamma) LUT for m, and M(0, vp)^gamma, M(1, vp)^gamma
  // ROMs (uQ/sQ.F) for the shortfall at the two clamped drives.
  bool lcd_ = false;
  std::array<Raw, 4> lcd_coefficients_{};       // p1..p4
  std::array<Raw, 4> lcd_held_coefficients_{};  // M(v, v): 2 p1 + p2, 0, 2 p3, p4
  std::unique_ptr<fx::InterpolatedLut> lcd_target_lut_;
  std::array<std::vector<Raw>, 2> lcd_end_luminance_;
  // The merge scaled to an integer: (2 Mx)^2 2^P M(t / (2 Mx), j / Mx).
  Raw scaled_merge(const std::array<Raw, 4>& p, Raw t, Raw j) const;
  // c = difference / sum through the reciprocal LUT, clamped to 1; difference > 0.
  Raw contrast_of(Raw difference, Raw sum) const;
  Raw lcd_drive_value(const std::array<Raw, 4>& p, Raw target_scaled, int code, Raw j) const;
};

// What persists between frames of one eye (DESIGN §5 frame stores).
struct EyeState {
  cv::Size full_size;
  cv::Mat lcd_previous_drive;   // LCD: v_{t-1} codes, full size, CV_16UC3 (empty: no history yet)
  cv::Mat lcd_previous_linear;  // LCD: x_{t-1}, full size, CV_32SC3 sQ.F
  bool have_residual = false;
  std::int64_t residual_index = 0;
  cv::Mat residual;       // rho, full size, CV_32SC3 raw residual format
  cv::Mat previous_low;   // d_t codes, reduced size, CV_16UC3
  std::vector<std::uint8_t> residual_nonzero;  // DESIGN §7 skip: one flag bit per full line, rho not all zero there
  DecodedFrame last_output;  // what this eye showed last (drive codes: the held-output store), re-shown when a
                             // view is lost
};

// A view that arrived with some lines lost (at least one lost, at least one intact), as the reference conceals it:
// lost lines of a full frame feed D as copies of the nearest intact line above (else below) and show L_t with
// rho = 0; lost lines of a reduced frame repeat the row of the stored d_{t-1} (substitute) or, without one, the
// nearest intact line above (else below).
struct Concealment {
  std::span<const std::uint8_t> intact;  // one entry per line of the view; 0 = lost
  int first_intact = 0;  // lost lines above it have no intact line above: they take this line's content
  int lost_lines = 0;
  cv::Mat substitute;    // reduced frames: the eye's d_{t-1} frame store (codes); empty: none
  bool lost(int y) const { return intact[static_cast<std::size_t>(y)] == 0; }
};

// The skip gates of one output line of a reduced frame that has a residual (DESIGN §7), from the line comparator
// flags of its U source rows and the full frame's residual line flag.
struct ReducedLineGate {
  bool motion_static = false;  // L_{t-1} = alpha on the whole line: w = 1, no motion test
  bool residual_zero = false;  // rho all zero on the line: no residual read, no add
};

// Output frame under construction and the per-pixel emission shared by both schedules.
struct FrameOutput {
  DecodedFrame frame;
  FrameTally tally;
  bool lcd_held = false;  // LCD: the eye's first frame (no v_{t-1} yet)
  bool full = false;
  int concealed_lines = 0;
  FixedStageTaps* taps = nullptr;  // test vectors: stage planes to fill (frame-at-a-time schedule only)
};

// The state and plumbing shared by both schedules: configuration, ROMs, eye states, input checks and output.
class FixedDecoderCore {
 public:
  explicit FixedDecoderCore(FixedDecoderConfig config);

  FixedKernels& kernels() { return kernels_; }
  const FixedDecoderConfig& config() const { return kernels_.config(); }
  const FixedStageCounts& last_counts() const { return last_counts_; }

  // Checks the frame and returns the eye state (reset on a change of view size).
  EyeState& begin(const LinkFrame& frame, const char* who);
  // Classifies a line mask as the reference does: Whole (empty or every line intact: decode normally), Lost (no
  // line intact: decode_lost) or Partial, for which `out` is filled. The substitute d_{t-1} is taken when the eye
  // holds a residual and a d_t of the view's reduced size, looked up before begin() (as the reference does).
  enum class Arrival { Whole, Partial, Lost };
  Arrival classify(const LinkFrame& frame, std::span<const std::uint8_t> line_intact, Concealment& out,
                   const char* who);
  // The codes of a partially received view with every lost line replaced (the frame-at-a-time schedule's form).
  static cv::Mat concealed_codes(const cv::Mat& codes, const Concealment& c);
  // A view that never arrived: this eye's previous output again (black if none); the residual is dropped.
  DecodedFrame decode_lost(const FrameMeta& meta, const char* who);
  // Allocates the output matrices at full size.
  FrameOutput start_output(const LinkFrame& frame) const;
  // Writes one output channel sample from the wanted linear value x (uQ1.F); returns the LCD shortfall (else 0).
  Raw emit(FrameOutput& out, EyeState& eye, int y, int x, int ch, Raw wanted) const;
  // Prepares the LCD frame stores of the eye for this frame (first frame: held history).
  void begin_lcd(FrameOutput& out, EyeState& eye) const;
  // One full-frame pixel, all channels (Eq. 2): U of the d_t rows i0/i1 of output row y, L, I from the codes row,
  // beta, shown (emitted), rho into residual_row. A lost (concealed) line takes beta = L.
  void full_pixel(FrameOutput& out, EyeState& eye, const Geometry& g, int y, int x, const std::uint16_t* codes_row,
                  const std::uint16_t* low0, const std::uint16_t* low1, std::int32_t* residual_row,
                  bool lost = false) const;
  // One reduced-frame pixel (Eqs. 1, 4-6): alpha from the received rows in0/in1; with a residual, L_prev from the
  // stored d_{t-1} rows prev0/prev1, w and alpha'. Without one (residual_row null), alpha alone.
  // With a gate (DESIGN §7 skips): motion_static takes L_{t-1} = alpha and w = 1 (prev0/prev1 are not read);
  // residual_zero reads no residual (residual_row may then be null) and adds nothing.
  void reduced_pixel(FrameOutput& out, EyeState& eye, const Geometry& g, int y, int x, const std::uint16_t* in0,
                     const std::uint16_t* in1, const std::uint16_t* prev0, const std::uint16_t* prev1,
                     const std::int32_t* residual_row, const ReducedLineGate* gate = nullptr) const;
  // DESIGN §7 skips (no-ops unless config().skip_unneeded):
  // after full-frame output line y: flags the line of the residual store whose rho is not all zero (the write
  // gate), counting the lines not written;
  void end_full_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* residual_row) const;
  bool skipping() const { return config().skip_unneeded; }
  // the gate of reduced-frame output line y from the comparator flags of its source rows (row_flags(k) gives row k's
  // FixedKernels::compare_line result), counting the skip events.
  template <typename RowFlags>
  ReducedLineGate reduced_line_gate(FrameOutput& out, const EyeState& eye, const Geometry& g, int y,
                                    RowFlags row_flags) const {
    const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
    const std::uint8_t f0 = row_flags(row.i0);
    // With a lower-row weight of 0, U reads the upper row alone (bilinear blend, exactly).
    const std::uint8_t f1 = row.upper == 0 ? static_cast<std::uint8_t>(FixedKernels::kLineStatic) : row_flags(row.i1);
    ReducedLineGate gate;
    gate.motion_static = (f0 & f1 & FixedKernels::kLineStatic) != 0;
    gate.residual_zero = eye.residual_nonzero.size() == static_cast<std::size_t>(g.full.height) &&
                         eye.residual_nonzero[static_cast<std::size_t>(y)] == 0;
    out.tally.counts.motion_test_lines_skipped += gate.motion_static ? 1 : 0;
    out.tally.counts.residual_read_lines_skipped += gate.residual_zero ? 1 : 0;
    return gate;
  }
  // Test vectors: marks the stages of this frame kind present in taps, sized and formatted, and attaches them.
  void start_taps(FrameOutput& out, FixedStageTaps& taps, const Geometry& g, bool full, bool residual) const;
  // Records one value of a stage plane (no-op without taps).
  static void tap(FrameOutput& out, FixedStage stage, int y, int x, int ch, Raw value) {
    if (out.taps == nullptr) return;
    FixedStagePlane& p = (*out.taps)[stage];
    p.values[(static_cast<std::size_t>(y) * static_cast<std::size_t>(p.size.width) + static_cast<std::size_t>(x)) *
                 static_cast<std::size_t>(p.channels) + static_cast<std::size_t>(ch)] = value;
  }
  // Fills FrameStats from the tally, remembers the counts and the eye's output.
  DecodedFrame finish(FrameOutput&& out, EyeState& eye, bool full, bool residual_applied);

 private:
  FixedKernels kernels_;
  std::map<int, EyeState> eyes_;
  FixedStageCounts last_counts_;
};

}  // namespace trm::fixed_detail
