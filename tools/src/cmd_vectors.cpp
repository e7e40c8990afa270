// `trm vectors`: per-stage golden vectors of the fixed-point decoder for RTL test benches, and the update of the
// checked-in golden hashes (tests/golden/vectors.txt).
#include "commands.hpp"
#include "hw_report.hpp"
#include "output_dir.hpp"
#include "vectors.hpp"

#include "trm/atomic_file.hpp"
#include "trm/decoder_json.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace trm::cli {

void register_vectors(CLI::App& app, Action& action) {
  auto options = std::make_shared<PipelineOptions>();
  options->frames = 4;
  auto out = std::make_shared<std::string>();
  auto golden = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "vectors", "Write per-stage golden vectors (hex, one line per image line) of the fixed-point decoder for a "
                 "scene, or regenerate the checked-in golden hashes with --update-golden");
  options->add_options(*cmd);
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)");
  cmd->add_option("--update-golden", *golden, "Regenerate the golden hash file (e.g. tests/golden/vectors.txt)");
  cmd->callback([options, out, golden, &action] {
    action = [options, out, golden] {
      if (!golden->empty()) {
        // The golden hashes cover a fixed set of scenes: an --out beside it would be silently ignored.
        if (!out->empty())
          throw std::invalid_argument("trm vectors: --update-golden FILE and --out DIR exclude each other");
        io::check_file_target(*golden);  // before generating
        const std::string text = golden_vectors_text();
        io::write_file_atomically(*golden, text);
        std::cout << "trm vectors: wrote " << *golden << "\n";
        return 0;
      }
      if (out->empty()) throw std::invalid_argument("trm vectors: --out DIR is required (or --update-golden FILE)");
      if (options->frames < 1) throw std::invalid_argument("--frames must be >= 1");
      const VectorSet set = generate_vectors(*options);
      Json report;
      report["parameters"] = {{"scene", options->scene},
                              {"size", {options->width, options->height}},
                              {"frames", options->frames},
                              {"decoder", fixed_decoder_json(fixed_config_of(*options))}};
      Json files = Json::array();
      OutputDir dir(*out);
      for (const VectorFile& f : set.files) {
        dir.write_text(f.name, f.text);
        char hash[20];
        std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a64(f.text)));
        files.push_back({{"file", f.name}, {"frame", f.frame}, {"eye", f.eye}, {"parity", f.parity},
                         {"stage", f.stage}, {"fnv1a64", hash}});
      }
      report["files"] = files;
      dir.write_text("README.md", set.readme);
      dir.write_text("report.json", report.dump(2) + "\n");
      dir.commit();
      std::cout << "trm vectors: " << options->scene << ", " << set.files.size() << " stage files in "
                << dir.target().string() << "/\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
