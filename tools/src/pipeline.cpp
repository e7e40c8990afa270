#include "pipeline.hpp"

#include "hw_report.hpp"

#include "trm/encoder_json.hpp"
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
  nlohmann::ordered_json meta = encoder_json(options.encoder);
  meta["method"] = options.method;
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
  cmd.add_option_function<std::string>(
         "--impl",
         [this](const std::string& name) {
           impl = name;
           impl_given = true;
         },
         "Decoder of the methods that send TRM frames (trm, ncsfi): reference (double), fixed (fixed-point, "
         "line-buffered streaming: the hardware model) or fixed-frame (the same arithmetic frame at a time); each "
         "conceals lines and views lost on the link")
      ->default_str(impl);
}

void PipelineOptions::add_method_option(CLI::App& cmd) {
  cmd.add_option("--method", method,
                 "Display method: trm, full, half-rate, interlace[:double], bfi or ncsfi (`trm methods` lists them)")
      ->capture_default_str();
}

std::string PipelineOptions::method_impl() const {
  return find_display_method(method).method->fixed_point ? impl : "reference";
}

MethodSetup PipelineOptions::method_setup() const {
  MethodSetup setup;
  setup.decoder = fixed_config_of(*this);
  setup.impl = method_impl();
  setup.option = find_display_method(method).option;
  return setup;
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
  try {
    check_display_method(method, impl_given ? impl : method_impl());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--method: ") + e.what());
  }
  // The decoder's whole configuration, before any output exists: the fixed-point formats only for those decoders.
  const FixedDecoderConfig decoder_config = fixed_config_of(*this);
  if (method_impl() == "reference") decoder_config.decoder.validate(); else decoder_config.validate();
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

  const MethodSetup setup = options.method_setup();
  const MethodChoice method = find_display_method(options.method);
  const std::unique_ptr<MethodSender> sender = method.method->make_sender(setup);
  const std::unique_ptr<MethodDisplay> display = method.method->make_display(setup);
  HeadsetDecoder* const decoder = display->decoder();  // the TRM decoder inside, if the method has one
  // The reference beside a fixed-point decoder sees exactly the same input.
  const bool compare = options.compare_reference && decoder != nullptr && setup.impl != "reference";
  MethodSetup reference_setup = setup;
  reference_setup.impl = "reference";
  std::unique_ptr<MethodDisplay> reference_beside;
  if (compare) reference_beside = method.method->make_display(reference_setup);
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
    link = encoder_config_from_json(meta);
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
  // Captures written before display methods existed carry TRM frames.
  capture_options.method = meta.value("method", std::string("trm"));
  try {
    check_display_method(capture_options.method, capture_options.impl_given ? capture_options.impl
                                                                            : capture_options.method_impl());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + "its method: " + e.what());
  }
  const MethodSetup setup = capture_options.method_setup();
  const MethodChoice method = find_display_method(capture_options.method);
  // The sender is built only for its schedule: which views were sent at all, and what each looked like.
  const std::unique_ptr<MethodSender> schedule = method.method->make_sender(setup);
  const std::unique_ptr<MethodDisplay> display = method.method->make_display(setup);

  // Views in link order: (t, eye) as t * eyes + eye. A view that lost every packet never comes out of the receiver;
  // the panel holds its previous output for it, and it is decoded and handed on as lost. A slot the method sends
  // nothing for is shown as the method shows it and handed on as not sent.
  const int eyes = link.stereo ? 2 : 1;
  std::int64_t next_view = 0;
  cv::Size full_size;
  bool right_eye_arrived = false;
  CaptureDecodeResult result;
  result.link_configuration = meta.dump();
  result.method = capture_options.method;
  result.impl = setup.impl;
  const auto hand_on_views_before = [&](std::int64_t view_number) {
    for (; next_view < view_number; ++next_view) {
      const std::int64_t t = next_view / eyes;
      const int eye = static_cast<int>(next_view % eyes);
      ++result.views;
      if (!schedule->sends(t, eye)) {
        const FrameMeta slot = unsent_slot(t, eye, full_size, link);
        sink(slot, SlotOutcome::NotSent, nullptr, display->show_unsent(slot));
        continue;
      }
      const FrameMeta lost = schedule->view_meta(t, eye, full_size);
      ++result.lost_views;
      sink(lost, SlotOutcome::Lost, nullptr, display->show_lost(lost));
    }
  };
  while (auto received = replay.next_frame()) {
    const FrameMeta& m = received->meta;
    const std::string view = "view t=" + std::to_string(m.index) + " eye " + std::to_string(m.eye);
    if (m.eye >= eyes) {
      throw std::runtime_error(where + "holds a view of eye " + std::to_string(m.eye) + " (stream " +
                               std::to_string(m.eye) + ") but its header says " + (eyes == 1 ? "mono" : "stereo"));
    }
    if (!schedule->sends(m.index, m.eye)) {
      throw std::runtime_error(where + view + " arrived, but method '" + capture_options.method +
                               "' sends nothing there");
    }
    const FrameMeta expected = schedule->view_meta(m.index, m.eye, cv::Size(m.full_width, m.full_height));
    if (m.parity != expected.parity || m.width != expected.width || m.height != expected.height) {
      throw std::runtime_error(where + view + " is sent " + to_string(m.parity) + " " + std::to_string(m.width) + "x" +
                               std::to_string(m.height) + ", but the header's method '" + capture_options.method +
                               "' and phase " + std::to_string(link.phase) + " make it " + to_string(expected.parity) +
                               " " + std::to_string(expected.width) + "x" + std::to_string(expected.height));
    }
    const std::int64_t view_number = m.index * eyes + m.eye;
    if (view_number < next_view) throw std::runtime_error(where + view + " arrives after a later one");
    if (frames_sent && m.index >= *frames_sent) {
      throw std::runtime_error(where + view + " lies beyond the " + std::to_string(*frames_sent) +
                               " frames its header says were sent");
    }
    if (full_size.empty()) full_size = cv::Size(m.full_width, m.full_height);
    if (m.eye == 1) right_eye_arrived = true;
    hand_on_views_before(view_number);
    const DecodedFrame decoded = display->show(LinkFrame{m, received->codes}, received->line_intact);
    result.concealed_lines += decoded.stats.concealed_lines;
    ++result.views;
    ++next_view;
    sink(m, SlotOutcome::Arrived, &*received, decoded);
  }
  if (full_size.empty()) throw std::runtime_error(where + "holds no frame that arrived");
  if (eyes == 2 && !right_eye_arrived) {
    throw std::runtime_error(where + "its header says stereo, but no view of eye 1 (stream 1) arrived: a mono stream");
  }
  if (frames_sent) hand_on_views_before(*frames_sent * eyes);
  result.receiver = replay.counters();
  return result;
}

}  // namespace trm::cli
