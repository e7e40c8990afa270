// The headset-side decoder interface and the vocabulary every decoder shares (DESIGN §4-5): its configuration, what
// it returns per view, and a factory by name. The double-precision reference (trm/reference_decoder.hpp) and the two
// fixed-point schedules (trm/fixed_decoder.hpp) implement it; the pipeline, capture replay, the rig feeder and the
// sweep use only this interface.
#pragma once

#include "trm/encoder.hpp"
#include "trm/frame.hpp"
#include "trm/panel.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm {

// Which x_{t-1} the LCD inverse builds frame t's pair target on (DESIGN §4).
enum class LcdHistory {
  Wanted,       // the linear value the decoder wanted in frame t-1 (the design's rule; default)
  Contributed,  // what frame t-1 actually contributed: x_{t-1} where reachable, else 2 M^gamma - x_{t-2}.
                // Avoids counting an unreachable full frame's shortfall twice (it is already in rho).
};

// The largest finite motion sensitivity any decoder accepts: the hardware's s register is uQ8.f (and w = exp(-s c)
// is below 2^-300 at 1 % contrast already at s = 255, so nothing larger means anything but +inf).
inline constexpr double kMaxFiniteSensitivity = 255.0;

struct DecoderConfig {
  EncoderConfig link;          // r, sigma, transfer, bits, resample space: must match the encoder
  double sensitivity = 10.0;   // s in w = exp(-s c) (Eq. 6); 0 <= s <= kMaxFiniteSensitivity or +inf (residual only
                               // where c = 0)
  Panel panel;                 // OLED or LCD inverse
  int output_bits = 8;         // drive code depth, 8 or 10
  bool record_stages = false;  // fill DecodedFrame::stages (per-stage vectors for golden tests)
  LcdHistory lcd_history = LcdHistory::Wanted;
  // The report planes of DecodedFrame (wanted_linear, drive, emitted_linear: three full-size CV_64FC3 planes, 3 x
  // 59 MiB at 2160x1200) besides the drive codes, the hardware's output. false leaves them empty: what a testbench,
  // a rig feed, a comparison of codes or a throughput run needs; the fixed-point LCD's report drive value (a division
  // per sample) and the reference's emitted light are then not computed, and the display methods that show plain
  // frames return their codes alone. Like record_stages, a run-time choice: the codes and statistics are the same
  // either way.
  bool report_planes = true;

  void validate() const;       // throws std::invalid_argument with a clear message
};

struct FrameStats {
  double clipped_fraction = 0.0;       // full frame: fraction of channel samples with beta outside [0, 1];
                                       // reduced frame: fraction with alpha + w rho outside [0, 1]
  double residual_mean_abs = 0.0;      // |rho| after this frame (full frames) / of the rho consumed (reduced)
  double residual_max_abs = 0.0;
  double dropped_sum = 0.0;            // reduced frame: sum over samples of what alpha' clipping dropped
  double mean_motion_weight = 1.0;     // reduced frame: mean w (NaN: not measured, see motion_weight_statistics)
  bool residual_applied = false;       // reduced frame: a residual from a preceding full frame was used
  double lcd_unreachable_fraction = 0.0;
  int concealed_lines = 0;             // lines of the received view that were lost and concealed
  bool frame_lost = false;             // nothing of this view arrived: the previous output was held
};

// The stages of one decoded view in DESIGN §4 notation: the one vocabulary of every decoder's stage record (the
// reference's DecodeStages in double precision, the fixed-point decoders' integer FixedStageTaps). Which stages a
// record holds depends on the frame kind and the panel; each stage means the same thing in both.
enum class Stage {
  Codes,              // received link codes (full size for full frames, reduced size for reduced frames)
  Linear,             // full: I = lin(E_t)
  Reduced,            // full: d_t = Q_b(D(E_t)) as the frame store holds it, link codes (exact ties rounded up;
                      // linear space: Q_b(enc(D(lin(E_t)))))
  LowPass,            // full: L = lin(U(d_t)) (linear space: U(lin(d_t)))
  Beta,               // full: beta = 2 I - L before clamping (Eq. 2)
  Shown,              // full: clamp(beta, 0, 1)
  Residual,           // full: rho after this frame, LCD shortfall included (fixed point: in the residual store
                      // format); reduced: the rho consumed
  Alpha,              // reduced: alpha = lin(U(i)) (Eq. 1)
  PreviousLowPass,    // reduced with residual: L_{t-1} = lin(U(d_{t-1})) for the motion test
  Contrast,           // reduced with residual: motion contrast c (Eq. 5), one value per pixel
  Weight,             // reduced with residual: w = exp(-s c) (Eq. 6), one value per pixel
  AlphaPrime,         // reduced: alpha' = clamp(alpha + w rho, 0, 1) (Eq. 4; clamp(alpha) without a residual)
  Drive,              // drive codes (output_bits)
  AlphaUnclamped,     // reduced with residual: alpha + w rho before clamping
  LcdTarget,          // LCD: the pair target m = ((x_t + x_{t-1}) / 2)^(1/gamma)
  LcdPreviousDrive,   // LCD: v_{t-1} the merge was solved against (the quantised drive, as a value)
  LcdPreviousLinear,  // LCD: x_{t-1} the target was built on (see LcdHistory)
  LcdUnreachable,     // LCD: 255 where M(v, v_{t-1}) = m had no root in [0, 1] (CV_8UC3)
};
inline constexpr int kStageCount = 18;

