// `trm analyze`: the supplement's parameter study (Figs. 2-4), Experiment 1 as a prediction (the paper's Fig. 11) and
// the supplement's §1.4 comparison of multiplexing cycles: analyze.md, study.csv, experiment1.csv, cycles.csv and
// the plots in one output directory, the headline figures on stdout.
#include "analyze.hpp"
#include "commands.hpp"
#include "output_dir.hpp"
#include "run_report.hpp"

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

namespace trm::cli {

void register_analyze(CLI::App& app, Action& action) {
  auto options = std::make_shared<AnalyzeOptions>();
  options->pipeline.default_frames = 8;
  // The paper's Experiment 1 monitor (Sec. 5): its scenes move in view widths per second.
  options->pipeline.width = 2560;
  options->pipeline.height = 1440;
  // An ideal gamma-2.2 panel, held for the whole frame (--persistence 1): the supplement's hold-type display.
  options->pipeline.panel = parse_panel("generic");
  // The supplement's model has no quantisation: 10-bit link and drive keep the rounding differences between TRM and
  // full rate, which show as a floor under the energy of low-contrast squares at 8 bits, four times lower.
  options->pipeline.encoder.bits = 10;
  options->pipeline.output_bits = 10;
  auto out = std::make_shared<std::string>("trm-analyze");
  CLI::App* cmd = app.add_subcommand(
      "analyze", "The supplement's parameter study (visual difference energy against pixels saved, Figs. 2-4), the "
                 "paper's Experiment 1 predicted (threshold r per scene and refresh rate) and 1 + k multiplexing cycles");
  options->pipeline.add_options(*cmd);
  // What the analysis sweeps or fixes itself.
  for (const char* name : {"--scene", "--input", "--image", "--reduction", "--phase", "--stereo", "--impl",
                           "--residual-bits", "--no-skip"}) {
    cmd->remove_option(cmd->get_option(name));
  }
  cmd->get_option("--refresh")->description("The study's refresh rate in Hz where it is not varied (default 90)");
  cmd->get_option("--size")->description("Experiment 1 view WxH (default 2560x1440, the paper's monitor)");
  cmd->get_option("--frames")->description("Frames K of every run (default 8; --quick: 4; the cycles: whole cycles of every k)");
  cmd->get_option("--bits")->description("Bits of the link and of the drive codes: 8 or 10 (default 10 here)");
  cmd->add_option("--ppd", options->ppd, "The study's pixels per degree where it is not varied")->capture_default_str();
  cmd->add_option("--contrast", options->contrast, "The study's Michelson contrast where it is not varied")
      ->capture_default_str();
  cmd->add_option("--persistence", options->persistence,
                  "Fraction of a frame an OLED panel emits (1: sample and hold)")->capture_default_str();
  cmd->add_option("--speeds", options->speeds, "Square speeds in deg/s, one chart each (default 5,20)")->delimiter(',');
  cmd->add_option("--contrasts", options->contrasts, "Fig. 2 contrasts (default 0.05,0.1,0.2,0.4)")->delimiter(',');
  cmd->add_option("--ppds", options->ppds, "Fig. 3 pixels per degree (default 15,30,45,60)")->delimiter(',');
  cmd->add_option("--refreshes", options->refreshes, "Fig. 4 refresh rates in Hz (default 90,120,144,165)")
      ->delimiter(',');
  cmd->add_option("--reductions", options->reductions, "The r grid (default 1,0.9,...,0.1)")->delimiter(',');
  cmd->add_option("--scenes", options->scenes, "Experiment 1 scenes (default discs,text,panorama)")->delimiter(',');
  cmd->add_option("--exp1-refreshes", options->exp1_refreshes, "Experiment 1 refresh rates (default 100,120,144,165)")
      ->delimiter(',');
  cmd->add_option("--exp1-ppd", options->exp1_ppd, "Experiment 1 pixels per degree")->capture_default_str();
  cmd->add_option("--calibrate-scene", options->calibration_scene, "Scene of the threshold's calibration point")
      ->capture_default_str();
  cmd->add_option("--calibrate-refresh", options->calibration_refresh_hz, "Refresh rate of the calibration point")
      ->capture_default_str();
  cmd->add_option("--calibrate-r", options->calibration_reduction, "r at which the calibration point is at threshold")
      ->capture_default_str();
  cmd->add_option("--cycles", options->cycles, "k of the 1 full + k reduced cycles compared (default 1,2,3)")
      ->delimiter(',');
  cmd->add_option("--substeps", options->substeps, "Retinal sub-frame steps S, the same for every run (default 16)");
  cmd->add_flag("--quick", options->quick, "A small grid of everything (seconds; what the CLI test runs)");
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->capture_default_str();
  cmd->callback([options, out, cmd, &action] {
    const bool size_given = cmd->count("--size") > 0;
    action = [options, out, size_given] {
      if (options->quick) {
        if (options->pipeline.frames == 0) options->pipeline.frames = 4;
        if (!size_given) {
          options->pipeline.width = 640;
          options->pipeline.height = 360;
        }
      }
      options->apply_defaults();
      options->validate();
      OutputDir dir(*out);
      Progress progress(analyze_work(*options));
      const AnalyzeResult result = run_analyze(*options, [&](std::int64_t done, std::int64_t) { progress.update(done); });
      progress.finish();
      dir.write_text("analyze.md", analyze_markdown(result));
      dir.write_text("study.csv", study_csv(result));
      dir.write_text("experiment1.csv", exp1_csv(result));
      dir.write_text("cycles.csv", cycles_csv(result));
      const std::vector<std::string> plots = write_analyze_plots(dir.staging().string(), result);
      dir.commit();
      std::cout << "trm analyze: " << result.study.size() << " study points, " << result.exp1.size()
                << " Experiment 1 conditions, " << result.cycles.size() << " cycle points in " << result.seconds
                << " s\n"
                << analyze_summary(result) << "  wrote " << dir.target().string()
                << "/ (analyze.md, study.csv, experiment1.csv, cycles.csv";
      for (const std::string& p : plots) std::cout << ", " << p;
      std::cout << ")\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
