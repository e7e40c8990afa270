// The streaming decoder's hot per-line steps over contiguous lanes, vectorised with Google Highway and dispatched at
// run time to the widest instruction set the CPU offers (the binary still runs on any x86-64). Each kernel gives the
// same bits as the per-sample stage functions of fixed_kernels.hpp for the formats FixedLinePlans accepts; the
// core keeps the per-sample path for every other format and for the work these do not cover (taps, report planes,
// lost lines, the LCD merge).
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace trm::fx {
class InterpolatedLut;
}  // namespace trm::fx

namespace trm::fixed_detail {

class FixedKernels;
struct Geometry;
class ThresholdIndex;

// U's column blend of one reduced row, one entry per output sample s = 3x + ch of the full-width line: the row
// samples of the column's two taps and the weight of the right one, uQ0.W. The exact sum (2^W - w) a + w b is kept
// unrounded (uQb.W), so U = the row blend of two of these, exactly as FixedKernels::blend computes it.
struct ColumnBlendPlan {
  std::vector<std::int32_t> left;
  std::vector<std::int32_t> right;
  std::vector<std::uint32_t> upper;
  std::uint32_t unit = 0;  // 2^W
  // The taps of a vector of L output samples lie within L consecutive row samples wherever r is not far below 1/2 (a
  // vector reads about L r of them): the kernel then loads that window once and permutes it (a lane table lookup)
  // instead of gathering each tap. Per vector width L (4, 8, 16 lanes of 32 bits): the window's start per block of L
  // samples and each sample's taps relative to it; empty for a width whose windows do not fit.
  struct Windows {
    std::vector<std::int32_t> start;  // per block
    std::vector<std::int32_t> left;   // per sample, in [0, L)
    std::vector<std::int32_t> right;
  };
  std::array<Windows, 3> windows;  // L = 4 << i
  // Where L samples do not fit (r = 1/2 at L = 8, AVX2: a vector's taps span up to 9 row samples), windows of 2L
  // samples read as two vectors, each tap taken from one of their permutations: taps in [0, 2L). The kernel takes the
  // single windows where both fit.
  std::array<Windows, 3> double_windows;
  // The least q with every weight `upper` a multiple of 2^(W - q) (2 at r = 1/2: quarters): U's row blend takes its
  // exact path where this and the row weight's q add up to at most the EOTF ROM's segment bits (blend_rows_eotf).
  int weight_bits = 0;
  static const Windows* of_width(const std::array<Windows, 3>& set, std::size_t lanes) {
    for (std::size_t i = 0; i < set.size(); ++i) {
      if ((std::size_t{4} << i) == lanes) return set[i].start.empty() ? nullptr : &set[i];
    }
    return nullptr;
  }
  const Windows* windows_for(std::size_t lanes) const { return of_width(windows, lanes); }
  const Windows* double_windows_for(std::size_t lanes) const { return of_width(double_windows, lanes); }
  // r = 1/2: every full column 2m blends reduced columns m - 1 and m by 1/4 and 3/4, and 2m + 1 columns m and m + 1 by
  // 3/4 and 1/4 (clamped at the row's ends; column_blend_plan checks each sample's coefficients). An output sample is
  // then (a_{j +- 3} + 3 a_j) 2^(W - 2) of its own channel's row samples j and j -+ 3 (the neighbour pixel before for
  // an even column, after for an odd one): a vector of L >= 8 output samples from one lane permutation of each of
  // three windows of L row samples, one pixel apart (no weights, no gathers). The permutation repeats every third
  // vector.
  bool half = false;
};

// U's row blend, its rounding to uQb.U and the EOTF ROM interpolation (FixedKernels::linear_of_upsampled): node y_i
// and step y_{i+1} - y_i per ROM word, the last step 0 (so the top code, whose weight is 0, reads the last word).
struct EotfPlan {
  std::vector<std::int64_t> node;
  std::vector<std::int64_t> step;
  std::vector<std::int64_t> packed;  // node << 32 | step as 32 bits, one lookup per sample (nodes below 2^31)
  std::uint32_t unit = 0;  // 2^W
  int blend_shift = 0;     // 2W - U
  int weight_bits = 0;     // U - k
  // Where the blend's weights are multiples of 2^-q_c (columns) and 2^-q_r (the row) with q_c + q_r <= k, as at
  // r = 1/2 (quarters, k = 4 by default), the exact blend has no bits below the ROM's input code: every sample's ROM
  // weight is 0 and its value the node at ((2^q_r - r) T + r B) 2^(k - q_c - q_r), with T, B the column blends over
  // 2^(W - q_c) and r the row weight over 2^(W - q_r): one lookup of a 32-bit node, no 64-bit arithmetic.
  int frac_bits = 0;                   // W
  int segments_log2 = 0;               // k
  std::vector<std::int32_t> node32;    // node in 32 bits (uQ1.F, F <= 28)
  // Every node in [0, 1]: U's every value is then in [0, 1] (an interpolation lies between two nodes), and Eq. 4's
  // clamp of alpha alone (a zero residual) is never taken.
  bool within_unit = false;