// The short, file-friendly name of a stage (test vector files, reports): "codes", "I", "d", "L", "beta", ...
const char* stage_name(Stage stage);

// Per-stage intermediates of one decoded frame in double precision, by Stage. Matrices that do not apply to the
// frame (or to the panel) are left empty. Full-size values are CV_64FC3 unless noted above; codes CV_16UC3.
struct DecodeStages {
  std::array<cv::Mat, kStageCount> planes;
  cv::Mat& at(Stage stage) { return planes[static_cast<std::size_t>(stage)]; }
  const cv::Mat& at(Stage stage) const { return planes[static_cast<std::size_t>(stage)]; }
};

struct DecodedFrame {
  FrameMeta meta;          // as received, except width/height: the full size of the decoded view
  cv::Mat wanted_linear;   // full: clamp(beta); reduced: alpha' (CV_64FC3, full size)
  cv::Mat drive;           // panel drive v in [0, 1] before output quantisation (CV_64FC3)
  cv::Mat drive_codes;     // floor(v (2^output_bits - 1) + 0.5) (CV_16UC3)
  cv::Mat emitted_linear;  // linear light the panel emits in this frame from the quantised drive;
                           // LCD: the merged value of (v_t, v_{t-1}) raised to gamma, which is already the
                           // time average of frames t-1 and t (so perceived_pair() applies to OLED only)
  FrameStats stats;
  std::optional<DecodeStages> stages;  // when DecoderConfig::record_stages
};

// What any decoder shows for a view that never arrived (DESIGN §4): `last`, this eye's previous output at the same
// view size, again; or black when there is none (null), its report planes only where they are wanted
// (DecoderConfig::report_planes). Marked lost, every line counted as concealed.
DecodedFrame lost_view_output(const FrameMeta& meta, const DecodedFrame* last, bool report_planes = true);

struct FixedDecoderConfig;
struct FixedStageCounts;
struct FixedStreamingReport;

// One headset-side decoder: per-eye state across views, one view in, the panel drive out.
class HeadsetDecoder {
 public:
  virtual ~HeadsetDecoder() = default;
  // The name the factory knows it by ("reference", "fixed", "fixed-frame").
  virtual const char* name() const = 0;
  // One view that arrived whole. Throws std::invalid_argument when it does not match the configuration.
  virtual DecodedFrame decode(const LinkFrame& frame) = 0;
  // A view received over a faulty link: line_intact holds one entry per line of frame.codes (0 = lost), concealed by
  // the rules of DESIGN §4 (README "Concealment"); a view with no intact line is decode_lost().
  virtual DecodedFrame decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) = 0;
  // A view that never arrived: the panel holds this eye's previous output (black if none), the residual is dropped.
  virtual DecodedFrame decode_lost(const FrameMeta& meta) = 0;
  // The fixed-point stage events (saturation, clipping, skips) of the last view; null for a decoder without them.
  virtual const FixedStageCounts* stage_counts() const { return nullptr; }
  // The hardware model's resources at a view size (latency, line buffers, frame stores, ROMs, arithmetic) into
  // `out`; false for a decoder that models no hardware.
  virtual bool hardware_report(cv::Size full, FixedStreamingReport& out) const {
    (void)full;
    (void)out;
    return false;
  }
};

// The decoders by name: "reference" (double precision), "fixed" (fixed-point, line-buffered streaming: the hardware
// model) and "fixed-frame" (the same arithmetic frame at a time). The reference takes config.decoder, the fixed-point
// ones the whole configuration. Throws std::invalid_argument for an unknown name (listing decoder_names()) or an
// invalid configuration.
std::unique_ptr<HeadsetDecoder> make_decoder(const std::string& name, const FixedDecoderConfig& config);
const std::vector<std::string>& decoder_names();
// Throws make_decoder's std::invalid_argument unless `name` is one of decoder_names().
void check_decoder_name(const std::string& name);

}  // namespace trm
