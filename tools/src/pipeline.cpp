#include "pipeline.hpp"

#include "hw_report.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <span>
#include <stdexcept>

namespace trm::cli {

namespace {

bool looks_like_image_sequence(const std::string& input) {
  const std::string ext = std::filesystem::path(input).extension().string();
  if (input.find_first_of("*?") != std::string::npos) return true;
  for (const char* e : {".png", ".PNG", ".tif", ".tiff", ".jpg", ".jpeg", ".exr", ".bmp"}) {
    if (ext == e) return true;
  }
  return false;
}

// Stored in a capture's header so that `trm decode --capture` can rebuild the decoder's link configuration.
std::string capture_metadata(const PipelineOptions& options) {
  nlohmann::ordered_json meta;
  meta["reduction"] = options.encoder.reduction;
  meta["sigma"] = options.encoder.effective_sigma();
  meta["phase"] = options.encoder.phase;
  meta["transfer"] = to_string(options.encoder.transfer);
  meta["resample_space"] = to_string(options.encoder.resample_space);
  meta["bits"] = options.encoder.bits;
  meta["stereo"] = options.encoder.stereo;
  meta["refresh_hz"] = options.refresh_hz;
  return meta.dump();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::unique_ptr<FrameSource> PipelineOptions::open_source() const {
  if (!input.empty()) return looks_like_image_sequence(input) ? open_image_sequence(input) : open_video(input);
  SceneParams params;
  params.width = width;
  params.height = height;
  params.refresh_hz = refresh_hz;
  params.seed = seed;
  params.image_path = image;
  return make_scene(scene, params);
}

void PipelineOptions::add_options(CLI::App& cmd) {
  cmd.add_option("--scene", scene, "Built-in scene (discs, text, panorama, line, zoneplate, checker, flash, static, jitter)")
      ->capture_default_str();
  cmd.add_option("--input", input, "Image sequence glob ('DIR/frame_*.png', sorted by name, sRGB) or a video file");
  cmd.add_option("--image", image, "Image for the panorama and static scenes (default: procedural texture)");
  cmd.add_option("--frames", frames, "Number of frames (default: all input frames, or " +
                                         std::to_string(default_frames) + " for a scene)");
  cmd.add_option_function<std::string>(
         "--size",
         [this](const std::string& text) {
           const cv::Size size = parse_view_size(text);
           width = size.width;
           height = size.height;
         },
         "View size WxH for built-in scenes (default 1080x1200, one eye of a Vive-class headset)");
  cmd.add_option("--refresh", refresh_hz, "Panel refresh rate in Hz")->capture_default_str();
  cmd.add_option("--reduction,-r", encoder.reduction, "Resolution reduction r in (0, 1]")->capture_default_str();
  cmd.add_option("--sigma", encoder.sigma, "Gaussian sigma of D in full-resolution pixels (default 1.25 / r)");
  cmd.add_option("--phase", encoder.phase, "0: even frames full, odd reduced; 1: swapped")->capture_default_str();
  cmd.add_option_function<std::string>(
      "--transfer", [this](const std::string& s) { encoder.transfer = parse_transfer(s); },
      "Link transfer function: srgb (default) or gamma2.2");
  cmd.add_option_function<std::string>(
      "--resample-space", [this](const std::string& s) { encoder.resample_space = parse_resample_space(s); },
      "Space in which D and U act: encoded (default) or linear");
  cmd.add_option_function<int>(
      "--bits",
      [this](int b) {
        encoder.bits = b;
        output_bits = b;
      },
      "Bits per channel on the link and of the panel drive codes: 8 (default) or 10");
  cmd.add_option("--link-bits", encoder.bits, "Link bits only (overrides --bits)");
  cmd.add_option("--output-bits", output_bits, "Drive code bits only (overrides --bits)");
  cmd.add_flag("--stereo", encoder.stereo, "Two eyes off-phase: every link frame carries one full and one reduced view");
  cmd.add_option("--sensitivity,-s", sensitivity, "Motion sensitivity s in w = exp(-s c)")->capture_default_str();
  cmd.add_option("--panel", panel, "vive | rift | generic | gamma:G | gamma:GR,GG,GB | lcd | lcd:p1,p2,p3,p4,gamma")
      ->capture_default_str();
  cmd.add_option_function<std::string>(
      "--lcd-history",
      [this](const std::string& s) {
        if (s == "wanted") {
          lcd_history = LcdHistory::Wanted;
        } else if (s == "contributed") {
          lcd_history = LcdHistory::Contributed;
        } else {
          throw CLI::ValidationError("--lcd-history", "expected wanted or contributed, got '" + s + "'");
        }
      },
      "LCD: build each pair target on the previous wanted value (wanted, the design's rule) or on what the "
      "previous frame actually contributed (contributed)");
  cmd.add_option("--seed", seed, "Seed for scenes with randomness")->capture_default_str();
  cmd.add_option("--residual-bits", residual_bits,
                 "Fixed-point residual store width N, signed sQ2.(N-2) (default: 30, lossless)");
  cmd.add_flag("--no-skip", no_skip,
               "Fixed-point decoders: do not skip the work a scene does not need (static lines' motion test, "
               "all-zero residual lines); the output is bit-identical either way");
  cmd.add_option("--impl", impl,
                 "Decoder: reference (double), fixed (fixed-point, line-buffered streaming: the hardware model) or "
                 "fixed-frame (the same arithmetic frame at a time); each conceals lines and views lost on the link")
      ->capture_default_str();
}

void PipelineOptions::add_link_options(CLI::App& cmd) {
  cmd.add_option("--link", link_preset,
                 "Simulate a display link: dp1.2, dp1.4, dp2.1-uhbr10, dp2.1-uhbr13.5, dp2.1-uhbr20, hdmi2.0, hdmi2.1, "
                 "wigig[:GBPS], usb3-gen1, usb3-gen2, custom:RATE_GBPS:EFFICIENCY");
  cmd.add_flag("--cvt-blanking", cvt_blanking, "Count CVT-RB v2 blanking against the frame period");
  cmd.add_option("--codec", codec, "Link payload coding: raw or jpegls (lossless, per packet slice)")
      ->capture_default_str();
  cmd.add_option("--lines-per-packet", lines_per_packet, "Whole lines per packet (jpegls: lines per slice)")
      ->capture_default_str();
  cmd.add_option("--ber", ber, "Random bit error rate on the link, e.g. 1e-6");
  cmd.add_option("--burst", burst, "Burst errors RATE:LENGTH_BITS, e.g. 1e-7:64");
  cmd.add_option("--drop", drop, "Probability that a packet is lost");
  cmd.add_option("--capture-out", capture_out, "Write the packet stream as sent to this .trmcap file");
}

link::LinkSimulationConfig PipelineOptions::link_config(int full_width, int full_height) const {
  link::LinkSimulationConfig config;
  if (codec == "raw") {
    config.packetizer.coding = link::PayloadCoding::Raw;
  } else if (codec == "jpegls") {
    config.packetizer.coding = link::PayloadCoding::JpegLs;
  } else {
    throw std::invalid_argument("unknown --codec '" + codec + "' (expected raw or jpegls)");
  }
  config.packetizer.max_lines_per_packet = lines_per_packet;
  config.packetizer.validate();
  config.budget.preset = link::parse_link_preset(link_preset.empty() ? "dp1.4" : link_preset);
  config.budget.refresh_hz = refresh_hz;
  if (cvt_blanking) {
    // Stereo views travel side by side in one video frame.
    config.budget.blanking =
        link::cvt_rb_v2_timing(encoder.stereo ? 2 * full_width : full_width, full_height, refresh_hz);
  }
  config.budget.validate();
  config.faults.bit_error_rate = ber;
  if (!burst.empty()) config.faults.burst = link::parse_burst(burst);
  config.faults.drop_probability = drop;
  config.faults.seed = seed;
  config.faults.validate();
  return config;
}

void PipelineOptions::validate() const {
  encoder.validate();
  if (!(std::isfinite(sensitivity) && sensitivity >= 0.0)) {
    throw std::invalid_argument("--sensitivity must be a finite number >= 0");
  }
  if (!(std::isfinite(refresh_hz) && refresh_hz > 0.0)) {
    throw std::invalid_argument("--refresh must be a positive number of Hz");
  }
  if (frames < 0) throw std::invalid_argument("--frames must be >= 0");
  if (output_bits != 8 && output_bits != 10) throw std::invalid_argument("output bits must be 8 or 10");
  if (impl != "reference" && impl != "fixed" && impl != "fixed-frame") {
    throw std::invalid_argument("unknown decoder implementation '" + impl + "' (available: reference, fixed, fixed-frame)");
  }
  (void)parse_panel(panel);
  if (link_enabled()) (void)link_config(width, height);
  if (input.empty()) {
    bool known = false;
    for (const auto& name : scene_names()) known = known || name == scene;
    if (!known) {
      std::string list;
      for (const auto& name : scene_names()) list += (list.empty() ? "" : ", ") + name;
      throw std::invalid_argument("unknown scene '" + scene + "' (available: " + list + ")");
    }
  }
}

PipelineResult run_pipeline(const PipelineOptions& options, const std::function<void(const DecodedView&)>& sink) {
  options.validate();
  const std::unique_ptr<FrameSource> source = options.open_source();

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

  TrmEncoder encoder(options.encoder);
  DecoderConfig decoder_config;
  decoder_config.link = options.encoder;
  decoder_config.sensitivity = options.sensitivity;
  decoder_config.panel = parse_panel(options.panel);
  decoder_config.output_bits = options.output_bits;
  decoder_config.lcd_history = options.lcd_history;
  ReferenceDecoder decoder(decoder_config);
  const FixedDecoderConfig fixed_config = fixed_config_of(options);
  std::optional<FixedStreamingDecoder> streaming;
  std::optional<FixedFrameDecoder> frame_at_a_time;
  if (options.impl == "fixed") streaming.emplace(fixed_config);
  if (options.impl == "fixed-frame") frame_at_a_time.emplace(fixed_config);
  const bool fixed = streaming || frame_at_a_time;
  const bool compare = fixed && options.compare_reference;
  // LCD codes compared free-running drift apart by the design's neutral mode (see adopt_panel_history); the
  // synchronised comparison is the criterion, the free-running one is reported beside it.
  std::optional<ReferenceDecoder> free_running;
  if (compare && decoder_config.panel.kind == PanelKind::Lcd) free_running.emplace(decoder_config);

  std::optional<link::LinkSimulation> simulation;
  PipelineResult result;
  if (options.link_enabled()) {
    link::LinkSimulationConfig config = options.link_config(source->width(), source->height());
    if (!options.capture_out.empty()) {
      config.capture = options.capture_out;
      config.capture_metadata = capture_metadata(options);
    }
    simulation.emplace(std::move(config));
    result.link.emplace();
  }

  // The decoder under test; the reference beside it (compare) sees exactly the same input.
  const auto decode_whole = [&](const LinkFrame& frame) {
    if (streaming) return streaming->decode(frame);
    if (frame_at_a_time) return frame_at_a_time->decode(frame);
    return decoder.decode(frame);
  };
  const auto decode_partial = [&](const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
    if (streaming) return streaming->decode(frame, line_intact);
    if (frame_at_a_time) return frame_at_a_time->decode(frame, line_intact);
    return decoder.decode(frame, line_intact);
  };
  const auto decode_lost = [&](const FrameMeta& meta) {
    if (streaming) return streaming->decode_lost(meta);
    if (frame_at_a_time) return frame_at_a_time->decode_lost(meta);
    return decoder.decode_lost(meta);
  };
  const int eyes = options.encoder.stereo ? 2 : 1;
  std::vector<LinkFrame> sent(static_cast<std::size_t>(eyes));
  std::vector<double> encode_seconds(static_cast<std::size_t>(eyes));
  for (std::int64_t t = 0; t < frames; ++t) {
    const auto render_start = std::chrono::steady_clock::now();
    const cv::Mat linear = source->linear_frame(t);
    const double render_seconds = seconds_since(render_start);
    for (int eye = 0; eye < eyes; ++eye) {
      const auto start = std::chrono::steady_clock::now();
      sent[static_cast<std::size_t>(eye)] = encoder.encode(linear, t, eye);
      encode_seconds[static_cast<std::size_t>(eye)] = seconds_since(start);
    }
    std::vector<link::ReceivedFrame> received;
    if (simulation) received = simulation->carry(t, sent);
    for (int eye = 0; eye < eyes; ++eye) {
      const LinkFrame& view_sent = sent[static_cast<std::size_t>(eye)];
      const auto start = std::chrono::steady_clock::now();
      DecodedFrame decoded;
      DecodedFrame reference;
      DecodedFrame free_running_reference;
      double decode_seconds = 0.0;  // of the decoder under test, not of the reference beside it
      if (simulation) {
        const link::ReceivedFrame* arrived = nullptr;
        for (const auto& r : received) {
          if (r.meta.eye == eye && r.meta.index == t) arrived = &r;
        }
        if (arrived) {
          const LinkFrame frame{arrived->meta, arrived->codes};
          decoded = decode_partial(frame, arrived->line_intact);
          decode_seconds = seconds_since(start);
          if (compare) {
            reference = decoder.decode(frame, arrived->line_intact);
            if (free_running) {
              decoder.adopt_panel_history(decoded);
              free_running_reference = free_running->decode(frame, arrived->line_intact);
            }
          }
        } else {
          decoded = decode_lost(view_sent.meta);
          decode_seconds = seconds_since(start);
          if (compare) reference = decoder.decode_lost(view_sent.meta);
          if (free_running) free_running_reference = free_running->decode_lost(view_sent.meta);
          ++result.link->lost_views;
        }
        result.link->concealed_lines += decoded.stats.concealed_lines;
      } else {
        decoded = decode_whole(view_sent);
        decode_seconds = seconds_since(start);
        if (compare) {
          reference = decoder.decode(view_sent);
          if (free_running) {
            decoder.adopt_panel_history(decoded);
            free_running_reference = free_running->decode(view_sent);
          }
        }
      }
      DecodedView view;
      view.source = source.get();
      view.linear_full = &linear;
      view.sent = &view_sent;
      view.decoded = &decoded;
      if (compare) view.reference = &reference;
      if (free_running) view.free_running_reference = &free_running_reference;
      if (fixed) view.fixed_counts = streaming ? &streaming->last_counts() : &frame_at_a_time->last_counts();
      view.render_seconds = render_seconds;
      view.encode_seconds = encode_seconds[static_cast<std::size_t>(eye)];
      view.decode_seconds = decode_seconds;
      sink(view);
    }
  }
  result.frames = frames;
  if (streaming) result.hardware = streaming->report(cv::Size(source->width(), source->height()));
  if (simulation) {
    simulation->finish();
    result.link->frames = simulation->meter().frames();
    result.link->summary = simulation->meter().summary();
    result.link->receiver = simulation->receiver_counters();
    result.link->faults = simulation->fault_counters();
    result.link->budget = simulation->meter().budget();
  }
  return result;
}

CaptureDecodeResult decode_capture_stream(
    const PipelineOptions& options, const std::string& capture_path,
    const std::function<void(const link::ReceivedFrame& received, const DecodedFrame& decoded)>& sink) {
  link::CaptureReplay replay(capture_path);
  nlohmann::json meta;
  try {
    meta = nlohmann::json::parse(replay.metadata());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("capture '" + capture_path + "' has no readable configuration in its header: " + e.what());
  }
  DecoderConfig config;
  try {
    config.link.reduction = meta.at("reduction").get<double>();
    config.link.sigma = meta.at("sigma").get<double>();
    config.link.phase = meta.at("phase").get<int>();
    config.link.transfer = parse_transfer(meta.at("transfer").get<std::string>());
    config.link.resample_space = parse_resample_space(meta.at("resample_space").get<std::string>());
    config.link.bits = meta.at("bits").get<int>();
    config.link.stereo = meta.at("stereo").get<bool>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("capture '" + capture_path + "': incomplete configuration in its header: " + e.what());
  }
  config.sensitivity = options.sensitivity;
  config.panel = parse_panel(options.panel);
  config.output_bits = options.output_bits;
  config.lcd_history = options.lcd_history;
  // The selected implementation; the fixed-point ones take the capture's link configuration as well.
  std::optional<ReferenceDecoder> reference;
  std::optional<FixedStreamingDecoder> streaming;
  std::optional<FixedFrameDecoder> frame_at_a_time;
  PipelineOptions fixed_options = options;
  fixed_options.encoder = config.link;
  if (options.impl == "fixed") {
    streaming.emplace(fixed_config_of(fixed_options));
  } else if (options.impl == "fixed-frame") {
    frame_at_a_time.emplace(fixed_config_of(fixed_options));
  } else {
    reference.emplace(config);
  }

  CaptureDecodeResult result;
  result.link_configuration = meta.dump();
  while (auto received = replay.next_frame()) {
    const LinkFrame frame{received->meta, received->codes};
    const DecodedFrame decoded = streaming         ? streaming->decode(frame, received->line_intact)
                                 : frame_at_a_time ? frame_at_a_time->decode(frame, received->line_intact)
                                                   : reference->decode(frame, received->line_intact);
    result.concealed_lines += decoded.stats.concealed_lines;
    ++result.views;
    sink(*received, decoded);
  }
  if (result.views == 0) throw std::runtime_error("capture '" + capture_path + "' holds no frames");
  result.receiver = replay.counters();
  return result;
}

}  // namespace trm::cli