  // q_r for a row weight `upper` after column blends of q_c = column_bits, where the exact path above applies; -1
  // where it does not.
  int exact_row_bits(std::uint32_t upper, int column_bits) const {
    const int row_bits = upper == 0 ? 0 : frac_bits - std::countr_zero(upper);
    return !node32.empty() && upper <= unit && column_bits + row_bits <= segments_log2 ? row_bits : -1;
  }
};

// The OLED drive code search (ThresholdIndex) of the three channels in one table each, for interleaved samples:
// sample s reads channel s mod 3's part through its offsets.
struct DrivePlan {
  std::vector<std::int64_t> base;        // the code at each bucket's lower end, plus the channel's threshold offset
  std::vector<std::int64_t> thresholds;  // every channel's padded threshold ROM, one after the other
  // Element i: channel i mod 3's first bucket / first threshold, for i < 3 + kMaxLanes, so that the offsets of the
  // samples s0.. of a vector are the elements (s0 mod 3)..
  static constexpr int kMaxLanes = 64;
  std::vector<std::int64_t> bucket_offset;
  std::vector<std::int64_t> threshold_offset;
  std::array<int, 3> threshold_count{};  // each channel's thresholds before the padding (the generic search's)
  int steps = 0;
  int mantissa_bits = 0;
  std::int64_t value_limit = 0;  // 2^value_bits: larger values (and negative ones) take the generic search
  // The same tables in 32 bits, where every value below value_limit and every table index fits (value_bits <= 30,
  // F = 28 by default): twice the lanes per vector. Thresholds above INT32_MAX, which no such value reaches, are
  // clamped to it. Empty otherwise.
  std::vector<std::int32_t> base32;
  std::vector<std::int32_t> thresholds32;
  std::vector<std::int32_t> bucket_offset32;
  std::vector<std::int32_t> threshold_offset32;
  // Where no bucket of any channel holds more than one threshold (steps == 1: 8-bit output at the default formats),
  // the search is one lookup: per bucket, the channel's code at the bucket's lower end lo, shifted left by
  // offset_bits, above the offset T_{k+1} - lo of the next threshold where it lies in the bucket, else the bucket's
  // width, which no offset within the bucket reaches. The code is k, plus one where x - lo reaches the offset. The
  // buckets are addressed by x's float: its bits shifted right by 23 - m (exponent and top m fraction bits) less
  // 126 << m, 0 for x = 0 (x from 2^24 on with its low six bits cleared first, so that the float is exact and the
  // bucket unchanged), and lo is that float with the fraction bits below the top m cleared: packed_buckets words per
  // channel, from packed_offset32[i mod 3] (i < 3 + kMaxLanes, as bucket_offset). Empty otherwise.
  std::vector<std::uint32_t> packed32;
  std::vector<std::int32_t> packed_offset32;
  std::int32_t packed_buckets = 0;
  int offset_bits = 0;
};

// The OLED's report drive value v = x^(1/gamma) (FixedKernels::drive_value) of the three channels for interleaved
// samples: each channel's octave-segmented ROM (InterpolatedLut::evaluate_raw) as packed words (EotfPlan::packed),
// one channel after the other. Built where every channel's ROM has a bottom region, rounds half up, is unsigned, packs
// (packed_rom) and holds every node its codes reach, and its input code is at most 30 bits (the weight is then a
// 32-bit operand); nothing otherwise (drive_value per sample).
struct DriveValuePlan {
  std::vector<std::int64_t> packed;
  std::vector<std::int64_t> rom_offset;  // element i: channel i mod 3's first word, i < 3 + DrivePlan::kMaxLanes
  int input_shift = 0;                   // the linear value's bits below the ROM's input code
  std::int64_t top_code = 0;             // 2^input_bits - 1
  int bottom_region_bits = 0;
  int segments_per_octave_log2 = 0;
  std::int64_t one = 0;         // 1.0 as uQ1.F: from it on, v is 1 exactly
  std::int64_t full_drive = 0;  // 1.0 as uQ1.drive_frac_bits
};

// D's horizontal half over a line (FixedKernels::gaussian_horizontal_line, encoded space), one entry per reduced
// output sample s = 3k + ch of tap slot t at [t n + s] (n = 3 reduced.width): the row sample the tap reads and its
// weight, uQ0.T; slots past a column's own taps weigh 0. Each exact sum stays below max_code 2^T < 2^32.
//
// Where the taps are regular (column k's support starts at f k + c for an integer decimation f = full / reduced width,
// as at r = 1/2 or 1/4), the kernel reads them as a polyphase filter instead of one gather per tap: the row is laid
// out once per line as 3 f planes, plane (ch, p) holding channel ch at the (clamped) columns c + f m + p, so that tap
// t of columns k.. is the contiguous run at m = k + t div f of plane (ch, t mod f). The same products are summed
// exactly, so the bits are the gather's.
struct GaussianColumnsPlan {
  std::vector<std::int32_t> index;
  std::vector<std::uint32_t> weight;
  std::size_t taps = 0;     // slots per sample
  std::size_t samples = 0;  // n
  // The polyphase form; decimation 0 where the taps are not regular.
  std::size_t decimation = 0;          // f
  std::size_t columns = 0;             // reduced width K
  std::size_t plane_length = 0;        // M = K + (taps - 1) div f
  std::int64_t first_column = 0;  // c: plane (ch, p) at m holds column clamp(c + f m + p) of the row's full_width
  std::size_t full_width = 0;
  std::vector<std::uint32_t> planar_weight;   // [t K + k]: tap slot t's weight of column k (every channel's)
  std::vector<std::size_t> tap_offset;        // slot t's run of column 0 in a channel's planes: (t mod f) M + t div f
  // Every column's slot weights symmetric (slot t's equal to slot taps - 1 - t's), as D's Gaussian gives them: the
  // kernel sums the two slots' samples before one product.
  bool symmetric = false;
};

// D's rounding shifts where its sums fit 32-bit lanes (horizontal) and 32-bit operands (vertical).
struct GaussianPlan {
  int horizontal_shift = 0;  // T - L, half to even
  int vertical_shift = 0;    // T + L, half up
  bool fold_rows = false;    // max_code 2^(L+1) < 2^32: two line values sum within a 32-bit operand
};

// A uniform ROM whose segment position per code is 2^k (InterpolatedLut::segment_step): node = code >> j and weight
// code mod 2^j for j = 32 - k, and the interpolation ((y_i << j) + (y_{i+1} - y_i) weight + 2^(j-1)) >> j is
// InterpolatedLut::interpolate's add-half-and-shift divided through by 2^k. The last step is 0, as for EotfPlan.
struct ShiftedRomPlan {
  std::vector<std::int64_t> packed;  // as EotfPlan::packed (node << 32 | step)
  int weight_bits = 0;  // j
};

// The motion test and Eq. 4 of a reduced frame with a residual (FixedKernels::luma, motion_weight, contrast_of,
// add_weighted_residual), for linear values in [0, 1] uQ1.F with F <= 30 (so every product is of 32-bit operands).
struct MotionPlan {
  std::array<std::uint32_t, 3> luma_weight{};  // uQ0.luma_shift
  int luma_shift = 0;
  int linear_frac_bits = 0;  // F
  std::int64_t one = 0;      // 2^F
  ShiftedRomPlan reciprocal;  // 1/m, m in [1, 2), uQ2.reciprocal_frac_bits
  int reciprocal_input_bits = 0;
  int reciprocal_frac_bits = 0;
  std::uint32_t sensitivity = 0;  // s, uQ8.sensitivity_frac_bits
  int exponent_shift = 0;         // s c (uQ.(S + F)) to uQ5.X
  int exp_input_frac_bits = 0;    // X
  ShiftedRomPlan exp_fraction;    // exp(-f), f in [0, 1), uQ1.F
  std::array<std::int64_t, 16> exp_integer{};  // exp(-i), uQ1.F
  int residual_frac_bits = 0;
  bool narrow_weighted_sum = false;  // Eq. 4's operands and sum within 32 bits (the 32-bit lanes' kernel)
  std::uint32_t residual_magnitude_limit = 0;  // 2^(width - 1): |rho| of the residual format
};

// What the motion test and Eq. 4 of a line add to the frame's tally (FrameTally's fields of the same names).
struct MotionTally {
  std::uint64_t underflow = 0;
  std::uint64_t clipped = 0;
  std::int64_t weight_sum = 0;
  std::int64_t dropped_sum = 0;
  std::int64_t residual_abs_sum = 0;
  std::int64_t residual_abs_max = 0;
};

struct ResidualTally;  // fixed_kernels.hpp

// The LCD drive (FixedKernels::lcd_drive, the eye's first (held) frame included, and emit's frame-store update): the
// target m = ((x_t + x_{t-1}) / 2)^(1/gamma) through the octave-segmented ROM, the code of m in the merge table's row
// v_{t-1} (through the per-row index below where it is built, else by binary search), and the unreachable ends.
struct LcdPlan {
  std::vector<std::int64_t> target_packed;  // the target ROM as EotfPlan::packed
  int target_shift = 0;                     // the sum's bits below the ROM's input code
  int target_input_bits = 0;
  int bottom_region_bits = 0;
  int segments_per_octave_log2 = 0;
  int linear_frac_bits = 0;
  std::int64_t one = 0;
  std::uint32_t scale = 0;  // (2 Mx)^2: the target's scaling to the merge table's integers
  std::vector<std::int64_t> merge;  // 2^o + 1 rows of 2^o words: row v_{t-1} (row 2^o: M(v, v)), column k
  std::int64_t width = 0;           // 2^o
  int width_log2 = 0;
  int top = 0;                      // 2^o - 1
  int steps = 0;                    // binary search steps that cover [0, top]
  // Per v_{t-1}: M(0, v_{t-1})^gamma and M(1, v_{t-1})^gamma (uQ/sQ.F) side by side, the unreachable ends (one
  // 128-bit load per sample on AVX2).
  std::vector<std::int64_t> ends;
  bool contributed = false;              // LcdHistory::Contributed: x_{t-1} stored is the contributed value
  // The search in one lookup (lcd_search_index): per row r (v_{t-1} = r, then the held row) the code is the number
  // of its thresholds U_k = ceil(merge[r][k] / scale) (the smallest target m with m scale >= merge) at or below m.
  // Where every bucket of 2^index_shift targets holds at most one threshold besides its lower end, and every
  // threshold lies in [1, one] (so a target clamped to [0, one] has its code), word [r index_buckets + q] holds the
  // code at the bucket's lower end q 2^s, shifted left by index_offset_bits, above the offset from it of the row's
  // next threshold (2^s where that is past the bucket). Empty otherwise: the binary search.
  std::vector<std::uint32_t> index;
  int index_shift = 0;
  int index_offset_bits = 0;
  std::int64_t index_buckets = 0;  // per row: (one >> s) + 1
  // The target ROM and the search in one lookup (lcd_composed_index; a simulation table, as FixedLinePlans::
  // drive_of_node: the modelled hardware runs both). The code depends on the sum x_t + x_{t-1} only through the ROM's
  // input c = min(max(sum, 0) >> target_shift, 2^target_input_bits), c = 2^target_input_bits standing for the target
  // one: per row r, C_k = the least c whose target reaches U_k does not fall as k rises, and the code is the number of
  // C_k at or below c. Word [r composed_buckets + b] holds, for bucket b of c addressed by c's float with
  // composed_mantissa_bits (as DrivePlan::packed32), the code at the bucket's lower end shifted left by
  // composed_offset_bits, above the offset of the row's next C_k from it (the bucket's width where that lies past
  // it). Built where the ROM's input fits a float's 24 bits, the target rises with c, every bucket of every row holds
  // at most one C_k and the table is at most kMaxComposedBytes; empty otherwise.
  static constexpr std::size_t kMaxComposedBytes = std::size_t{16} << 20;
  std::vector<std::uint32_t> composed;
  int composed_mantissa_bits = 0;
  int composed_offset_bits = 0;
  std::int32_t composed_buckets = 0;
  // Per v_{t-1}: 2 M(0, v_{t-1})^gamma in the low 32 bits, 2 M(1, v_{t-1})^gamma in the high, the
  // sums' unreachable ends for the composed kernel's 32-bit lanes (both at most 2^30 wherever composed is built).
  std::vector<std::uint64_t> ends32;
  // The report's drive value (FixedKernels::lcd_report_drive: v between the code's thresholds, interpolated in M) of
  // lcd_drive_values: per v_{t-1} = j, report_row_words = 2^o + 1 words M(clamp(2c - 1, 0, 2 Mx), j) scaled as the
  // merge table, c = 0 .. 2^o (the thresholds either side of code c at c and c + 1). Built where every positive span
  // between them stays below 2^62 / (2 Mx + 2), and every word within (-2^61, 2^61), so that the interpolation's
  // operands and its denominator fit 63 bits, and drive_frac_bits <= 30; empty otherwise.
  std::vector<std::int64_t> report_merge;
  std::int64_t report_row_words = 0;
  int drive_frac_bits = 0;
};

// The per-row target index of an LCD plan (LcdPlan::index): the coarsest bucket width that holds at most one
// threshold, from 2^(F-8) down to 2^(F-14) targets; none where no width does.
void lcd_search_index(LcdPlan& plan);
// LcdPlan::composed and ends32 of a plan whose target ROM is `target`: the coarsest float addressing, from 2^6 to
// 2^10 buckets per octave, that fits; none where none does.
void lcd_composed_index(LcdPlan& plan, const fx::InterpolatedLut& target);

// What the line kernels need from a configuration, or nothing where its formats do not fit their lanes.
struct FixedLinePlans {
  std::optional<EotfPlan> eotf;    // encoded-space U and EOTF (8-bit sums, W <= 24, 2W > U, interpolation on 64 bits)
  std::optional<DrivePlan> drive;  // OLED drive codes
  std::optional<DriveValuePlan> drive_value;  // the OLED's report drive values
  std::optional<MotionPlan> motion;  // finite, non-zero s; uniform reciprocal and exp ROMs with power-of-two steps
  std::optional<GaussianPlan> gaussian;  // encoded space, max_code 2^T and max_code 2^L below 2^32
  std::optional<LcdPlan> lcd;            // LCD with the merge table (output codes up to 8 bits), F <= 30
  std::vector<std::int64_t> code_rom;  // I = lin(E) per link code
  std::int64_t one = 0;
  // code_rom in 32 bits. FixedDecoderConfig bounds F to 28, so a line's linear values (uQ1.F), beta in [-2^F,
  // 2^(F+1)], rho and alpha' all fit 32 bits, and the line kernels keep their lines in 32-bit words (the overloads
  // below on std::int32_t lines; an LCD's rho plus its drive shortfall is added in 64 bits): twice the lanes where
  // the arithmetic is 32-bit (Eq. 2 and the split, Eq. 4, the drive codes' input) and half the line traffic
  // elsewhere.
  std::vector<std::int32_t> code_rom32;
  // U's exact path composed with the OLED drive (a simulation table; the modelled hardware runs both): [3 i + ch] is
  // the drive code of eotf->node32[i] on channel ch, which is a sample's code wherever its shown value is its U node
  // itself (a reduced line whose stored residual is all zero: alpha' = clamp(alpha) = alpha). Built where every node
  // lies in [0, 1] (EotfPlan::within_unit) and the table has at most 2^17 nodes; empty otherwise.
  std::vector<std::uint16_t> drive_of_node;

