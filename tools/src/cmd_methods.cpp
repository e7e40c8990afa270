// `trm methods`: the display methods `trm run --method` takes, one line each.
#include "commands.hpp"

#include "trm/display_method.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>

namespace trm::cli {

void register_methods(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand("methods", "List the display methods of `trm run --method` (the paper's Table 1)");
  cmd->callback([&action] {
    action = [] {
      std::size_t width = 0;
      for (const DisplayMethod& m : display_methods()) width = std::max(width, m.name.size());
      for (const DisplayMethod& m : display_methods()) {
        std::cout << m.name << std::string(width + 2 - m.name.size(), ' ') << m.summary
                  << (m.fixed_point ? " [fixed-point decoder: --impl fixed|fixed-frame]" : "") << "\n";
        if (!m.option_help.empty()) {
          std::cout << std::string(width + 2, ' ') << "option " << m.name << ":" << m.option_help << "\n";
        }
      }
      return 0;
    };
  });
}

}  // namespace trm::cli
