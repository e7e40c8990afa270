// `trm compare`: every display method on the same scene, link and panel, as the paper's Table 1 with measured
// columns: compare.md, compare.csv and report.json in the output directory, the table on stdout.
#include "commands.hpp"
#include "compare.hpp"
#include "output_dir.hpp"
#include "run_report.hpp"

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <optional>

namespace trm::cli {

void register_compare(CLI::App& app, Action& action) {
  auto options = std::make_shared<CompareOptions>();
  options->pipeline.default_frames = 30;
  auto out = std::make_shared<std::string>("trm-compare");
  CLI::App* cmd = app.add_subcommand(
      "compare", "Run every display method (trm methods) on the same frames and compare them: pixels rendered and "
                 "sent, link bandwidth, luminance, flicker, MTCD, pair PSNR (default: discs, 1080x1200, 30 frames)");
  options->pipeline.add_options(*cmd);
  options->pipeline.add_link_options(*cmd);
  // Every method is shown by its double-precision headset side: the comparison is of methods, not decoders.
  cmd->remove_option(cmd->get_option("--impl"));
  cmd->add_option("--methods", options->methods, "Methods to compare, comma separated (default: every method)")
      ->delimiter(',');
  cmd->add_option("--viewer", options->viewer, "Eye's pixels per degree from a headset preset: vive, rift, monitor")
      ->capture_default_str();
  cmd->add_option("--ppd", options->ppd, "Pixels per degree (instead of --viewer's)");
  cmd->add_option("--speed", options->speed_deg_s,
                  "Speed of the pursued target in deg/s (every motion of the scene scaled alike; default: the scene's)");
  cmd->add_option("--substeps", options->substeps, "Retinal sub-frame steps S (default 16, docs/eye_model.md)");
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->capture_default_str();
  cmd->callback([options, out, &action] {
    action = [options, out] {
      options->validate();
      OutputDir dir(*out);
      const std::int64_t frames = options->pipeline.frames > 0 ? options->pipeline.frames : options->pipeline.default_frames;
      // The total is run_compare's: the chosen methods and, when `full` is not among them, the full-rate reference.
      std::optional<Progress> progress;
      const CompareResult result = run_compare(*options, [&](std::int64_t done, std::int64_t total) {
        if (!progress) progress.emplace(total);
        progress->update(done);
      });
      if (progress) progress->finish();
      dir.write_text("compare.md", compare_markdown(result));
      dir.write_text("compare.csv", compare_csv(result));
      dir.write_text("report.json", compare_json(result).dump(2) + "\n");
      for (std::size_t i = 0; i < result.figures.size(); ++i) {
        if (!result.figures[i].empty()) dir.write_png(figure_name(result.methods[i].method), result.figures[i]);
      }
      dir.commit();
      std::cout << "trm compare: " << (options->pipeline.input.empty() ? options->pipeline.scene : options->pipeline.input)
                << ", " << result.size.width << "x" << result.size.height << ", " << frames << " frames\n"
                << compare_table(result) << "  wrote " << dir.target().string()
                << "/ (compare.md, compare.csv, report.json, fig12_<method>.png)\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
