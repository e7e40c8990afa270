// The options every command that runs the pipeline shares, registered, validated and turned into configurations in
// one place: the scene or input, the encoder, the display method, the decoder and its fixed-point formats, the link.
#pragma once

#include "trm/cli.hpp"
#include "trm/display_method.hpp"
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/link_simulation.hpp"
#include "trm/scene.hpp"
#include "view_size.hpp"

#include <memory>
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
  double motion_scale = 1.0;          // SceneParams::motion_scale (set by trm compare --speed)
  double pixels_per_degree = viewer_preset("vive").pixels_per_degree;  // the viewer (set by trm compare --viewer/--ppd)
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
  int threads = 1;                    // fixed impl: FixedDecoderConfig::threads
  bool report_planes = true;          // DecoderConfig::report_planes (not an option: trm feed,
                                      // whose rig takes the drive codes alone, turns them off)
  bool motion_weight_statistics = true;  // fixed impl: FixedDecoderConfig::motion_weight_statistics (likewise)

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

// The decoder configuration of the shared pipeline options (link, sensitivity, panel, output bits, LCD history,
// residual width, skipping) with the default fixed-point formats.
FixedDecoderConfig fixed_config_of(const PipelineOptions& options);

// Residual store of total signed width `bits` (sQ2.(bits - 2)); throws std::invalid_argument outside
// [3, 2 + linear_frac_bits] (and 32).
fx::RuntimeFormat residual_format_of_bits(int bits, int linear_frac_bits);

// Peak memory of a pipeline run per pixel of the view (measured; see pipeline.cpp), and the check every command that
// allocates per pixel makes before it starts: throws std::runtime_error saying how much the view needs and how much
// this machine has (MemAvailable) when about 100 MB + bytes_per_pixel W H does not fit.
double run_bytes_per_pixel(const PipelineOptions& options);
void require_memory(const std::string& what, double bytes_per_pixel, cv::Size view);

// Option checks with exact messages: a whole number >= `lowest`, and a finite number >= 0. `meaning` follows the
// rule in the message (e.g. "; leave --frames out for every input frame").
CLI::Validator whole_number_at_least(long long lowest, const std::string& meaning = "");
CLI::Validator finite_non_negative(const std::string& meaning = "");

}  // namespace trm::cli
