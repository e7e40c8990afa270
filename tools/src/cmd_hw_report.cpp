// `trm hw-report`: the decoder as hardware for one configuration and view size: line buffers, frame stores, ROMs,
// arithmetic per stage, latency, on-/off-chip totals and the paper's frame-store comparison (DESIGN §5).
#include "commands.hpp"
#include "hw_report.hpp"
#include "output_dir.hpp"

#include "trm/atomic_file.hpp"
#include "trm/decoder_json.hpp"

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace trm::cli {

void register_hw_report(CLI::App& app, Action& action) {
  auto options = std::make_shared<PipelineOptions>();
  auto out = std::make_shared<std::string>();
  auto json = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "hw-report", "Report the fixed-point decoder as hardware: line buffers, frame stores, ROMs, arithmetic per "
                   "stage, latency and memory totals (default 1080x1200, r = 1/2, vive OLED)");
  options->add_options(*cmd);
  cmd->add_option("--out,-o", *out, "Also write DIR/report.json (directory written whole or not at all)");
  cmd->add_option("--json", *json, "Also write the JSON to FILE");
  cmd->callback([options, out, json, &action] {
    action = [options, out, json] {
      options->validate();
      if (!json->empty()) io::check_file_target(*json);  // before --out is replaced
      FixedDecoderConfig config = fixed_config_of(*options);
      const FixedStreamingDecoder decoder(config);  // validates the configuration
      const cv::Size size(options->width, options->height);
      const Json report = hw_report_json(config, size, decoder.report(size));
      const std::string text = report.dump(2) + "\n";
      if (!out->empty()) {
        OutputDir dir(*out);
        dir.write_text("report.json", text);
        dir.commit();
      }
      if (!json->empty()) io::write_file_atomically(*json, text);
      std::cout << "trm hw-report: " << options->panel.name << ", r = " << options->encoder.reduction << " ("
                << to_string(options->encoder.resample_space) << " resample space), "
                << options->encoder.bits << "-bit link, " << options->output_bits << "-bit drive, residual "
                << config.residual.to_string() << "\n"
                << hardware_summary(report["hardware"]);
      return 0;
    };
  });
}

}  // namespace trm::cli
