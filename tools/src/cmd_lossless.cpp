// `trm lossless`: the lossless curve of the paper's Fig. 13, measured. Every built-in scene (or the ones asked
// for) is encoded with TRM at several reductions r and each view sent is coded losslessly with JPEG-LS; the
// result is coded bits per displayed pixel, next to full-rate coding of the same frames.
#include "commands.hpp"
#include "output_dir.hpp"
#include "pipeline.hpp"

#include "trm/encoder.hpp"
#include "trm/jpegls.hpp"
#include "trm/scene.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

namespace trm::cli {

namespace {

struct LosslessOptions {
  std::vector<std::string> scenes;
  std::vector<double> reductions{1.0, 0.75, 0.5, 0.25};
  int width = 540, height = 600;
  std::int64_t frames = 8;
  int bits = 8;
  double refresh_hz = 90.0;
  std::string out;
};

// Peak memory per view pixel, measured with /usr/bin/time: `trm lossless --scene discs --frames 8` (every r) at
// 1024x1024 against 256x256.
constexpr double kLosslessBytesPerPixel = 130.0;

// Coded bits per displayed pixel of `frames` frames of a scene: full rate (every frame full, r irrelevant)
// when full_rate, else TRM at the given r.
double bits_per_pixel(const std::string& scene, const LosslessOptions& o, double r, bool full_rate) {
  SceneParams params;
  params.width = o.width;
  params.height = o.height;
  params.refresh_hz = o.refresh_hz;
  auto source = make_scene(scene, params);
  EncoderConfig config;
  config.reduction = r;
  config.bits = o.bits;
  const TrmEncoder encoder(config);
  link::LosslessTally tally;
  for (std::int64_t t = 0; t < o.frames; ++t) {
    const cv::Mat linear = source->linear_frame(t);
    // Full rate: every frame is sent as a full frame, i.e. TRM's even-frame encoding at each t.
    tally.add(full_rate ? encoder.encode(linear, 0) : encoder.encode(linear, t));
  }
  return tally.bits_per_displayed_pixel();
}

}  // namespace

void register_lossless(CLI::App& app, Action& action) {
  auto o = std::make_shared<LosslessOptions>();
  CLI::App* cmd = app.add_subcommand(
      "lossless", "Measure JPEG-LS bits per displayed pixel with and without TRM for several r (paper Fig. 13)");
  cmd->add_option("--scene", o->scenes, "Scenes to measure (default: every built-in scene)");
  cmd->add_option("--reduction,-r", o->reductions, "Reductions r to measure")->capture_default_str();
  cmd->add_option_function<std::string>(
      "--size",
      [o](const std::string& text) {
        const cv::Size size = parse_view_size(text);
        o->width = size.width;
        o->height = size.height;
      },
      "View size WxH (default 540x600)");
  cmd->add_option("--frames", o->frames, "Frames per scene")->capture_default_str()->check(whole_number_at_least(2, " (a TRM pair)"));
  cmd->add_option("--bits", o->bits, "Link bits, 8 or 10")->capture_default_str();
  cmd->add_option("--out,-o", o->out, "Also write lossless.json and lossless.csv into this directory");
  cmd->callback([o, &action] {
    action = [o] {
      if (o->scenes.empty()) o->scenes = scene_names();
      if (o->frames < 2) throw std::invalid_argument("--frames must be >= 2 (a TRM pair)");
      require_memory("for the lossless measurement", kLosslessBytesPerPixel, cv::Size(o->width, o->height));
      for (double r : o->reductions) {
        EncoderConfig c;
        c.reduction = r;
        c.bits = o->bits;
        c.validate();
      }
      nlohmann::ordered_json results = nlohmann::ordered_json::array();
      std::ostringstream csv;
      csv << "scene,full_rate_bpp";
      for (double r : o->reductions) csv << ",trm_r" << r << "_bpp";
      csv << "\n";
      std::printf("JPEG-LS bits per displayed pixel, %dx%d, %lld frames, %d-bit\n", o->width, o->height,
                  static_cast<long long>(o->frames), o->bits);
      std::printf("  %-10s %10s", "scene", "full rate");
      for (double r : o->reductions) std::printf("   r=%-5g", r);
      std::printf("\n");
      for (const std::string& scene : o->scenes) {
        const double full = bits_per_pixel(scene, *o, 1.0, true);
        std::printf("  %-10s %10.3f", scene.c_str(), full);
        csv << scene << "," << full;
        nlohmann::ordered_json row;
        row["scene"] = scene;
        row["full_rate_bpp"] = full;
        for (double r : o->reductions) {
          const double bpp = bits_per_pixel(scene, *o, r, false);
          std::printf("   %7.3f", bpp);
          csv << "," << bpp;
          row["trm_bpp"][std::to_string(r)] = bpp;
        }
        std::printf("\n");
        std::fflush(stdout);
        csv << "\n";
        results.push_back(row);
      }
      if (!o->out.empty()) {
        OutputDir dir(o->out);
        nlohmann::ordered_json report;
        report["tool"] = "trm";
        report["size"] = {o->width, o->height};
        report["frames"] = o->frames;
        report["bits"] = o->bits;
        report["results"] = results;
        dir.write_text("report.json", report.dump(2) + "\n");
        dir.write_text("lossless.csv", csv.str());
        dir.commit();
      }
      return 0;
    };
  });
}

}  // namespace trm::cli
