// The retinal integration's accuracy knob S (sub-steps per frame): error against the closed form and run time, the
// two columns docs/eye_model.md chooses the default from.
//
// BM_EdgeError: one pursued moving edge (a 1×512 scan line, 4 frames at 90 Hz on the Vive's 11.42 ppd), perfect
// pursuit; counters max_error (the worst |error| over 16 sub-pixel eye phases, in units of the edge's contrast) and
// px_per_step (how far the eye moves within one step). The OLED and the held LCD with an instant response have a
// closed form (each frame's still profile swept over its lit window); the LCD with τ = 2 ms is measured against
// S = 4096. BM_RetinalImage: a whole 1080×1200 RGB view pair (2 frames) at 30 deg/s; items are pixels per frame.
#include "trm/panel_light.hpp"
#include "trm/retina.hpp"

#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <vector>

namespace {

constexpr double kRefresh = 90.0;
constexpr int kWidth = 512, kFrames = 4, kPhases = 16;

enum PanelCase { kOled = 0, kHold = 1, kLcd = 2 };

trm::PanelLight light_of(int panel) {
  if (panel == kOled) return trm::PanelLight({kRefresh, trm::kViveOledDuty, 0.0, 0.0});
  return trm::PanelLight({kRefresh, 1.0, 0.0, panel == kLcd ? trm::kDefaultLcdTauS : 0.0});
}

cv::Mat moving_edge(double start, double px_per_frame) {
  cv::Mat xt(kFrames, kWidth, CV_64FC1);
  for (int n = 0; n < kFrames; ++n) {
    for (int i = 0; i < kWidth; ++i) xt.at<double>(n, i) = i < start + px_per_frame * n ? 1.0 : 0.0;
  }
  return xt;
}

cv::Mat exact_row(const cv::Mat& frames, const trm::PanelLight& light, const trm::Viewer& viewer, double eye,
                  double origin_s) {
  const double period = light.frame_period_s();
  cv::Mat sum = cv::Mat::zeros(1, frames.cols, CV_64FC1);
  for (int n = 0; n < frames.rows; ++n) {
    const double t0 = n * period + light.window_begin_s(), t1 = n * period + light.window_end_s();
    sum += trm::ideal_retinal_row(frames.row(n), viewer, trm::Gaze{0.0, eye}, t0, t1, origin_s) * (t1 - t0);
  }
  return sum / (frames.rows * period * light.config().duty);
}

// Args: panel case, speed deg/s, S.
void BM_EdgeError(benchmark::State& state) {
  const int panel = static_cast<int>(state.range(0));
  const auto speed = static_cast<double>(state.range(1));
  const int substeps = static_cast<int>(state.range(2));
  const trm::PanelLight light = light_of(panel);
  const trm::Viewer viewer = trm::viewer_preset("vive");
  const double px_per_frame = speed * viewer.pixels_per_degree / kRefresh;
  trm::RetinaOptions options, reference;
  options.substeps = substeps;
  reference.substeps = 4096;
  const cv::Mat frames = moving_edge(100.0, px_per_frame);
  double worst = 0.0;
  for (auto _ : state) {
    worst = 0.0;
    for (int phase = 0; phase < kPhases; ++phase) {
      // The eye starts phase / kPhases px behind, so pixel kinks fall at every offset within a step.
      options.origin_s = reference.origin_s = phase / (kPhases * speed * viewer.pixels_per_degree);
      const cv::Mat exact = panel == kLcd ? trm::retinal_row(frames, light, viewer, speed, reference)
                                          : exact_row(frames, light, viewer, speed, options.origin_s);
      const cv::Mat retina = trm::retinal_row(frames, light, viewer, speed, options);
      worst = std::max(worst, cv::norm(retina, exact, cv::NORM_INF));
    }
  }
  state.counters["max_error"] = worst;
  state.counters["px_per_step"] =
      speed * viewer.pixels_per_degree * (light.window_end_s() - light.window_begin_s()) / substeps;
}

void edge_cases(benchmark::internal::Benchmark* bench) {
  for (const int panel : {kOled, kHold, kLcd}) {
    for (const int speed : {10, 30, 80}) {
      for (const int substeps : {1, 2, 4, 8, 16, 32, 64}) bench->Args({panel, speed, substeps});
    }
  }
}
BENCHMARK(BM_EdgeError)->Apply(edge_cases)->ArgNames({"panel", "deg_s", "S"})->Iterations(1);

// Args: panel case, S.
void BM_RetinalImage(benchmark::State& state) {
  const trm::PanelLight light = light_of(static_cast<int>(state.range(0)));
  trm::RetinaOptions options;
  options.substeps = static_cast<int>(state.range(1));
  std::vector<cv::Mat> frames(2, cv::Mat(1200, 1080, CV_64FC3));
  cv::RNG rng(3);
  for (cv::Mat& frame : frames) {
    frame = cv::Mat(1200, 1080, CV_64FC3);
    rng.fill(frame, cv::RNG::UNIFORM, 0.0, 1.0);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(trm::retinal_image(frames, light, trm::viewer_preset("vive"), 30.0, options));
  }
  state.SetItemsProcessed(state.iterations() * 1080 * 1200 * 2);
}
BENCHMARK(BM_RetinalImage)
    ->ArgsProduct({{kOled, kLcd}, {1, 4, 16, 64}})
    ->ArgNames({"panel", "S"})
    ->UseRealTime()  // rows run on every core: wall time is the cost
    ->Unit(benchmark::kMillisecond);

}  // namespace
