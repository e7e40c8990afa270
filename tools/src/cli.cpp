#include "commands.hpp"

#include "trm/atomic_file.hpp"

#include <exception>
#include <iostream>

#ifndef TRM_VERSION
#define TRM_VERSION "0.0.0"
#endif

namespace trm::cli {

int run_main(int argc, char** argv) {
  // First, before any thread starts: every later thread inherits the blocked signals, so only the cleanup
  // thread receives them.
  io::install_signal_cleanup();
  CLI::App app{"trm: headset-side Temporal Resolution Multiplexing simulator "
               "(GPU-side encoder, simulated link, bit-accurate display-controller decoder, panel and eye models)"};
  app.set_version_flag("--version", std::string("trm ") + TRM_VERSION);
  app.require_subcommand(0, 1);

  Action action;
  register_run(app, action);
  register_decode(app, action);
  register_lossless(app, action);
  register_feed(app, action);
  register_hw_report(app, action);
  register_vectors(app, action);
  register_sweep(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (!action) {
    std::cout << app.help();
    return 0;
  }
  try {
    return action();
  } catch (const std::exception& e) {
    std::cerr << "trm: error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace trm::cli
