// The C API's cost per line (trm/trm_c.h) against the C++ streaming decoder it wraps: a full and a reduced view of
// 2160x1200 (r = 1/2, vive OLED, encoded noise) pushed line by line, every ready row read after each push: as a span
// in C++ (FixedStreamingDecoder::drive_row), copied into the caller's buffer through trm_decoder_pop_line in C. The
// counter ns_per_line (shown in seconds) is the pair's CPU time over its input lines (1200 full + 600 reduced). The
// decode dominates and varies more than the interface costs, so the *CallsPerLine pair times the interfaces alone.
#include "trm/decoder_json.hpp"
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/panel.hpp"
#include "trm/trm_c.h"

#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

constexpr int kWidth = 2160;
constexpr int kHeight = 1200;

trm::FixedDecoderConfig config() {
  trm::FixedDecoderConfig c;
  c.decoder.link.reduction = 0.5;
  c.decoder.panel = trm::parse_panel("vive");
  return c;
}

// A full view t = 0 and the reduced view t = 1 after it, of slowly moving noise.
const std::vector<trm::LinkFrame>& views() {
  static const std::vector<trm::LinkFrame> frames = [] {
    const trm::TrmEncoder encoder(config().decoder.link);
    cv::Mat image(kHeight, kWidth, CV_64FC3);
    cv::RNG rng(7);
    rng.fill(image, cv::RNG::UNIFORM, cv::Scalar::all(0.0), cv::Scalar::all(1.0));
    std::vector<trm::LinkFrame> out;
    out.push_back(encoder.encode(image, 0, 0));
    cv::Mat moved;
    cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 1, 0, 1, 0);
    cv::warpAffine(image, moved, shift, image.size(), cv::INTER_NEAREST, cv::BORDER_REFLECT);
    out.push_back(encoder.encode(moved, 1, 0));
    return out;
  }();
  return frames;
}

constexpr double kLinesPerPair = kHeight + kHeight / 2;

void BM_CppStreamingPerLine(benchmark::State& state) {
  trm::FixedStreamingDecoder decoder(config());
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    for (const trm::LinkFrame& frame : views()) {
      decoder.begin_view(frame.meta);
      int next = 0;
      for (int y = 0; y < frame.codes.rows; ++y) {
        const std::size_t samples = 3 * static_cast<std::size_t>(frame.codes.cols);
        const int ready = decoder.push_line(std::span<const std::uint16_t>(frame.codes.ptr<std::uint16_t>(y), samples));
        for (; next < ready; ++next) checksum += decoder.drive_row(next)[0];
      }
      benchmark::DoNotOptimize(decoder.end_view());
    }
  }
  benchmark::DoNotOptimize(checksum);
  state.counters["ns_per_line"] =
      benchmark::Counter(kLinesPerPair, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_CApiPerLine(benchmark::State& state) {
  trm_decoder* d = nullptr;
  const std::string json = trm::fixed_decoder_json(config()).dump();
  if (trm_decoder_create_json(json.c_str(), &d) != TRM_OK) {
    state.SkipWithError(trm_last_error());
    return;
  }
  std::vector<std::uint16_t> row(3 * kWidth);
  std::uint64_t checksum = 0;
  bool failed = false;
  for (auto _ : state) {
    for (const trm::LinkFrame& frame : views()) {
      const int kind = frame.meta.parity == trm::Parity::Full ? TRM_FRAME_FULL : TRM_FRAME_REDUCED;
      failed |= trm_decoder_begin_view(d, kWidth, kHeight, kind, 0, frame.meta.index) != TRM_OK;
      for (int y = 0; y < frame.codes.rows; ++y) {
        failed |= trm_decoder_push_line(d, frame.codes.ptr<std::uint16_t>(y), 3 * static_cast<size_t>(frame.codes.cols),
                                        1) != TRM_OK;
        int32_t index = 0;
        while (trm_decoder_pop_line(d, &index, row.data(), row.size(), nullptr) == TRM_OK) checksum += row[0];
      }
      failed |= trm_decoder_end_view(d) != TRM_OK;
    }
  }
  if (failed) state.SkipWithError(trm_decoder_last_error(d));
  benchmark::DoNotOptimize(checksum);
  trm_decoder_destroy(d);
  state.counters["ns_per_line"] =
      benchmark::Counter(kLinesPerPair, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// The interfaces alone, without decoding: a full view whose every line is lost computes nothing until its end (a lost
// view then holds the previous output), so these time the calls per line: push, end, and reading each row (C++: a
// span of the returned frame; C: trm_decoder_pop_line copying it out).
void BM_CppCallsPerLine(benchmark::State& state) {
  trm::FixedStreamingDecoder decoder(config());
  const trm::LinkFrame& frame = views()[0];
  decoder.decode(frame);  // a previous output to hold
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    decoder.begin_view(frame.meta);
    for (int y = 0; y < kHeight; ++y) decoder.push_line({}, false);
    const trm::DecodedFrame held = decoder.end_view();
    for (int y = 0; y < kHeight; ++y) checksum += held.drive_codes.ptr<std::uint16_t>(y)[0];
  }
  benchmark::DoNotOptimize(checksum);
  state.counters["ns_per_line"] = benchmark::Counter(
      kHeight, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_CApiCallsPerLine(benchmark::State& state) {
  trm_decoder* d = nullptr;
  const std::string json = trm::fixed_decoder_json(config()).dump();
  if (trm_decoder_create_json(json.c_str(), &d) != TRM_OK) {
    state.SkipWithError(trm_last_error());
    return;
  }
  const trm::LinkFrame& frame = views()[0];
  bool failed = trm_decoder_begin_view(d, kWidth, kHeight, TRM_FRAME_FULL, 0, 0) != TRM_OK;
  for (int y = 0; y < kHeight; ++y) {
    failed |= trm_decoder_push_line(d, frame.codes.ptr<std::uint16_t>(y), 3 * kWidth, 1) != TRM_OK;
  }
  failed |= trm_decoder_end_view(d) != TRM_OK;
  std::vector<std::uint16_t> row(3 * kWidth);
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    failed |= trm_decoder_begin_view(d, kWidth, kHeight, TRM_FRAME_FULL, 0, 0) != TRM_OK;
    for (int y = 0; y < kHeight; ++y) failed |= trm_decoder_push_line(d, nullptr, 0, 0) != TRM_OK;
    failed |= trm_decoder_end_view(d) != TRM_OK;
    int32_t index = 0;
    while (trm_decoder_pop_line(d, &index, row.data(), row.size(), nullptr) == TRM_OK) checksum += row[0];
  }
  if (failed) state.SkipWithError(trm_decoder_last_error(d));
  benchmark::DoNotOptimize(checksum);
  trm_decoder_destroy(d);
  state.counters["ns_per_line"] = benchmark::Counter(
      kHeight, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_CppCallsPerLine);
BENCHMARK(BM_CApiCallsPerLine);
BENCHMARK(BM_CppStreamingPerLine)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_CApiPerLine)->Unit(benchmark::kMillisecond)->MinTime(2.0);
