// The libusb bulk transport against an emulated rig: byte-exact delivery, flow control, and every
// failure an operator can meet, each with its documented error kind.
#include "emulated_bench.hpp"
#include "rig/feeder.hpp"
#include "rig/file_transport.hpp"
#include "rig/usb_bulk_transport.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace trm::rig::testing {
namespace {

using namespace std::chrono_literals;

UsbBulkOptions bulk_options(std::size_t packet_size = 512) {
  UsbBulkOptions o;
  o.id = kBulkRigId;
  o.packet_size = packet_size;
  o.timeout = 300ms;
  return o;
}

std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(UsbBulk, DeliversSeveralFramesByteExact) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  const auto frames = test_scene();
  FeedStats stats;
  {
    UsbBulkTransport transport(bulk_options(512));
    stats = feed_all(transport, frames);
  }
  const std::vector<std::uint8_t> expected = expected_stream(frames, 512, false);
  EXPECT_EQ(bench.bulk_received(), expected);
  expect_same_frames(receive_stream(bench.bulk_received()), frames);
  EXPECT_EQ(stats.frames_sent, 4);
  EXPECT_EQ(stats.wire_bytes_sent, expected.size());
}

TEST(UsbBulk, ChunkSequencesForSizesThatAreNotMultiplesOfTheChunk) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  // 61 x 7 x 3 x 2 bytes = 2562 bytes of payload in 120-byte chunks: 21 full chunks and 42 bytes.
  const RigFrame frame = synthetic_frame(5, 1, 61, 7, 10);
  {
    UsbBulkTransport transport(bulk_options(128));
    feed_all(transport, {frame});
  }
  const auto packets = split_stream(bench.bulk_received());
  ASSERT_EQ(packets.size(), 1u + 22u + 1u);
  for (std::uint32_t s = 0; s < 22; ++s) {
    const ChunkHeader h = decode_chunk_header(packets[1 + s]);
    EXPECT_EQ(h.sequence, s);
    EXPECT_EQ(h.last, s == 21);
    EXPECT_EQ(h.length, s == 21 ? 42 : 120);
  }
  EXPECT_EQ(decode_frame_start(packets.front()).chunk_count, 22u);
  EXPECT_EQ(decode_frame_end(packets.back()).chunk_count, 22u);
  expect_same_frames(receive_stream(bench.bulk_received()), {frame});
}

TEST(UsbBulk, FileTransportWritesExactlyWhatTheDeviceReceived) {
  const auto frames = test_scene();
  EmulatedBench bench;
  bench.add_bulk_rig();
  {
    UsbBulkTransport transport(bulk_options(512));
    feed_all(transport, frames);
  }
  const std::string path = "/tmp/trm-rig-file-" + std::to_string(::getpid()) + ".bin";
  {
    FileTransport file({path, FileTransportOptions::Framing::Bulk, 512, {}});
    feed_all(file, frames);
    file.finish();
  }
  const auto written = read_file(path);
  ::unlink(path.c_str());
  ASSERT_FALSE(written.empty());
  EXPECT_EQ(written, bench.bulk_received());
}

TEST(UsbBulk, ResendAnswerIsHonoured) {
  RigBehaviour rig;
  rig.answer = [](const FrameEnd& end, int times_seen) -> std::optional<Answer> {
    if (end.frame_index == 1 && times_seen == 1) return Answer{AnswerKind::Resend, 0, 2, end.frame_index};
    return Answer{AnswerKind::Ready, 0, 0, end.frame_index};
  };
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  const auto frames = test_scene();
  FeedOptions options;
  options.flow_control = true;
  options.answer_timeout = 2000ms;
  FeedStats stats;
  {
    UsbBulkTransport transport(bulk_options(128));
    ASSERT_TRUE(transport.can_receive());
    stats = feed_all(transport, frames, options);
  }
  EXPECT_EQ(stats.frames_sent, 4);
  EXPECT_EQ(stats.resends, 1);
  EXPECT_EQ(bench.answers_sent(), 5);  // four READY, one RESEND

  // Frame 1 (the 10-bit one, index 2 in the scene) goes out once, then again from chunk 2 on.
  std::vector<std::uint8_t> expected;
  for (const auto& f : frames) {
    const EncodedFrame e = encode_frame(f, 128, true);
    auto add = [&](const std::vector<std::uint8_t>& p) { expected.insert(expected.end(), p.begin(), p.end()); };
    add(e.start_packet);
    for (std::uint32_t s = 0; s < e.chunk_count(); ++s) add(e.chunk_packet(s));
    add(e.end_packet);
    if (f.index == 1) {
      for (std::uint32_t s = 2; s < e.chunk_count(); ++s) add(e.chunk_packet(s));
      add(e.end_packet);
    }
  }
  EXPECT_EQ(bench.bulk_received(), expected);
  // A rig that rewinds on the resend reassembles every frame intact.
  StreamReceiver receiver;
  bool frame1_ended = false;
  for (const auto& p : split_stream(bench.bulk_received())) {
    // The receiver closes a frame at its first FRAME_END; reopen for the resent tail as a rig does.
    if (p[0] == static_cast<std::uint8_t>(PacketType::FrameEnd) && decode_frame_end(p).frame_index == 1 && !frame1_ended) {
      frame1_ended = true;
      continue;  // the rig asked for a resend instead of accepting this end
    }
    receiver.accept_packet(p);
  }
  expect_same_frames(receiver.frames(), frames);
}

