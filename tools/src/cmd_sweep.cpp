// `trm sweep`: error against run time and memory for every approximation knob of the fixed-point decoder
// (DESIGN §7). Writes sweep.csv, sweep.md, sweep_<knob>.png, sweep_pareto.png and report.json into one output
// directory.
#include "commands.hpp"
#include "output_dir.hpp"
#include "run_report.hpp"
#include "sweep.hpp"
#include "sweep_report.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace trm::cli {

namespace {

// The options as given, in canonical form, to name the command that reproduces a run.
std::string command_line(const CLI::App& cmd) {
  std::string line = "trm sweep";
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt->count() == 0 || opt->get_name() == "--help") continue;
    if (opt->get_expected_min() == 0) {
      line.append(" ").append(opt->get_name());
      continue;
    }
    for (const std::string& value : opt->results()) {
      const bool quote = value.find_first_of(" *?'\"") != std::string::npos;
      line.append(" ").append(opt->get_name()).append(" ");
      line.append(quote ? "'" : "").append(value).append(quote ? "'" : "");
    }
  }
  return line;
}

std::string knob_listing() {
  std::ostringstream s;
  const SweepConfig base;
  for (const auto& k : sweep_knobs()) {
    s << "  " << std::left << std::setw(30) << k.name << std::right << " default " << std::setw(5) << k.get(base)
      << "  values";
    for (int v : k.values) s << " " << v;
    s << "\n      " << k.description << "; cost: " << k.cost
      << (k.oled && k.lcd ? "" : k.oled ? " (OLED panels only)" : " (LCD panel only)")
      << (k.linear_space_only ? " (swept around a --resample-space linear base)" : "") << "\n";
  }
  return s.str();
}

}  // namespace

void register_sweep(CLI::App& app, Action& action) {
  auto options = std::make_shared<SweepOptions>();
  options->pipeline.width = 270;
  options->pipeline.height = 300;
  options->pipeline.default_frames = 12;
  auto out = std::make_shared<std::string>("trm-sweep");
  auto quick = std::make_shared<bool>(false);
  auto list = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Sweep every approximation knob (the fixed-point decoder's, the eye model's) alone and report "
               "error against the reference vs run time and memory, with the Pareto fronts (default: discs, 270x300, "
               "12 frames, r = 1/2, vive OLED; a few minutes on two cores)");
  options->pipeline.add_options(*cmd);
  // The sweep always decodes with the streaming fixed-point decoder beside the reference.
  cmd->remove_option(cmd->get_option("--impl"));
  cmd->get_option("--size")->description("View size WxH decoded at each point (default 270x300)");
  cmd->get_option("--residual-bits")
      ->description("Residual store width N of the base configuration, sQ2.(N-2) (default: 30, lossless)");
  cmd->add_option("--knob", options->knobs, "Knob to sweep (repeatable; default: every knob the panel uses)");
  cmd->add_option("--values", options->values, "Values of the one --knob, comma separated (the base value is added)")
      ->delimiter(',');
  cmd->add_option("--repeats", options->repeats,
                  "Decodes of the sequence per point; each view's median time is reported")
      ->capture_default_str();
  cmd->add_option_function<std::string>(
      "--hw-size", [options](const std::string& text) { options->hw_size = parse_view_size(text, "--hw-size"); },
      "View size WxH the memory figures are reported for (default 1080x1200)");
  cmd->add_flag("--quick", *quick, "Small and fast (CI): 48x40, 4 frames, 1 repeat unless given");
  cmd->add_flag("--list-knobs", *list, "List the knobs and their default ranges, then exit");
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->capture_default_str();
  cmd->callback([options, out, quick, list, cmd, &action] {
    if (*quick) {
      if (cmd->count("--size") == 0) {
        options->pipeline.width = 48;
        options->pipeline.height = 40;
      }
      if (cmd->count("--frames") == 0) options->pipeline.frames = 4;
      if (cmd->count("--repeats") == 0) options->repeats = 1;
    }
    options->command = command_line(*cmd);
    action = [options, out, list] {
      if (*list) {
        std::cout << knob_listing();
        return 0;
      }
      options->validate();
      OutputDir dir(*out);
      std::optional<Progress> progress;
      const SweepResult result = run_sweep(*options, [&progress](std::int64_t done, std::int64_t total) {
        if (!progress) progress.emplace(total);
        progress->update(done);
      });
      if (progress) progress->finish();
      dir.write_text("sweep.csv", sweep_csv(result));
      dir.write_text("sweep.md", sweep_markdown(result));
      int plots = 0;
      for (const auto& knob : result.knobs) {
        if (!knob.skipped.empty()) continue;
        std::string name = "sweep_";
        name.append(knob.knob->name).append(".png");
        write_sweep_plot(dir.file(name), result, knob);
        ++plots;
      }
      write_pareto_plot(dir.file("sweep_pareto.png"), result);
      ++plots;
      dir.write_text("report.json", sweep_json(result).dump(2) + "\n");
      dir.commit();
      std::cout << "trm sweep: " << result.knobs.size() << " knob(s)\n"
                << sweep_summary(result) << "  wrote " << dir.target().string() << "/ (sweep.csv, sweep.md, " << plots
                << " plot(s), report.json) in " << std::fixed << std::setprecision(1) << result.wall_seconds << " s\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
