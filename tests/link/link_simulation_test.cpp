// The assembled link: transmitter -> capture -> faults -> receiver, and capture replay.
#include "trm/link_simulation.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace trm::link {
namespace {

using test_support::out_dir;

using test_support::make_view;
using test_support::same_codes;

TEST(LinkSimulation, CarriesAccountsRecordsAndReplays) {
  const auto capture = out_dir() / "simulation.trmcap";
  LinkSimulationConfig config;
  config.budget = {parse_link_preset("dp1.2"), 90.0, std::nullopt};
  config.faults = {1e-4, {}, 0.05, 3};
  config.capture = capture;
  config.capture_metadata = R"({"stereo":true})";
  LinkSimulation sim(config);

  std::vector<std::vector<LinkFrame>> sent;
  std::uint64_t intact_lines = 0;
  for (std::int64_t t = 0; t < 6; ++t) {
    std::vector<LinkFrame> views = {make_view(t, 0, 50, 20, 0.5, 10), make_view(t, 1, 50, 20, 0.5, 10)};
    const std::vector<ReceivedFrame> received = sim.carry(t, views);
    const LinkFrameUsage& u = sim.meter().last();
    EXPECT_EQ(u.index, t);
    EXPECT_EQ(u.views, 2);
    EXPECT_EQ(u.bits.pixel_bits, (50u * 20 + 25 * 10) * 30);  // stereo off-phase: the same every frame
    EXPECT_TRUE(u.fits);
    for (const ReceivedFrame& f : received) {
      EXPECT_EQ(f.meta.index, t);
      const LinkFrame& v = views[static_cast<std::size_t>(f.meta.eye)];
      for (int y = 0; y < f.meta.height; ++y)
        if (f.line_intact[static_cast<std::size_t>(y)]) {
          EXPECT_TRUE(same_codes(f.codes.row(y), v.codes.row(y)));
          ++intact_lines;
        }
    }
    sent.push_back(std::move(views));
  }
  sim.finish();

  EXPECT_EQ(sim.meter().summary().link_frames, 6);
  const FaultCounters& fc = sim.fault_counters();
  const ReceiverCounters& rc = sim.receiver_counters();
  EXPECT_EQ(rc.packets_received, fc.packets_seen - fc.packets_dropped);
  EXPECT_EQ(rc.crc_failures, fc.packets_damaged);
  EXPECT_EQ(intact_lines, rc.packets_accepted);  // one line per packet
  EXPECT_GT(fc.packets_dropped + fc.packets_damaged, 0u);

  // The capture holds the stream as sent: replayed, every view arrives complete and exact.
  CaptureReplay replay(capture);
  EXPECT_EQ(replay.metadata(), R"({"stereo":true})");
  std::size_t n = 0;
  while (std::optional<ReceivedFrame> f = replay.next_frame()) {
    ASSERT_LT(n, 12u);
    const LinkFrame& v = sent[n / 2][n % 2];
    EXPECT_EQ(f->meta.index, v.meta.index);
    EXPECT_EQ(f->meta.eye, v.meta.eye);
    EXPECT_TRUE(f->complete());
    EXPECT_TRUE(same_codes(f->codes, v.codes));
    ++n;
  }
  EXPECT_EQ(n, 12u);
  EXPECT_EQ(replay.counters().crc_failures, 0u);
}

TEST(LinkSimulation, TruncatedCaptureReplayIsAClearError) {
  const auto capture = out_dir() / "replay_truncated.trmcap";
  {
    LinkSimulationConfig config;
    config.budget = {parse_link_preset("dp1.2"), 90.0, std::nullopt};
    config.capture = capture;
    LinkSimulation sim(config);
    const std::vector<LinkFrame> views = {make_view(0, 0, 16, 8, 0.5, 8)};
    sim.carry(0, views);
    sim.finish();
  }
  std::filesystem::resize_file(capture, std::filesystem::file_size(capture) - 30);
  CaptureReplay replay(capture);
  EXPECT_THROW(
      {
        while (replay.next_frame()) {
        }
      },
      CaptureError);
}

TEST(LinkSimulation, RejectsAViewOfAnotherFrame) {
  LinkSimulationConfig config;
  config.budget = {parse_link_preset("dp1.2"), 90.0, std::nullopt};
  LinkSimulation sim(config);
  const std::vector<LinkFrame> views = {make_view(3, 0, 16, 8, 0.5, 8)};
  EXPECT_THROW(sim.carry(2, views), std::invalid_argument);
  config.faults.bit_error_rate = 2.0;
  EXPECT_THROW(LinkSimulation{config}, std::invalid_argument);
}

}  // namespace
}  // namespace trm::link
