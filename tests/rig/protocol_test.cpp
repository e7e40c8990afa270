// The wire protocol byte by byte (docs/rig_protocol.md): layouts, CRCs, chunking, the reference receiver.
#include "rig/hid_report.hpp"
#include "rig/protocol.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

namespace trm::rig::testing {
namespace {

std::uint32_t u32_at(const std::vector<std::uint8_t>& p, std::size_t at) {
  return p[at] | (p[at + 1] << 8) | (p[at + 2] << 16) | (static_cast<std::uint32_t>(p[at + 3]) << 24);
}

TEST(RigProtocol, Crc32IsZlibsIeeeCrc) {
  const char* check = "123456789";  // the standard CRC-32 check value
  EXPECT_EQ(crc32_ieee(std::span(reinterpret_cast<const std::uint8_t*>(check), 9)), 0xCBF43926u);
}

TEST(RigProtocol, FrameStartLayoutByteByByte) {
  RigFrame f = synthetic_frame(0x0102030405060708LL, 1, 3, 2, 10);
  f.view_width = 1080;
  f.view_height = 1200;
  f.region_x = 16;
  f.region_y = 32;
  f.step = 4;
  const EncodedFrame e = encode_frame(f, 64, true);
  const auto& p = e.start_packet;
  ASSERT_EQ(p.size(), 64u);
  const std::vector<std::uint8_t> head = {0x01, 'T', 'R', 'M', 1, 0, 10, 2, 0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,
                                          1, 1, 56, 0};
  EXPECT_EQ(std::vector<std::uint8_t>(p.begin(), p.begin() + 20), head);
  EXPECT_EQ(u32_at(p, 20), 3u);
  EXPECT_EQ(u32_at(p, 24), 2u);
  EXPECT_EQ(u32_at(p, 28), 1080u);
  EXPECT_EQ(u32_at(p, 32), 1200u);
  EXPECT_EQ(u32_at(p, 36), 16u);
  EXPECT_EQ(u32_at(p, 40), 32u);
  EXPECT_EQ(p[44], 4);
  EXPECT_EQ(p[45], 0);
  EXPECT_EQ(p[46], 0);
  EXPECT_EQ(p[47], 0);
  EXPECT_EQ(u32_at(p, 48), 36u);  // 3 x 2 pixels x 3 channels x 2 bytes
  EXPECT_EQ(u32_at(p, 52), 1u);
  EXPECT_EQ(u32_at(p, 56), crc32_ieee(pack_samples(f)));
  EXPECT_EQ(u32_at(p, 60), crc32_ieee(std::span(p).first(60)));
  const FrameStart s = decode_frame_start(p);
  EXPECT_EQ(s.frame_index, 0x0102030405060708LL);
  EXPECT_EQ(s.flags, kFlagAnswerExpected);
}

TEST(RigProtocol, SamplesAreRowMajorRgbAndTenBitIsLittleEndian) {
  RigFrame f;
  f.width = 2;
  f.height = 1;
  f.bits = 10;
  f.samples = {0x3FF, 0x001, 0x200, 0x0AB, 0x100, 0x000};
  EXPECT_EQ(pack_samples(f), (std::vector<std::uint8_t>{0xFF, 0x03, 0x01, 0x00, 0x00, 0x02, 0xAB, 0x00, 0x00, 0x01, 0x00, 0x00}));
  f.bits = 8;
  f.samples = {255, 1, 2, 3, 4, 5};
  EXPECT_EQ(pack_samples(f), (std::vector<std::uint8_t>{255, 1, 2, 3, 4, 5}));
}

// validate() finds a code above 2^bits - 1 by one OR over the frame: checked at every depth, with the offending code
// at every position of a vector's width and in the tail, and with every single bit above the depth.
TEST(RigProtocol, CodesAboveTheBitDepthAreRefusedWherever) {
  for (int bits = 1; bits <= 16; ++bits) {
    RigFrame f = synthetic_frame(0, 0, 13, 3, bits);  // 117 samples: vector bodies and a tail
    const auto top = static_cast<std::uint16_t>((1u << bits) - 1u);
    std::fill(f.samples.begin(), f.samples.end(), top);
    EXPECT_NO_THROW(f.validate()) << bits << " bits, every code at the top";
    EXPECT_NO_THROW(encode_frame(f, 64, false)) << bits << " bits, every code at the top";
    for (int bit = bits; bit < 16; ++bit) {
      for (std::size_t at : {std::size_t{0}, std::size_t{31}, std::size_t{64}, f.samples.size() - 1}) {
        RigFrame over = f;
        over.samples[at] = static_cast<std::uint16_t>(over.samples[at] | (1u << bit));
        EXPECT_THROW(over.validate(), std::invalid_argument) << bits << " bits, bit " << bit << " set at " << at;
        // Packing checks the codes as it goes (encode_frame runs no validate() pass of its own).
        EXPECT_THROW(pack_samples(over), std::invalid_argument) << bits << " bits, bit " << bit << " set at " << at;
        EXPECT_THROW(encode_frame(over, 64, false), std::invalid_argument) << bits << " bits, bit " << bit;
      }
    }
  }
}

TEST(RigProtocol, ChunkAndEndLayout) {
  const RigFrame f = synthetic_frame(9, 0, 20, 1, 8);  // 60 payload bytes: chunks of 56 and 4
  const EncodedFrame e = encode_frame(f, 64, false);
  ASSERT_EQ(e.chunk_count(), 2u);
  const auto c0 = e.chunk_packet(0), c1 = e.chunk_packet(1);
  EXPECT_EQ(std::vector<std::uint8_t>(c0.begin(), c0.begin() + 8), (std::vector<std::uint8_t>{0x02, 0x00, 56, 0, 0, 0, 0, 0}));
  EXPECT_EQ(std::vector<std::uint8_t>(c1.begin(), c1.begin() + 8), (std::vector<std::uint8_t>{0x02, 0x01, 4, 0, 1, 0, 0, 0}));
  EXPECT_EQ(c0.size(), 64u);
  EXPECT_EQ(c1.size(), 12u);
  EXPECT_TRUE(std::equal(c1.begin() + 8, c1.end(), e.payload.begin() + 56));
  const auto& end = e.end_packet;
  ASSERT_EQ(end.size(), 24u);
  EXPECT_EQ(end[0], 0x03);
  EXPECT_EQ(u32_at(end, 4), 2u);
  EXPECT_EQ(u32_at(end, 8), 9u);
  EXPECT_EQ(u32_at(end, 16), crc32_ieee(e.payload));
  EXPECT_EQ(u32_at(end, 20), crc32_ieee(std::span(end).first(20)));
}

TEST(RigProtocol, RoundTripsThroughTheReferenceReceiverForAwkwardSizes) {
  for (std::size_t packet : {64u, 100u, 512u, 16384u}) {
    std::vector<RigFrame> frames = {synthetic_frame(0, 0, 1, 1, 8), synthetic_frame(1, 1, 97, 13, 10), synthetic_frame(2, 0, 33, 31, 8)};
    const auto frames_back = receive_stream(expected_stream(frames, packet, false));
    expect_same_frames(frames_back, frames);
  }
}

TEST(RigProtocol, ReceiverRejectsCorruption) {
  auto stream = expected_stream({synthetic_frame(0, 0, 10, 10, 8)}, 128, false);
  stream[64 + 8 + 5] ^= 0x10;  // one payload bit in the first chunk
  EXPECT_THROW(receive_stream(stream), std::runtime_error);
  auto header = expected_stream({synthetic_frame(0, 0, 10, 10, 8)}, 128, false);
  header[20] ^= 1;  // width: caught by the header CRC
  EXPECT_THROW(receive_stream(header), std::runtime_error);
}

// Found by fuzz/fuzz_rig_stream.cpp: a FRAME_START with a valid CRC but 0 bytes per sample and an empty
// payload reached a division by zero at FRAME_END; other header values the CRC does not vouch for gave
// frames that are not valid RigFrames. The reference receiver now rejects them at FRAME_START.
TEST(RigProtocol, ReceiverRejectsFrameStartsDescribingNoValidFrame) {
  FrameStart empty;
  empty.frame_index = 3;
  empty.width = empty.height = 1;
  empty.bytes_per_sample = 0;  // with payload length, chunk count and payload CRC 0 (crc32 of nothing)
  {
    StreamReceiver receiver;
    EXPECT_THROW(receiver.accept_packet(encode_frame_start(empty)), std::runtime_error);
    EXPECT_THROW(receiver.accept_packet(encode_frame_end(FrameEnd{0, 3, 0})), std::runtime_error);  // no frame open
    EXPECT_TRUE(receiver.frames().empty());
  }

  const RigFrame frame = synthetic_frame(7, 0, 4, 3, 10);
  const EncodedFrame good = encode_frame(frame, 64, false);
  const auto rejected = [&](auto&& edit) {
    FrameStart s = good.start;
    edit(s);
    StreamReceiver receiver;
    EXPECT_THROW(receiver.accept_packet(encode_frame_start(s)), std::runtime_error);
  };
  rejected([](FrameStart& s) { s.bits = 0; });
  rejected([](FrameStart& s) { s.bits = 17; });
  rejected([](FrameStart& s) { s.bytes_per_sample = 1; });         // 10 bits in one byte
  rejected([](FrameStart& s) { s.channel_order = ChannelOrder{1}; });
  rejected([](FrameStart& s) { s.width = 0; });
  rejected([](FrameStart& s) { s.width = 5; });                    // payload length no longer 4 x 3 x 3 x 2
  rejected([](FrameStart& s) { s.payload_length = 0xFFFFFFF0u; });  // would have reserved 4 GB
  rejected([](FrameStart& s) { s.step = 0; });
  rejected([](FrameStart& s) { s.region_x = 0x80000000u; });

  // Codes wider than the bits the header states: rejected at FRAME_END, once the payload is known.
  FrameStart narrow = good.start;
  narrow.bits = 9;
  StreamReceiver receiver;
  receiver.accept_packet(encode_frame_start(narrow));
  for (std::uint32_t s = 0; s < good.chunk_count(); ++s) receiver.accept_packet(good.chunk_packet(s));
  EXPECT_THROW(receiver.accept_packet(good.end_packet), std::runtime_error);
  EXPECT_TRUE(receiver.frames().empty());

  // The unedited frame still goes through.
  EXPECT_EQ(receive_stream(expected_stream({frame}, 64, false)).size(), 1u);
}

TEST(RigProtocol, AnswersRoundTrip) {
  const Answer a{AnswerKind::Resend, 0, 17, -3};
  const auto bytes = encode_answer(a);
  ASSERT_EQ(bytes.size(), kAnswerSize);
  EXPECT_EQ(bytes[0], 0x82);
  const auto back = decode_answer(bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->kind, AnswerKind::Resend);
  EXPECT_EQ(back->sequence, 17u);
  EXPECT_EQ(back->frame_index, -3);
  EXPECT_FALSE(decode_answer(std::vector<std::uint8_t>(16, 0)));
}

TEST(RigProtocol, HidFramingPerReportId) {
  const std::vector<std::uint8_t> packet = {1, 2, 3};
  const auto unnumbered = hid_wire_report(HidReportFormat{64, 0, false}, packet);
  ASSERT_EQ(unnumbered.size(), 64u);
  EXPECT_EQ(unnumbered[0], 1);
  EXPECT_EQ(unnumbered[63], 0);
  const auto numbered = hid_wire_report(HidReportFormat{64, 6, false}, packet);
  ASSERT_EQ(numbered.size(), 65u);
  EXPECT_EQ(numbered[0], 6);
  EXPECT_EQ(numbered[1], 1);
  EXPECT_EQ(hidapi_report_buffer(HidReportFormat{64, 0, false}, packet).size(), 65u);
  EXPECT_THROW(HidReportFormat({32, 0, false}).validate(), std::invalid_argument);
  EXPECT_THROW(HidReportFormat({2048, 0, false}).validate(), std::invalid_argument);
}

TEST(RigProtocol, RegionAndDownscaleKeepCodesExactly) {
  const RigFrame view = synthetic_frame(4, 1, 10, 8, 8);
  const RigFrame roi = crop_and_decimate(view, Region{3, 2, 5, 4}, 2);  // columns 3,5,7 rows 2,4
  EXPECT_EQ(roi.width, 3);
  EXPECT_EQ(roi.height, 2);
  EXPECT_EQ(roi.region_x, 3);
  EXPECT_EQ(roi.region_y, 2);
  EXPECT_EQ(roi.step, 2);
  EXPECT_EQ(roi.view_width, 10);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(roi.samples[(y * 3 + x) * 3 + c], view.samples[((2 + 2 * y) * 10 + 3 + 2 * x) * 3 + c]);
  EXPECT_THROW(crop_and_decimate(view, Region{8, 0, 5, 1}, 1), std::invalid_argument);
}

}  // namespace
}  // namespace trm::rig::testing
