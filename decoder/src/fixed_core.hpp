// The state and plumbing both fixed-point schedules share: what persists per eye (DESIGN §5 frame stores), the
// output frame under construction, and the per-pixel full and reduced frame steps over the stage arithmetic of
// fixed_kernels.hpp.
#pragma once

#include "fixed_kernels.hpp"
#include "frame_planes.hpp"
#include "view_arrival.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace trm::fixed_detail {

using detail::frame_plane;
using detail::plane_owners;
using detail::reusable_plane;

// Order-independent accumulators of one frame (integers, so both schedules report identical statistics).
struct FrameTally {
  FixedStageCounts counts;
  std::uint64_t clipped = 0;     // samples for FrameStats::clipped_fraction
  Raw dropped_sum = 0;           // uQ.F
  Raw weight_sum = 0;            // uQ.F over pixels
  Raw residual_abs_sum = 0;      // in residual format LSBs
  Raw residual_abs_max = 0;
  std::uint64_t unweighed_lines = 0;  // lines whose w was not computed (ReducedLineGate::weight_unused)

  // The residual store's part.
  void add(const ResidualTally& r) {
    counts.residual_saturated += r.saturated;
    counts.residual_rounded += r.rounded;
    residual_abs_sum += r.abs_sum;
    residual_abs_max = std::max(residual_abs_max, r.abs_max);
  }
  // The tally of two parts of one frame (bands of lines decoded apart).
  FrameTally& operator+=(const FrameTally& t) {
    counts += t.counts;
    clipped += t.clipped;
    dropped_sum += t.dropped_sum;
    weight_sum += t.weight_sum;
    residual_abs_sum += t.residual_abs_sum;
    residual_abs_max = std::max(residual_abs_max, t.residual_abs_max);
    unweighed_lines += t.unweighed_lines;
    return *this;
  }
};

// The bands a whole view of an eye ran in on several threads (their first output rows) and the seconds each took: the
// simulation's schedule, which the next view of the same kind and height balances its bands by (no modelled store).
struct BandTimes {
  int height = 0;
  std::vector<int> begins;
  std::vector<double> seconds;
};

// Output rows [begin, end) of a view decoded in bands, and the rows of d_t [reduced_begin, reduced_end) the band
// writes to the d_t frame store (the rows its outputs need from the band above are computed again, not stored
// twice).
struct RowBand {
  int begin = 0;
  int end = 0;
  int reduced_begin = 0;
  int reduced_end = 0;
};
// A band re-reads the Gaussian's support above it, so short bands waste work.
constexpr int kMinBandRows = 64;
// The bands of a view for `threads` threads: equal shares of the output rows, none shorter than kMinBandRows.
std::vector<RowBand> row_bands(const Geometry& g, int threads);
// `count` bands (as many as row_bands gives) of about equal cost by the times `last` measured for the eye's last view
// of the same kind (a cost per row in each of its bands), none shorter than kMinBandRows / 2; row_bands' equal shares
// where there is no such view or no such split. A reduced view's cost follows its content (the runs and lines that
// hold a residual, the static lines), which moves little from one view to the next: with equal shares its bands'
// times differed by up to 2x.
std::vector<RowBand> balanced_bands(const Geometry& g, int count, const BandTimes& last);

// What persists between frames of one eye (DESIGN §5 frame stores).
struct EyeState {
  cv::Size full_size;
  cv::Mat lcd_previous_drive;   // LCD: v_{t-1} codes, full size, CV_8UC3 up to 8-bit output, else CV_16UC3 (empty:
                                // no history yet)
  cv::Mat lcd_previous_linear;  // LCD: x_{t-1}, full size, CV_32SC3 sQ.F
  bool have_residual = false;
  std::int64_t residual_index = 0;
  cv::Mat residual;       // rho, full size, CV_32SC3 raw residual format
  cv::Mat previous_low;   // d_t codes, reduced size, CV_16UC3
  std::vector<std::uint8_t> residual_nonzero;  // DESIGN §7 skip: one flag bit per full line, rho not all zero there
  // And one per run of kMotionRunPixels pixels of each line (line y's runs from y * runs), which a reduced line reads
  // for the runs that hold a residual (without the motion statistics) in place of the stored rho itself.
  std::vector<std::uint8_t> residual_run_nonzero;
  // DESIGN §7 chroma skip: one grey flag per row of the d_t store (from the flags of its D taps) and per line of the
  // residual store (R = G = B in the stored rho); empty when not skipping.
  std::vector<std::uint8_t> low_grey;
  std::vector<std::uint8_t> residual_grey;
  DecodedFrame last_output;  // what this eye showed last (drive codes: the held-output store), re-shown when a
                             // view is lost
  // Planes of earlier views (output, rho, d_t) kept for reuse: one that no caller holds any more is filled again, so
  // a view in steady state allocates (and faults in) no frame-sized memory.
  std::vector<DecodedFrame> spare_outputs;
  std::vector<cv::Mat> spare_planes;
  std::array<BandTimes, 2> band_times;  // of the last reduced [0] and full [1] view decoded in bands
};