TEST(UsbBulk, ErrorAnswerStopsWithRigReported) {
  RigBehaviour rig;
  rig.answer = [](const FrameEnd& end, int) -> std::optional<Answer> {
    if (end.frame_index == 1) return Answer{AnswerKind::Error, 1, 0, end.frame_index};
    return Answer{AnswerKind::Ready, 0, 0, end.frame_index};
  };
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  FeedOptions options;
  options.flow_control = true;
  std::optional<RigErrorKind> error;
  std::string message;
  UsbBulkTransport transport(bulk_options());
  const FeedStats stats = feed_all(transport, test_scene(), options, &error, &message);
  ASSERT_EQ(error, RigErrorKind::RigReported);
  EXPECT_NE(message.find("error 1 (payload CRC mismatch)"), std::string::npos) << message;
  EXPECT_EQ(stats.frames_sent, 2);
  EXPECT_EQ(stats.last_frame_sent, 0);
  EXPECT_EQ(stats.interrupted_frame, 1);
}

TEST(UsbBulk, SilentRigTimesOut) {
  EmulatedBench bench;
  bench.add_bulk_rig();  // never answers
  FeedOptions options;
  options.flow_control = true;
  options.answer_timeout = 200ms;
  std::optional<RigErrorKind> error;
  std::string message;
  UsbBulkTransport transport(bulk_options());
  const auto started = std::chrono::steady_clock::now();
  const FeedStats stats = feed_all(transport, test_scene(), options, &error, &message);
  const auto waited = std::chrono::steady_clock::now() - started;
  ASSERT_EQ(error, RigErrorKind::Timeout);
  EXPECT_NE(message.find("stopped answering"), std::string::npos) << message;
  EXPECT_GE(waited, 200ms);
  EXPECT_LT(waited, 1500ms);
  EXPECT_EQ(stats.frames_sent, 0);
  EXPECT_EQ(stats.interrupted_frame, 0);
}

struct UsbFaultCase {
  Fault fault;
  RigErrorKind expected;
  const char* words;
};

class UsbBulkFault : public ::testing::TestWithParam<UsbFaultCase> {};

TEST_P(UsbBulkFault, MidFrameFaultGivesTheDocumentedErrorAndKeepsTheTally) {
  RigBehaviour rig;
  rig.fault = GetParam().fault;
  const auto frames = test_scene();
  // Strike inside the third frame: after the first two frames and a few chunks of the third.
  const std::size_t first_two = expected_stream({frames[0], frames[1]}, 128, false).size();
  rig.fault_after_bytes = first_two + 64 + 3 * 128;
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  std::optional<RigErrorKind> error;
  std::string message;
  FeedStats stats;
  const auto started = std::chrono::steady_clock::now();
  {
    UsbBulkTransport transport(bulk_options(128));
    stats = feed_all(transport, frames, {}, &error, &message);
  }
  EXPECT_LT(std::chrono::steady_clock::now() - started, 3s);
  ASSERT_EQ(error, GetParam().expected) << message;
  EXPECT_NE(message.find(GetParam().words), std::string::npos) << message;
  EXPECT_EQ(stats.frames_sent, 2);
  EXPECT_EQ(stats.last_frame_sent, 0);
  ASSERT_EQ(stats.interrupted_frame, 1);
  EXPECT_EQ(stats.interrupted_chunks_sent, 3u);
  // Everything before the fault arrived intact.
  const auto received = bench.bulk_received();
  ASSERT_EQ(received.size(), rig.fault_after_bytes);
  const auto prefix = expected_stream(frames, 128, false);
  EXPECT_TRUE(std::equal(received.begin(), received.end(), prefix.begin()));
  EXPECT_EQ(stats.wire_bytes_sent, received.size());
}

