// Recorded packet streams: what a capture's header records of the run that wrote it, and the replay of a capture
// through the receiver into a display method's headset side (`trm decode --capture`, `trm feed --capture`).
#pragma once

#include "options.hpp"

#include "trm/link_simulation.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace trm::cli {

// The configuration a capture's header stores (encoder, method, refresh, frames sent), so that replay can rebuild
// the headset side; decode_capture_stream reads it back.
std::string capture_metadata(const PipelineOptions& options, std::int64_t frames);

// A recorded packet stream (.trmcap) replayed through the receiver into the decoder options.impl names (reference,
// fixed or fixed-frame; each conceals lost lines). The link configuration (r, sigma, transfer, bits, ...) comes from
// the capture's header; panel, sensitivity, output bits and the fixed-point residual width from the options. Throws link::CaptureError / std::runtime_error with the file name on a bad capture.
struct CaptureDecodeResult {
  std::string link_configuration;   // the capture header's JSON
  std::string method;               // the display method the capture was sent with (its header's, else trm)
  std::string impl;                 // the decoder its headset side used
  link::ReceiverCounters receiver;
  std::int64_t views = 0;           // slots handed to the sink, lost and unsent ones included
  std::int64_t lost_views = 0;      // views none of whose packets arrived (the panel held its previous output)
  std::int64_t concealed_lines = 0;
};
// What became of a view slot of a replayed capture.
enum class SlotOutcome { Arrived, Lost, NotSent };
// Called for every view slot in link order: `received` is null unless it arrived (a lost view shows the held output;
// a slot the method sends nothing for shows what the method shows there).
using CaptureSink = std::function<void(const FrameMeta& meta, SlotOutcome outcome, const link::ReceivedFrame* received,
                                       const DecodedFrame& decoded)>;
CaptureDecodeResult decode_capture_stream(const PipelineOptions& options, const std::string& capture_path,
                                          const CaptureSink& sink);

}  // namespace trm::cli
