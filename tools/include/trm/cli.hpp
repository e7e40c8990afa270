// The `trm` command line. Each subcommand lives in tools/src/cmd_<name>.cpp and exposes one
// register function, listed in tools/src/cli.cpp; the action it stores runs after parsing and
// returns the process exit code.
#pragma once

#include <functional>

// CLI11 is header-only and costs every translation unit that includes it seconds of code generation (its
// validator objects are defined in each): only the files that build options include it.
namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace trm::cli {

using Action = std::function<int()>;

// Builds the app with every subcommand, parses argv, runs the chosen action. Never throws:
// errors print one clear message to stderr and give a non-zero exit code.
int run_main(int argc, char** argv);

}  // namespace trm::cli
