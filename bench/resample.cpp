// The double-precision reference resamplers on one 1080x1200 view (one eye of a Vive-class headset) at r = 1/2:
// D (separable polyphase Gaussian, sigma = 1.25 / r) and U (bilinear). Items are output pixels. This replaces a
// timed unit test: a speed figure is a benchmark's, never a test's.
#include "trm/resample.hpp"

#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

namespace {

constexpr int kWidth = 1080, kHeight = 1200;

cv::Mat random_view(int width, int height) {
  cv::Mat image(height, width, CV_64FC3);
  cv::RNG rng(2);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
  return image;
}

void BM_DownsampleFullView(benchmark::State& state) {
  const cv::Mat full = random_view(kWidth, kHeight);
  for (auto _ : state) benchmark::DoNotOptimize(trm::downsample(full, kWidth / 2, kHeight / 2, 2.5));
  state.SetItemsProcessed(state.iterations() * (kWidth / 2) * (kHeight / 2));
}
BENCHMARK(BM_DownsampleFullView)->Unit(benchmark::kMillisecond);

void BM_UpsampleToFullView(benchmark::State& state) {
  const cv::Mat reduced = random_view(kWidth / 2, kHeight / 2);
  for (auto _ : state) benchmark::DoNotOptimize(trm::upsample(reduced, kWidth, kHeight));
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight);
}
BENCHMARK(BM_UpsampleToFullView)->Unit(benchmark::kMillisecond);

}  // namespace
