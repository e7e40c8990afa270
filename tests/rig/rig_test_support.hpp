// Deterministic frames and expected device-side bytes for the rig tests.
#pragma once

#include "rig/feeder.hpp"
#include "rig/hid_report.hpp"
#include "rig/protocol.hpp"
#include "rig/transport.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace trm::rig::testing {

// A frame whose codes depend on every coordinate, so any misplaced byte shows.
inline RigFrame synthetic_frame(std::int64_t index, int eye, int width, int height, int bits) {
  RigFrame f;
  f.index = index;
  f.eye = eye;
  f.width = width;
  f.height = height;
  f.bits = bits;
  f.samples.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3u);
  const std::uint32_t mask = (1u << bits) - 1u;
  std::uint32_t state = 0x9E3779B9u ^ static_cast<std::uint32_t>(index * 7919 + eye);
  for (auto& s : f.samples) {
    state = state * 1664525u + 1013904223u;  // LCG: deterministic on every platform
    s = static_cast<std::uint16_t>((state >> 13) & mask);
  }
  return f;
}

// The test scene: several views of sizes that are not multiples of any chunk size, 8- and 10-bit.
inline std::vector<RigFrame> test_scene() {
  return {synthetic_frame(0, 0, 37, 23, 8), synthetic_frame(0, 1, 37, 23, 8), synthetic_frame(1, 0, 61, 7, 10),
          synthetic_frame(2, 0, 5, 3, 8)};
}

// Every packet of a frame as the feeder sends it (no resends).
inline std::vector<std::vector<std::uint8_t>> expected_packets(const RigFrame& frame, std::size_t max_packet, bool answer_expected) {
  const EncodedFrame e = encode_frame(frame, max_packet, answer_expected);
  std::vector<std::vector<std::uint8_t>> packets{e.start_packet};
  for (std::uint32_t s = 0; s < e.chunk_count(); ++s) packets.push_back(e.chunk_packet(s));
  packets.push_back(e.end_packet);
  return packets;
}

inline std::vector<std::uint8_t> expected_stream(const std::vector<RigFrame>& frames, std::size_t max_packet, bool answer_expected) {
  std::vector<std::uint8_t> bytes;
  for (const auto& f : frames)
    for (const auto& p : expected_packets(f, max_packet, answer_expected)) bytes.insert(bytes.end(), p.begin(), p.end());
  return bytes;
}

inline std::vector<std::vector<std::uint8_t>> expected_hid_reports(const std::vector<RigFrame>& frames, const HidReportFormat& format,
                                                                   bool answer_expected) {
  std::vector<std::vector<std::uint8_t>> reports;
  for (const auto& f : frames)
    for (const auto& p : expected_packets(f, format.report_size, answer_expected)) reports.push_back(hid_wire_report(format, p));
  return reports;
}

// Reassembles frames from device-side HID reports, as a rig would.
inline std::vector<RigFrame> receive_hid(const std::vector<std::vector<std::uint8_t>>& reports, std::uint8_t report_id) {
  StreamReceiver receiver;
  for (const auto& r : reports) receiver.accept_packet(report_id ? std::span(r).subspan(1) : std::span(r));
  return receiver.frames();
}

inline std::vector<RigFrame> receive_stream(const std::vector<std::uint8_t>& bytes) {
  StreamReceiver receiver;
  for (const auto& p : split_stream(bytes)) receiver.accept_packet(p);
  return receiver.frames();
}

inline void expect_same_frames(const std::vector<RigFrame>& got, const std::vector<RigFrame>& sent) {
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, sent[i].index);
    EXPECT_EQ(got[i].eye, sent[i].eye);
    EXPECT_EQ(got[i].width, sent[i].width);
    EXPECT_EQ(got[i].height, sent[i].height);
    EXPECT_EQ(got[i].bits, sent[i].bits);
    EXPECT_EQ(got[i].samples, sent[i].samples) << "frame " << i;
  }
}

// Feeds frames as fast as possible; returns the stats, or the error kind via `error`.
inline FeedStats feed_all(RigTransport& transport, const std::vector<RigFrame>& frames, FeedOptions options = {},
                          std::optional<RigErrorKind>* error = nullptr, std::string* message = nullptr) {
  RigFeeder feeder(transport, options);
  try {
    for (const auto& f : frames) feeder.feed(f);
  } catch (const RigError& e) {
    if (error) *error = e.kind();
    if (message) *message = e.what();
    if (!error) ADD_FAILURE() << "unexpected rig error: " << e.what();
  }
  return feeder.stats();
}

}  // namespace trm::rig::testing