INSTANTIATE_TEST_SUITE_P(Faults, UsbBulkFault,
                         ::testing::Values(UsbFaultCase{Fault::Stall, RigErrorKind::Stalled, "stalled"},
                                           UsbFaultCase{Fault::Vanish, RigErrorKind::Disconnected, "disappeared"},
                                           UsbFaultCase{Fault::Hang, RigErrorKind::Timeout, "stopped accepting data"}),
                         [](const auto& info) {
                           return std::string(info.param.fault == Fault::Stall ? "Stall" : info.param.fault == Fault::Vanish ? "Unplug" : "Hang");
                         });

template <typename Fn>
RigError expect_rig_error(Fn&& fn) {
  try {
    fn();
  } catch (const RigError& e) {
    return e;
  }
  ADD_FAILURE() << "no RigError thrown";
  return RigError(RigErrorKind::Io, "none");
}

TEST(UsbBulkOpen, NoDeviceNamesTheVidPid) {
  EmulatedBench bench;  // nothing plugged in
  const RigError e = expect_rig_error([] { UsbBulkTransport t(bulk_options()); });
  EXPECT_EQ(e.kind(), RigErrorKind::NoDevice);
  EXPECT_NE(std::string(e.what()).find("no USB device 1234:5678 found"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("--list"), std::string::npos) << e.what();
}

TEST(UsbBulkOpen, SelectsBySerialAndBusPort) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  UsbBulkOptions o = bulk_options();
  o.serial = kBulkRigSerial;
  o.bus_port = "1-1";
  UsbBulkTransport transport(o);
  EXPECT_NE(transport.description().find("bus-port 1-1"), std::string::npos) << transport.description();

  o.serial = "OTHER";
  const RigError e = expect_rig_error([&] { UsbBulkTransport t(o); });
  EXPECT_EQ(e.kind(), RigErrorKind::NoDevice);
  EXPECT_NE(std::string(e.what()).find("with serial RIG-0001"), std::string::npos) << e.what();
}

TEST(UsbBulkOpen, MissingEndpointListsWhatIsThere) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  UsbBulkOptions o = bulk_options();
  o.endpoint_out = 0x03;
  const RigError e = expect_rig_error([&] { UsbBulkTransport t(o); });
  EXPECT_EQ(e.kind(), RigErrorKind::EndpointMissing);
  EXPECT_NE(std::string(e.what()).find("0x01 bulk OUT"), std::string::npos) << e.what();
}

TEST(UsbBulkOpen, KernelDriverNeedsDetachOption) {
  RigBehaviour rig;
  rig.kernel_driver = "rig_kmod";
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  UsbBulkOptions o = bulk_options();
  const RigError e = expect_rig_error([&] { UsbBulkTransport t(o); });
  EXPECT_EQ(e.kind(), RigErrorKind::Busy);
  EXPECT_NE(std::string(e.what()).find("--detach-kernel-driver"), std::string::npos) << e.what();

  o.detach_kernel_driver = true;
  UsbBulkTransport transport(o);
  const auto frames = test_scene();
  feed_all(transport, frames);
  EXPECT_EQ(bench.bulk_received(), expected_stream(frames, 512, false));
}

TEST(UsbBulkOpen, InterfaceClaimedElsewhereIsBusy) {
  RigBehaviour rig;
  rig.claim_busy = true;
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  const RigError e = expect_rig_error([] { UsbBulkTransport t(bulk_options()); });
  EXPECT_EQ(e.kind(), RigErrorKind::Busy);
  EXPECT_NE(std::string(e.what()).find("claimed by another program"), std::string::npos) << e.what();
}

}  // namespace
}  // namespace trm::rig::testing
