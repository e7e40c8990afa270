// What the display methods share. PanelShow is the headset side of the methods that send plain frames (full, half-rate, interlace, bfi): linear light onto the
// panel with no temporal compensation. The drive is the panel's held inverse (OLED v = x^(1/gamma_c); LCD the v with
// M(v, v)^gamma = x), quantised to the output depth; the light is the panel's forward model of the codes shown,
// which on an LCD merges each frame with the one before (Eq. 7), as an uncompensated panel does. TRM's own inverse
// (and its LCD pair compensation) lives in the decoders. With DecoderConfig::report_planes = false it returns the
// drive codes alone, as the TRM decoders do (no wanted, drive or emitted planes; an OLED's codes without a pow per
// sample, OledDriveCodes), the same codes and statistics.
#pragma once

#include "trm/decoder.hpp"
#include "trm/display_method.hpp"
#include "trm/encoder.hpp"
#include "trm/oled_drive_codes.hpp"

#include <functional>
#include <map>
#include <optional>
#include <span>

namespace trm::methods {

class PanelShow {
 public:
  explicit PanelShow(const DecoderConfig& config);
  // Shows `wanted` (CV_64FC3, linear, full size) in the slot `meta` describes.
  DecodedFrame show(const FrameMeta& meta, const cv::Mat& wanted);
  // Shows a received full view: checked against the configuration, lost lines (line_intact, empty: none) concealed
  // by the nearest intact line, linearised and shown.
  DecodedFrame show_received(const LinkFrame& frame, std::span<const std::uint8_t> line_intact);
  // Shows this eye's previous output again (black if none): the same codes, re-emitted.
  DecodedFrame hold(const FrameMeta& meta);
  // Shows black: every drive code 0.
  DecodedFrame black(const FrameMeta& meta);
  // A view that never arrived: the previous output held, marked lost.
  DecodedFrame lost(const FrameMeta& meta);
  const DecoderConfig& config() const { return config_; }

 private:
  DecodedFrame emit(const FrameMeta& meta, cv::Mat wanted, cv::Mat drive, cv::Mat codes);
  cv::Mat oled_codes_of(const cv::Mat& wanted) const;
  DecoderConfig config_;
  PanelEmission emission_;
  std::optional<OledDriveCodes> oled_codes_;  // an OLED without report planes: its codes without a pow per sample
  std::map<int, DecodedFrame> last_;  // per eye
};

// Throws std::invalid_argument unless `frame` is a view this configuration can show: metadata in range, the link's
// bits and transfer, CV_16UC3 codes of the size the metadata says, no code above the link's depth.
void check_received(const LinkFrame& frame, const DecoderConfig& config, const char* method);

// The GPU side of the methods that send the full view as rendered: in every slot, or (every_slot = false) only in
// the slots where TRM would send its full frame (TRM's parity rule, so --phase and stereo off-phase apply alike).
class FullViewSender : public MethodSender {
 public:
  FullViewSender(const EncoderConfig& link, bool every_slot);
  bool sends(std::int64_t t, int eye) const override;
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override;
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override;

 private:
  TrmEncoder encoder_;
  bool every_slot_;
};

// The headset side of the methods whose views are TRM frames (trm, ncsfi): a decoder of make_decoder() by name.
class TrmFrameDisplay : public MethodDisplay {
 public:
  TrmFrameDisplay(const std::string& impl, const FixedDecoderConfig& config);
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override;
  DecodedFrame show_lost(const FrameMeta& slot) override;
  DecodedFrame show_unsent(const FrameMeta& slot) override;
  HeadsetDecoder* decoder() override { return decoder_.get(); }

 private:
  std::unique_ptr<HeadsetDecoder> decoder_;
};

// The metadata of TRM's view (t, eye): full or reduced by TRM's parity rule (trm and ncsfi send these).
FrameMeta trm_view_meta(std::int64_t t, int eye, cv::Size full, const EncoderConfig& link);

// A method whose views are TRM frames, shown by the TRM decoder of --impl (fixed_point = true): its sender, and the
// decoder configuration its headset side uses (the run's, or adjusted, e.g. ncsfi's s = 0).
using SenderFactory = std::function<std::unique_ptr<MethodSender>(const EncoderConfig& link)>;
using HeadsetConfig = std::function<FixedDecoderConfig(FixedDecoderConfig)>;
DisplayMethod trm_frame_method(std::string name, std::string summary, SenderFactory sender,
                               HeadsetConfig headset = [](FixedDecoderConfig c) { return c; });

// What a plain-frame method shows in the slots between its rendered frames.
enum class Between {
  Nothing,  // there are none: every slot is rendered and sent
  Repeat,   // the last frame again, code for code
  Black,    // a black frame
};
// The headset side of a method that sends whole full views: each shown through PanelShow, the slots it sends
// nothing for filled by `between`.
std::unique_ptr<MethodDisplay> plain_frame_display(const DecoderConfig& config, Between between);
// A method that renders and sends whole frames (every slot, or TRM's full slots only) and shows them through
// PanelShow: full, half-rate, bfi differ only in `between`.
DisplayMethod plain_frame_method(std::string name, std::string summary, Between between);

// Linear light of received link codes (the view's transfer function), CV_64FC3.
cv::Mat linear_of_codes(const cv::Mat& codes, const FrameMeta& meta);
// Replaces every lost row of `codes` (line_intact[y] == 0) by the nearest intact row above, else below; returns the
// number replaced. Needs at least one intact row.
int conceal_lost_rows(cv::Mat& codes, std::span<const std::uint8_t> line_intact);
// The view as shown: its metadata with the full size, as every decoder returns it.
FrameMeta shown_meta(const FrameMeta& sent);

}  // namespace trm::methods
