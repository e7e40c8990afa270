// Decode time of the fixed-point streaming decoder with the DESIGN §7 skips on and off
// (FixedDecoderConfig::skip_unneeded), on the static scene (every line of a reduced frame skips the motion test),
// a moving one (discs) and a grey one (text: every line computes one channel, the chroma skip). Items are decoded views. BM_DecodeSkipRatio times both paths in each iteration and
// reports time(skip) / time(full path) as the counter "skip_over_full" (all views) and "reduced_skip_over_full"
// (reduced views alone, where the motion test and the residual read are skipped).
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/scene.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <string>
#include <vector>

namespace {

using namespace trm;

constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr int kFrames = 6;

const char* scene_of(std::int64_t arg) { return arg == 0 ? "static" : arg == 1 ? "discs" : "text"; }

EncoderConfig link_config() {
  EncoderConfig link;
  link.reduction = 0.5;
  return link;
}

std::vector<LinkFrame> frames_of(const std::string& scene_name) {
  SceneParams params;
  params.width = kWidth;
  params.height = kHeight;
  params.supersample = 2;
  auto scene = make_scene(scene_name, params);
  const TrmEncoder encoder(link_config());
  std::vector<LinkFrame> frames;
  for (int t = 0; t < kFrames; ++t) frames.push_back(encoder.encode(scene->linear_frame(t), t, 0));
  return frames;
}

FixedDecoderConfig config_of(bool skip) {
  FixedDecoderConfig config;
  config.decoder.link = link_config();
  config.decoder.panel = parse_panel("vive");
  config.skip_unneeded = skip;
  return config;
}

void decode_all(FixedStreamingDecoder& decoder, const std::vector<LinkFrame>& frames) {
  for (const LinkFrame& f : frames) benchmark::DoNotOptimize(decoder.decode(f));
}

// Seconds spent on all views and on the reduced views.
struct Timing {
  double all = 0.0;
  double reduced = 0.0;
};

void decode_timed(FixedStreamingDecoder& decoder, const std::vector<LinkFrame>& frames, Timing& timing) {
  for (const LinkFrame& f : frames) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(decoder.decode(f));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    timing.all += seconds;
    if (f.meta.parity == Parity::Reduced) timing.reduced += seconds;
  }
}

// Args: scene (0 = static, 1 = discs, 2 = text), skip (0 = full path, 1 = skip_unneeded).
void BM_DecodeSkip(benchmark::State& state) {
  const std::vector<LinkFrame> frames = frames_of(scene_of(state.range(0)));
  FixedStreamingDecoder decoder(config_of(state.range(1) != 0));
  for (auto _ : state) decode_all(decoder, frames);
  state.SetItemsProcessed(state.iterations() * kFrames);
  state.SetLabel(std::string(scene_of(state.range(0))) + (state.range(1) != 0 ? " skip" : " full path"));
}
BENCHMARK(BM_DecodeSkip)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond);

// Args: scene, skip (1: the second decoder skips; 0: both run the full path, an A/A control of the ratio: two
// decoder instances differ by several per cent on a shared machine, from where their tables land in memory).
// Both decoders decode the same frames in every iteration, in alternating order; the counters are time ratios.
void BM_DecodeSkipRatio(benchmark::State& state) {
  const std::vector<LinkFrame> frames = frames_of(scene_of(state.range(0)));
  FixedStreamingDecoder full(config_of(false));
  FixedStreamingDecoder skip(config_of(state.range(1) != 0));
  Timing full_time;
  Timing skip_time;
  bool skip_first = false;  // alternated, so neither path always runs on a warm cache
  for (auto _ : state) {
    if (skip_first) {
      decode_timed(skip, frames, skip_time);
      decode_timed(full, frames, full_time);
    } else {
      decode_timed(full, frames, full_time);
      decode_timed(skip, frames, skip_time);
    }
    skip_first = !skip_first;
  }
  state.counters["skip_over_full"] = full_time.all > 0.0 ? skip_time.all / full_time.all : 0.0;
  state.counters["reduced_skip_over_full"] = full_time.reduced > 0.0 ? skip_time.reduced / full_time.reduced : 0.0;
  state.SetLabel(std::string(scene_of(state.range(0))) + (state.range(1) != 0 ? " skip / full" : " A/A control"));
}
BENCHMARK(BM_DecodeSkipRatio)
    ->Args({0, 1})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({2, 1})
    ->Args({2, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
