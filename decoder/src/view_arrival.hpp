// How a received view arrived, decided once for every decoder: the checks a view must pass before any stage runs,
// the classification of a line mask into a whole, partial or lost view, the concealment of a partial one and what
// a lost one shows (DESIGN §4, README "Concealment"). The reference and both fixed-point schedules call these, so
// they reject the same views with the same messages and conceal the same lines the same way.
#pragma once

#include "trm/decoder.hpp"

#include <cstdint>
#include <span>
#include <string>

namespace trm::detail {

// "<parity> frame t=<index> eye=<eye>", as messages name a view.
std::string frame_name(const FrameMeta& meta);

// Throws std::invalid_argument "<who>: <frame name>: <problem>" unless the view is one the link configuration can
// produce: valid metadata, the link's bits and transfer, non-empty CV_16UC3 codes of the metadata's size, that size
// the view's full or reduced size, and no code beyond the link bit depth. The codes are scanned on `threads` threads
// (bands of rows): a frame's codes are read from memory once before the decode reads them again, and the decoder's
// threads are idle until it is checked.
void check_link_frame(const LinkFrame& frame, const EncoderConfig& link, const std::string& who, int threads = 1);

// The metadata checks of check_link_frame for a view that arrives line by line (no codes yet): valid metadata, the
// link's bits and transfer, and metadata width x height the view's full or reduced size.
void check_view_header(const FrameMeta& meta, const EncoderConfig& link, const std::string& who);
// The code check of check_link_frame for one line of such a view: throws std::invalid_argument
// "<who>: <frame name>: line <y>: code <c> exceeds the <b>-bit range".
void check_line_codes(const FrameMeta& meta, int line, std::span<const std::uint16_t> codes, int bits,
                      const std::string& who);

// Throws std::invalid_argument "<who>: lost <frame name>: <problem>" unless the metadata of a view that never
// arrived is valid.
void check_lost_view(const FrameMeta& meta, const std::string& who);

// A view that arrived with some lines lost (at least one lost, at least one intact): lost lines of a full frame feed
// D as copies of the nearest intact line above (else below) and show L_t with rho = 0; lost lines of a reduced frame
// repeat the row of the stored d_{t-1} (substitute) or, without one, the nearest intact line above (else below).
struct Concealment {
  std::span<const std::uint8_t> intact;  // one entry per line of the view; 0 = lost
  int first_intact = 0;  // lost lines above it have no intact line above: they take this line's content
  int lost_lines = 0;
  cv::Mat substitute;    // reduced frames: the eye's d_{t-1} frame store (codes); empty: none
  bool lost(int y) const { return intact[static_cast<std::size_t>(y)] == 0; }
};

// Whole: an empty mask or every line intact (decode as received); Lost: no line intact (decode_lost); Partial: some
// lines lost, concealed as Concealment says.
enum class Arrival { Whole, Partial, Lost };

// Counts a line mask into `out` and classifies it. Throws std::invalid_argument ("<who>: line mask has ...") for a
// mask whose length is not the view's line count. The substitute is left for the caller (concealment_substitute).
Arrival classify_arrival(const LinkFrame& frame, std::span<const std::uint8_t> line_intact, Concealment& out,
                         const std::string& who);

// The d_{t-1} a partial reduced view's lost lines repeat: the eye's stored d_t when the eye holds a residual and a
// d_t of the view's reduced size, looked up before a change of view size resets the eye; else empty. Over the
// reference's and the fixed-point decoders' eye maps (same member names).
template <typename EyeMap>
cv::Mat concealment_substitute(const EyeMap& eyes, const FrameMeta& meta) {
  if (meta.parity != Parity::Reduced) return cv::Mat();
  const auto found = eyes.find(meta.eye);
  if (found == eyes.end() || !found->second.have_residual ||
      found->second.previous_low.size() != cv::Size(meta.width, meta.height)) {
    return cv::Mat();
  }
  return found->second.previous_low;
}
template <typename EyeMap>
cv::Mat concealment_substitute(const EyeMap& eyes, const LinkFrame& frame) {
  if (frame.meta.parity != Parity::Reduced) return cv::Mat();
  const auto found = eyes.find(frame.meta.eye);
  if (found == eyes.end() || !found->second.have_residual || found->second.previous_low.size() != frame.codes.size()) {
    return cv::Mat();
  }
  return found->second.previous_low;
}

// The codes of a partially received view with every lost line replaced (the frame-at-a-time form of the rules).
cv::Mat concealed_codes(const cv::Mat& codes, const Concealment& c);

// What every decoder does with one eye's state when a whole view is lost (over the reference's and the fixed-point
// decoders' eye states: same member names, different sample types). The eye's previous output is shown again if it has one at this view size (else black, and the eye starts afresh
// at the new size). The residual belonged to a pair that is now broken and is dropped with the d_t it was built
// against; the LCD stores keep the drive the panel still shows.
template <typename EyeState>
DecodedFrame hold_lost_view(EyeState& eye, const FrameMeta& meta, bool report_planes) {
  const cv::Size full(meta.full_width, meta.full_height);
  const bool held = eye.full_size == full && !eye.last_output.drive_codes.empty();
  if (!held) {
    eye = EyeState();
    eye.full_size = full;
  }
  DecodedFrame out = lost_view_output(meta, held ? &eye.last_output : nullptr, report_planes);
  eye.have_residual = false;
  eye.residual.release();
  eye.previous_low.release();
  return out;
}

}  // namespace trm::detail
