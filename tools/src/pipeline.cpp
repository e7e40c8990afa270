#include "pipeline.hpp"

#include "hw_report.hpp"

#include "trm/resample.hpp"

#include <nlohmann/json.hpp>

#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <span>
#include <sstream>
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
std::string capture_metadata(const PipelineOptions& options, std::int64_t frames) {
  nlohmann::ordered_json meta;
  meta["reduction"] = options.encoder.reduction;
  meta["sigma"] = options.encoder.effective_sigma();
  meta["phase"] = options.encoder.phase;
  meta["transfer"] = to_string(options.encoder.transfer);
  meta["resample_space"] = to_string(options.encoder.resample_space);
  meta["bits"] = options.encoder.bits;
  meta["stereo"] = options.encoder.stereo;
  meta["refresh_hz"] = options.refresh_hz;
  meta["frames"] = frames;  // link frames the run sends: views lost at the end of a capture are known too
  return meta.dump();
}

// A library parser's std::invalid_argument, reported as an error of the option that gave the text.
template <class Parse>
std::function<void(const std::string&)> option_parser(const std::string& option, Parse parse) {
  return [option, parse](const std::string& text) {
    try {
      parse(text);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError(option, e.what());
    }
  };
}

// Peak resident memory of a run per pixel of the view, measured with /usr/bin/time on `trm run` at 256x256 and
// 1024x1024 (the fixed decoder beside the reference, every frame store and stage image): about 450 B with an OLED,
// 720 B with an LCD (its panel history and shortfall images), a stereo run 1.55 times a mono one; plus about 100 MB
// of program and ROMs. Used only to refuse, up front, runs that cannot fit.
constexpr double kRunBaseBytes = 100e6;
constexpr double kRunBytesPerPixelOled = 450.0;
constexpr double kRunBytesPerPixelLcd = 720.0;
constexpr double kRunStereoFactor = 1.55;

std::optional<double> available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0.0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024.0;
  }
  return std::nullopt;
}

std::string gigabytes(double bytes) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(bytes < 10e9 ? 2 : 1) << bytes / 1e9 << " GB";
  return text.str();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

double run_bytes_per_pixel(const PipelineOptions& options) {
  const bool lcd = options.panel.has_history();
  return (lcd ? kRunBytesPerPixelLcd : kRunBytesPerPixelOled) * (options.encoder.stereo ? kRunStereoFactor : 1.0);
}

void require_memory(const std::string& what, double bytes_per_pixel, cv::Size view) {
  const std::optional<double> available = available_memory_bytes();
  if (!available) return;  // no /proc: nothing to compare with
  const double needed = kRunBaseBytes + bytes_per_pixel * static_cast<double>(view.width) * view.height;
  if (needed > *available) {
    throw std::runtime_error("a " + std::to_string(view.width) + "x" + std::to_string(view.height) + " view needs about " +
                             gigabytes(needed) + " of memory (about " +
                             std::to_string(static_cast<long long>(bytes_per_pixel)) + " B per pixel " + what +
                             "), but only " + gigabytes(*available) + " is available: use a smaller --size");
  }
}

CLI::Validator whole_number_at_least(long long lowest, const std::string& meaning) {
  return CLI::Validator(
      [lowest, meaning](std::string& text) -> std::string {
        long long value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error == std::errc::result_out_of_range) return "'" + text + "' is out of range";
        if (error != std::errc() || end != text.data() + text.size()) return "'" + text + "' is not a whole number";
        if (value < lowest) return "must be >= " + std::to_string(lowest) + meaning + ", got " + text;
        return "";
      },
      "N >= " + std::to_string(lowest));
}

