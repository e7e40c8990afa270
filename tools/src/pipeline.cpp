#include "pipeline.hpp"
#include "elapsed.hpp"

#include "capture_replay.hpp"

#include "trm/reference_decoder.hpp"

#include <chrono>
#include <optional>
#include <stdexcept>

namespace trm::cli {

PipelineResult run_pipeline(const PipelineOptions& options, const std::function<void(const DecodedView&)>& sink,
                            const std::function<void(const link::LinkFrameUsage&)>& link_sink) {
  options.validate();
  const std::unique_ptr<FrameSource> source = options.open_source();
  require_memory(std::string("with this panel") + (options.encoder.stereo ? " in stereo" : ""),
                 run_bytes_per_pixel(options), cv::Size(source->width(), source->height()));

  std::int64_t frames = options.frames;
  const auto available = source->frame_count();
  if (available) {
    if (*available == 0) throw std::runtime_error("input '" + options.input + "' has no frames");
    if (frames == 0) frames = *available;
    if (frames > *available) {
      throw std::invalid_argument("--frames " + std::to_string(frames) + " asks for more frames than the input has (" +
                                  std::to_string(*available) + ")");
    }
  } else if (frames == 0) {
    frames = options.default_frames;
  }

  MethodSetup setup = options.method_setup();
  setup.scene.at = [scene = source.get()](std::int64_t t) { return scene->motion(t); };
  setup.source = source.get();  // the renderer's knowledge of its scene (head poses, motion)
  const MethodChoice method = find_display_method(options.method);
  const std::unique_ptr<MethodSender> sender = method.method->make_sender(setup);
  const std::unique_ptr<MethodDisplay> display = method.method->make_display(setup);
  HeadsetDecoder* const decoder = display->decoder();  // the TRM decoder inside, if the method has one
  // The reference beside a fixed-point decoder sees exactly the same input.
  const bool compare = options.compare_reference && decoder != nullptr && setup.impl != "reference";
  MethodSetup reference_setup = setup;
  reference_setup.impl = "reference";
  // The reference beside is held to the decoder by its drive codes alone (DESIGN §6): it makes no report planes.
  MethodSetup codes_reference_setup = reference_setup;
  codes_reference_setup.decoder.decoder.report_planes = false;
  std::unique_ptr<MethodDisplay> reference_beside;
  if (compare) reference_beside = method.method->make_display(codes_reference_setup);
  // LCD codes compared free-running drift apart by the design's neutral mode (see adopt_panel_history); the
  // synchronised comparison is the criterion, the free-running one is reported beside it.
  std::unique_ptr<MethodDisplay> free_running;
  if (compare && setup.decoder.decoder.panel.has_history()) {
    free_running = method.method->make_display(reference_setup);
  }
  auto* const synchronised_reference =
      reference_beside ? dynamic_cast<ReferenceDecoder*>(reference_beside->decoder()) : nullptr;

  std::optional<link::LinkSimulation> simulation;
  PipelineResult result;
  if (options.link_enabled()) {
    link::LinkSimulationConfig config = options.link_config(source->width(), source->height());
    if (!options.capture_out.empty()) {
      config.capture = options.capture_out;
      config.capture_metadata = capture_metadata(options, frames);
    }
    simulation.emplace(std::move(config));
    result.link.emplace();
  }

  const cv::Size full(source->width(), source->height());
  const int eyes = options.encoder.stereo ? 2 : 1;
  for (std::int64_t t = 0; t < frames; ++t) {
    const auto render_start = std::chrono::steady_clock::now();
    const cv::Mat linear = source->linear_frame(t);
    const double render_seconds = seconds_since(render_start);
    // The GPU side: the views this method sends at t, in stream order.
    std::vector<LinkFrame> sent;
    std::vector<int> sent_index(static_cast<std::size_t>(eyes), -1);
    std::vector<std::int64_t> pixels_rendered(static_cast<std::size_t>(eyes), 0);
    std::vector<double> encode_seconds(static_cast<std::size_t>(eyes), 0.0);
    for (int eye = 0; eye < eyes; ++eye) {
      if (!sender->sends(t, eye)) continue;
      const auto start = std::chrono::steady_clock::now();
      Transmission transmission = sender->send(linear, t, eye);
      encode_seconds[static_cast<std::size_t>(eye)] = seconds_since(start);
      pixels_rendered[static_cast<std::size_t>(eye)] = transmission.pixels_rendered;
      sent_index[static_cast<std::size_t>(eye)] = static_cast<int>(sent.size());
      sent.push_back(std::move(transmission.frame));
    }
    std::vector<link::ReceivedFrame> received;
    if (simulation) {
      received = simulation->carry(t, sent);
      if (link_sink) link_sink(simulation->meter().last());
    }
    for (int eye = 0; eye < eyes; ++eye) {
      const int index = sent_index[static_cast<std::size_t>(eye)];
      const LinkFrame* view_sent = index >= 0 ? &sent[static_cast<std::size_t>(index)] : nullptr;
      const FrameMeta slot = view_sent ? view_sent->meta : unsent_slot(t, eye, full, options.encoder);
      // One slot through a display: what arrived, what was lost, or what was never sent.
      const link::ReceivedFrame* arrived = nullptr;
      bool lost = false;
      if (view_sent && simulation) {
        for (const auto& r : received) {
          if (r.meta.eye == eye && r.meta.index == t) arrived = &r;
        }
        lost = arrived == nullptr;
      }
      const auto show = [&](MethodDisplay& on) {
        if (!view_sent) return on.show_unsent(slot);
        if (lost) return on.show_lost(slot);
        if (arrived) return on.show(LinkFrame{arrived->meta, arrived->codes}, arrived->line_intact);
        return on.show(*view_sent, {});
      };
      const auto start = std::chrono::steady_clock::now();
      const DecodedFrame decoded = show(*display);
      const double decode_seconds = seconds_since(start);  // of the display under test, not of the reference beside
      DecodedFrame reference;
      DecodedFrame free_running_reference;
      if (compare) {
        reference = show(*reference_beside);
        if (free_running && synchronised_reference && !lost) {
          synchronised_reference->adopt_panel_history(decoded);
        }
        if (free_running) free_running_reference = show(*free_running);
      }
      if (lost) ++result.link->lost_views;
      if (simulation) result.link->concealed_lines += decoded.stats.concealed_lines;
      DecodedView view;
      view.source = source.get();
      view.linear_full = &linear;
      view.slot = slot;
      view.sent = view_sent;
      view.pixels_rendered = pixels_rendered[static_cast<std::size_t>(eye)];
      view.decoded = &decoded;
      if (compare) view.reference = &reference;
      if (free_running) view.free_running_reference = &free_running_reference;
      view.fixed_counts = decoder ? decoder->stage_counts() : nullptr;
      view.render_seconds = render_seconds;
      view.encode_seconds = encode_seconds[static_cast<std::size_t>(eye)];
      view.decode_seconds = decode_seconds;
      sink(view);
    }
  }
  result.frames = frames;
  if (FixedStreamingReport hardware; decoder && decoder->hardware_report(full, hardware)) {
    result.hardware = std::move(hardware);
  }
  if (simulation) {
    simulation->finish();
    result.link->summary = simulation->meter().summary();
    result.link->receiver = simulation->receiver_counters();
    result.link->faults = simulation->fault_counters();
    result.link->budget = simulation->meter().budget();
  }
  return result;
}

}  // namespace trm::cli
