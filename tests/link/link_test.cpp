// Transmitter and receiver: round trips, exact payload ratios, frame boundaries, damage handling.
#include "trm/faults.hpp"
#include "trm/link.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace trm::link {
namespace {

using test_support::make_view;
using test_support::reduced_size;
using test_support::same_codes;

struct RoundTripCase {
  int width, height, bits;
  double r;
  PacketizerConfig config;
};

TEST(Link, RoundTripIsExactForEveryPacketisation) {
  PacketizerConfig one_line;
  PacketizerConfig four_lines{4, 1 << 20, PayloadCoding::Raw};
  PacketizerConfig slices{1, 40, PayloadCoding::Raw};   // 40 bytes: 13 pixels at 8 bits, 10 at 10 bits
  PacketizerConfig tiny{1, 4, PayloadCoding::Raw};      // one pixel per packet
  const std::vector<RoundTripCase> cases = {
      {97, 61, 8, 0.5, one_line}, {97, 61, 10, 0.5, one_line}, {64, 48, 10, 0.75, four_lines},
      {33, 7, 8, 0.25, slices},   {33, 7, 10, 0.25, slices},   {5, 3, 10, 0.5, tiny},
      {1, 1, 8, 0.5, one_line},
  };
  for (const RoundTripCase& c : cases) {
    std::vector<LinkFrame> views;
    for (int t = 0; t < 3; ++t)
      for (int eye = 0; eye < 2; ++eye) views.push_back(make_view(t, eye, c.width, c.height, c.r, c.bits));
    Receiver rx;
    Transmitter tx(c.config);
    for (const LinkFrame& v : views) {
      for (const auto& p : tx.send(v).packets) ASSERT_EQ(rx.push(p), PushResult::Accepted);
    }
    rx.flush();
    const std::vector<ReceivedFrame> got = rx.take_frames();
    ASSERT_EQ(got.size(), views.size()) << c.width << "x" << c.height;
    for (std::size_t i = 0; i < views.size(); ++i) {
      SCOPED_TRACE(::testing::Message() << c.width << "x" << c.height << " bits " << c.bits << " view " << i);
      EXPECT_EQ(got[i].meta.index, views[i].meta.index);
      EXPECT_EQ(got[i].meta.eye, views[i].meta.eye);
      EXPECT_EQ(got[i].meta.parity, views[i].meta.parity);
      EXPECT_EQ(got[i].meta.full_width, views[i].meta.full_width);
      EXPECT_EQ(got[i].meta.bits, c.bits);
      EXPECT_TRUE(got[i].complete());
      EXPECT_TRUE(same_codes(got[i].codes, views[i].codes));
    }
    EXPECT_EQ(rx.counters().frames_complete, views.size());
    EXPECT_EQ(rx.counters().lines_lost, 0u);
    EXPECT_EQ(rx.counters().sequence_gaps, 0u);
  }
}

TEST(Link, SlicesAndMultiLinePacketsFollowThePayloadLimit) {
  const LinkFrame v = make_view(0, 0, 100, 10, 0.5, 8);  // 300-byte lines
  Transmitter slices({1, 128, PayloadCoding::Raw});       // 42 pixels per slice: 42 + 42 + 16
  EXPECT_EQ(slices.send(v).packets.size(), 10u * 3u);
  Transmitter grouped({8, 1000, PayloadCoding::Raw});     // 3 lines fit 1000 bytes
  const SentView s = grouped.send(v);
  EXPECT_EQ(s.packets.size(), 4u);  // 3 + 3 + 3 + 1 lines
  for (const auto& p : s.packets) EXPECT_LE(p.size() - kPacketOverheadBytes, 1000u);
  EXPECT_EQ(s.bits.wire_bits(), [&] {
    std::uint64_t bytes = 0;
    for (const auto& p : s.packets) bytes += p.size();
    return bytes * 8;
  }());
}

// DESIGN §6: the payload of a frame pair is (W*H + w*h) / (2*W*H) of full rate, exactly (raw).
TEST(Link, PayloadPerFramePairIsExactlyTheTrmRatio) {
  struct Case { int width, height; double r; };
  for (const Case c : {Case{97, 61, 0.5}, Case{64, 48, 0.75}, Case{1080, 1200, 0.5}, Case{101, 77, 0.25},
                       Case{30, 20, 1.0}}) {
    for (int bits : {8, 10}) {
      const std::uint64_t w = static_cast<std::uint64_t>(reduced_size(c.width, c.r));
      const std::uint64_t h = static_cast<std::uint64_t>(reduced_size(c.height, c.r));
      const std::uint64_t W = static_cast<std::uint64_t>(c.width), H = static_cast<std::uint64_t>(c.height);
      Transmitter tx;
      std::uint64_t pair_payload = 0;
      for (int t = 0; t < 2; ++t) pair_payload += tx.send(make_view(t, 0, c.width, c.height, c.r, bits, false)).bits.payload_bits;
      const std::uint64_t full_rate_pair = 2 * W * H * 3 * static_cast<std::uint64_t>(bits);
      // pair / full_rate == (W*H + w*h) / (2*W*H), cross-multiplied in integers.
      EXPECT_EQ(pair_payload * 2 * W * H, full_rate_pair * (W * H + w * h))
          << c.width << "x" << c.height << " r=" << c.r << " bits=" << bits;
      if (c.r == 0.5 && c.width % 2 == 0 && c.height % 2 == 0) {
        EXPECT_DOUBLE_EQ(static_cast<double>(pair_payload) / static_cast<double>(full_rate_pair), (1 + 0.25) / 2);
      }
    }
  }
}

TEST(Link, StereoOffPhaseCarriesTheSamePayloadEveryLinkFrame) {
  Transmitter tx;
  std::vector<std::uint64_t> stereo, mono;
  for (int t = 0; t < 6; ++t) {
    std::uint64_t s = 0;
    for (int eye = 0; eye < 2; ++eye) s += tx.send(make_view(t, eye, 97, 61, 0.5, 10, true)).bits.wire_bits();
    stereo.push_back(s);
    mono.push_back(tx.send(make_view(t, 0, 97, 61, 0.5, 10, false)).bits.wire_bits());
  }
  for (int t = 1; t < 6; ++t) EXPECT_EQ(stereo[static_cast<std::size_t>(t)], stereo[0]);  // flat
  EXPECT_GT(mono[0], mono[1]);                                                         // mono alternates
  EXPECT_EQ(mono[0] + mono[1], stereo[0]);
}

TEST(Link, PredictionMatchesTheTransmitter) {
  for (const PacketizerConfig& config : {PacketizerConfig{}, PacketizerConfig{3, 500, PayloadCoding::Raw},
                                         PacketizerConfig{1, 37, PayloadCoding::Raw}}) {
    Transmitter tx(config);
    for (int t = 0; t < 2; ++t) {
      const LinkFrame v = make_view(t, 0, 97, 61, 0.5, 10, false);
      const ViewBits predicted = predict_raw_view_bits(v.meta, config), sent = tx.send(v).bits;
      EXPECT_EQ(predicted.pixel_bits, sent.pixel_bits);
      EXPECT_EQ(predicted.payload_bits, sent.payload_bits);
      EXPECT_EQ(predicted.overhead_bits, sent.overhead_bits);
      EXPECT_EQ(predicted.packets, sent.packets);
    }
  }
}

TEST(Link, TransmitterRejectsBadFrames) {
  Transmitter tx;
  LinkFrame v = make_view(0, 0, 8, 4, 0.5, 8);
  LinkFrame bad = v;
  bad.codes.at<cv::Vec3w>(1, 1)[2] = 256;
  EXPECT_THROW(tx.send(bad), std::invalid_argument);
  bad = v;
  bad.meta.width = 9;
  bad.meta.full_width = 9;
  EXPECT_THROW(tx.send(bad), std::invalid_argument);
  bad = v;
  bad.codes.convertTo(bad.codes, CV_8UC3);
  EXPECT_THROW(tx.send(bad), std::invalid_argument);
  bad = v;
  bad.meta.eye = 2;
  EXPECT_THROW(tx.send(bad), std::invalid_argument);
  bad = v;
  bad.meta.bits = 12;
  EXPECT_THROW(tx.send(bad), std::invalid_argument);
  EXPECT_THROW(Transmitter({0, 100, PayloadCoding::Raw}), std::invalid_argument);
  EXPECT_THROW(Transmitter({1, 3, PayloadCoding::Raw}), std::invalid_argument);
}

TEST(Link, LostAndDamagedPacketsLoseExactlyTheirLines) {
  const LinkFrame v = make_view(0, 0, 40, 12, 0.5, 10);
  Transmitter tx;
  const SentView sent = tx.send(v);
  ASSERT_EQ(sent.packets.size(), 12u);
  Receiver rx;
  for (std::size_t i = 0; i < sent.packets.size(); ++i) {
    if (i == 3) continue;  // dropped
    std::vector<std::uint8_t> p = sent.packets[i];
    if (i == 7) p[100] ^= 0x10;  // one bit error in the payload
    rx.push(p);
  }
  rx.flush();
  const auto frames = rx.take_frames();
  ASSERT_EQ(frames.size(), 1u);
  const ReceivedFrame& f = frames[0];
  EXPECT_EQ(f.intact_lines(), 10);
  for (int y = 0; y < 12; ++y) {
    const bool lost = y == 3 || y == 7;
    EXPECT_EQ(f.line_intact[static_cast<std::size_t>(y)], lost ? 0 : 1) << y;
    if (lost) {
      EXPECT_EQ(cv::countNonZero(f.codes.row(y).reshape(1)), 0);
    } else {
      EXPECT_TRUE(same_codes(f.codes.row(y), v.codes.row(y)));
    }
  }
  const ReceiverCounters& c = rx.counters();
  EXPECT_EQ(c.packets_received, 11u);
  EXPECT_EQ(c.packets_accepted, 10u);
  EXPECT_EQ(c.crc_failures, 1u);
  EXPECT_EQ(c.sequence_gaps, 2u);
  EXPECT_EQ(c.lines_lost, 2u);
  EXPECT_EQ(c.frames_partial, 1u);
  EXPECT_EQ(c.frames_complete, 0u);
}

TEST(Link, LostSliceLosesTheWholeLine) {
  const LinkFrame v = make_view(0, 0, 100, 3, 0.5, 8);
  Transmitter tx({1, 120, PayloadCoding::Raw});  // 40 pixels per slice: 3 slices per line
  const SentView sent = tx.send(v);
  ASSERT_EQ(sent.packets.size(), 9u);
  Receiver rx;
  for (std::size_t i = 0; i < sent.packets.size(); ++i)
    if (i != 4) rx.push(sent.packets[i]);  // middle slice of line 1
  rx.flush();
  const auto f = rx.take_frames().at(0);
  EXPECT_EQ(f.line_intact, (std::vector<std::uint8_t>{1, 0, 1}));
  EXPECT_EQ(cv::countNonZero(f.codes.row(1).reshape(1)), 0);  // never half a line
}

TEST(Link, FramesAreHandedOutWhenTheLinkMovesOnInIndexThenStreamOrder) {
  Transmitter tx;
  Receiver rx;
  // Right eye first within each link frame: the output is still (index, stream) ordered.
  for (int t = 0; t < 3; ++t)
    for (int eye : {1, 0})
      for (const auto& p : tx.send(make_view(t, eye, 16, 8, 0.5, 8)).packets) rx.push(p);
  auto frames = rx.take_frames();
  ASSERT_EQ(frames.size(), 4u);  // t = 0, 1 are over; t = 2 still open
  EXPECT_EQ(frames[0].meta.index, 0);
  EXPECT_EQ(frames[0].meta.eye, 0);
  EXPECT_EQ(frames[1].meta.eye, 1);
  EXPECT_EQ(frames[3].meta.index, 1);
  rx.flush();
  frames = rx.take_frames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].meta.index, 2);
}