// Without FixedDecoderConfig::motion_weight_statistics, a reduced line with a residual runs the motion test on the
// runs of this many pixels that hold a residual sample that is not 0 (FixedDecoderCore::reduced_line).
inline constexpr std::size_t kMotionRunPixels = 64;
inline std::size_t motion_runs(int width) {
  return (static_cast<std::size_t>(width) + kMotionRunPixels - 1) / kMotionRunPixels;
}
// run(index, x0, x1) for each run [x0, x1) of a line of `pixels` pixels, the last one shorter where it ends the line.
template <typename Run>
void for_each_motion_run(std::size_t pixels, const Run& run) {
  for (std::size_t x0 = 0; x0 < pixels; x0 += kMotionRunPixels) {
    run(x0 / kMotionRunPixels, x0, std::min(pixels, x0 + kMotionRunPixels));
  }
}

// The skip gates of one output line of a reduced frame that has a residual (DESIGN §7), from the line comparator
// flags of its U source rows and the full frame's residual line flag.
struct ReducedLineGate {
  bool motion_static = false;  // L_{t-1} = alpha on the whole line: w = 1, no motion test
  bool residual_zero = false;  // rho all zero on the line: no residual read, no add
  // residual_zero without motion weight statistics (FixedDecoderConfig::motion_weight_statistics): w weighs
  // nothing, no motion test
  bool weight_unused = false;
  // The motion test reads U of the d_{t-1} rows.
  bool reads_previous() const { return !motion_static && !weight_unused; }
};

// U's column blends of the last two reduced rows read from one source (a row of d_t, i or d_{t-1} held by the
// schedule's line buffers or frame stores), so that each row is blended along x once although two or more output
// lines read it. A row is known by its buffer address and its row index, which within one view (and band) name one
// content: the schedules write a row before they read it and never rewrite it.
class ColumnBlendCache {
 public:
  ColumnBlendCache() = default;
  // A copy (a band of a view, with buffers of its own) starts empty: its rows live at other addresses.
  ColumnBlendCache(const ColumnBlendCache&) {}
  ColumnBlendCache& operator=(const ColumnBlendCache&) {
    *this = ColumnBlendCache();
    return *this;
  }
  ColumnBlendCache(ColumnBlendCache&&) = default;
  ColumnBlendCache& operator=(ColumnBlendCache&&) = default;
  const std::uint32_t* row(const std::uint16_t* codes, int index, const ColumnBlendPlan& plan);

 private:
  struct Entry {
    const std::uint16_t* codes = nullptr;
    int index = -1;
    std::vector<std::uint32_t> blended;
  };
  Entry entries_[2];
  int next_ = 0;
};

