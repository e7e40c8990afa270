// `trm decode`: the contract hardware users and independent checks rely on. Input PNGs are the GPU's
// full-resolution renders (sRGB-encoded); the encoder and decoder run on them and the panel drive of every
// frame is written as drive_NNNN.png (16 bit: round(v * 65535) of the unquantised drive) and
// driveB_NNNN.png (the B-bit drive codes; 10-bit codes are stored in a 16-bit PNG).
#include "commands.hpp"
#include "elapsed.hpp"
#include "output_dir.hpp"
#include "link_report.hpp"
#include "capture_replay.hpp"
#include "pipeline.hpp"
#include "run_report.hpp"

#include "trm/link_simulation.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

namespace trm::cli {

namespace {

std::string numbered(const std::string& prefix, std::int64_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%04lld.png", prefix.c_str(), static_cast<long long>(index));
  return name;
}

cv::Mat drive_16bit(const cv::Mat& drive) {
  cv::Mat out(drive.size(), CV_16UC3);
  for (int y = 0; y < drive.rows; ++y) {
    const auto* src = drive.ptr<cv::Vec3d>(y);
    auto* dst = out.ptr<cv::Vec3w>(y);
    for (int x = 0; x < drive.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        // round half up of v * 65535, v already in [0, 1]
        dst[x][c] = static_cast<std::uint16_t>(std::floor(std::clamp(src[x][c], 0.0, 1.0) * 65535.0 + 0.5));
      }
    }
  }
  return out;
}

// `trm decode --capture`: replays a recorded packet stream through the receiver into the --impl decoder. The link
// configuration (r, sigma, transfer, bits, ...) comes from the capture's header; panel, sensitivity and output
// bits from the command line.
// Writes frame t's drive_tttt.png (16-bit round(v * 65535)) and driveB_tttt.png (the B-bit codes; 8-bit codes as
// an 8-bit PNG); the right eye of a stereo stream gets a "_right" suffix.
void write_drive_files(const OutputDir& dir, const FrameMeta& meta, const DecodedFrame& decoded, int output_bits) {
  const std::string eye = meta.eye == 0 ? "" : "_right";
  dir.write_png(numbered("drive" + eye, meta.index), drive_16bit(decoded.drive));
  cv::Mat codes = decoded.drive_codes;
  if (output_bits == 8) codes.convertTo(codes, CV_8U);
  dir.write_png(numbered("drive" + std::to_string(output_bits) + eye, meta.index), codes);
}

int decode_capture(const PipelineOptions& options, const std::string& capture_path, const std::string& out) {
  OutputDir dir(out);
  JsonLinesWriter views(dir.file("views.jsonl"));
  const CaptureDecodeResult result =
      decode_capture_stream(options, capture_path, [&](const FrameMeta& meta, SlotOutcome outcome,
                                                       const link::ReceivedFrame* received, const DecodedFrame& decoded) {
        // A lost view is written too: it is what the panel shows (its previous output, held); so is a slot the
        // method sends nothing for.
        write_drive_files(dir, meta, decoded, options.output_bits);
        views.write({{"t", meta.index},
                     {"eye", meta.eye},
                     {"parity", to_string(meta.parity)},
                     {"sent", outcome != SlotOutcome::NotSent},
                     {"lost", outcome == SlotOutcome::Lost},
                     {"intact_lines", received ? received->intact_lines() : 0},
                     {"concealed_lines", decoded.stats.concealed_lines},
                     {"clipped_fraction", decoded.stats.clipped_fraction}});
      });
  views.close();
  const link::ReceiverCounters& c = result.receiver;
  Json report;
  report["tool"] = "trm";
  report["capture"] = capture_path;
  report["link_configuration"] = Json::parse(result.link_configuration);
  report["parameters"] = {{"sensitivity", options.sensitivity},
                          {"panel", options.panel},
                          {"output_bits", options.output_bits},
                          {"method", result.method},
                          {"impl", result.impl}};
  report["receiver"] = receiver_json(c);
  report["summary"] = {
      {"views", result.views}, {"lost_views", result.lost_views}, {"concealed_lines", result.concealed_lines}};
  report["records"] = {{"views", views.file_name()}};
  dir.write_text("report.json", report.dump(2) + "\n");
  dir.commit();
  std::cout << "trm decode: " << result.views << " views from " << capture_path << " -> " << dir.target().string()
            << "/ (" << c.crc_failures << " damaged packets, " << result.concealed_lines << " lines concealed, "
            << result.lost_views << " views lost and held)\n";
  return 0;
}

}  // namespace

void register_decode(CLI::App& app, Action& action) {
  auto options = std::make_shared<PipelineOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "decode", "Encode and decode an input sequence, writing the panel drive of every frame (drive_*.png, drive8_*.png "
                "or drive10_*.png) and report.json");
  auto capture = std::make_shared<std::string>();
  options->add_options(*cmd);
  options->add_method_option(*cmd);
  cmd->add_option("--capture", *capture,
                  "Decode a recorded packet stream (.trmcap) instead of --input, with the --impl decoder (lost lines "
                  "concealed)")
      ->excludes(cmd->get_option("--input"));
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->required();
  cmd->callback([options, out, capture, &action] {
    action = [options, out, capture] {
      if (!capture->empty()) {
        options->validate();
        return decode_capture(*options, *capture, *out);
      }
      if (options->input.empty()) throw std::invalid_argument("decode needs --input GLOB or --capture FILE");
      options->validate();
      if (options->refresh_hz < 90.0) {
        std::cerr << "trm: warning: refresh " << options->refresh_hz << " Hz is below 90 Hz: expect visible flicker\n";
      }
      const auto start = std::chrono::steady_clock::now();
      OutputDir dir(*out);
      RunRecorder recorder(*options, dir.staging());
      const std::int64_t frames = run_pipeline(*options, [&](const DecodedView& view) {
        recorder.add(view);
        write_drive_files(dir, view.slot, *view.decoded, options->output_bits);
      }).frames;
      recorder.close();
      const double wall = seconds_since(start);
      dir.write_text("report.json", recorder.report(wall).dump(2) + "\n");
      dir.commit();
      std::cout << "trm decode: " << frames << " frames -> " << dir.target().string() << "/\n"
                << recorder.summary_table();
      return 0;
    };
  });
}

}  // namespace trm::cli
