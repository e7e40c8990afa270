// Pacing, dropping and the summary, with an in-memory transport (no device involved).
#include "rig/feeder.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace trm::rig::testing {
namespace {

using namespace std::chrono_literals;

class MemoryTransport final : public RigTransport {
 public:
  explicit MemoryTransport(std::chrono::milliseconds delay_per_frame_end = 0ms) : delay_(delay_per_frame_end) {}
  std::string description() const override { return "memory"; }
  std::size_t max_packet_size() const override { return 256; }
  void send(std::span<const std::uint8_t> packet) override {
    bytes.insert(bytes.end(), packet.begin(), packet.end());
    if (packet[0] == static_cast<std::uint8_t>(PacketType::FrameEnd)) std::this_thread::sleep_for(delay_);
  }
  bool can_receive() const override { return false; }
  std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds) override { return std::nullopt; }
  TransportRate nominal_rate() const override { return {64000.0, "test"}; }
  std::vector<std::uint8_t> bytes;

 private:
  std::chrono::milliseconds delay_;
};

TEST(RigFeeder, PacesFramesAtTheRequestedRate) {
  MemoryTransport transport;
  FeedOptions options;
  options.fps = 100.0;
  const auto started = std::chrono::steady_clock::now();
  std::vector<RigFrame> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(synthetic_frame(i, 0, 4, 4, 8));
  const FeedStats stats = feed_all(transport, frames, options);
  const auto took = std::chrono::steady_clock::now() - started;
  EXPECT_GE(took, 50ms);  // slots 0..5 open at 0, 10, ..., 50 ms
  EXPECT_LT(took, 1000ms);
  EXPECT_EQ(stats.frames_sent, 6);
  EXPECT_EQ(stats.frames_dropped, 0);
  expect_same_frames(receive_stream(transport.bytes), frames);
}

// The feeder reuses its payload and chunk buffers from frame to frame: frames that grow, shrink, change depth and
// fail in between still arrive each exactly as given.
TEST(RigFeeder, ReusedBuffersCarryEveryFrameExactlyAcrossSizesAndDepths) {
  MemoryTransport transport;
  RigFeeder feeder(transport, FeedOptions{});
  std::vector<RigFrame> frames = {synthetic_frame(0, 0, 40, 30, 8), synthetic_frame(1, 1, 8, 4, 10),
                                  synthetic_frame(2, 0, 64, 48, 10), synthetic_frame(3, 0, 3, 5, 8)};
  for (const RigFrame& f : frames) EXPECT_TRUE(feeder.feed(f));
  RigFrame too_high = synthetic_frame(4, 0, 16, 16, 8);
  too_high.samples.back() = 256;
  EXPECT_THROW(feeder.feed(too_high), std::invalid_argument);
  frames.push_back(synthetic_frame(5, 0, 16, 16, 8));
  EXPECT_TRUE(feeder.feed(frames.back()));
  expect_same_frames(receive_stream(transport.bytes), frames);
}

TEST(RigFeeder, DropsFramesWhoseSlotHasPassed) {
  MemoryTransport transport(25ms);  // each frame takes 2.5 slots at 100 Hz
  FeedOptions options;
  options.fps = 100.0;
  std::vector<RigFrame> frames;
  for (int i = 0; i < 8; ++i) frames.push_back(synthetic_frame(i, 0, 4, 4, 8));
  const FeedStats stats = feed_all(transport, frames, options);
  EXPECT_EQ(stats.frames_sent + stats.frames_dropped, 8);
  EXPECT_GE(stats.frames_dropped, 3);
  EXPECT_EQ(static_cast<std::int64_t>(receive_stream(transport.bytes).size()), stats.frames_sent);

  MemoryTransport unhurried(25ms);
  options.drop_late = false;
  EXPECT_EQ(feed_all(unhurried, frames, options).frames_dropped, 0);
}

// A source whose first two frames come late (a decoder's start-up): without a pre-roll the run starts behind its
// slots and drops; with one, those frames go out as they come and the pace starts with the third.
TEST(RigFeeder, PreRolledFramesGoOutBeforeThePaceStarts) {
  std::vector<RigFrame> frames;
  for (int i = 0; i < 8; ++i) frames.push_back(synthetic_frame(i, 0, 4, 4, 8));
  const auto feed_with_slow_start = [&](int preroll, std::chrono::steady_clock::duration* paced_part) {
    MemoryTransport transport;
    FeedOptions options;
    options.fps = 50.0;  // 20 ms slots: room for a loaded machine
    options.preroll_frames = preroll;
    RigFeeder feeder(transport, options);
    std::chrono::steady_clock::time_point third;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      if (i == 1) std::this_thread::sleep_for(90ms);  // frame 1 comes 4.5 slots after frame 0
      if (i == 2) third = std::chrono::steady_clock::now();
      feeder.feed(frames[i]);
    }
    if (paced_part) *paced_part = std::chrono::steady_clock::now() - third;
    EXPECT_EQ(static_cast<std::int64_t>(receive_stream(transport.bytes).size()), feeder.stats().frames_sent);
    return feeder.stats();
  };
  const FeedStats behind = feed_with_slow_start(0, nullptr);
  EXPECT_GE(behind.frames_dropped, 1) << "frame 1 came after its slot closed";
  std::chrono::steady_clock::duration paced{};
  const FeedStats rolled = feed_with_slow_start(2, &paced);
  EXPECT_EQ(rolled.frames_dropped, 0);
  EXPECT_EQ(rolled.frames_sent, 8);
  EXPECT_GE(paced, 100ms) << "frames 2..7 are paced: their slots open at 0, 20, ..., 100 ms";
  MemoryTransport unused;
  FeedOptions negative;
  negative.preroll_frames = -1;
  EXPECT_THROW(RigFeeder(unused, negative), std::invalid_argument);
}

TEST(RigFeeder, SummaryAndProgressLine) {
  MemoryTransport transport;
  FeedOptions options;
  int progress_calls = 0;
  options.on_progress = [&](const FeedStats&) { ++progress_calls; };
  const FeedStats stats = feed_all(transport, {synthetic_frame(7, 0, 30, 30, 10)}, options);
  EXPECT_GE(progress_calls, 1);
  const auto j = stats.to_json();
  EXPECT_EQ(j["frames_sent"], 1);
  EXPECT_EQ(j["last_frame_sent"], 7);
  EXPECT_EQ(j["wire_bytes_sent"], transport.bytes.size());
  EXPECT_EQ(j["payload_bytes_sent"], 30u * 30u * 3u * 2u);
  EXPECT_FALSE(j.contains("interrupted"));
  EXPECT_NE(stats.progress_line().find("sent 1 frames"), std::string::npos);
}

TEST(RigFeeder, TimePerFrameFollowsTheTransportRate) {
  MemoryTransport transport;  // 64 kB/s, 256-byte packets
  RigFrame headset;
  headset.width = 1080;
  headset.height = 1200;
  headset.bits = 8;
  // 3,888,000 payload bytes in 248-byte chunks: 15,678 chunks, 8 bytes of header each.
  const double seconds = RigFeeder::seconds_per_frame(transport, headset);
  EXPECT_NEAR(seconds, (3888000.0 + 15678 * 8 + 64 + 24) / 64000.0, 1e-6);
}

TEST(RigFeeder, FlowControlNeedsATransportThatCanAnswer) {
  MemoryTransport transport;
  FeedOptions options;
  options.flow_control = true;
  EXPECT_THROW(RigFeeder(transport, options), std::invalid_argument);
}

}  // namespace
}  // namespace trm::rig::testing
