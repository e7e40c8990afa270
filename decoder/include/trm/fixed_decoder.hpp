// The fixed-point TRM decoder (DESIGN §4-5): the reference algorithm with integer arithmetic only, in two
// schedules of the same per-pixel arithmetic:
//   FixedFrameDecoder      frame at a time, stage by stage over whole frames (easy to read);
//   FixedStreamingDecoder  raster order, one input line in and output lines out through explicit circular line
//                          buffers and frame stores (the hardware model).
// Both produce identical bits. Every stage has an explicit Q format, listed in FixedDecoderConfig.
//
// Notation: uQi.f is unsigned with i integer and f fraction bits, sQi.f signed (i includes the sign bit).
// "codes" are link code units (0 .. 2^b - 1); linear light is normalised to [0, 1].
//
// Panels: OLED (per-channel gamma) and LCD (the Eq. 7 temporal merge), the latter for merge coefficients that make
// M(v_t, v_{t-1}) increasing in v_t on [0, 1] (the defaults do; others are rejected).
#pragma once

#include "trm/fixed_runtime.hpp"
#include "trm/frame.hpp"
#include "trm/decoder.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace trm {

inline constexpr int kMaxDecoderThreads = 64;

struct FixedDecoderConfig {
  // The algorithm parameters shared with ReferenceDecoder: link (r, sigma, transfer, bits, resample space), motion
  // sensitivity s, panel, output_bits (8 or 10), lcd_history. record_stages is ignored (no DecodeStages are filled;
  // FixedFrameDecoder::decode(frame, taps) records the integer stages instead).
  DecoderConfig decoder;

  // Why the defaults below are wider than natural content needs (docs/sweeps.md: F = 18..22, U weights 4 bits, an
  // 18-bit residual store meet >= 99.9 % identical on discs): the motion test amplifies the error of L_{t-1} and
  // alpha. alpha' = alpha + w rho with w = exp(-s c), c = |Yp - Ya| / (Yp + Ya), so an error e in Yp moves alpha' by
  // about s w |rho| e / (Yp + Ya), and the drive code by that times the panel's slope (x^(1/gamma) (2^o - 1) is
  // steep in the dark): 8,000 drive codes per unit of e for a counter-phase checkerboard at r = 0.4. A periodic
  // pattern repeats any pixel that lands near a drive rounding boundary in every period, so its share of differing
  // codes is set by the worst pixel, not the average. Over 150 checkerboard sequences inverting every frame
  // (FixedExtremes.CounterPhaseBoardsAcrossReductions) the former defaults (F = 24, U weights 16 bits, U output 14
  // bits, 8 EOTF segments per code, exp address 20 bits, rho sQ2.24) left 7 below 99.9 % identical (worst 99.65 %;
  // 14 at 10-bit output); the ones below leave none, with vive and rift panels, 8- and 10-bit output. The cost is
  // in `trm hw-report` and the README ("Why the defaults are wider").
  //
  // Linear light I, L, alpha, shown beta, alpha': uQ1.F (the integer bit holds 1.0 exactly). beta = 2I - L is
  // sQ3.F. F = 24 resolves the darkest OLED drive thresholds ((0.5/255)^2.29 = 6.5e-7 = 11 LSB); F = 16 cannot
  // tell drive codes 0, 1 and 2 apart (rejected).
  int linear_frac_bits = 28;

