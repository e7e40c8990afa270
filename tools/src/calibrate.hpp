// `trm calibrate`: the LCD characterised the way the TRM paper measured its monitor (Sec. 4.4, Fig. 7 and 9). A
// simulated panel (steady light v^γ_native, the level-dependent LC response of lc_response.hpp) shows alternating
// drive pairs (v_t, v_{t−1}) over a grid at the refresh rate; a photometer integrates the emitted light over a long
// window (the paper's Specbos 1211: 1 s), optionally with relative noise; Eq. 7's p1..p4 and γ are fitted to the
// readings by least squares, Y ≈ max(M(v_t, v_{t−1}), 0)^γ, and the result is an LCD panel preset.
#pragma once

#include "trm/lc_response.hpp"
#include "trm/panel.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace trm::cli {

struct CalibrationOptions {
  double refresh_hz = 120.0;  // the paper's 120 Hz
  int grid = 9;               // drive values per axis: 0, 1/(grid−1), ..., 1 (grid >= 3, <= 64)
  double window_s = 1.0;      // photometer integration time (Specbos 1211 in the paper: 1 s)
  double warmup_s = 0.5;      // alternation shown before the window opens, so the LC is periodic
  double noise = 0.0;         // photometer noise: relative σ of each reading, in [0, 0.5)
  std::uint64_t seed = 1;     // of the noise
  double native_gamma = 2.2;  // the simulated panel's held light v^γ
  LcResponseParams lc;        // the simulated liquid crystal
  bool overdrive = false;     // the simulated panel overdrives it (PanelLightConfig::overdrive); so does the preset
  // Throws std::invalid_argument naming the option and its range.
  void validate() const;
};

struct PairReading {
  double v_t = 0.0;
  double v_prev = 0.0;
  double luminance = 0.0;  // the photometer's mean light over the window (1: white held)
};

// Every ordered pair of the grid, v_prev the slower index.
std::vector<PairReading> measure_pairs(const CalibrationOptions& options);

struct Eq7Fit {
  LcdPanel panel;                   // the fitted p1..p4 and γ
  std::vector<double> residuals;    // reading − fitted luminance, one per reading
  double rms = 0.0, max_abs = 0.0;  // of the residuals (luminance, 1 = white)
  // The single-frame model the paper starts from (Fig. 7): the mean of the two frames' held light v^γ, with γ fitted
  // to the held pairs (v, v): what Eq. 7 improves on.
  double plain_gamma = 0.0;
  std::vector<double> plain_residuals;
  double plain_rms = 0.0, plain_max_abs = 0.0;
  int iterations = 0;
  // The readings pulled dM/dv_t at a corner of [0, 1]² toward 0 and the fit holds it at the smallest slope the
  // decoders' inverse accepts (Eq. 7 cannot follow the panel there).
  bool slope_constrained = false;
};

// Levenberg–Marquardt from `start` (default: the default LCD merge). Throws std::invalid_argument for fewer than 6
// readings or a non-finite or negative reading, std::runtime_error when the fit does not converge or the fitted
// merge breaks validate_panel's rules (it is then no panel the decoders can invert).
Eq7Fit fit_eq7(const std::vector<PairReading>& readings, const LcdPanel& start = {});

// The readings and both models' predictions, one line per reading.
std::string readings_csv(const std::vector<PairReading>& readings, const Eq7Fit& fit);

}  // namespace trm::cli
