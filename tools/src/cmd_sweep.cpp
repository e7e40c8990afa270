// `trm sweep`: error against run time and memory for every approximation knob of the fixed-point decoder
// (DESIGN §7). Writes sweep.csv, sweep.md, sweep_<knob>.png, sweep_pareto.png and report.json into one output
// directory; with --shard K/N one part of the points into a part directory, which --merge joins (sweep_shard.hpp).
#include "commands.hpp"
#include "output_dir.hpp"
#include "run_report.hpp"
#include "sweep.hpp"
#include "sweep_report.hpp"
#include "sweep_shard.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#ifndef TRM_VERSION
#define TRM_VERSION "0.0.0"
#endif

namespace trm::cli {

namespace {

constexpr const char* kShardOption = "--shard";
constexpr const char* kMergeOption = "--merge";
constexpr const char* kOutOption = "--out";

// What `trm sweep` parses into.
struct SweepCli {
  SweepOptions options;
  std::string out = "trm-sweep";
  bool quick = false;
  bool list = false;
  std::vector<std::string> merge;
};

// The options of `trm sweep`, defined once: for the command line, and for reading a part's options again at a merge.
void define_sweep_options(CLI::App* cmd, SweepCli* cli) {
  SweepOptions* options = &cli->options;
  options->pipeline.width = 270;
  options->pipeline.height = 300;
  options->pipeline.default_frames = 12;
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
  cmd->add_flag("--quick", cli->quick, "Small and fast (CI): 48x40, 4 frames, 1 repeat unless given");
  cmd->add_flag("--list-knobs", cli->list, "List the knobs and their default ranges, then exit");
  cmd->add_option_function<std::string>(
      kShardOption,
      [options](const std::string& text) {
        try {
          options->shard = parse_sweep_shard(text);
        } catch (const std::invalid_argument& e) {
          throw CLI::ValidationError(kShardOption, e.what());
        }
      },
      "Evaluate only shard K of N of the points (K/N, 1 <= K <= N) and write it as a part directory for --merge");
  cmd->add_option(kMergeOption, cli->merge,
                  "Join the part directories of every shard of one sweep into the outputs a single run writes (the "
                  "sweep's options come from the parts)");
  cmd->add_option("--out,-o", cli->out, "Output directory (written whole or not at all)")->capture_default_str();
}

// --quick's defaults, for what the command line left unset.
void apply_quick(const CLI::App& cmd, SweepCli& cli) {
  if (!cli.quick) return;
  PipelineOptions& pipeline = cli.options.pipeline;
  if (cmd.count("--size") == 0) {
    pipeline.width = 48;
    pipeline.height = 40;
  }
  if (cmd.count("--frames") == 0) pipeline.frames = 4;
  if (cmd.count("--repeats") == 0) cli.options.repeats = 1;
}

// Every option given, in the order the command defines them (so in canonical order), except those named.
std::vector<GivenOption> given_options(const CLI::App& cmd, const std::set<std::string>& except) {
  std::vector<GivenOption> given;
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt->count() == 0 || opt->get_name() == "--help" || except.count(opt->get_name()) > 0) continue;
    GivenOption o{opt->get_name(), {}};
    if (opt->get_expected_min() != 0) o.values = opt->results();
    given.push_back(std::move(o));
  }
  return given;
}

// A part's options parsed again by the definitions above, into `cli` (which the parsed options point into).
void parse_part_options(const std::vector<GivenOption>& given, SweepCli& cli) {
  CLI::App app;
  CLI::App* cmd = app.add_subcommand("sweep");
  define_sweep_options(cmd, &cli);
  std::vector<std::string> args = {"sweep"};
  for (const GivenOption& o : given) {
    if (o.values.empty()) args.push_back(o.name);
    for (const std::string& value : o.values) {
      args.push_back(o.name);
      args.push_back(value);
    }
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes the words last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw std::runtime_error("--merge: the parts' options `" + sweep_command_text(given) +
                             "` do not parse with this trm: " + e.what());
  }
  apply_quick(*cmd, cli);
}