  // D (polyphase Gaussian): taps uQ0.F, per reduced sample summing exactly to 2^F (largest remainder, mirror
  // symmetric where the taps are). d_t must reproduce the encoder's reduced frame code for code (a differing code
  // reads as motion, Eq. 5). Q_b rounds to the nearest code with exact half-code ties up, as the encoder's
  // quantise_reduced does (it counts a double D within 1e-9 code of a half as the half, so the encoder's rounding
  // noise cannot break a tie either way); mirror-symmetric taps and the half-to-even line buffer keep the ties of
  // symmetric content (Nyquist checkerboards, two codes averaged) exact here, so both round them up. Measured against the reference over every scene and noise at r in {1, .75, .5, .4, .25}:
  // Q0.14: 0.064 % of output codes differ, up to 28 LSB; Q0.16: 0.015 %, 7 LSB; Q0.20: 0.004 %, 3 LSB;
  // Q0.24: 0.0015 %, 1 LSB.
  int gaussian_tap_frac_bits = 24;
  // The horizontal D result as the vertical line buffer holds it: codes uQb.F, rounded half to even (RndConv: two
  // rows that sum to an integer still do after rounding, so an exact tie of the vertical sum stays exact).
  int gaussian_line_frac_bits = 16;

  // D in the linear resample space (link.resample_space == ResampleSpace::Linear, the encoder's Q_b(enc(D(lin(E))))):
  // lin(E) from a direct ROM per link code in uQ1.P (P = linear_resample_frac_bits), taps uQ0.T (T =
  // linear_gaussian_tap_frac_bits, summing exactly to 2^T as above), the horizontal result in the line buffer and the
  // vertical result in uQ1.P (rounded half up). d_t is re-encoded to link codes by a threshold ROM (2^b words of
  // uQ1.P; T_k is the smallest grid value the encoder's floor(enc(x) (2^b - 1) + 1/2) quantises to k or above) and a
  // b-step binary search: exactly the encoder's quantiser for every value on the grid, so d_t differs from the
  // encoder's reduced frame only where D's rounding puts the value on the other side of a threshold. The thresholds
  // follow quantise_reduced (ties, and values within its tolerance of a half code, round up).
  // Wider than the encoded space's D formats: in linear light the code steps near black are narrow (gamma 2.2 at 10
  // bits: 2^-21 between the first thresholds), and a d_t code that differs from the encoder's reads as motion in
  // Eq. 5. d_t codes differing from the encoder's, over every scene and noise at r in {1, .75, .5, .4, .25}, sRGB and
  // gamma 2.2 (1,125,720 codes): 8-bit link, P = T = 24: 7 (output still within 1 LSB), P >= 28: 0; 10-bit link,
  // P = T = 24: 47 (outputs up to 3 LSB off), P = 28, T = 24: 2 (2 LSB), P = 30, T = 26 and P = 32, T = 28: 0 (1 LSB).
  // The headturn scene, added since, has one code 0.21 grid LSB above its threshold at P = 32, T = 28 (48x32, r = 1/4,
  // 8 bits), which these defaults put one code low; P = 34 resolves it (tests/decoder/fixed_linear_space_test.cpp).
  // The defaults keep two bits of margin over the narrowest that measured exact. P + T <= 62.
  int linear_resample_frac_bits = 32;
  int linear_gaussian_tap_frac_bits = 28;

  // U (bilinear): weights uQ0.F (weight of the lower tap = 2^F - weight of the upper). In the linear resample space U
  // blends lin(d) from the I = lin(E) ROM (uQ1.linear_frac_bits) and its result is linear light uQ1.linear_frac_bits
  // (rounded half up; no EOTF LUT). The weights of r = 0.4, 0.6, ... are not dyadic: their rounding times a step of
  // 255 codes between neighbours is U's largest error on sharp content (2^-17 x 255 = 0.002 code at 16 bits).
  int bilinear_weight_frac_bits = 24;
  // U output in code units, uQb.U, rounded (Rnd). Encoded space only. Its top b + k bits address the EOTF ROM (k =
  // eotf_segments_per_code_log2) and the other U - k bits are the interpolation weight, so U is not bound by the
  // ROM's address width: U in [k, 32] (above 2 bilinear_weight_frac_bits the exact blend is only padded). (The motion test amplifies U's rounding:
  // see linear_frac_bits. At U = 16 the rounding alone moves a bright alpha by up to 5e-8.)
  int upsample_frac_bits = 32;
  // EOTF LUT after U (encoded space only): uniform segments aligned to link codes, 2^k segments per code step:
  // (2^b - 1) 2^k + 1 ROM words of uQ1.linear_frac_bits (4081 words at 8 bits), y = rom[i] + round((rom[i+1] -
  // rom[i]) w) with w the low U - k bits of U's output. Interpolation error ~h^2/8 |f''|
  // (h = 1/(2^k (2^b - 1))): 4 segments per code leave ~2e-7 (0.09 % of drive codes differed on the line scene at
  // F = 24), 16 leave ~1.4e-8.
  int eotf_segments_per_code_log2 = 4;

