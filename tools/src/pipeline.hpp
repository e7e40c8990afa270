// The simulation pipeline shared by `trm run`, `trm decode` and `trm feed`: a frame source, the GPU-side
// encoder, and a decoder, producing panel drive frames in order.
#pragma once

#include "trm/encoder.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/scene.hpp"

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
  std::string panel = "vive";
  int output_bits = 8;
  std::string impl = "reference";
  LcdHistory lcd_history = LcdHistory::Wanted;

  // Adds the shared options (--scene --input --image --frames --size --refresh --reduction --sigma
  // --phase --transfer --resample-space --bits --stereo --sensitivity --panel --output-bits --seed)
  // to a subcommand.
  void add_options(CLI::App& cmd);
  // Validates everything up front (throws std::invalid_argument with one clear message).
  void validate() const;
};

// One decoded view, as the pipeline hands it to a sink.
struct DecodedView {
  const FrameSource* source = nullptr;
  const cv::Mat* linear_full = nullptr;   // what was rendered (full resolution, linear)
  const LinkFrame* sent = nullptr;        // what crossed the link
  const DecodedFrame* decoded = nullptr;  // what the decoder produced
  double encode_seconds = 0.0;
  double decode_seconds = 0.0;
};

// Runs source -> encoder -> decoder for every frame and eye, calling sink for each view in order.
// Returns the number of link frames processed.
std::int64_t run_pipeline(const PipelineOptions& options, const std::function<void(const DecodedView&)>& sink);

}  // namespace trm::cli
