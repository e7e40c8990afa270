// `trm analyze`: the supplement's parameter study (§1.2, Figs. 2-4), the paper's Experiment 1 (Sec. 5, Fig. 11) as a
// prediction, and the supplement's §1.4 claim about longer multiplexing cycles, all measured with the supplement's
// visual difference energy (Eqs. 1-4, trm/visual_difference.hpp) on x-t images of an eye pursuing the target
// (trm/retina.hpp) against full-rate rendering of the same frames on the same panel.
#pragma once

#include "options.hpp"

#include <functional>
#include <string>
#include <vector>

namespace trm::cli {

struct AnalyzeOptions {
  // Panel, link bits, transfer, resample space, sigma, sensitivity, output bits; refresh_hz is the study's default
  // rate (the supplement's 90 Hz); width x height the Experiment 1 view; frames the frames K of every run.
  PipelineOptions pipeline;
  double ppd = 30.0;          // the study's default angular resolution (supplement §1.2)
  double contrast = 0.2;      // the study's default Michelson contrast of the square
  double persistence = 1.0;   // fraction of each frame an OLED panel emits (1: sample and hold, as the supplement's
                              // monitor); an LCD holds with its liquid-crystal response whatever this is
  std::vector<double> speeds;       // deg/s of the square: one chart per speed
  std::vector<double> contrasts;    // Fig. 2
  std::vector<double> ppds;         // Fig. 3
  std::vector<double> refreshes;    // Fig. 4 (Hz)
  std::vector<double> reductions;   // the r grid of every curve
  std::vector<std::string> scenes;  // Experiment 1
  std::vector<double> exp1_refreshes;
  double exp1_ppd = 56.0;           // the paper's monitor at 75 cm (Sec. 5)
  // The one calibration point of Experiment 1's threshold: this scene at this rate reaches it at this r.
  std::string calibration_scene = "discs";
  double calibration_refresh_hz = 100.0;
  double calibration_reduction = 0.4;
  std::vector<int> cycles;          // k of the 1 + k cycles compared (§1.4)
  int substeps = 0;                 // retinal sub-frame steps S, the same for every run; 0: kDefaultRetinaSubsteps
  bool quick = false;               // a small grid of everything (the CLI test's run)

  // Fills every list left empty with the default (or --quick) grid.
  void apply_defaults();
  // Throws std::invalid_argument with one clear message for any bad value (after apply_defaults).
  void validate() const;
  std::int64_t frames() const;
  int retina_substeps() const;
};

// One point of Figs. 2-4: `parameter` (contrast, ppd or refresh) at `value`, the others at their defaults.
struct StudyPoint {
  std::string parameter;
  double value = 0.0;
  double speed_deg_s = 0.0;
  double reduction = 0.0;
  double pixels_saved_percent = 0.0;  // (0.5 - 0.5 r^2) 100
  double energy = 0.0;                // TRM against full rate
};

// One scene at one rate of Experiment 1: the energy over the r grid and the smallest r under the threshold.
struct Exp1Point {
  std::string scene;
  double refresh_hz = 0.0;
  double target_velocity_deg_s = 0.0;  // the pursued target's speed along the analysed line
  bool vertical = false;               // the target moves vertically (text): the line is a column
  std::vector<double> reductions;      // descending, with the bisection's points merged in
  std::vector<double> energies;
  double threshold_reduction = 0.0;    // smallest r whose energy, and every larger r's, stays under the threshold
  bool below_grid = false;             // every r of the grid stays under: the threshold is at most the grid's least
  double pixels_saved_percent() const { return 100.0 * (0.5 - 0.5 * threshold_reduction * threshold_reduction); }
};

// One point of the §1.4 comparison: one full frame followed by k reduced frames.
struct CyclePoint {
  int reduced_frames = 1;             // k
  double speed_deg_s = 0.0;
  double reduction = 0.0;
  double pixels_saved_percent = 0.0;  // k / (k + 1) (1 - r^2) 100
  double cycle_hz = 0.0;              // refresh / (k + 1): the fundamental of the alternation
  double energy = 0.0;                // the cycle model against full rate
  double clipped_percent = 0.0;       // |rho| of the full frames: boost outside [0, 1], % of the full frames' light
  double pipeline_energy = 0.0;       // k = 1: the real encoder and decoder's energy at this point (else NaN)
};

// The supplement's trends, decided from the measurements.
struct TrendCheck {
  std::string claim;
  bool holds = false;
  std::string evidence;
};

struct AnalyzeResult {
  AnalyzeOptions options;
  std::vector<StudyPoint> study;
  double threshold_energy = 0.0;
  std::vector<Exp1Point> exp1;
  std::vector<CyclePoint> cycles;
  std::int64_t cycle_frames = 0;  // frames of the cycle runs: whole cycles of every k
  std::vector<TrendCheck> trends;
  double seconds = 0.0;
};

// The work units run_analyze reports progress in (one per encoder-decoder run of K frames).
std::int64_t analyze_work(const AnalyzeOptions& options);
AnalyzeResult run_analyze(const AnalyzeOptions& options,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

std::string study_csv(const AnalyzeResult& result);
std::string exp1_csv(const AnalyzeResult& result);
std::string cycles_csv(const AnalyzeResult& result);
std::string analyze_markdown(const AnalyzeResult& result);
std::string analyze_summary(const AnalyzeResult& result);
// Writes study_contrast.png, study_ppd.png, study_refresh.png, experiment1.png and cycles.png into `directory`;
// returns their names.
std::vector<std::string> write_analyze_plots(const std::string& directory, const AnalyzeResult& result);

}  // namespace trm::cli