// The U results of one output line (L_t; alpha and L_{t-1}) and the line kernels' buffers, reused from line to line:
// one per pipeline (each band of a view has its own, so no two threads share one).
struct LineScratch {
  std::vector<Raw> first;
  std::vector<Raw> second;
  ColumnBlendCache first_rows;   // U's source rows of `first` (d_t for a full frame, i for a reduced one)
  ColumnBlendCache second_rows;  // and of `second` (d_{t-1})
  std::vector<Raw> shown;        // the line's emitted linear values
  std::vector<Raw> rho;          // a full frame's beta - shown
  std::vector<Raw> weight;       // a reduced frame's motion weight w per pixel
  std::vector<Raw> shortfall;    // an LCD full frame's unreachable drive shortfall (joins rho: on a 32-bit line, rho
                                 // plus the shortfall here, in 64 bits)
  std::vector<std::int32_t> zero_residual;  // the residual of a line the store holds all zero (DESIGN §7 skip)
  // Whether the last full line's stored residual has a sample that is not 0, where its store kernel said so.
  std::optional<bool> residual_nonzero;
  // The line kernels' lines in 32-bit words (FixedLinePlans::code_rom32, narrow_lines): a full line's L_t, shown and
  // rho, a reduced line's shown.
  std::vector<std::int32_t> first32;
  std::vector<std::int32_t> shown32;
  std::vector<std::int32_t> rho32;
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

// The state and plumbing shared by both schedules: configuration, ROMs, eye states and output.
class FixedDecoderCore {
 public:
  explicit FixedDecoderCore(FixedDecoderConfig config);

  FixedKernels& kernels() { return kernels_; }
  const FixedKernels& kernels() const { return kernels_; }
  const FixedDecoderConfig& config() const { return kernels_.config(); }
  const FixedStageCounts& last_counts() const { return last_counts_; }

