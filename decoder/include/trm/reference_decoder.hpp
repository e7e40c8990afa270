// The reference TRM decoder in double precision (DESIGN §4, paper Eqs. 1-7). The fixed-point decoders
// are held to it.
#pragma once

#include "trm/decoder.hpp"
#include "trm/oled_drive_codes.hpp"

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <vector>

namespace trm {

class ReferenceDecoder : public HeadsetDecoder {
 public:
  explicit ReferenceDecoder(DecoderConfig config);
  const char* name() const override { return "reference"; }
  const DecoderConfig& config() const { return config_; }
  // Decodes one view; each eye keeps its own residual / previous-frame state. Throws std::invalid_argument
  // when the frame does not match the configuration (bits, transfer, size, codes out of range). A reduced
  // frame uses the residual only when the eye's previous frame was the full frame with index t - 1.
  DecodedFrame decode(const LinkFrame& frame) override;
  // The same for a view received over a faulty link: line_intact holds one entry per line of frame.codes
  // (0 = lost). Concealment: a lost line of a full frame shows the upsampled low-pass estimate U(d_t) and its
  // residual is cleared; a lost line of a reduced frame repeats the matching line of the stored d_t (or the
  // nearest intact line when there is none). Lost lines feed D as copies of the nearest intact line above
  // (else below). A view with no intact line is decoded as decode_lost().
  DecodedFrame decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override;
  // A view that never arrived: the panel holds this eye's previous output (black if none), and the residual is
  // dropped, so the next reduced frame adds none (DESIGN §4: a reduced frame after a lost frame adds nothing).
  DecodedFrame decode_lost(const FrameMeta& meta) override;
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
    cv::Mat previous_low_linear;  // L_t = lin(U(d_t)), full size: what the motion test recomputes from d_t
    double residual_mean_abs = 0.0;  // of rho as kept (after the LCD shortfall)
    double residual_max_abs = 0.0;
    cv::Mat previous_drive;    // LCD: v_{t-1} actually shown (quantised drive as a value in [0, 1])
    DecodedFrame last_output;  // what this eye showed last, held when a view is lost
    cv::Mat previous_wanted;   // LCD: x_{t-1}, what frame t-1 contributed in linear light: the wanted value,
                               // or 2 M(v_{t-1}, v_{t-2})^gamma - x_{t-2} where that was unreachable
    std::vector<cv::Mat> spare_planes;  // planes of earlier views, filled again once nothing else holds them
  };
  // Decodes a view whose lost lines (line_intact[y] == 0; empty: none lost) were already filled in.
  DecodedFrame decode_view(const LinkFrame& frame, std::span<const std::uint8_t> line_intact);

  DecoderConfig config_;
  PanelEmission emission_;  // the light of every drive code (after every previous code, with history)
  std::optional<OledDriveCodes> oled_codes_;  // OLED without report planes: its codes without a pow per sample
  std::vector<double> drive_value_of_code_;   // dequantise(q, 2^output_bits - 1) of every drive code q
  std::map<int, EyeState> eyes_;
};

}  // namespace trm