  // The residual frame store rho: signed, saturating, default sQ2.28 (lossless for rho in [-1, 1] at F = 28). A
  // narrower store rounds rho, and alpha' = alpha + rho no longer cancels exactly where alpha = L_{t-1} and I = 0:
  // sQ2.24 left 2.6e-8 there, above the first 10-bit drive threshold (14 of 150 counter-phase boards below 99.9 %
  // at 10-bit output). `--residual-bits N` / docs/sweeps.md: what a narrower store costs on natural content.
  fx::RuntimeFormat residual{2, 28, true, fx::Quant::Rnd, fx::Overflow::Sat};

  // Eq. 5 motion contrast: Rec. 709 luma weights uQ0.F summing exactly to 2^F; 1/(Y_prev + Y_alpha) through a
  // normalised reciprocal LUT (mantissa in [1, 2), 24 address bits, `reciprocal_entries` ROM words, uQ2.24).
  int luma_weight_frac_bits = 24;
  int reciprocal_entries = 1025;

  // Eq. 6 w = exp(-s c): s as uQ8.F (s <= 255, or +inf); x = s c as uQ5.exp_input_frac_bits, split into an integer
  // part (a 16-word ROM exp(-i), x >= 16 gives w = 0) and a fraction (an interpolated LUT of exp(-f) on [0, 1)
  // with `exp_entries` words); w = exp(-i) exp(-f) in uQ1.linear_frac_bits.
  int sensitivity_frac_bits = 16;
  int exp_input_frac_bits = 24;
  int exp_entries = 2049;

  // OLED drive: codes from a per-channel threshold ROM (2^output_bits words of uQ1.linear_frac_bits,
  // T_k = ((k - 1/2)/(2^o - 1))^gamma rounded up to the linear grid) searched by binary comparison: the largest k
  // with x >= T_k. That is exactly floor(x^(1/gamma) (2^o - 1) + 1/2) for every x on the grid.
  // The drive value v itself (DecodedFrame::drive, for reports only) comes from an octave-segmented x^(1/gamma)
  // LUT with `drive_segments_per_octave` segments per octave, uQ1.drive_frac_bits.
  int drive_frac_bits = 16;
  int drive_segments_per_octave = 32;

  // LCD (Eq. 7 inverse): p1..p4 as sQ7.linear_frac_bits (|p| <= 16); the target m = ((x_t + x_{t-1})/2)^(1/gamma) from an
  // octave-segmented LUT with `lcd_segments_per_octave` segments per octave (uQ1.linear_frac_bits; relative error
  // ~(1/S)^2/8 |f''| x^2/f: 512 keeps it near 1e-7); the code is the largest k whose threshold merge
  // M((k - 1/2)/(2^o - 1), v_{t-1}) <= m, compared exactly in integers (binary search). Unreachable targets clamp to
  // code 0 or 2^o - 1 and, for full frames, the linear shortfall (from 2 x 2^o-word ROMs of M(0|1, v_{t-1})^gamma)
  // joins rho.
  int lcd_segments_per_octave = 512;

