// The hidapi transport against an emulated HID rig, built once per hidapi backend
// (TRM_RIG_HID_BACKEND): byte-exact reports, numbered and feature reports, flow control, faults.
#include "emulated_bench.hpp"
#include "rig/device_list.hpp"
#include "rig/feeder.hpp"
#include "rig/file_transport.hpp"
#include "rig/hid_transport.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace trm::rig::testing {
namespace {

using namespace std::chrono_literals;

constexpr const char* kBackend = TRM_RIG_HID_BACKEND;

// The libusb backend talks to the USB device node; the hidraw node exists only for the hidraw backend.
HidRigConfig rig_config(std::size_t report_size = 64, std::uint8_t report_id = 0) {
  HidRigConfig config;
  config.report_size = report_size;
  config.report_id = report_id;
  config.with_hidraw_node = std::string(kBackend) == "hidraw";
  return config;
}

HidOptions hid_options(std::size_t report_size = 64, std::uint8_t report_id = 0, bool feature = false) {
  HidOptions o;
  o.id = kHidRigId;
  o.format = HidReportFormat{report_size, report_id, feature};
  return o;
}

// Small frames: a 64-byte report carries 56 payload bytes, so every frame spans many reports.
std::vector<RigFrame> hid_scene() {
  return {synthetic_frame(0, 0, 9, 5, 8), synthetic_frame(0, 1, 9, 5, 8), synthetic_frame(1, 0, 7, 3, 10)};
}

TEST(Hid, LinkedBackendIsTheOneThisBinaryTests) { EXPECT_EQ(linked_hidapi().backend, kBackend); }

struct FormatCase {
  std::size_t report_size;
  std::uint8_t report_id;
  bool feature;
};

class HidDelivery : public ::testing::TestWithParam<FormatCase> {};

TEST_P(HidDelivery, SeveralFramesArriveByteExact) {
  const FormatCase c = GetParam();
  HidRigConfig config = rig_config(c.report_size, c.report_id);
  EmulatedBench bench;
  bench.add_hid_rig(config);
  const auto frames = hid_scene();
  FeedStats stats;
  {
    HidTransport transport(hid_options(c.report_size, c.report_id, c.feature));
    EXPECT_NE(transport.description().find(std::string("hidapi ") + kBackend), std::string::npos);
    stats = feed_all(transport, frames);
  }
  const HidReportFormat format{c.report_size, c.report_id, c.feature};
  const auto expected = expected_hid_reports(frames, format, false);
  const auto received = bench.hid_reports_received();
  ASSERT_EQ(received.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(received[i], expected[i]) << "report " << i;
  for (const auto& kind : bench.hid_report_kinds()) EXPECT_EQ(kind, c.feature ? "feature" : "interrupt");
  expect_same_frames(receive_hid(received, c.report_id), frames);
  EXPECT_EQ(stats.frames_sent, 3);
  EXPECT_EQ(stats.wire_bytes_sent, expected.size() * (c.report_size + (c.report_id ? 1 : 0)));
}

INSTANTIATE_TEST_SUITE_P(Formats, HidDelivery,
                         ::testing::Values(FormatCase{64, 0, false}, FormatCase{64, 7, false}, FormatCase{1024, 0, false},
                                           FormatCase{512, 3, false}, FormatCase{64, 0, true}, FormatCase{64, 5, true}),
                         [](const auto& info) {
                           return std::string(info.param.feature ? "Feature" : "Output") + std::to_string(info.param.report_size) +
                                  "Id" + std::to_string(info.param.report_id);
                         });

TEST(Hid, ChunkingOfAFrameThatIsNotAMultipleOfTheReport) {
  EmulatedBench bench;
  bench.add_hid_rig(rig_config());
  // 7 x 3 x 3 x 2 = 126 payload bytes in 56-byte chunks: 56, 56, 14.
  const RigFrame frame = synthetic_frame(3, 0, 7, 3, 10);
  {
    HidTransport transport(hid_options());
    feed_all(transport, {frame});
  }
  const auto reports = bench.hid_reports_received();
  ASSERT_EQ(reports.size(), 5u);
  for (const auto& r : reports) EXPECT_EQ(r.size(), 64u);
  for (std::uint32_t s = 0; s < 3; ++s) {
    const ChunkHeader h = decode_chunk_header(reports[1 + s]);
    EXPECT_EQ(h.sequence, s);
    EXPECT_EQ(h.last, s == 2);
    EXPECT_EQ(h.length, s == 2 ? 14 : 56);
  }
  // The short last chunk is zero-padded to the report size.
  for (std::size_t i = kChunkHeaderSize + 14; i < 64; ++i) EXPECT_EQ(reports[3][i], 0) << i;
}

TEST(Hid, FileTransportWritesExactlyWhatTheDeviceReceived) {
  const auto frames = hid_scene();
  EmulatedBench bench;
  bench.add_hid_rig(rig_config(64, 9));
  {
    HidTransport transport(hid_options(64, 9));
    feed_all(transport, frames);
  }
  const std::string path = "/tmp/trm-rig-hid-" + std::to_string(::getpid()) + ".bin";
  {
    FileTransport file({path, FileTransportOptions::Framing::Hid, 0, HidReportFormat{64, 9, false}});
    feed_all(file, frames);
    file.finish();
  }
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> written{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ::unlink(path.c_str());
  std::vector<std::uint8_t> device;
  for (const auto& r : bench.hid_reports_received()) device.insert(device.end(), r.begin(), r.end());
  ASSERT_FALSE(device.empty());
  EXPECT_EQ(written, device);
}

TEST(Hid, ResendAndReadyAnswersAreHonoured) {
  HidRigConfig config = rig_config();
  config.behaviour.answer = [](const FrameEnd& end, int times_seen) -> std::optional<Answer> {
    if (end.frame_index == 1 && times_seen == 1) return Answer{AnswerKind::Resend, 0, 1, end.frame_index};
    return Answer{AnswerKind::Ready, 0, 0, end.frame_index};
  };
  EmulatedBench bench;
  bench.add_hid_rig(config);
  const auto frames = hid_scene();
  FeedOptions options;
  options.flow_control = true;
  options.answer_timeout = 2000ms;
  FeedStats stats;
  {
    HidTransport transport(hid_options());
    stats = feed_all(transport, frames, options);
  }
  EXPECT_EQ(stats.frames_sent, 3);
  EXPECT_EQ(stats.resends, 1);
  EXPECT_EQ(bench.answers_sent(), 4);
  // Frame 1 is followed by its chunks 1.. and its end once more.
  const HidReportFormat format{64, 0, false};
  auto expected = expected_hid_reports(frames, format, true);
  const EncodedFrame last = encode_frame(frames[2], 64, true);
  for (std::uint32_t s = 1; s < last.chunk_count(); ++s) expected.push_back(hid_wire_report(format, last.chunk_packet(s)));
  expected.push_back(hid_wire_report(format, last.end_packet));
  EXPECT_EQ(bench.hid_reports_received(), expected);
}

TEST(Hid, ErrorAnswerStopsWithRigReported) {
  HidRigConfig config = rig_config(64, 2);
  config.behaviour.answer = [](const FrameEnd& end, int) -> std::optional<Answer> {
    return Answer{end.frame_index == 0 ? AnswerKind::Ready : AnswerKind::Error, 3, 0, end.frame_index};
  };
  EmulatedBench bench;
  bench.add_hid_rig(config);
  FeedOptions options;
  options.flow_control = true;
  std::optional<RigErrorKind> error;
  std::string message;
  HidTransport transport(hid_options(64, 2));
  const FeedStats stats = feed_all(transport, {synthetic_frame(0, 0, 4, 4, 8), synthetic_frame(1, 0, 4, 4, 8)}, options, &error, &message);
  ASSERT_EQ(error, RigErrorKind::RigReported);
  EXPECT_NE(message.find("out of buffer memory"), std::string::npos) << message;
  EXPECT_EQ(stats.frames_sent, 1);
  EXPECT_EQ(stats.interrupted_frame, 1);
}

TEST(Hid, SilentRigTimesOut) {
  EmulatedBench bench;
  bench.add_hid_rig(rig_config());
  FeedOptions options;
  options.flow_control = true;
  options.answer_timeout = 200ms;
  std::optional<RigErrorKind> error;
  std::string message;
  HidTransport transport(hid_options());
  const auto started = std::chrono::steady_clock::now();
  const FeedStats stats = feed_all(transport, hid_scene(), options, &error, &message);
  const auto waited = std::chrono::steady_clock::now() - started;
  ASSERT_EQ(error, RigErrorKind::Timeout);
  EXPECT_NE(message.find("stopped answering"), std::string::npos) << message;
  EXPECT_GE(waited, 200ms);
  EXPECT_LT(waited, 1500ms);
  EXPECT_EQ(stats.frames_sent, 0);
}

struct HidFaultCase {
  Fault fault;
  RigErrorKind expected;
};

class HidFault : public ::testing::TestWithParam<HidFaultCase> {};

TEST_P(HidFault, MidFrameFaultGivesTheDocumentedErrorAndKeepsTheTally) {
  HidRigConfig config = rig_config();
  config.behaviour.fault = GetParam().fault;
  const auto frames = hid_scene();
  const std::size_t reports_before = expected_hid_reports({frames[0]}, HidReportFormat{}, false).size() + 3;
  // hidraw hands the device 65 bytes per unnumbered report (the 0 ID byte), libusb 64.
  const std::size_t bytes_per_report = std::string(kBackend) == "hidraw" ? 65 : 64;
  config.behaviour.fault_after_bytes = reports_before * bytes_per_report;
  EmulatedBench bench;
  bench.add_hid_rig(config);
  std::optional<RigErrorKind> error;
  std::string message;
  FeedStats stats;
  const auto started = std::chrono::steady_clock::now();
  {
    HidTransport transport(hid_options());
    stats = feed_all(transport, frames, {}, &error, &message);
  }
  EXPECT_LT(std::chrono::steady_clock::now() - started, 5s);
  ASSERT_EQ(error, GetParam().expected) << message;
  EXPECT_EQ(stats.frames_sent, 1);
  EXPECT_EQ(stats.interrupted_frame, 0);  // frame index of the second view (eye 1)
  EXPECT_EQ(stats.interrupted_chunks_sent, 2u);
  EXPECT_EQ(bench.hid_reports_received().size(), reports_before);
  EXPECT_EQ(stats.packets_sent, static_cast<std::int64_t>(reports_before));
}

INSTANTIATE_TEST_SUITE_P(Faults, HidFault,
                         ::testing::Values(HidFaultCase{Fault::Stall, RigErrorKind::Stalled},
                                           HidFaultCase{Fault::Vanish, RigErrorKind::Disconnected}),
                         [](const auto& info) { return std::string(info.param.fault == Fault::Stall ? "Stall" : "Unplug"); });

TEST(HidOpen, NoDeviceNamesTheVidPid) {
  EmulatedBench bench;
  try {
    HidTransport transport(hid_options());
    FAIL() << "opened a device that is not there";
  } catch (const RigError& e) {
    EXPECT_EQ(e.kind(), RigErrorKind::NoDevice);
    EXPECT_NE(std::string(e.what()).find("no HID device 1234:5679 found"), std::string::npos) << e.what();
  }
}

TEST(HidOpen, OpensByTheListedPath) {
  EmulatedBench bench;
  bench.add_hid_rig(rig_config());
  const DeviceListing listing = list_devices(linked_hidapi());
  ASSERT_EQ(listing.hid.size(), 1u);
  if (std::string(kBackend) == "hidraw") {
    EXPECT_EQ(listing.hid[0].path, kHidrawNode);
  }
  EXPECT_EQ(listing.hid[0].serial, kHidRigSerial);
  HidOptions o = hid_options();
  o.id.reset();
  o.path = listing.hid[0].path;
  const auto frames = hid_scene();
  {
    HidTransport transport(o);
    feed_all(transport, frames);
  }
  EXPECT_EQ(bench.hid_reports_received(), expected_hid_reports(frames, HidReportFormat{}, false));
}

TEST(HidOpen, MissingHidrawPathIsNoDevice) {
  if (std::string(kBackend) != "hidraw") GTEST_SKIP() << "paths are /dev/hidrawN only with the hidraw backend";
  EmulatedBench bench;
  HidOptions o = hid_options();
  o.id.reset();
  o.path = "/dev/hidraw7";
  try {
    HidTransport transport(o);
    FAIL();
  } catch (const RigError& e) {
    EXPECT_EQ(e.kind(), RigErrorKind::NoDevice) << e.what();
  }
}

}  // namespace
}  // namespace trm::rig::testing
