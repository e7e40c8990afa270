// The whole pipeline over a faulty link: the run completes, the counters add up, and with an OLED panel every
// frame pair that arrives intact decodes to exactly the bits of a fault-free run.
#include "capture_replay.hpp"
#include "pipeline.hpp"

#include "trm/capture.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <unistd.h>
#include <utility>
#include <vector>

namespace trm::cli {
namespace {

struct ViewRecord {
  cv::Mat codes;
  bool intact = false;
  Parity parity = Parity::Full;
};
using Records = std::map<std::pair<std::int64_t, int>, ViewRecord>;

Records run(const PipelineOptions& options, PipelineResult* result = nullptr,
            std::vector<link::LinkFrameUsage>* usage = nullptr) {
  Records records;
  PipelineResult r = run_pipeline(
      options,
      [&](const DecodedView& view) {
        const FrameStats& s = view.decoded->stats;
        records[{view.sent->meta.index, view.sent->meta.eye}] = {
            view.decoded->drive_codes.clone(), s.concealed_lines == 0 && !s.frame_lost, view.sent->meta.parity};
      },
      [&](const link::LinkFrameUsage& u) {
        if (usage) usage->push_back(u);
      });
  if (result) *result = std::move(r);
  return records;
}

PipelineOptions small_run(bool stereo, int width = 64, int height = 48, std::int64_t frames = 24) {
  PipelineOptions options;
  options.scene = "discs";
  options.width = width;
  options.height = height;
  options.frames = frames;
  options.encoder.stereo = stereo;
  return options;
}

struct FaultCase {
  double ber = 0.0;
  double drop = 0.0;
  bool stereo = false;
  int width = 64, height = 48;  // small views at high error rates, so that some pairs still arrive intact
  std::int64_t frames = 24;
};

class LinkRecovery : public ::testing::TestWithParam<FaultCase> {};

TEST_P(LinkRecovery, IntactPairsAreBitExactAfterFaults) {
  const FaultCase c = GetParam();
  const auto [ber, drop, stereo] = std::make_tuple(c.ber, c.drop, c.stereo);
  const Records clean = run(small_run(stereo, c.width, c.height, c.frames));
  PipelineOptions faulty = small_run(stereo, c.width, c.height, c.frames);
  faulty.link_preset = "dp1.4";
  faulty.ber = ber;
  faulty.drop = drop;
  faulty.seed = 7;
  PipelineResult result;
  const Records got = run(faulty, &result);
  ASSERT_TRUE(result.link);
  const auto& f = result.link->faults;
  const auto& rx = result.link->receiver;
  // Every packet was either dropped or delivered, and every delivered damaged packet failed its CRC (or, if a
  // flip hit the header so that it no longer parses, was rejected as malformed).
  EXPECT_EQ(rx.packets_received + f.packets_dropped, f.packets_seen);
  EXPECT_EQ(rx.crc_failures + rx.malformed, f.packets_damaged);
  EXPECT_EQ(rx.packets_accepted, rx.packets_received - f.packets_damaged);
  EXPECT_EQ(got.size(), clean.size());

  int intact_pairs = 0, damaged_views = 0;
  for (const auto& [key, record] : got) {
    if (!record.intact) ++damaged_views;
    const auto [t, eye] = key;
    // A TRM pair of one eye: its full frame and the reduced frame right after it.
    if (record.parity == Parity::Reduced && got.count({t - 1, eye}) > 0) {
      const ViewRecord& first = got.at({t - 1, eye});
      if (first.intact && record.intact) {
        ++intact_pairs;
        EXPECT_EQ(cv::norm(first.codes, clean.at({t - 1, eye}).codes, cv::NORM_INF), 0.0) << "t = " << t - 1;
        EXPECT_EQ(cv::norm(record.codes, clean.at(key).codes, cv::NORM_INF), 0.0) << "t = " << t;
      }
    }
  }
  EXPECT_GT(damaged_views, 0) << "the fault rate should damage something in this run";
  EXPECT_GT(intact_pairs, 0) << "the fault rate should leave some pair intact in this run";
}

INSTANTIATE_TEST_SUITE_P(Faults, LinkRecovery,
                         ::testing::Values(FaultCase{1e-6, 0.0, false}, FaultCase{1e-5, 0.0, true},
                                           FaultCase{1e-4, 0.0, false, 16, 12, 60},
                                           FaultCase{1e-3, 0.0, false, 6, 4, 200},
                                           FaultCase{1e-3, 0.0, true, 6, 4, 300}, FaultCase{0.0, 0.05, false, 16, 12, 60},
                                           FaultCase{0.0, 0.02, true}, FaultCase{1e-5, 0.01, true}));

// Replay reads the capture on a thread of its own, a view ahead of the decoder: the views still come out in link
// order with the run's bits, and a capture cut short hands on every view before the cut before its error.
TEST(Link, CaptureReplayReadAheadKeepsOrderBitsAndErrorsInPlace) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("trm-replay-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  PipelineOptions options = small_run(true, 32, 24, 8);
  options.impl = "fixed";
  options.capture_out = (dir / "run.trmcap").string();
  const Records sent = run(options);
  ASSERT_EQ(sent.size(), 16u);

  PipelineOptions replay = small_run(true, 32, 24, 8);
  replay.impl = "fixed";
  std::vector<std::pair<std::int64_t, int>> order;
  const CaptureDecodeResult whole = decode_capture_stream(
      replay, options.capture_out,
      [&](const FrameMeta& meta, SlotOutcome outcome, const link::ReceivedFrame*, const DecodedFrame& decoded) {
        EXPECT_EQ(outcome, SlotOutcome::Arrived);
        order.emplace_back(meta.index, meta.eye);
        EXPECT_EQ(cv::norm(decoded.drive_codes, sent.at({meta.index, meta.eye}).codes, cv::NORM_INF), 0.0)
            << "t = " << meta.index << ", eye " << meta.eye;
      });
  EXPECT_EQ(whole.views, 16);
  ASSERT_EQ(order.size(), 16u);
  for (std::size_t i = 0; i < order.size(); ++i) {
    EXPECT_EQ(order[i], std::make_pair(static_cast<std::int64_t>(i / 2), static_cast<int>(i % 2)));
  }

  const fs::path cut = dir / "cut.trmcap";
  fs::copy_file(options.capture_out, cut);
  fs::resize_file(cut, fs::file_size(cut) * 5 / 8);  // inside link frame 4 or 5 of 8
  std::vector<std::pair<std::int64_t, int>> before_cut;
  EXPECT_THROW(decode_capture_stream(replay, cut.string(),
                                     [&](const FrameMeta& meta, SlotOutcome, const link::ReceivedFrame*,
                                         const DecodedFrame&) { before_cut.emplace_back(meta.index, meta.eye); }),
               link::CaptureError);
  EXPECT_GE(before_cut.size(), 6u) << "the views read before the cut are handed on before the error";
  EXPECT_LT(before_cut.size(), 16u);
  for (std::size_t i = 0; i < before_cut.size(); ++i) EXPECT_EQ(before_cut[i], order[i]);
  fs::remove_all(dir);
}

TEST(Link, PayloadPerPairIsExactAndStereoIsFlat) {
  for (bool stereo : {false, true}) {
    PipelineOptions options = small_run(stereo);
    options.width = 97;
    options.height = 61;
    options.frames = 6;
    options.link_preset = "dp1.2";
    PipelineResult result;
    std::vector<link::LinkFrameUsage> usage;
    run(options, &result, &usage);
    ASSERT_TRUE(result.link);
    ASSERT_EQ(usage.size(), 6u);
    EXPECT_EQ(result.link->summary.link_frames, 6);
    const int w = 49, h = 31;  // floor(0.5 * 97 + 0.5), floor(0.5 * 61 + 0.5)
    const std::uint64_t full_bits = 97ull * 61 * 3 * 8, reduced_bits = static_cast<std::uint64_t>(w) * h * 3 * 8;
    for (const auto& frame : usage) {
      if (stereo) {
        EXPECT_EQ(frame.bits.pixel_bits, full_bits + reduced_bits);
        EXPECT_EQ(frame.bits.wire_bits(), usage.front().bits.wire_bits());
      } else {
        EXPECT_EQ(frame.bits.pixel_bits, frame.index % 2 == 0 ? full_bits : reduced_bits);
      }
    }
    EXPECT_TRUE(result.link->summary.fits);
  }
}

}  // namespace
}  // namespace trm::cli
