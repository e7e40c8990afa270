// One whole view of the streaming fixed-point decoder at a headset size (2160x1200, r = 1/2, panorama, drive codes
// only: what `trm bench` calls `fixed`), full and reduced views timed apart, on 1 and 2 threads (bands of output
// lines), OLED and LCD; the same with the report planes (`fixed+planes`) and for the double reference. Items are output pixels, so items_per_second reads as pixels per second. Each iteration decodes
// a full view and the reduced view after it; the timed one is the argument's, the other runs with the timer paused
// (a reduced view needs the full view's stores).
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/scene.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>

#include <string>
#include <vector>

namespace {

using namespace trm;

constexpr int kWidth = 2160;
constexpr int kHeight = 1200;

EncoderConfig link_config() {
  EncoderConfig link;
  link.reduction = 0.5;
  return link;
}

const std::vector<LinkFrame>& pair_of_views() {
  static const std::vector<LinkFrame> views = [] {
    SceneParams params;
    params.width = kWidth;
    params.height = kHeight;
    params.supersample = 1;
    const auto scene = make_scene("panorama", params);
    const TrmEncoder encoder(link_config());
    return std::vector<LinkFrame>{encoder.encode(scene->linear_frame(0), 0, 0),
                                  encoder.encode(scene->linear_frame(1), 1, 0)};
  }();
  return views;
}

// What `trm bench` calls `fixed`: drive codes only (no report planes or motion weight statistics), in bands of output lines on `threads` threads.
FixedDecoderConfig codes_only(const char* panel, std::int64_t threads) {
  FixedDecoderConfig config;
  config.decoder.link = link_config();
  config.decoder.panel = parse_panel(panel);
  config.decoder.report_planes = false;
  config.motion_weight_statistics = false;
  config.threads = static_cast<int>(threads);
  return config;
}

// Each iteration decodes a full view and the reduced view after it, one of them timed (Args: timed view, 0 = full,
// 1 = reduced; threads; panel, 0 = vive OLED, 1 = lcd), after a pair before the timing: the decoder's geometry, stores
// and output spares exist, as in a long run.
void time_views(benchmark::State& state, HeadsetDecoder& decoder) {
  const std::vector<LinkFrame>& views = pair_of_views();
  const bool timed_reduced = state.range(0) != 0;
  benchmark::DoNotOptimize(decoder.decode(views[0]));
  benchmark::DoNotOptimize(decoder.decode(views[1]));
  for (auto _ : state) {
    if (timed_reduced) state.PauseTiming();
    benchmark::DoNotOptimize(decoder.decode(views[0]));
    if (timed_reduced) {
      state.ResumeTiming();
    } else {
      state.PauseTiming();
    }
    benchmark::DoNotOptimize(decoder.decode(views[1]));
    if (!timed_reduced) state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight);
  state.SetLabel(std::string(timed_reduced ? "reduced" : "full") + " view, " + (state.range(2) == 0 ? "vive" : "lcd") +
                 ", " + std::to_string(state.range(1)) + " thread(s)");
}

void BM_DecodeView(benchmark::State& state) {
  FixedStreamingDecoder decoder(codes_only(state.range(2) == 0 ? "vive" : "lcd", state.range(1)));
  time_views(state, decoder);
}
BENCHMARK(BM_DecodeView)
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The same views with the three double report planes and the motion weight statistics, as `trm run`, `trm sweep` and
// `trm compare` decode them (`trm bench`'s `fixed+planes`). Args: timed view, threads, panel, as BM_DecodeView.
void BM_DecodeViewWithPlanes(benchmark::State& state) {
  FixedDecoderConfig config = codes_only(state.range(2) == 0 ? "vive" : "lcd", state.range(1));
  config.decoder.report_planes = true;
  config.motion_weight_statistics = true;
  FixedStreamingDecoder decoder(config);
  time_views(state, decoder);
}
BENCHMARK(BM_DecodeViewWithPlanes)
    ->ArgsProduct({{0, 1}, {1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The double reference's full and reduced views, as `trm bench` times it (its rows split over OpenCV's threads, drive
// codes only). Args: timed view (0 = full, 1 = reduced), threads (OpenCV's), panel (0 = vive, 1 = lcd).
void BM_ReferenceView(benchmark::State& state) {
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(static_cast<int>(state.range(1)));
  ReferenceDecoder decoder(codes_only(state.range(2) == 0 ? "vive" : "lcd", 1).decoder);
  time_views(state, decoder);
  cv::setNumThreads(threads_before);
}
BENCHMARK(BM_ReferenceView)
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A fresh decoder's first views (its tables, geometry and frame stores come with them), as `trm bench` times each
// repeat: Args: view (0, 1, 2, ..., 9: the decoder's first, second, ... view; even: full, odd: reduced), threads.
void BM_FreshDecoderView(benchmark::State& state) {
  const std::vector<LinkFrame>& views = pair_of_views();
  const FixedDecoderConfig config = codes_only("vive", state.range(1));
  const int timed = static_cast<int>(state.range(0));
  for (auto _ : state) {
    state.PauseTiming();
    {
      FixedStreamingDecoder decoder(config);
      for (int v = 0; v <= timed; ++v) {
        if (v == timed) state.ResumeTiming();
        LinkFrame view = views[static_cast<std::size_t>(v % 2)];
        view.meta.index = v;
        benchmark::DoNotOptimize(decoder.decode(view));
      }
      state.PauseTiming();
    }
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight);
}
BENCHMARK(BM_FreshDecoderView)->ArgsProduct({{0, 1, 2, 3, 5, 7, 9}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
