// The reference TRM decoder in double precision (DESIGN §4, paper Eqs. 1-7). The fixed-point decoders
// are held to it.
#pragma once

#include "trm/encoder.hpp"
#include "trm/frame.hpp"
#include "trm/panel.hpp"

#include <cstdint>
#include <map>
#include <optional>
#include <span>
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

  void validate() const;       // throws std::invalid_argument with a clear message
};

struct FrameStats {
  double clipped_fraction = 0.0;       // full frame: fraction of channel samples with beta outside [0, 1];
                                       // reduced frame: fraction with alpha + w rho outside [0, 1]
  double residual_mean_abs = 0.0;      // |rho| after this frame (full frames) / of the rho consumed (reduced)
  double residual_max_abs = 0.0;
  double dropped_sum = 0.0;            // reduced frame: sum over samples of what alpha' clipping dropped
  double mean_motion_weight = 1.0;     // reduced frame: mean w
  bool residual_applied = false;       // reduced frame: a residual from a preceding full frame was used
  double lcd_unreachable_fraction = 0.0;
  int concealed_lines = 0;             // lines of the received view that were lost and concealed
  bool frame_lost = false;             // nothing of this view arrived: the previous output was held
};

// Per-stage intermediates of one decoded frame (DESIGN §4 notation). Matrices that do not apply to the frame
// (or to the panel) are left empty. Full-size values are CV_64FC3 unless noted.
struct DecodeStages {
  cv::Mat low_codes;            // full: d_t = Q_b(D(E_t)); reduced: i_t as received (CV_16UC3, reduced size)
  cv::Mat low_linear;           // full: L_t = lin(U(d_t)); reduced: alpha = lin(U(i_t))
  cv::Mat full_linear;          // full: I_t = lin(E_t)
  cv::Mat beta;                 // full: beta = 2 I_t - L_t before clamping (Eq. 2)
  cv::Mat residual;             // full: rho_t after this frame, LCD shortfall included; reduced: the rho consumed
  cv::Mat previous_low_linear;  // reduced with residual: L_prev = lin(U(d_{t-1}))
  cv::Mat contrast;             // reduced with residual: c (Eq. 5), CV_64FC1
  cv::Mat weight;               // reduced with residual: w = exp(-s c) (Eq. 6), CV_64FC1
  cv::Mat alpha_unclamped;      // reduced with residual: alpha + w rho (Eq. 4) before clamping
  cv::Mat lcd_target;           // LCD: target merged value m = ((x_t + x_{t-1}) / 2)^(1/gamma)
  cv::Mat lcd_previous_drive;   // LCD: v_{t-1} the merge was solved against (quantised drive, as a value)
  cv::Mat lcd_previous_linear;  // LCD: x_{t-1} the target was built on (see EyeState::previous_wanted)
  cv::Mat lcd_unreachable;      // LCD: 255 where M(v, v_{t-1}) = m had no root in [0, 1] (CV_8UC3)
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
// view size, again; or black when there is none (null). Marked lost, every line counted as concealed.
DecodedFrame lost_view_output(const FrameMeta& meta, const DecodedFrame* last);

class ReferenceDecoder {
 public:
  explicit ReferenceDecoder(DecoderConfig config);
  const DecoderConfig& config() const { return config_; }
  // Decodes one view; each eye keeps its own residual / previous-frame state. Throws std::invalid_argument
  // when the frame does not match the configuration (bits, transfer, size, codes out of range). A reduced
  // frame uses the residual only when the eye's previous frame was the full frame with index t - 1.
  DecodedFrame decode(const LinkFrame& frame);
  // The same for a view received over a faulty link: line_intact holds one entry per line of frame.codes
  // (0 = lost). Concealment: a lost line of a full frame shows the upsampled low-pass estimate U(d_t) and its
  // residual is cleared; a lost line of a reduced frame repeats the matching line of the stored d_t (or the
  // nearest intact line when there is none). Lost lines feed D as copies of the nearest intact line above
  // (else below). A view with no intact line is decoded as decode_lost().
  DecodedFrame decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact);
  // A view that never arrived: the panel holds this eye's previous output (black if none), and the residual is
  // dropped, so the next reduced frame adds none (DESIGN §4: a reduced frame after a lost frame adds nothing).
  DecodedFrame decode_lost(const FrameMeta& meta);
  // LCD: replaces this eye's panel history v_{t-1} by the drive codes `shown` put on the panel (same view size,
  // output_bits codes) - the panel as another decoder drove it. Comparing two implementations of the LCD
  // inverse frame by frame needs it: v_t is solved against v_{t-1} with dv_t/dv_{t-1} close to -1, so one code
  // that rounds differently is answered by the opposite difference in the pixel's every later frame (a neutral
  // mode of the design's rule, not an error), and codes compared free-running drift apart while the merge
  // M(v_t, v_{t-1}) the eye sees stays within a code. Throws std::invalid_argument for an OLED panel, an eye
  // with no LCD history yet, or a frame of another size or depth.
  void adopt_panel_history(const DecodedFrame& shown);

 private:
  struct EyeState {
    cv::Size full_size;        // the view size the state belongs to; a change of size starts afresh
    bool have_residual = false;
    std::int64_t residual_index = 0;  // index t of the full frame the residual comes from
    cv::Mat residual;          // rho_t, full size, signed
    cv::Mat previous_low;      // d_t = Q_b(D(E_t)) codes, reduced size, for the motion test
    cv::Mat previous_drive;    // LCD: v_{t-1} actually shown (quantised drive as a value in [0, 1])
    DecodedFrame last_output;  // what this eye showed last, held when a view is lost
    cv::Mat previous_wanted;   // LCD: x_{t-1}, what frame t-1 contributed in linear light: the wanted value,
                               // or 2 M(v_{t-1}, v_{t-2})^gamma - x_{t-2} where that was unreachable
  };
  // Decodes a view whose lost lines (line_intact[y] == 0; empty: none lost) were already filled in.
  DecodedFrame decode_view(const LinkFrame& frame, std::span<const std::uint8_t> line_intact);

  DecoderConfig config_;
  std::map<int, EyeState> eyes_;
};

}  // namespace trm
