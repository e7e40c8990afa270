// The simulation pipeline shared by `trm run`, `trm decode` and `trm feed`: a frame source, the GPU-side
// encoder, and a decoder, producing panel drive frames in order.
#pragma once

#include "options.hpp"

#include "trm/link_simulation.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace trm::cli {

// One decoded view slot, as the pipeline hands it to a sink.
struct DecodedView {
  const FrameSource* source = nullptr;
  const cv::Mat* linear_full = nullptr;   // the scene at t (full resolution, linear): what full rate would render
  FrameMeta slot;                         // the view as sent, or (nothing sent) unsent_slot()
  const LinkFrame* sent = nullptr;        // what crossed the link; null when the method sends nothing in this slot
  std::int64_t pixels_rendered = 0;       // what the method's GPU side rendered for this view
  const DecodedFrame* decoded = nullptr;  // what the headset showed
  // The reference decoder's output (drive codes and statistics, no report planes), when compared beside a fixed
  // impl. LCD: the reference takes the fixed
  // decoder's drive codes as its panel history after every frame (ReferenceDecoder::adopt_panel_history), so each
  // frame's inverse is compared from the same panel state; free_running_reference keeps its own history.
  const DecodedFrame* reference = nullptr;
  const DecodedFrame* free_running_reference = nullptr;
  const FixedStageCounts* fixed_counts = nullptr;  // fixed impl: saturation / clip events of this view per stage
  double render_seconds = 0.0;            // producing the source frame (shared by the eyes of a link frame)
  double encode_seconds = 0.0;
  double decode_seconds = 0.0;
};

struct LinkOutcome {
  link::BandwidthSummary summary;  // per-frame usage goes to run_pipeline's link_sink as it happens
  link::ReceiverCounters receiver;
  link::FaultCounters faults;
  link::LinkBudget budget;
  std::int64_t concealed_lines = 0;
  std::int64_t lost_views = 0;
};

struct PipelineResult {
  std::int64_t frames = 0;            // link frames (time steps) processed
  std::optional<FixedStreamingReport> hardware;  // impl fixed: latency, line buffers and frame stores
  std::optional<LinkOutcome> link;    // when the link was simulated
};

// Runs source -> encoder -> [link] -> decoder for every frame and eye, calling sink for each view in order and,
// when the link is simulated, link_sink for each link frame once it has been carried.
PipelineResult run_pipeline(const PipelineOptions& options, const std::function<void(const DecodedView&)>& sink,
                            const std::function<void(const link::LinkFrameUsage&)>& link_sink = {});

}  // namespace trm::cli