  // DESIGN §7, "leave out what a scene does not need", gated as hardware would; the output is bit-identical either
  // way (false runs the full path everywhere):
  //   * static lines skip the motion test: a line comparator checks each reduced input line against the stored
  //     d_{t-1} row as it streams in (exact ties resolved as the motion test resolves them); an output line whose U
  //     source rows (both, or the upper one alone where the lower has bilinear weight 0) all matched has
  //     L_{t-1} = alpha exactly, hence c = 0 and w = 1: U of d_{t-1}, luma, reciprocal and exp are not evaluated and
  //     the d_{t-1} rows are not read (except for the exact-tie correction, where a tie made a stored code differ);
  //   * lines without clipping skip residual traffic: a full frame flags each output line whose stored rho is all
  //     zero (one bit per line); such a line is not written to the residual store, and the next reduced frame
  //     neither reads nor adds it (alpha' = clamp(alpha)). The motion test still runs there, as its w feeds the
  //     frame's mean motion weight and underflow count, unless motion_weight_statistics is false;
  //   * OLED has no LCD stores (v_{t-1}, x_{t-1}) in any case.
  //   * grey lines compute one channel: a line whose every pixel has R = G = B in every line it is computed from
  //     (the input line, its D taps, U's source rows, the residual line) gives the same linear light in each
  //     channel, so D, U, the EOTF, Eq. 2, the residual store and Eq. 4 run on the first channel and the result is
  //     copied (one grey flag per held line beside each line buffer and frame store); the panel drive still runs
  //     per channel (each has its own threshold ROM, and the LCD its own v_{t-1}, x_{t-1}).
  bool skip_unneeded = true;

  // Execution settings: how the model runs, not what it computes (the codes and statistics are the same bits for
  // every value; they are not part of fixed_decoder_json).
  // The frame's mean motion weight and weight-underflow count over every pixel of a reduced frame. Where a pixel's
  // residual is zero w weighs nothing (alpha' = clamp(alpha)), and the motion test runs there only for these
  // statistics. false skips it there, with U of d_{t-1} and its reads, as a controller without these counters
  // would: on a line whose residual is all zero (the residual skip above; counted in motion_test_lines_skipped),
  // and on a line with a residual outside the runs of kMotionRunPixels pixels (fixed_core.hpp) that hold a
  // residual sample that is not 0. The codes are the same bits; the frame's mean_motion_weight is then NaN (not
  // measured) where a line skipped any pixel, weight_underflow counts the pixels whose motion test ran, and
  // grey_lines may count more lines (a skipped line's chroma skip no longer depends on the d_{t-1} rows it does not
  // read). No effect with skip_unneeded false or with stage taps (test vectors record w everywhere).
  // What a rig feed or a throughput run needs.
  bool motion_weight_statistics = true;
  // FixedStreamingDecoder::decode of a whole view: bands of output lines on this many threads, each band with its
  // own line buffers (two pipelines side by side, as a wider controller would run them). Views pushed line by line
  // and views with lost lines run on one. In [1, kMaxDecoderThreads].
  int threads = 1;
  // The streaming and frame schedules' hot steps over whole lines in SIMD lanes (U with each d row blended along x
  // once, the EOTF, Eq. 2, the OLED drive code search), where the formats fit the lanes (8-bit link sums, see
  // fixed_lines.hpp); false runs the per-sample stage functions everywhere, the path the line kernels are held to.
  bool line_kernels = true;

  // Throws std::invalid_argument naming the stage whose format or table is unusable.
  void validate() const;
};

// Per-stage event counters of the last decoded frame (channel samples).
struct FixedStageCounts {
  std::uint64_t beta_clipped = 0;        // Eq. 2: beta outside [0, 1] (full frames)
  std::uint64_t residual_saturated = 0;  // rho outside the residual store's range (saturated)
  std::uint64_t residual_rounded = 0;    // rho not representable exactly in the residual store (rounded)
  std::uint64_t alpha_clipped = 0;       // Eq. 4: alpha + w rho outside [0, 1] (reduced frames)
  std::uint64_t weight_underflow = 0;    // Eq. 6: pixels with s c >= 16, w forced to 0 (where the test ran)
  std::uint64_t lcd_unreachable = 0;     // LCD: M(v, v_{t-1}) = m had no root in [0, 1]
  // Skip events (FixedDecoderConfig::skip_unneeded; all 0 when it is false), in output lines of the frame:
  std::uint64_t motion_test_lines_skipped = 0;    // reduced: lines whose motion test was skipped (static, w = 1;
                                                  // or no residual, without motion_weight_statistics)
  std::uint64_t residual_read_lines_skipped = 0;  // reduced: lines with no residual to read or add
  std::uint64_t residual_write_lines_skipped = 0; // full: lines whose rho is all zero (not written to the store)
  std::uint64_t grey_lines = 0;                   // output lines whose linear pipeline ran on one channel
  std::uint64_t grey_reduced_rows = 0;            // full: rows of d_t (both D passes) computed on one channel