// The command a single run into the merge's output directory would name: the parts' options, the merge's --out.
std::vector<GivenOption> merged_command_options(const CLI::App& cmd, const std::vector<GivenOption>& part_options) {
  const std::vector<GivenOption> merge_out = given_options(cmd, {kMergeOption});
  std::vector<GivenOption> given;
  for (const CLI::Option* opt : cmd.get_options()) {
    const std::vector<GivenOption>& source = opt->get_name() == kOutOption ? merge_out : part_options;
    const auto it = std::find_if(source.begin(), source.end(),
                                 [&](const GivenOption& o) { return o.name == opt->get_name(); });
    if (it != source.end()) given.push_back(*it);
  }
  return given;
}

std::string knob_listing() {
  std::ostringstream s;
  const SweepConfig base;
  for (const auto& k : sweep_knobs()) {
    s << "  " << std::left << std::setw(30) << k.name << std::right << " default " << std::setw(5) << k.get(base)
      << "  values";
    for (int v : k.values) {
      s << " " << v;
      if (!k.value_names.empty()) s << "=" << k.value_label(v);
    }
    s << "\n      " << k.description << "; cost: " << k.cost
      << (k.oled && k.lcd ? "" : k.oled ? " (OLED panels only)" : " (LCD panel only)")
      << (k.linear_space_only ? " (swept around a --resample-space linear base)" : "") << "\n";
  }
  return s.str();
}

// The outputs of a finished sweep, of a single run and of a merge alike.
void write_outputs(OutputDir& dir, const SweepResult& result) {
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
}

int run(const SweepCli& cli, const std::vector<GivenOption>& part_options) {
  const SweepOptions& options = cli.options;
  options.validate();
  OutputDir dir(cli.out);
  std::optional<Progress> progress;
  const SweepResult result = run_sweep(options, [&progress](std::int64_t done, std::int64_t total) {
    if (!progress) progress.emplace(total);
    progress->update(done);
  });
  if (progress) progress->finish();
  if (options.shard.whole()) {
    write_outputs(dir, result);
    return 0;
  }
  dir.write_text(kSweepPartFile, sweep_part_text(result, part_options, TRM_VERSION));
  dir.commit();
  std::size_t points = (options.shard.owns(0) ? 1 : 0) + (result.linear_base ? 1 : 0);
  for (const auto& k : result.knobs) points += k.points.size();
  std::cout << "trm sweep: shard " << options.shard.index << "/" << options.shard.count << ": " << points << " of "
            << sweep_point_count(plan_sweep(options)) << " points; wrote " << dir.target().string() << "/ ("
            << kSweepPartFile << ") in " << std::fixed << std::setprecision(1) << result.wall_seconds
            << " s; join the " << options.shard.count << " parts with trm sweep --merge DIR...\n";
  return 0;
}

int merge(const CLI::App& cmd, const SweepCli& cli) {
  std::vector<SweepPart> parts;
  for (const std::string& dir : cli.merge) parts.push_back(read_sweep_part(dir));
  check_sweep_parts(parts, cli.out);
  SweepCli again;
  parse_part_options(parts.front().options, again);
  again.options.command = sweep_command_text(merged_command_options(cmd, parts.front().options));
  const SweepResult merged = merge_sweep_parts(parts, again.options);
  OutputDir dir(cli.out);
  write_outputs(dir, merged);
  return 0;
}

}  // namespace

void register_sweep(CLI::App& app, Action& action) {
  auto cli = std::make_shared<SweepCli>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Sweep every approximation knob (the fixed-point decoder's, the eye model's) alone and report "
               "error against the reference vs run time and memory, with the Pareto fronts (default: discs, 270x300, "
               "12 frames, r = 1/2, vive OLED; a few minutes on two cores)");
  define_sweep_options(cmd, cli.get());
  cmd->callback([cli, cmd, &action] {
    if (!cli->merge.empty()) {
      for (const CLI::Option* opt : cmd->get_options()) {
        const std::string& name = opt->get_name();
        if (opt->count() > 0 && name != kMergeOption && name != kOutOption) {
          throw CLI::ValidationError(kMergeOption, "takes the sweep's options from its parts; leave out " + name);
        }
      }
      action = [cli, cmd] { return merge(*cmd, *cli); };
      return;
    }
    apply_quick(*cmd, *cli);
    cli->options.command = sweep_command_text(given_options(*cmd, {}));
    const std::vector<GivenOption> part_options = given_options(*cmd, {kShardOption, kOutOption});
    action = [cli, part_options] {
      if (cli->list) {
        std::cout << knob_listing();
        return 0;
      }
      return run(*cli, part_options);
    };
  });
}

}  // namespace trm::cli