  static FixedLinePlans build(const FixedKernels& kernels);
};

// The column blend plan of a view size (for FixedLinePlans::eotf).
ColumnBlendPlan column_blend_plan(const Geometry& g, std::uint32_t unit);
// The OLED drive code search of three channels' threshold indices (for FixedLinePlans::drive), or nothing where an
// index is not usable or their value ranges differ.
std::optional<DrivePlan> drive_plan(const std::array<const ThresholdIndex*, 3>& channels);
// D's horizontal taps of a view size as tap slots (for FixedLinePlans::gaussian).
GaussianColumnsPlan gaussian_columns_plan(const Geometry& g);

namespace lines {

// out[s] = (2^W - upper[s]) row[left[s]] + upper[s] row[right[s]] for s < n (uQb.W, exact).
void blend_columns(const std::uint16_t* row, const ColumnBlendPlan& plan, std::size_t n, std::uint32_t* out);
// out[s] = lin(round((2^W - upper) top[s] + upper bottom[s]) to uQb.U) through the EOTF ROM, uQ1.F; top and bottom
// are column blends whose weights are multiples of 2^-column_weight_bits (ColumnBlendPlan::weight_bits).
void blend_rows_eotf(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                     int column_weight_bits, const EotfPlan& plan, std::int64_t* out);
// codes[s] = drive_of_node[3 i + s mod 3] for U's node i of sample s (FixedLinePlans::drive_of_node), where U's exact
// path applies to the row (EotfPlan::exact_row_bits); false, writing nothing, where it does not.
bool blend_rows_drive(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                      int column_weight_bits, const EotfPlan& plan, const std::vector<std::uint16_t>& drive_of_node,
                      std::uint16_t* codes);
// out[s] = the drive code of linear[s] (channel s mod 3), as ThresholdIndex::search gives it.
void drive_codes(const std::int64_t* linear, std::size_t n, const DrivePlan& plan, std::uint16_t* out);
// out[s] = FixedKernels::drive_value(linear[s], s mod 3), the OLED's report drive value, on a line of either width.
void drive_values(const std::int64_t* linear, std::size_t n, const DriveValuePlan& plan, const FixedKernels& kernels,
                  std::int64_t* out);
void drive_values(const std::int32_t* linear, std::size_t n, const DriveValuePlan& plan, const FixedKernels& kernels,
                  std::int64_t* out);
// Eq. 2 and the split (FixedKernels::compensate): beta = 2 lin(codes[s]) - low[s] (lin through plans.code_rom),
// shown[s] = clamp(beta, 0, one),
// rho[s] = beta - shown[s]. Returns the number of clipped samples (beta outside [0, one]).
std::uint64_t compensate(const std::uint16_t* codes, const std::int64_t* low, std::size_t n,
                         const FixedLinePlans& plans, std::int64_t* shown, std::int64_t* rho);
// D's horizontal half: out[s] = round(sum_t weight[t n + s] row[index[t n + s]], T - L), half to even, for s < n.
void gaussian_columns(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan,
                      int shift, std::int64_t* out);
// D's vertical half: out[i] = round(sum_j weight[j] rows[j][i], T + L), half up, for i < n (rows[j][i] < 2^32).
// fold: rows[j][i] + rows[k][i] < 2^32 too, so that symmetric weights may be summed in pairs (GaussianPlan::fold_rows).
void gaussian_rows(const std::int64_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                   int shift, bool fold, std::uint16_t* out);
// The same on 32-bit line words (every D sum of a GaussianPlan fits them): half the line buffers' bytes.
void gaussian_columns(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan,
                      int shift, std::uint32_t* out);
void gaussian_rows(const std::uint32_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                   int shift, bool fold, std::uint16_t* out);
// The LCD drive of n samples of one line: codes[s] and, where shortfall is not null, shortfall[s] as
// FixedKernels::lcd_drive(wanted[s], previous_linear[s], previous_code[s], held) gives them, and the frame stores
// previous_code / previous_linear replaced as FixedDecoderCore::emit replaces them (held: the eye's first frame,
// whose stores are written and not read; v_{t-1} in 8 bits, the plan's widest output). Returns the number of
// unreachable samples.
std::uint64_t lcd_drive(const std::int64_t* wanted, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                        std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                        std::int64_t* shortfall);
// The LCD drive's search alone (for tests): codes[s] = the largest k with merge[rows[s]][k] <= target[s] scale (row
// rows[s] of the plan's merge table, the held row at 2^o), through LcdPlan::index where it is built, else by the
// binary search, for target[s] in [0, one].
void lcd_search(const std::int64_t* target, const std::int64_t* rows, std::size_t n, const LcdPlan& plan,
                std::uint16_t* codes);
// target[s] = FixedKernels::lcd_target(sum[s]): the LCD drive's target m of x_t + x_{t-1} = sum[s] through the plan's
// ROM, uQ1.F.
void lcd_targets(const std::int64_t* sum, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                 std::int64_t* target);
// drive[s] = FixedKernels::lcd_report_drive(sum[s], target[s], rows[s], codes[s]): the LCD's report drive value of
// a sample whose x_t + x_{t-1} = sum[s], whose target m = lcd_target(sum[s]), v_{t-1} = rows[s] and code codes[s].
void lcd_drive_values(const std::int64_t* sum, const std::int64_t* target, const std::uint16_t* rows,
                      const std::uint16_t* codes, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                      std::int64_t* drive);
// Eqs. 5-6 per pixel: weight[x] = motion_weight(luma(previous + 3x), luma(alpha + 3x)) for x < pixels. Pixels
// whose operands leave the plan's lanes (values outside [0, 1], sums too small to normalise) take the stage functions
// of `kernels`.
void motion_weights(const std::int64_t* previous, const std::int64_t* alpha, std::size_t pixels, const MotionPlan& plan,
                    const FixedKernels& kernels, std::int64_t* weight, MotionTally& tally);
// Eq. 4 per sample: shown[s] = add_weighted_residual(alpha[s], weight[s / 3], residual[s]).alpha_prime for s < n.
void add_weighted_residuals(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                            std::size_t n, const MotionPlan& plan, const FixedKernels& kernels, std::int64_t* shown,
                            MotionTally& tally);
// The residual store of a line: FixedKernels::store_residual of each rho into `stored`; a vector of zeros (beta
// within [0, 1], the common case) stores zeros without the stage function. Returns whether a stored value is not 0.
bool store_residuals(const std::int64_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                     ResidualTally& tally);
// The same steps on 32-bit lines (FixedLinePlans::code_rom32: every value within 32 bits), the same bits;
// drive_codes on 32-bit lines needs the plan's 32-bit tables (DrivePlan::base32) for its vector path.
void blend_rows_eotf(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                     int column_weight_bits, const EotfPlan& plan, std::int32_t* out);
void drive_codes(const std::int32_t* linear, std::size_t n, const DrivePlan& plan, std::uint16_t* out);
std::uint64_t compensate(const std::uint16_t* codes, const std::int32_t* low, std::size_t n,
                         const FixedLinePlans& plans, std::int32_t* shown, std::int32_t* rho);
bool store_residuals(const std::int32_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                     ResidualTally& tally);
std::uint64_t lcd_drive(const std::int32_t* wanted, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                        std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                        std::int64_t* shortfall);
void add_weighted_residuals(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                            std::size_t n, const MotionPlan& plan, const FixedKernels& kernels, std::int32_t* shown,
                            MotionTally& tally);
// The instruction set the kernels dispatch to on this CPU (e.g. "AVX3", "AVX2", "SSE4").
const char* target_name();

}  // namespace lines
}  // namespace trm::fixed_detail