  // Totals over frames.
  FixedStageCounts& operator+=(const FixedStageCounts& c) {
    beta_clipped += c.beta_clipped;
    residual_saturated += c.residual_saturated;
    residual_rounded += c.residual_rounded;
    alpha_clipped += c.alpha_clipped;
    weight_underflow += c.weight_underflow;
    lcd_unreachable += c.lcd_unreachable;
    motion_test_lines_skipped += c.motion_test_lines_skipped;
    residual_read_lines_skipped += c.residual_read_lines_skipped;
    residual_write_lines_skipped += c.residual_write_lines_skipped;
    grey_lines += c.grey_lines;
    grey_reduced_rows += c.grey_reduced_rows;
    return *this;
  }
};

// One line buffer or frame store of the streaming model.
struct FixedBufferReport {
  std::string name;
  int lines = 0;       // lines (line buffer) or rows (frame store)
  int samples = 0;     // samples per line (channel samples)
  int bits = 0;        // bits per sample
  std::int64_t total_bits() const { return static_cast<std::int64_t>(lines) * samples * bits; }
};

// One ROM of the decoder (a lookup table or a direct table), `count` identical-shape copies (e.g. per channel).
struct FixedRomReport {
  std::string name;
  int entries = 0;
  int word_bits = 0;
  int count = 1;
  std::int64_t total_bits() const { return static_cast<std::int64_t>(count) * entries * word_bits; }
};

// Arithmetic of one stage, as the shared kernels (decoder/src/fixed_stages.cpp) perform it: operators per
// evaluation, and evaluations per frame of the given kind. Comparators include clamps and binary-search steps;
// rounding additions (of the half LSB before a shift) are counted as adders.
struct FixedArithmeticReport {
  std::string stage;
  std::string frame;          // "full", "reduced" or "both"
  std::string evaluated_per;  // what one evaluation covers, e.g. "channel sample", "pixel"
  std::int64_t evaluations = 0;  // per frame of that kind, at the reported size
  int adders = 0;
  int multipliers = 0;
  int comparators = 0;
  int rom_reads = 0;
};

struct FixedStreamingReport {
  int full_latency_lines = 0;     // full frame: input lines received before output line y is produced, minus y
  int reduced_latency_lines = 0;  // reduced frame: same in reduced input lines (output y needs reduced row i1(y))
  cv::Size full;                  // the view size reported on
  cv::Size reduced;
  std::vector<FixedBufferReport> buffers;  // names start with "line:" (on chip) or "frame:" (off chip)
  std::vector<FixedRomReport> roms;
  std::vector<FixedArithmeticReport> arithmetic;
  // Frame stores against the paper's (Sec. 9: "one [buffer] for storing the previous frame and another one for the
  // residual"): a full-size previous frame in link codes plus the full-size residual, at this configuration's
  // formats; and this model's residual plus the reduced-size d_t (the LCD stores, needed by both, left out).
  std::int64_t paper_frame_store_bits = 0;
  std::int64_t model_frame_store_bits = 0;
  // How lost lines and lost views are concealed in raster order, what that costs beyond the buffers above (the
  // held-output store, listed with them) and its effect on latency.
  std::string concealment;
};

