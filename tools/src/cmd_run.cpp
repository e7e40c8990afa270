// `trm run`: the main job. Renders a scene (or reads an input), runs the GPU-side encoder and the decoder,
// and writes report.json, the per-view and per-pair records (views.jsonl, pairs.jsonl, streamed as they come) and
// PNG previews of the first frame pair into the output directory.
#include "commands.hpp"
#include "elapsed.hpp"
#include "hw_report.hpp"
#include "link_report.hpp"
#include "output_dir.hpp"
#include "pipeline.hpp"
#include "run_report.hpp"

#include "trm/transfer.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <functional>
#include <memory>
#include <optional>

namespace trm::cli {

namespace {

cv::Mat codes_preview(const LinkFrame& frame) {
  // Link codes are encoded values: show them as they are, scaled to 8 bits.
  cv::Mat out;
  frame.codes.convertTo(out, CV_8U, 255.0 / (std::ldexp(1.0, frame.meta.bits) - 1.0));
  return out;
}

void warn_refresh(double refresh_hz) {
  if (refresh_hz < 90.0) {
    std::cerr << "trm: warning: refresh " << refresh_hz
              << " Hz is below 90 Hz: the full/reduced alternation will be seen as flicker "
                 "(TRM assumes >= 90 Hz, paper Sec. 4.1)\n";
  }
}

}  // namespace

void register_run(CLI::App& app, Action& action) {
  auto options = std::make_shared<PipelineOptions>();
  // The main job decodes with the hardware model and holds it to the reference beside it.
  options->impl = "fixed";
  options->compare_reference = true;
  auto out = std::make_shared<std::string>("trm-out");
  CLI::App* cmd = app.add_subcommand("run", "Run the whole chain on a scene or input and write a report (default: "
                                            "discs, 1080x1200, 90 Hz, r = 1/2, vive OLED)");
  options->add_options(*cmd);
  options->add_method_option(*cmd);
  options->add_link_options(*cmd);
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->capture_default_str();
  action = nullptr;
  cmd->callback([options, out, &action] {
    action = [options, out] {
      options->validate();
      warn_refresh(options->refresh_hz);
      const auto start = std::chrono::steady_clock::now();
      OutputDir dir(*out);
      RunRecorder recorder(*options, dir.staging());
      const std::int64_t total_views =
          (options->frames > 0 ? options->frames : options->default_frames) * (options->encoder.stereo ? 2 : 1);
      Progress progress(total_views);
      bool previews_written = false;
      std::int64_t done = 0;
      cv::Mat first_full_shown;
      LinkFrame first_full_sent;
      PipelineOptions run_options = *options;
      if (run_options.link_enabled() && run_options.capture_out.empty()) {
        run_options.capture_out = dir.file("link.trmcap").string();  // moves into place with the rest
      }
      std::optional<LinkRecorder> link_recorder;
      if (run_options.link_enabled()) link_recorder.emplace(dir, *options);
      std::function<void(const link::LinkFrameUsage&)> link_sink;
      if (link_recorder) link_sink = [&](const link::LinkFrameUsage& usage) { link_recorder->add(usage); };
      const PipelineResult result = run_pipeline(run_options, [&](const DecodedView& view) {
        const cv::Mat perceived = recorder.add(view);
        const FrameMeta& meta = view.slot;
        if (!previews_written && meta.eye == 0) {
          // The first pair of slots (TRM's full slot, then its reduced one), whatever the method sends in them.
          if (meta.parity == Parity::Full) {
            first_full_shown = view.decoded->wanted_linear.clone();
            first_full_sent = view.sent ? LinkFrame{meta, view.sent->codes.clone()} : LinkFrame{};
          } else if (!first_full_shown.empty() && !perceived.empty()) {
            if (!first_full_sent.codes.empty()) dir.write_png("pair_sent_full.png", codes_preview(first_full_sent));
            if (view.sent) dir.write_png("pair_sent_reduced.png", codes_preview(*view.sent));
            dir.write_png("pair_shown_beta.png", preview_8bit(first_full_shown));
            dir.write_png("pair_shown_alpha.png", preview_8bit(view.decoded->wanted_linear));
            dir.write_png("pair_perceived.png", preview_8bit(perceived));
            dir.write_png("pair_full_rate_reference.png", preview_8bit(recorder.last_reference_pair()));
            previews_written = true;
          }
        }
        progress.update(++done);
      }, link_sink);
      progress.finish();
      recorder.close();
      const double wall = seconds_since(start);
      Json report = recorder.report(wall);
      std::string link_lines;
      if (result.hardware) report["hardware"] = hardware_json(*result.hardware);
      if (result.link) {
        report["link"] = link_recorder->finish(*result.link, recorder.full_width(), recorder.full_height());
        report["records"]["link_frames"] = "frames.csv";
        link_lines = link_summary_lines(*result.link);
      }
      dir.write_text("report.json", report.dump(2) + "\n");
      dir.commit();
      std::cout << "trm run: " << (options->input.empty() ? options->scene : options->input) << "\n"
                << recorder.summary_table() << link_lines << "  wrote " << dir.target().string() << "/ (report.json"
                << (previews_written ? ", pair_*.png previews" : "") << ") in " << wall << " s\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
