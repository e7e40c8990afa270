#include "commands.hpp"

#include "trm/atomic_file.hpp"

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#ifndef TRM_VERSION
#define TRM_VERSION "0.0.0"
#endif

namespace trm::cli {

int run_main(int argc, char** argv) {
  // First, before any thread starts: every later thread inherits the blocked signals, so only the cleanup
  // thread receives them.
  io::install_signal_cleanup();
#if defined(__GLIBC__)
  // Frame-sized buffers stay in the process's heap once freed instead of going back to the kernel. By default glibc
  // serves large blocks (a 2160x1200 double plane is 59 MiB) by mmap, unmaps them on free and trims the heap's top,
  // so every frame faulted its buffers in again page by page: about 10 us a page on a virtual machine, where the
  // OpenCV pipeline of `trm bench` ran at 4.3 Mpix/s with the default and at 36 with this (docs/performance_history.md).
  // The resident set stays at its peak; malloc_trim still gives the free pages back.
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);
#endif
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
  register_methods(app, action);
  register_compare(app, action);
  register_bench(app, action);
  register_analyze(app, action);
  register_calibrate(app, action);

  // Every failure, of parsing or of the run, is one "trm: error:" line on stderr and a non-zero exit.
  const auto usage_hint = [&app] {
    const auto chosen = app.get_subcommands();
    return std::string("Run 'trm") + (chosen.empty() ? "" : " " + chosen.front()->get_name()) +
           " --help' for the options.\n";
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "trm: error: " << e.what() << "\n" << usage_hint();
    return e.get_exit_code();
  } catch (const std::exception& e) {
    // An option callback that threw something other than a CLI11 error (a library parser's message).
    std::cerr << "trm: error: " << e.what() << "\n" << usage_hint();
    return 2;
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