// The off-chip traffic the DESIGN §7 skips avoided (bits), from the skip counters of the views decoded and the
// widths of the frame stores FixedStreamingReport lists (the one home of that arithmetic):
// * residual write: a full-frame line whose rho is all zero is not written, 3 W samples of the residual format;
// * residual read: a reduced-frame line with no residual is not read, the same;
// * d_{t-1} read: a static line (motion test skipped) does not read the two d_{t-1} rows U blends for L_{t-1},
//   2 × 3 w link codes (the model keeps no line buffer of d_{t-1}; the comparator's one read per row as it enters
//   the U buffer is made either way);
// * LCD stores (OLED): per sample of every view an LCD reads v_{t-1} (output bits) and reads and writes x_{t-1}
//   (sQ3.F); its v_t write is the OLED's held-output store's too, which the OLED keeps.
// The chroma skip (grey lines) saves arithmetic, not traffic: a grey line's copied channels are written whole to the
// line buffers and stores, so it has no entry here (its saving is the benchmark's time, README "Performance").
struct FixedSkipTraffic {
  std::int64_t residual_write_bits = 0;
  std::int64_t residual_read_bits = 0;
  std::int64_t previous_low_read_bits = 0;
  std::int64_t lcd_store_bits = 0;
  std::int64_t total_bits() const {
    return residual_write_bits + residual_read_bits + previous_low_read_bits + lcd_store_bits;
  }
};
// `counts` summed over `views` decoded views of size `full` (w = reduced_size(W, r) of config.decoder.link). Throws
// std::invalid_argument naming `full` (below 1x1) or `views` (< 0).
FixedSkipTraffic skip_traffic_saved(const FixedDecoderConfig& config, cv::Size full, const FixedStageCounts& counts,
                                    std::int64_t views);

// The integer planes of every stage of one decoded frame, for test vectors (FixedFrameDecoder::decode with taps),
// by Stage (the stages up to Drive; the LCD and unclamped-alpha stages are not tapped). Values are the raw integers
// of the stage's format, row-major with channels interleaved (R G B) where channels == 3; motion contrast and weight
// are one value per pixel.
struct FixedStagePlane {
  bool present = false;
  std::string name;      // stage_name() of its stage, e.g. "beta"
  std::string format;    // e.g. "sQ3.24"
  int bits = 0;          // word width including the sign bit
  bool is_signed = false;
  cv::Size size;
  int channels = 3;
  std::vector<std::int64_t> values;
};

struct FixedStageTaps {
  std::array<FixedStagePlane, kStageCount> planes;
  FixedStagePlane& operator[](Stage s) { return planes[static_cast<std::size_t>(s)]; }
  const FixedStagePlane& operator[](Stage s) const { return planes[static_cast<std::size_t>(s)]; }
};

namespace fixed_detail {
class FixedDecoderCore;
class StreamingView;
}
namespace detail {
struct Concealment;
}

// Frame-at-a-time schedule.
class FixedFrameDecoder : public HeadsetDecoder {
 public:
  explicit FixedFrameDecoder(FixedDecoderConfig config);  // validates; throws std::invalid_argument
  ~FixedFrameDecoder() override;
  FixedFrameDecoder(FixedFrameDecoder&&) noexcept;
  FixedFrameDecoder& operator=(FixedFrameDecoder&&) noexcept;
  const char* name() const override { return "fixed-frame"; }
  const FixedStageCounts* stage_counts() const override { return &last_counts(); }

  const FixedDecoderConfig& config() const;
  // As ReferenceDecoder::decode: one view, per-eye state; the doubles are the fixed values converted exactly.
  DecodedFrame decode(const LinkFrame& frame) override;
  // The same, also filling taps with every stage's integer plane of this frame (the others are not present).
  DecodedFrame decode(const LinkFrame& frame, FixedStageTaps& taps);
  // As ReferenceDecoder::decode(frame, line_intact): a view received over a faulty link, line_intact holding one
  // entry per line of frame.codes (0 = lost; empty = none lost), concealed by the reference's rules.
  DecodedFrame decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override;
  // As ReferenceDecoder::decode_lost: the panel holds this eye's previous output (black if none), the residual is
  // dropped.
  DecodedFrame decode_lost(const FrameMeta& meta) override;
  const FixedStageCounts& last_counts() const;

