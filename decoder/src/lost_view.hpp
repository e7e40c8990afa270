// What every decoder does with one eye's state when a whole view is lost (DESIGN §4), over the reference's and the
// fixed-point decoders' eye states (same member names, different sample types).
#pragma once

#include "trm/reference_decoder.hpp"

namespace trm::detail {

// The eye's previous output is shown again if it has one at this view size (else black, and the eye starts afresh
// at the new size). The residual belonged to a pair that is now broken and is dropped with the d_t it was built
// against; the LCD stores keep the drive the panel still shows.
template <typename EyeState>
DecodedFrame hold_lost_view(EyeState& eye, const FrameMeta& meta) {
  const cv::Size full(meta.full_width, meta.full_height);
  const bool held = eye.full_size == full && !eye.last_output.drive.empty();
  if (!held) {
    eye = EyeState();
    eye.full_size = full;
  }
  DecodedFrame out = lost_view_output(meta, held ? &eye.last_output : nullptr);
  eye.have_residual = false;
  eye.residual.release();
  eye.previous_low.release();
  return out;
}

}  // namespace trm::detail
