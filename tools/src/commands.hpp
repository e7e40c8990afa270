// Register functions of the subcommands (one per tools/src/cmd_<name>.cpp).
#pragma once

#include "trm/cli.hpp"

namespace trm::cli {

void register_run(CLI::App& app, Action& action);
void register_decode(CLI::App& app, Action& action);
void register_lossless(CLI::App& app, Action& action);
void register_feed(CLI::App& app, Action& action);
void register_hw_report(CLI::App& app, Action& action);
void register_vectors(CLI::App& app, Action& action);
void register_sweep(CLI::App& app, Action& action);
void register_methods(CLI::App& app, Action& action);
void register_compare(CLI::App& app, Action& action);
void register_bench(CLI::App& app, Action& action);
void register_analyze(CLI::App& app, Action& action);
void register_calibrate(CLI::App& app, Action& action);

}  // namespace trm::cli
