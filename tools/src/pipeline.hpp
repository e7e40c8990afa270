// The simulation pipeline shared by `trm run`, `trm decode` and `trm feed`: a frame source, the GPU-side
// encoder, and a decoder, producing panel drive frames in order.
#pragma once

#include "trm/display_method.hpp"
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/link_simulation.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/scene.hpp"
#include "view_size.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace trm::cli {

struct PipelineOptions {
  std::string scene = "discs";        // analytic scene, used when input is empty
  std::string input;                  // image-sequence glob or video file
  std::string image;                  // --image for panorama/static
  std::int64_t frames = 0;            // 0: the source's own count (analytic scenes: default_frames)
  std::int64_t default_frames = 90;
  int width = 1080, height = 1200;    // per-eye view size for analytic scenes
  double refresh_hz = 90.0;
  std::uint64_t seed = 1;
  EncoderConfig encoder;
  double sensitivity = 10.0;
  Panel panel = parse_panel("vive");  // --panel, parsed once as it is read
  int output_bits = 8;
  std::string method = "trm";         // display method (trm/display_method.hpp): NAME or NAME:OPTION
  std::string impl = "reference";     // reference | fixed (streaming, the hardware model) | fixed-frame
  bool impl_given = false;            // --impl was on the command line (a plain-frame method then refuses fixed)
  bool compare_reference = false;     // with a fixed impl: also run the reference and compare codes
  int residual_bits = 0;              // fixed impl: residual store width N (sQ2.(N-2)); 0 = the default
  bool no_skip = false;               // fixed impl: run the full path everywhere (FixedDecoderConfig::skip_unneeded)
  LcdHistory lcd_history = LcdHistory::Wanted;

  // Simulated display link (off when link_preset is empty and no fault or capture is asked for).
  std::string link_preset;            // dp1.2 ... custom:RATE:EFF
  bool cvt_blanking = false;          // subtract CVT-RB v2 blanking from the time a frame may use
  std::string codec = "raw";          // raw | jpegls
  int lines_per_packet = 1;
  double ber = 0.0;
  std::string burst;                  // RATE:LENGTH
  double drop = 0.0;
  std::string capture_out;            // write the packet stream as sent
  bool link_enabled() const {
    return !link_preset.empty() || ber > 0.0 || !burst.empty() || drop > 0.0 || !capture_out.empty();
  }
  // Adds --link --cvt-blanking --codec --lines-per-packet --ber --burst --drop --capture-out.
  void add_link_options(CLI::App& cmd);
  // The link configuration these options describe (validated); the preset defaults to dp1.4 when only
  // faults or a capture were asked for.
  link::LinkSimulationConfig link_config(int full_width, int full_height) const;

  // Adds --method: the commands that show a sequence on the panel (run, decode, feed); the others model TRM's decoder.
  void add_method_option(CLI::App& cmd);

  // Adds the shared options (--scene --input --image --frames --size --refresh --reduction --sigma
  // --phase --transfer --resample-space --bits --stereo --sensitivity --panel --output-bits --seed)
  // to a subcommand.
  void add_options(CLI::App& cmd);
  // Validates everything up front (throws std::invalid_argument with one clear message).
  void validate() const;
  // The decoder the method's headset side uses: --impl for a method that decodes TRM frames, else the reference
  // (a plain-frame method has no fixed-point decoder; an explicit --impl other than reference is refused).
  std::string method_impl() const;
  // What the method is built from.
  MethodSetup method_setup() const;
  // The frame source these options name: the --input sequence or video, else the built-in scene.
  std::unique_ptr<FrameSource> open_source() const;
};

// One decoded view slot, as the pipeline hands it to a sink.
struct DecodedView {
  const FrameSource* source = nullptr;
  const cv::Mat* linear_full = nullptr;   // the scene at t (full resolution, linear): what full rate would render
  FrameMeta slot;                         // the view as sent, or (nothing sent) unsent_slot()
  const LinkFrame* sent = nullptr;        // what crossed the link; null when the method sends nothing in this slot
  std::int64_t pixels_rendered = 0;       // what the method's GPU side rendered for this view
  const DecodedFrame* decoded = nullptr;  // what the headset showed
  // The reference decoder's output, when compared beside a fixed impl. LCD: the reference takes the fixed
  // decoder's drive codes as its panel history after every frame (ReferenceDecoder::adopt_panel_history), so each
  // frame's inverse is compared from the same panel state; free_running_reference keeps its own history.
  const DecodedFrame* reference = nullptr;
  const DecodedFrame* free_running_reference = nullptr;
  const FixedStageCounts* fixed_counts = nullptr;  // fixed impl: saturation / clip events of this view per stage
  double render_seconds = 0.0;            // producing the source frame (shared by the eyes of a link frame)
  double encode_seconds = 0.0;
  double decode_seconds = 0.0;
};

// Peak memory of a pipeline run per pixel of the view (measured; see pipeline.cpp), and the check every command that
// allocates per pixel makes before it starts: throws std::runtime_error saying how much the view needs and how much
// this machine has (MemAvailable) when about 100 MB + bytes_per_pixel W H does not fit.
double run_bytes_per_pixel(const PipelineOptions& options);
void require_memory(const std::string& what, double bytes_per_pixel, cv::Size view);

// Option checks with exact messages: a whole number >= `lowest`, and a finite number >= 0. `meaning` follows the
// rule in the message (e.g. "; leave --frames out for every input frame").
CLI::Validator whole_number_at_least(long long lowest, const std::string& meaning = "");
CLI::Validator finite_non_negative(const std::string& meaning = "");

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

// Runs source -> encoder -> [link] -> decoder for every frame and eye, calling sink for each view in order and,
// when the link is simulated, link_sink for each link frame once it has been carried.
PipelineResult run_pipeline(const PipelineOptions& options, const std::function<void(const DecodedView&)>& sink,
                            const std::function<void(const link::LinkFrameUsage&)>& link_sink = {});

}  // namespace trm::cli
