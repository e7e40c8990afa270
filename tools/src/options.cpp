#include "options.hpp"

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
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

FixedDecoderConfig fixed_config_of(const PipelineOptions& options) {
  FixedDecoderConfig config;
  config.decoder.link = options.encoder;
  config.decoder.sensitivity = options.sensitivity;
  config.decoder.panel = options.panel;
  config.decoder.output_bits = options.output_bits;
  config.decoder.lcd_history = options.lcd_history;
  config.skip_unneeded = !options.no_skip;
  config.threads = options.threads;
  config.decoder.report_planes = options.report_planes;
  config.motion_weight_statistics = options.motion_weight_statistics;
  if (options.residual_bits != 0) config.residual = residual_format_of_bits(options.residual_bits, config.linear_frac_bits);
  return config;
}

fx::RuntimeFormat residual_format_of_bits(int bits, int linear_frac_bits) {
  const int highest = std::min(32, 2 + linear_frac_bits);
  if (bits < 3 || bits > highest) {
    throw std::invalid_argument("--residual-bits " + std::to_string(bits) + " is out of range: the residual store is "
                                "sQ2.(N - 2) (rho in [-1, 1] needs a sign and an integer bit, at most " +
                                std::to_string(linear_frac_bits) + " fraction bits), so N must be in [3, " +
                                std::to_string(highest) + "]");
  }
  return fx::RuntimeFormat{2, bits - 2, true, fx::Quant::Rnd, fx::Overflow::Sat};
}

std::unique_ptr<FrameSource> PipelineOptions::open_source() const {
  if (!input.empty()) return looks_like_image_sequence(input) ? open_image_sequence(input) : open_video(input);
  SceneParams params;
  params.width = width;
  params.height = height;
  params.refresh_hz = refresh_hz;
  params.seed = seed;
  params.image_path = image;
  params.motion_scale = motion_scale;
  return make_scene(scene, params);
}

void PipelineOptions::add_options(CLI::App& cmd) {
  cmd.add_option("--scene", scene, "Built-in scene (discs, text, panorama, line, zoneplate, checker, flash, static, jitter, headturn, square)")
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
         "vive | rift | generic | gamma:G | gamma:GR,GG,GB | lcd | lcd:p1,p2,p3,p4,gamma | "
         "lcd:FILE.json (a preset of trm calibrate)")
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
  cmd.add_option("--threads", threads,
                 "Fixed-point streaming decoder: threads per view (bands of output lines, each with its own line "
                 "buffers); the output is bit-identical for every count")
      ->check(CLI::Range(1, kMaxDecoderThreads))
      ->capture_default_str();
  cmd.add_option_function<std::string>(
         "--impl",
         [this](const std::string& name) {
           impl = name;
           impl_given = true;
         },
         "Decoder of the methods that send TRM frames (trm, ncsfi, kim-trm): reference (double), fixed (fixed-point, "
         "line-buffered streaming: the hardware model) or fixed-frame (the same arithmetic frame at a time); each "
         "conceals lines and views lost on the link")
      ->default_str(impl);
}

void PipelineOptions::add_method_option(CLI::App& cmd) {
  cmd.add_option("--method", method,
                 "Display method: trm, full, half-rate, interlace[:double], bfi, ncsfi, didyk[:N|:hold|:N-hold], "
                 "kim[:OPTIONS], kim-trm[:OPTIONS] or reprojection (`trm methods` lists them)")
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
  setup.scene.refresh_hz = refresh_hz;
  setup.scene.pixels_per_degree = pixels_per_degree;
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

}  // namespace trm::cli