  // Checks the frame and returns the eye state (reset on a change of view size).
  EyeState& begin(const LinkFrame& frame, const char* who);
  // The same for a view already checked (detail::check_view_header) that arrives line by line.
  EyeState& begin(const FrameMeta& meta);
  // The d_{t-1} a partial view's lost lines would repeat (detail::concealment_substitute), before begin.
  cv::Mat concealment_substitute(const FrameMeta& meta) const { return detail::concealment_substitute(eyes_, meta); }
  // Classifies a line mask (detail::classify_arrival) and, for a partial view, takes the substitute d_{t-1} from
  // this decoder's eyes (detail::concealment_substitute).
  detail::Arrival classify(const LinkFrame& frame, std::span<const std::uint8_t> line_intact,
                           detail::Concealment& out, const char* who);
  // A view that never arrived: this eye's previous output again (black if none); the residual is dropped.
  DecodedFrame decode_lost(const FrameMeta& meta, const char* who);
  // The output matrices at full size: planes of an earlier view of the eye that no caller holds any more, else new.
  // codes_checked: every code of the view has passed its range check before its first line (decode; a view pushed
  // line by line keeps the held output whole until it ends): the held output (read only for a lost view) then gives
  // its planes to this view where no caller keeps them, so that the eye holds one output plane, and is let go only
  // then (an internal failure after that leaves the eye no held output, and a lost view after it black).
  FrameOutput start_output(const FrameMeta& meta, EyeState& eye, bool codes_checked) const;
  // Writes one output channel sample from the wanted linear value x (uQ1.F); returns the LCD shortfall (else 0).
  Raw emit(FrameOutput& out, EyeState& eye, int y, int x, int ch, Raw wanted) const;
  // Prepares the LCD frame stores of the eye for this frame (first frame: held history).
  void begin_lcd(FrameOutput& out, EyeState& eye) const;
  // One full-frame output line (Eq. 2): U of the d_t rows low0/low1 (L_t, one pass over the line), then per pixel
  // I from the codes row, beta, shown (emitted), rho into residual_row. A lost (concealed) line takes beta = L.
  // grey: every channel has the same codes and d_t rows here (the chroma skip): channel 0 is computed, the others
  // take its values (counted as if computed). scratch: the line's U results (one per pipeline).
  void full_line(FrameOutput& out, EyeState& eye, const Geometry& g, int y, const std::uint16_t* codes_row,
                 const std::uint16_t* low0, const std::uint16_t* low1, std::int32_t* residual_row, bool lost,
                 bool grey, LineScratch& scratch) const;
  // One reduced-frame output line (Eqs. 1, 4-6): alpha from the received rows in0/in1; with a residual, L_prev from
  // the stored d_{t-1} rows prev0/prev1, w and alpha'. Without one (residual_row null), alpha alone.
  // With a gate (DESIGN §7 skips): motion_static takes L_{t-1} = alpha and w = 1 (prev0/prev1 are not read);
  // residual_zero reads no residual (residual_row may then be null) and adds nothing. grey: the received rows, the
  // d_{t-1} rows read and the residual line are grey (the chroma skip).
  void reduced_line(FrameOutput& out, EyeState& eye, const Geometry& g, int y, const std::uint16_t* in0,
                    const std::uint16_t* in1, const std::uint16_t* prev0, const std::uint16_t* prev1,
                    const std::int32_t* residual_row, const ReducedLineGate* gate, bool grey,
                    LineScratch& scratch) const;
  // The chroma skip (DESIGN §7) of the lines these functions decide, from the grey flags of the lines they read;
  // all false unless skipping.
  //   full-frame output line y: its input line and U's two d_t rows grey;
  bool full_line_grey(FrameOutput& out, bool codes_grey, bool low0_grey, bool low1_grey) const {
    const bool grey = skipping() && codes_grey && low0_grey && low1_grey;
    out.tally.counts.grey_lines += grey ? 1 : 0;
    return grey;
  }
  //   reduced-frame output line y: U's two received rows grey, and where a residual applies the d_{t-1} rows the
  //   motion test reads (none on a static line) and the residual line (none on a zero line);
  bool reduced_line_grey(FrameOutput& out, const EyeState& eye, const Geometry& g, int y, bool in0_grey,
                         bool in1_grey, bool residual_applies, const ReducedLineGate& gate) const {
    if (!skipping() || !in0_grey || !in1_grey) return false;
    bool grey = true;
    if (residual_applies) {
      const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
      const auto flag = [](const std::vector<std::uint8_t>& flags, int k) {
        return static_cast<std::size_t>(k) < flags.size() && flags[static_cast<std::size_t>(k)] != 0;
      };
      grey = (!gate.reads_previous() || (flag(eye.low_grey, row.i0) && flag(eye.low_grey, row.i1))) &&
             (gate.residual_zero || flag(eye.residual_grey, y));
    }
    out.tally.counts.grey_lines += grey ? 1 : 0;
    return grey;
  }
  //   row k of d_t: every input line of its vertical taps grey (flag(line) gives a line's flag); counted, and kept
  //   in the d_t store's flags when `store`.
  template <typename LineFlag>
  bool reduced_row_grey(FrameOutput& out, EyeState& eye, const Geometry& g, int k, bool store, LineFlag flag) const {
    if (!skipping()) return false;
    bool grey = true;
    for (int index : g.gauss_rows[static_cast<std::size_t>(k)].index) grey = grey && flag(index);
    out.tally.counts.grey_reduced_rows += grey && store ? 1 : 0;
    if (store) eye.low_grey[static_cast<std::size_t>(k)] = grey ? 1 : 0;
    return grey;
  }
  // DESIGN §7 skips (no-ops unless config().skip_unneeded):
  // before the first line of a full frame: clears the residual-nonzero line flags;
  void start_full_lines(EyeState& eye, const Geometry& g) const;
  // after full-frame output line y: flags the line of the residual store whose rho is not all zero (the write
  // gate), counting the lines not written;
  // (scratch.residual_nonzero, where full_line knows it, spares reading the line again)
  void end_full_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* residual_row,
                     const LineScratch& scratch) const;
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
    gate.weight_unused = gate.residual_zero && !gate.motion_static && !config().motion_weight_statistics &&
                         out.taps == nullptr;
    out.tally.unweighed_lines += gate.weight_unused ? 1 : 0;
    out.tally.counts.motion_test_lines_skipped += gate.reads_previous() ? 0 : 1;
    out.tally.counts.residual_read_lines_skipped += gate.residual_zero ? 1 : 0;
    return gate;
  }
  // Test vectors: marks the stages of this frame kind present in taps, sized and formatted, and attaches them.
  void start_taps(FrameOutput& out, FixedStageTaps& taps, const Geometry& g, bool full, bool residual) const;
  // Records one value of a stage plane (no-op without taps).
  static void tap(FrameOutput& out, Stage stage, int y, int x, int ch, Raw value) {
    if (out.taps == nullptr) return;
    FixedStagePlane& p = (*out.taps)[stage];
    p.values[(static_cast<std::size_t>(y) * static_cast<std::size_t>(p.size.width) + static_cast<std::size_t>(x)) *
                 static_cast<std::size_t>(p.channels) + static_cast<std::size_t>(ch)] = value;
  }
  // Fills FrameStats from the tally, remembers the counts and the eye's output.
  DecodedFrame finish(FrameOutput&& out, EyeState& eye, bool full, bool residual_applied);

 private:
  // The per-pixel steps of full_line and reduced_line, from the line's U results (low: L_t of the pixel; alpha and
  // previous_low: alpha and L_{t-1}, previous_low null where the motion test does not read it).
  // U and lin() of output line y from d rows row0 (g.bilinear_rows[y].i0) and row1 (.i1): through the line kernels
  // and the cache where the plans allow, else FixedKernels::upsample_line.
  void upsample(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y, Raw* out, bool grey,
                ColumnBlendCache& cache) const;
  // The same on a 32-bit line (narrow_lines).
  void upsample(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y, std::int32_t* out,
                ColumnBlendCache& cache) const;
  // The line kernels keep a line in 32-bit words (FixedLinePlans::code_rom32): an OLED's where the drive search has
  // its 32-bit tables, an LCD's where its drive kernel runs.
  bool narrow_lines(const FrameOutput& out) const {
    const FixedLinePlans& plans = kernels_.line_plans();
    if (!line_values(out) || plans.code_rom32.empty()) return false;
    return plans.drive ? !plans.drive->base32.empty() : plans.lcd.has_value();
  }
  // A line's codes may come without its shown values (U's nodes' codes, FixedLinePlans::drive_of_node): where no
  // report plane wants those values.
  bool codes_alone() const { return !config().decoder.report_planes; }
  // The drive codes of output line y from its shown values on a 32-bit line (narrow_lines): the OLED drive kernel,
  // or the LCD's, whose shortfall (where not null) a full frame adds to rho.
  void emit_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* shown, Raw* shortfall) const;
  // The line kernels take a whole line, the OLED drive included (the report planes then from the line's shown values
  // and codes, report_line): no taps (the stage records are the per-sample path's).
  bool line_kernels(const FrameOutput& out) const { return line_values(out) && kernels_.line_plans().drive; }
  // A reduced-frame line's shown values over the whole line, emitted afterwards (emit_line): any panel.
  bool line_values(const FrameOutput& out) const { return kernels_.line_plans().eotf && out.taps == nullptr; }
  // The report planes of output line y (wanted linear, drive value, emitted light) from its shown values and the
  // drive codes the OLED drive kernel wrote: the samples emit gives them.
  template <typename Linear>
  void report_line(FrameOutput& out, int y, const Linear* shown) const;
  // Output line y through the LCD drive kernel (its codes, frame stores and shortfall where not null), and with
  // report planes their samples as emit gives them, from the stores' v_{t-1} and x_{t-1} before the kernel.
  template <typename Linear>
  void drive_lcd_line(FrameOutput& out, EyeState& eye, int y, const Linear* shown, Raw* shortfall) const;
  // The drive codes of output line y by the OLED or the LCD drive kernel, with the report planes where wanted; false
  // where neither kernel runs.
  template <typename Linear>
  bool drive_line(FrameOutput& out, EyeState& eye, int y, const Linear* shown, Raw* shortfall) const;
  // The drive codes of a line's shown values: the OLED drive kernel, the LCD drive kernel, else emit per sample in
  // raster order (the LCD's frame stores). shortfall, where not null, receives each sample's LCD shortfall (0 on an
  // OLED), which a full frame adds to rho (Sec. 4.4).
  void emit_line(FrameOutput& out, EyeState& eye, int y, const Raw* shown, Raw* shortfall) const;
  void full_pixel(FrameOutput& out, EyeState& eye, int y, int x, const std::uint16_t* codes_row, const Raw* low,
                  std::int32_t* residual_row, bool lost, bool grey) const;
  // shown: null emits each sample; else the samples' wanted values are stored at shown[3x + ch] for the line's
  // drive codes.
  void reduced_pixel(FrameOutput& out, EyeState& eye, int y, int x, const Raw* alpha, const Raw* previous_low,
                     const std::int32_t* residual_row, const ReducedLineGate* gate, bool grey, Raw* shown) const;

  FixedKernels kernels_;
  std::map<int, EyeState> eyes_;
  FixedStageCounts last_counts_;
};

}  // namespace trm::fixed_detail