CLI::Validator finite_non_negative(const std::string& meaning) {
  return CLI::Validator(
      [meaning](std::string& text) -> std::string {
        double value = 0.0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error != std::errc() || end != text.data() + text.size()) return "'" + text + "' is not a number";
        if (!std::isfinite(value) || value < 0.0) return "must be a finite number >= 0" + meaning + ", got " + text;
        return "";
      },
      "X >= 0");
}

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
                                         std::to_string(default_frames) + " for a scene)")
      ->check(whole_number_at_least(1, " (leave --frames out for every input frame)"));
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
      "--transfer", option_parser("--transfer", [this](const std::string& s) { encoder.transfer = parse_transfer(s); }),
      "Link transfer function: srgb (default) or gamma2.2");
  cmd.add_option_function<std::string>(
      "--resample-space",
      option_parser("--resample-space", [this](const std::string& s) { encoder.resample_space = parse_resample_space(s); }),
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
  cmd.add_option_function<std::string>(
         "--panel", [this](const std::string& spec) { panel = parse_panel(spec); },
         "vive | rift | generic | gamma:G | gamma:GR,GG,GB | lcd | lcd:p1,p2,p3,p4,gamma")
      ->default_str(panel.name);
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
  validate_refresh_hz(refresh_hz, "--refresh");
  if (frames < 0) throw std::invalid_argument("--frames must be >= 0");
  if (output_bits != 8 && output_bits != 10) throw std::invalid_argument("output bits must be 8 or 10");
  try {
    check_decoder_name(impl);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--impl: ") + e.what());
  }
  // The decoder's whole configuration, before any output exists: the fixed-point formats only for those decoders.
  const FixedDecoderConfig decoder_config = fixed_config_of(*this);
  if (impl == "reference") decoder_config.decoder.validate(); else decoder_config.validate();
  // Link and fault options are checked whether or not they switch the link on (--ber -1 is an error either way).
  (void)link_config(width, height);
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

  TrmEncoder encoder(options.encoder);
  const FixedDecoderConfig fixed_config = fixed_config_of(options);
  const DecoderConfig& decoder_config = fixed_config.decoder;
  const std::unique_ptr<HeadsetDecoder> decoder = make_decoder(options.impl, fixed_config);
  // The reference beside a fixed-point decoder sees exactly the same input.
  const bool compare = options.compare_reference && options.impl != "reference";
  std::optional<ReferenceDecoder> reference_beside;
  if (compare) reference_beside.emplace(decoder_config);
  // LCD codes compared free-running drift apart by the design's neutral mode (see adopt_panel_history); the
  // synchronised comparison is the criterion, the free-running one is reported beside it.
  std::optional<ReferenceDecoder> free_running;
  if (compare && decoder_config.panel.has_history()) free_running.emplace(decoder_config);

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
    if (simulation) {
      received = simulation->carry(t, sent);
      if (link_sink) link_sink(simulation->meter().last());
    }
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
          decoded = decoder->decode(frame, arrived->line_intact);
          decode_seconds = seconds_since(start);
          if (compare) {
            reference = reference_beside->decode(frame, arrived->line_intact);
            if (free_running) {
              reference_beside->adopt_panel_history(decoded);
              free_running_reference = free_running->decode(frame, arrived->line_intact);
            }
          }
        } else {
          decoded = decoder->decode_lost(view_sent.meta);
          decode_seconds = seconds_since(start);
          if (compare) reference = reference_beside->decode_lost(view_sent.meta);
          if (free_running) free_running_reference = free_running->decode_lost(view_sent.meta);
          ++result.link->lost_views;
        }
        result.link->concealed_lines += decoded.stats.concealed_lines;
      } else {
        decoded = decoder->decode(view_sent);
        decode_seconds = seconds_since(start);
        if (compare) {
          reference = reference_beside->decode(view_sent);
          if (free_running) {
            reference_beside->adopt_panel_history(decoded);
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
      view.fixed_counts = decoder->stage_counts();
      view.render_seconds = render_seconds;
      view.encode_seconds = encode_seconds[static_cast<std::size_t>(eye)];
      view.decode_seconds = decode_seconds;
      sink(view);
    }
  }
  result.frames = frames;
  if (FixedStreamingReport hardware; decoder->hardware_report(cv::Size(source->width(), source->height()), hardware)) {
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

CaptureDecodeResult decode_capture_stream(const PipelineOptions& options, const std::string& capture_path,
                                          const CaptureSink& sink) {
  link::CaptureReplay replay(capture_path);
  const std::string where = "capture '" + capture_path + "': ";
  nlohmann::json meta;
  try {
    meta = nlohmann::json::parse(replay.metadata());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + "no readable configuration in its header: " + e.what());
  }
  // The link configuration comes from the header, checked as strictly as the command line that wrote it; panel,
  // sensitivity, output bits and fixed-point formats come from the options.
  PipelineOptions capture_options = options;
  EncoderConfig& link = capture_options.encoder;
  std::optional<std::int64_t> frames_sent;
  try {
    if (!meta.is_object()) throw std::invalid_argument("the header's configuration is not a JSON object");
    link.reduction = meta.at("reduction").get<double>();
    link.sigma = meta.at("sigma").get<double>();
    link.phase = meta.at("phase").get<int>();
    link.transfer = parse_transfer(meta.at("transfer").get<std::string>());
    link.resample_space = parse_resample_space(meta.at("resample_space").get<std::string>());
    link.bits = meta.at("bits").get<int>();
    link.stereo = meta.at("stereo").get<bool>();
    link.validate();
    validate_refresh_hz(meta.at("refresh_hz").get<double>(), "refresh_hz");
    if (meta.contains("frames")) {
      frames_sent = meta.at("frames").get<std::int64_t>();
      if (*frames_sent < 1) throw std::invalid_argument("frames must be >= 1");
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + "incomplete configuration in its header: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + "invalid configuration in its header: " + e.what());
  }
  const std::unique_ptr<HeadsetDecoder> decoder = make_decoder(options.impl, fixed_config_of(capture_options));

  // Views in link order: (t, eye) as t * eyes + eye. A view that lost every packet never comes out of the receiver;
  // the panel holds its previous output for it, and it is decoded and handed on as lost.
  const int eyes = link.stereo ? 2 : 1;
  std::int64_t next_view = 0;
  cv::Size full_size;
  bool right_eye_arrived = false;
  CaptureDecodeResult result;
  result.link_configuration = meta.dump();
  const auto hand_on_lost_views_before = [&](std::int64_t view_number) {
    for (; next_view < view_number; ++next_view) {
      FrameMeta lost;
      lost.index = next_view / eyes;
      lost.eye = static_cast<int>(next_view % eyes);
      lost.parity = parity_of(lost.index, lost.eye, link);
      lost.full_width = full_size.width;
      lost.full_height = full_size.height;
      const bool full = lost.parity == Parity::Full;
      lost.width = full ? full_size.width : reduced_size(full_size.width, link.reduction);
      lost.height = full ? full_size.height : reduced_size(full_size.height, link.reduction);
      lost.bits = link.bits;
      lost.transfer = link.transfer;
      const DecodedFrame decoded = decoder->decode_lost(lost);
      ++result.views;
      ++result.lost_views;
      sink(lost, nullptr, decoded);
    }
  };
  while (auto received = replay.next_frame()) {
    const FrameMeta& m = received->meta;
    if (m.eye >= eyes) {
      throw std::runtime_error(where + "holds a view of eye " + std::to_string(m.eye) + " (stream " +
                               std::to_string(m.eye) + ") but its header says " + (eyes == 1 ? "mono" : "stereo"));
    }
    if (m.parity != parity_of(m.index, m.eye, link)) {
      throw std::runtime_error(where + "view t=" + std::to_string(m.index) + " eye " + std::to_string(m.eye) +
                               " is sent " + to_string(m.parity) + ", but the header's phase " +
                               std::to_string(link.phase) + " makes it " +
                               to_string(parity_of(m.index, m.eye, link)));
    }
    const std::int64_t view_number = m.index * eyes + m.eye;
    if (view_number < next_view) {
      throw std::runtime_error(where + "view t=" + std::to_string(m.index) + " eye " + std::to_string(m.eye) +
                               " arrives after a later one");
    }
    if (frames_sent && m.index >= *frames_sent) {
      throw std::runtime_error(where + "view t=" + std::to_string(m.index) + " lies beyond the " +
                               std::to_string(*frames_sent) + " frames its header says were sent");
    }
    if (full_size.empty()) full_size = cv::Size(m.full_width, m.full_height);
    if (m.eye == 1) right_eye_arrived = true;
    hand_on_lost_views_before(view_number);
    const LinkFrame frame{m, received->codes};
    const DecodedFrame decoded = decoder->decode(frame, received->line_intact);
    result.concealed_lines += decoded.stats.concealed_lines;
    ++result.views;
    ++next_view;
    sink(m, &*received, decoded);
  }
  if (full_size.empty()) throw std::runtime_error(where + "holds no frame that arrived");
  if (eyes == 2 && !right_eye_arrived) {
    throw std::runtime_error(where + "its header says stereo, but no view of eye 1 (stream 1) arrived: a mono stream");
  }
  if (frames_sent) hand_on_lost_views_before(*frames_sent * eyes);
  result.receiver = replay.counters();
  return result;
}

}  // namespace trm::cli