TEST(Link, StaleDuplicateAndInconsistentPacketsAreRefused) {
  Transmitter tx;
  Receiver rx;
  const SentView a = tx.send(make_view(0, 0, 16, 8, 0.5, 8));
  EXPECT_EQ(rx.push(a.packets[0]), PushResult::Accepted);
  EXPECT_EQ(rx.push(a.packets[0]), PushResult::Duplicate);
  // Same index and stream but another geometry: inconsistent with the view being assembled.
  LinkFrame other = make_view(0, 0, 18, 8, 0.5, 8);
  EXPECT_EQ(rx.push(tx.send(other).packets[1]), PushResult::Inconsistent);
  rx.flush();
  EXPECT_EQ(rx.push(a.packets[1]), PushResult::Stale);  // frame 0 was handed out
  const SentView later = tx.send(make_view(5, 0, 16, 8, 0.5, 8));
  EXPECT_EQ(rx.push(later.packets[0]), PushResult::Accepted);
  const ReceiverCounters& c = rx.counters();
  EXPECT_EQ(c.duplicates, 1u);
  EXPECT_EQ(c.inconsistent, 1u);
  EXPECT_EQ(c.stale, 1u);
  EXPECT_EQ(c.frame_index_gaps, 4u);  // 1..4 never seen
}

