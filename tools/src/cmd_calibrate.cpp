// `trm calibrate`: measure the simulated LCD as the paper measured its monitor and fit Eq. 7 (calibrate.hpp). Writes
// panel.json (the preset `--panel lcd:DIR/panel.json` loads), readings.csv and residuals.png.
#include "calibrate.hpp"
#include "commands.hpp"
#include "output_dir.hpp"

#include "trm/plot.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

namespace trm::cli {

namespace {

// Residual against v_t, one series per v_{t−1}: the layout of the paper's Fig. 7 and 9.
plot::Chart residual_chart(const std::string& title, const std::vector<PairReading>& readings,
                           const std::vector<double>& residuals, int grid) {
  plot::Chart chart;
  chart.title = title;
  chart.x.label = "v_t (drive of the current frame)";
  chart.y.label = "reading - model (luminance, 1 = white)";
  for (int j = 0; j < grid; ++j) {
    plot::Series series;
    series.style = plot::Style::LineAndPoints;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      if (k / static_cast<std::size_t>(grid) != static_cast<std::size_t>(j)) continue;
      series.x.push_back(readings[k].v_t);
      series.y.push_back(residuals[k]);
    }
    char label[32];
    std::snprintf(label, sizeof label, "v_t-1 = %.3g", readings[static_cast<std::size_t>(j * grid)].v_prev);
    series.label = label;
    chart.series.push_back(std::move(series));
  }
  chart.legend = plot::LegendPlace::Best;
  return chart;
}

}  // namespace

void register_calibrate(CLI::App& app, Action& action) {
  auto options = std::make_shared<CalibrationOptions>();
  auto out = std::make_shared<std::string>("trm-calibrate");
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Measure the simulated LCD with alternating drive pairs and a photometer (paper Sec. 4.4) and fit "
                   "Eq. 7's p1..p4 and gamma; writes the panel preset for --panel lcd:DIR/panel.json");
  cmd->add_option("--refresh", options->refresh_hz, "Refresh rate in Hz")->capture_default_str();
  cmd->add_option("--grid", options->grid, "Drive values per axis (grid x grid pairs)")->capture_default_str();
  cmd->add_option("--window", options->window_s, "Photometer integration time in s")->capture_default_str();
  cmd->add_option("--warmup", options->warmup_s, "Alternation shown before the window opens, in s")
      ->capture_default_str();
  cmd->add_option("--noise", options->noise, "Photometer noise: relative sigma of each reading (0: none)")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "Seed of the photometer noise")->capture_default_str();
  cmd->add_option("--native-gamma", options->native_gamma, "The simulated panel's held light v^gamma")
      ->capture_default_str();
  cmd->add_option("--tau-off", options->lc.tau_off_s,
                  "LC fall (elastic) time constant in s (the written preset carries it)")
      ->capture_default_str();
  cmd->add_option("--drive-ratio", options->lc.drive_ratio, "LC V_max / V_th (rise tau_off / ((V/V_th)^2 - 1))")
      ->capture_default_str();
  cmd->add_flag("--overdrive", options->overdrive,
               "The panel overdrives its LC (each frame reaches its level where the drive range allows); the "
               "written preset says so too");
  cmd->add_option("--out,-o", *out, "Output directory (written whole or not at all)")->capture_default_str();
  cmd->callback([options, out, &action] {
    action = [options, out] {
      options->validate();
      OutputDir dir(*out);
      const std::vector<PairReading> readings = measure_pairs(*options);
      const Eq7Fit fit = fit_eq7(readings);
      Panel panel;
      panel.kind = PanelKind::Lcd;
      panel.name = "calibrated";
      panel.lcd = fit.panel;
      panel.lcd.lc_response = options->lc;  // the preset is the simulated panel's, crystal included
      panel.lcd.overdrive = options->overdrive;
      nlohmann::ordered_json preset;
      to_json(preset, panel);
      dir.write_text("panel.json", preset.dump(2) + "\n");
      dir.write_text("readings.csv", readings_csv(readings, fit));
      plot::Figure figure;
      figure.title = "trm calibrate: photometer reading minus model, alternating pairs at " +
                     std::to_string(static_cast<int>(options->refresh_hz)) + " Hz";
      figure.width = 1400;
      figure.charts.push_back(residual_chart("Eq. 7 temporal model", readings, fit.residuals, options->grid));
      if (!fit.plain_residuals.empty()) {
        figure.charts.push_back(
            residual_chart("single-frame gamma (mean of two frames)", readings, fit.plain_residuals, options->grid));
      }
      plot::write_png(dir.file("residuals.png"), figure);
      dir.commit();
      std::printf("trm calibrate: %zu pairs (%dx%d grid) at %g Hz, %g s window, noise %g\n", readings.size(),
                  options->grid, options->grid, options->refresh_hz, options->window_s, options->noise);
      std::printf("  Eq. 7 fit: p1 %.6f  p2 %.6f  p3 %.6f  p4 %.6f  gamma %.4f  (%d iterations)\n", fit.panel.p1,
                  fit.panel.p2, fit.panel.p3, fit.panel.p4, fit.panel.gamma, fit.iterations);
      std::printf("  fit error (luminance, 1 = white): Eq. 7 RMS %.3e max %.3e; single-frame gamma %.4f RMS %.3e "
                  "max %.3e\n",
                  fit.rms, fit.max_abs, fit.plain_gamma, fit.plain_rms, fit.plain_max_abs);
      if (fit.slope_constrained) {
        std::printf("  note: dM/dv_t held at its minimum at a corner of [0, 1]^2 (Eq. 7 cannot follow this panel "
                    "there and stay invertible)\n");
      }
      std::cout << "  wrote " << dir.target().string() << "/ (panel.json, readings.csv, residuals.png); use it with "
                << "--panel lcd:" << (dir.target() / "panel.json").string() << "\n";
      return 0;
    };
  });
}

}  // namespace trm::cli