 private:
  std::unique_ptr<fixed_detail::FixedDecoderCore> core_;
  DecodedFrame decode_impl(const LinkFrame& frame, FixedStageTaps* taps, const detail::Concealment* lost);
};

// Line-buffered raster schedule (the hardware model); bit-identical to FixedFrameDecoder.
//
// Incremental, as the hardware sees a view: begin_view, push_line once per input line in raster order (each push
// produces the output rows the schedule has ready then, in raster order), end_view. decode() is that sequence over a
// whole frame.
class FixedStreamingDecoder : public HeadsetDecoder {
 public:
  explicit FixedStreamingDecoder(FixedDecoderConfig config);
  ~FixedStreamingDecoder() override;
  FixedStreamingDecoder(FixedStreamingDecoder&&) noexcept;
  FixedStreamingDecoder& operator=(FixedStreamingDecoder&&) noexcept;
  const char* name() const override { return "fixed"; }
  const FixedStageCounts* stage_counts() const override { return &last_counts(); }
  bool hardware_report(cv::Size full, FixedStreamingReport& out) const override {
    out = report(full);
    return true;
  }

  const FixedDecoderConfig& config() const;
  DecodedFrame decode(const LinkFrame& frame) override;
  // Concealment as FixedFrameDecoder (bit-identical), with every lost line replaced as it arrives, in raster order
  // (see FixedStreamingReport::concealment).
  DecodedFrame decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override;
  DecodedFrame decode_lost(const FrameMeta& meta) override;
  const FixedStageCounts& last_counts() const;
  // Latency, line buffers / frame stores, ROMs and arithmetic per stage for a view of the given full size.
  FixedStreamingReport report(cv::Size full) const;
  // The threads (bands of output lines) decode() runs a whole view of this full size on: config().threads, fewer
  // for a view too short to share.
  int threads_for(cv::Size full) const;

  // Opens a view as the link announces it (meta.width x meta.height: the size sent). Throws std::invalid_argument
  // for a view the decoder cannot take (the checks of decode), std::logic_error while another view is open.
  void begin_view(const FrameMeta& meta);
  // The next input line of the open view: 3 * meta.width link codes, or a line lost on the link (intact false: codes
  // are not read; concealed as decode(frame, line_intact) conceals it). Returns rows_ready(). Throws
  // std::invalid_argument for a wrong length or a code beyond the link range and std::logic_error without an open
  // view or after its last line; nothing is taken then.
  int push_line(std::span<const std::uint16_t> codes, bool intact = true);
  // Output rows of the open view that are final: rows 0 .. rows_ready() - 1. Lost lines above a view's first intact
  // line hold its rows back until that line arrives; a view with no intact line has its rows at end_view.
  int rows_ready() const;
  // The drive codes (3 * full width, R G B) of ready row y of the open view.
  std::span<const std::uint16_t> drive_row(int y) const;
  bool view_open() const;
  int lines_pushed() const;
  // Ends the open view once every line is pushed: what decode() returns for it (frame stores and counters final).
  // Throws std::logic_error without an open view or with lines missing.
  DecodedFrame end_view();

 private:
  std::unique_ptr<fixed_detail::FixedDecoderCore> core_;
  std::unique_ptr<fixed_detail::StreamingView> view_;
  // The lines of a frame already checked whole (check_link_frame), through the incremental path.
  DecodedFrame decode_checked(const LinkFrame& frame, std::span<const std::uint8_t> line_intact);
  // A whole view already begun, in bands of output lines on FixedDecoderConfig::threads threads.
  DecodedFrame decode_in_bands(const LinkFrame& frame);
  void take_line(const std::uint16_t* codes, bool intact);
};

}  // namespace trm