TEST(Link, GarbageNeverCrashesTheReceiver) {
  Receiver rx({256, 256, 65536});
  std::mt19937_64 rng(7);
  std::vector<std::uint8_t> base = Transmitter().send(make_view(0, 0, 16, 8, 0.5, 8)).packets[0];
  for (int i = 0; i < 2000; ++i) {
    std::vector<std::uint8_t> p = base;
    p.resize(rng() % (base.size() * 2));
    for (auto& b : p)
      if (rng() % 8 == 0) b = static_cast<std::uint8_t>(rng());
    rx.push(p);
  }
  rx.flush();
  (void)rx.take_frames();
  EXPECT_EQ(rx.counters().packets_received, 2000u);
}

// Faults at BER 1e-6 ... 1e-3 with dropped packets: the run completes, and what the receiver reports
// intact is exactly what was sent, line by line; everything lost is accounted for.
TEST(Link, FaultSweepCountersAndIntactLinesAreExact) {
  for (double ber : {1e-6, 1e-5, 1e-4, 1e-3}) {
    SCOPED_TRACE(::testing::Message() << "BER " << ber);
    FaultInjector faults({ber, {1e-5, 24}, 0.02, 42});
    Transmitter tx;
    Receiver rx;
    std::map<std::pair<std::int64_t, int>, std::pair<LinkFrame, std::vector<std::uint8_t>>> expected;
    std::uint64_t delivered_clean = 0, delivered_damaged = 0;
    for (int t = 0; t < 24; ++t) {
      for (int eye = 0; eye < 2; ++eye) {
        LinkFrame v = make_view(t, eye, 120, 40, 0.5, 10);
        const SentView sent = tx.send(v);
        std::vector<std::uint8_t> intact(static_cast<std::size_t>(v.meta.height), 0);
        for (std::size_t i = 0; i < sent.packets.size(); ++i) {
          std::vector<std::uint8_t> p = sent.packets[i];
          if (!faults.apply(p)) continue;
          if (p == sent.packets[i]) {
            intact[i] = 1;  // one line per packet
            ++delivered_clean;
          } else {
            ++delivered_damaged;
          }
          rx.push(p);
        }
        expected[{t, eye}] = {v, intact};
      }
      rx.flush();
      for (const ReceivedFrame& f : rx.take_frames()) {
        const auto& [view, intact] = expected.at({f.meta.index, f.meta.eye});
        EXPECT_EQ(f.line_intact, intact);
        for (int y = 0; y < f.meta.height; ++y)
          if (intact[static_cast<std::size_t>(y)]) {
            EXPECT_TRUE(same_codes(f.codes.row(y), view.codes.row(y)));
          }
        expected.erase({f.meta.index, f.meta.eye});
      }
    }
    // Views not handed out are exactly those of which nothing arrived intact.
    for (const auto& [key, value] : expected)
      EXPECT_EQ(std::count(value.second.begin(), value.second.end(), 1), 0);
    const ReceiverCounters& c = rx.counters();
    const FaultCounters& fc = faults.counters();
    EXPECT_EQ(c.packets_received, fc.packets_seen - fc.packets_dropped);
    EXPECT_EQ(c.packets_accepted, delivered_clean);
    EXPECT_EQ(fc.packets_damaged, delivered_damaged);
    EXPECT_EQ(c.crc_failures, delivered_damaged);  // every damaged packet caught by the CRC
    EXPECT_GT(fc.packets_dropped, 0u);
    if (ber >= 1e-4) {
      EXPECT_GT(c.crc_failures, 0u);
    }
  }
}

}  // namespace
}  // namespace trm::link
