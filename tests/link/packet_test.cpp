// Packet format: byte layout, CRC, and that the parser trusts no field.
#include "trm/link.hpp"
#include "trm/packet.hpp"
#include "trm/crc32.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <functional>

namespace trm::link {
namespace {

PacketHeader small_header() {
  PacketHeader h;
  h.stream = 1;
  h.parity = Parity::Reduced;
  h.frame_index = 0x0102030405LL;
  h.width = 5;
  h.height = 4;
  h.full_width = 10;
  h.full_height = 8;
  h.bits = 10;
  h.transfer = Transfer::Gamma22;
  h.first_line = 2;
  h.line_count = 1;
  h.first_column = 1;
  h.column_count = 3;
  h.sequence = 0xA1B2C3D4u;
  return h;
}

std::vector<std::uint8_t> small_packet() {
  const PacketHeader h = small_header();
  std::vector<std::uint8_t> payload(raw_payload_bytes(h.column_count, h.line_count, h.bits), 0x5A);
  payload.back() = 0x40;  // 3 pixels x 30 bits = 90 bits: the last 6 bits of the 12 bytes are zero padding
  return build_packet(h, payload);
}

// Rewrites the CRC so that a mutated packet reaches the field checks.
void fix_crc(std::vector<std::uint8_t>& packet) {
  const std::uint32_t crc = packet_crc(packet);
  for (int i = 0; i < 4; ++i) packet[packet.size() - 4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
}

PacketError error_of(const std::vector<std::uint8_t>& packet, ReceiverLimits limits = {}) {
  PacketError e = PacketError::None;
  (void)parse_packet(packet, limits, &e);
  return e;
}

TEST(Packet, CrcIsTheStandardCrc32) {
  // The check value of CRC-32/ISO-HDLC (zlib, IEEE 802.3) over "123456789" is 0xCBF43926.
  std::vector<std::uint8_t> bytes = {'1', '2', '3', '4', '5', '6', '7', '8', '9', 0, 0, 0, 0};
  EXPECT_EQ(packet_crc(bytes), 0xCBF43926u);
}

// The library's carry-less-multiply CRC against the definition computed a bit at a time, at every length up to 600
// bytes (its short and tail paths) and at large lengths from every alignment (its folding loops).
TEST(Packet, Crc32EqualsTheBitwiseDefinitionAtEveryLengthAndAlignment) {
  const auto bitwise = [](std::span<const std::uint8_t> bytes) {
    std::uint32_t crc = 0xFFFFFFFFu;
    for (const std::uint8_t b : bytes) {
      crc ^= b;
      for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
  };
  std::mt19937 rng(11);
  std::vector<std::uint8_t> bytes(70000);
  for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
  const std::span<const std::uint8_t> all(bytes);
  for (std::size_t n = 0; n <= 600; ++n) EXPECT_EQ(crc32_ieee(all.first(n)), bitwise(all.first(n))) << n << " bytes";
  for (std::size_t offset = 0; offset < 64; ++offset) {
    const std::size_t n = 65537 + offset * 13;
    EXPECT_EQ(crc32_ieee(all.subspan(offset, n)), bitwise(all.subspan(offset, n))) << n << " bytes at " << offset;
  }
}

TEST(Packet, ByteLayoutIsLittleEndianAsDocumented) {
  const std::vector<std::uint8_t> p = small_packet();
  ASSERT_EQ(p.size(), kPacketHeaderBytes + 12 + kPacketCrcBytes);
  EXPECT_EQ(std::memcmp(p.data(), "TRMP", 4), 0);
  EXPECT_EQ(p[4], 1);                 // version
  EXPECT_EQ(p[5], 44);                // header length
  EXPECT_EQ(p[6], 1);                 // stream
  EXPECT_EQ(p[7], 0x01);              // flags: reduced
  EXPECT_EQ(p[8], 0x05);              // frame index, least significant byte first
  EXPECT_EQ(p[12], 0x01);
  EXPECT_EQ(p[15], 0x00);
  EXPECT_EQ(p[16], 5);                // width
  EXPECT_EQ(p[20], 10);               // full width
  EXPECT_EQ(p[24], 1);                // RGB
  EXPECT_EQ(p[25], 10);               // bits
  EXPECT_EQ(p[26], 1);                // gamma 2.2
  EXPECT_EQ(p[27], 0);                // raw
  EXPECT_EQ(p[28], 2);                // first line
  EXPECT_EQ(p[30], 1);                // line count
  EXPECT_EQ(p[32], 1);                // first column
  EXPECT_EQ(p[34], 3);                // column count
  EXPECT_EQ(p[36], 12);               // payload length
  EXPECT_EQ(p[40], 0xD4);             // sequence
  EXPECT_EQ(p[43], 0xA1);
  const std::uint32_t crc = packet_crc(p);
  EXPECT_EQ(p[p.size() - 4], crc & 0xFF);
  EXPECT_EQ(p[p.size() - 1], crc >> 24);
}

TEST(Packet, ParseReturnsEveryField) {
  PacketError e;
  const std::vector<std::uint8_t> p = small_packet();
  const auto parsed = parse_packet(p, {}, &e);
  ASSERT_TRUE(parsed) << to_string(e);
  const PacketHeader a = small_header(), &b = parsed->header;
  EXPECT_EQ(b.stream, a.stream);
  EXPECT_EQ(b.parity, a.parity);
  EXPECT_EQ(b.frame_index, a.frame_index);
  EXPECT_EQ(b.width, a.width);
  EXPECT_EQ(b.height, a.height);
  EXPECT_EQ(b.full_width, a.full_width);
  EXPECT_EQ(b.full_height, a.full_height);
  EXPECT_EQ(b.bits, a.bits);
  EXPECT_EQ(b.transfer, a.transfer);
  EXPECT_EQ(b.coding, a.coding);
  EXPECT_EQ(b.first_line, a.first_line);
  EXPECT_EQ(b.line_count, a.line_count);
  EXPECT_EQ(b.first_column, a.first_column);
  EXPECT_EQ(b.column_count, a.column_count);
  EXPECT_EQ(b.sequence, a.sequence);
  EXPECT_EQ(b.payload_length, 12u);
  EXPECT_EQ(parsed->payload.size(), 12u);
}

TEST(Packet, EverySingleBitFlipIsDetectedByTheCrc) {
  const std::vector<std::uint8_t> p = small_packet();
  for (std::size_t bit = 0; bit < p.size() * 8; ++bit) {
    std::vector<std::uint8_t> damaged = p;
    damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_EQ(error_of(damaged), PacketError::CrcMismatch) << "bit " << bit;
  }
}

TEST(Packet, EveryBurstUpTo32BitsIsDetectedByTheCrc) {
  const std::vector<std::uint8_t> p = small_packet();
  for (int length = 2; length <= 32; ++length) {
    for (std::size_t start = 0; start + static_cast<std::size_t>(length) <= p.size() * 8; start += 7) {
      std::vector<std::uint8_t> damaged = p;
      for (std::size_t bit : {start, start + static_cast<std::size_t>(length) - 1})  // first and last always flip
        damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
      EXPECT_EQ(error_of(damaged), PacketError::CrcMismatch);
    }
  }
}

TEST(Packet, TruncatedPacketsAreRejected) {
  const std::vector<std::uint8_t> p = small_packet();
  for (std::size_t n = 0; n < p.size(); ++n) {
    const std::vector<std::uint8_t> cut(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(n));
    const PacketError e = error_of(cut);
    EXPECT_TRUE(e == PacketError::TooShort || e == PacketError::CrcMismatch) << n;
  }
}

struct FieldCase {
  const char* name;
  std::function<void(std::vector<std::uint8_t>&)> mutate;
  PacketError expected;
};

TEST(Packet, NoHeaderFieldIsTrusted) {
  const std::vector<FieldCase> cases = {
      {"magic", [](auto& p) { p[0] = 'X'; }, PacketError::BadMagic},
      {"version", [](auto& p) { p[4] = 2; }, PacketError::BadVersion},
      {"header length", [](auto& p) { p[5] = 48; }, PacketError::BadVersion},
      {"stream 2", [](auto& p) { p[6] = 2; }, PacketError::BadField},
      {"reserved flag", [](auto& p) { p[7] |= 0x80; }, PacketError::BadField},
      {"negative index", [](auto& p) { p[15] = 0x80; }, PacketError::BadField},
      {"width 0", [](auto& p) { p[16] = 0; }, PacketError::BadField},
      {"height 0", [](auto& p) { p[18] = 0; }, PacketError::BadField},
      {"full width < width", [](auto& p) { p[20] = 4; }, PacketError::BadField},
      {"full frame not at full size", [](auto& p) { p[7] = 0; }, PacketError::BadField},
      {"pixel format", [](auto& p) { p[24] = 2; }, PacketError::BadField},
      {"bits 9", [](auto& p) { p[25] = 9; }, PacketError::BadField},
      {"transfer", [](auto& p) { p[26] = 2; }, PacketError::BadField},
      {"coding", [](auto& p) { p[27] = 2; }, PacketError::BadField},
      {"line count 0", [](auto& p) { p[30] = 0; }, PacketError::BadRectangle},
      {"lines past the view", [](auto& p) { p[28] = 4; }, PacketError::BadRectangle},
      {"column count 0", [](auto& p) { p[34] = 0; }, PacketError::BadRectangle},
      {"columns past the view", [](auto& p) { p[34] = 5; }, PacketError::BadRectangle},
      {"first line 65535 (overflow)", [](auto& p) { p[28] = 0xFF; p[29] = 0xFF; }, PacketError::BadRectangle},
      {"payload length vs packet", [](auto& p) { p[36] = 13; }, PacketError::BadLength},
      {"payload length huge", [](auto& p) { p[39] = 0xFF; }, PacketError::BadLength},
      {"payload vs rectangle", [](auto& p) { p[34] = 2; }, PacketError::BadLength},
  };
  for (const FieldCase& c : cases) {
    std::vector<std::uint8_t> p = small_packet();
    c.mutate(p);
    fix_crc(p);
    EXPECT_EQ(error_of(p), c.expected) << c.name;
  }
}

TEST(Packet, ViewsBeyondTheReceiverLimitsAreRefusedBeforeAllocation) {
  PacketHeader h = small_header();
  h.width = h.full_width = 65535;
  h.height = h.full_height = 65535;
  h.parity = Parity::Full;
  h.line_count = 1;
  h.column_count = 1;
  h.first_line = h.first_column = 0;
  const std::vector<std::uint8_t> payload(raw_payload_bytes(1, 1, h.bits), 0);
  const std::vector<std::uint8_t> p = build_packet(h, payload);
  EXPECT_EQ(error_of(p), PacketError::TooLarge);
  ReceiverLimits tiny{100, 100, 10000};
  h.width = h.full_width = 101;
  h.height = h.full_height = 10;
  EXPECT_EQ(error_of(build_packet(h, payload), tiny), PacketError::TooLarge);
}

TEST(Packet, RawPayloadBytesDoNotOverflow) {
  EXPECT_EQ(raw_payload_bytes(1, 1, 8), 3u);
  EXPECT_EQ(raw_payload_bytes(1, 1, 10), 4u);      // 30 bits
  EXPECT_EQ(raw_payload_bytes(4, 1, 10), 15u);     // 120 bits
  EXPECT_EQ(raw_payload_bytes(65535, 65535, 10), (std::uint64_t{65535} * 65535 * 30 + 7) / 8);
}

TEST(Packet, TenBitComponentsArePackedMsbFirst) {
  LinkFrame f;
  f.meta.width = f.meta.full_width = 1;
  f.meta.height = f.meta.full_height = 1;
  f.meta.bits = 10;
  f.codes = cv::Mat(1, 1, CV_16UC3, cv::Scalar(0x3FF, 0x000, 0x155));
  Transmitter tx;
  const SentView sent = tx.send(f);
  ASSERT_EQ(sent.packets.size(), 1u);
  const std::vector<std::uint8_t>& p = sent.packets[0];
  ASSERT_EQ(p.size(), kPacketOverheadBytes + 4);
  // 1111111111 0000000000 0101010101 + 2 zero padding bits
  EXPECT_EQ(p[44], 0xFF);
  EXPECT_EQ(p[45], 0xC0);
  EXPECT_EQ(p[46], 0x05);
  EXPECT_EQ(p[47], 0x54);
  EXPECT_EQ(sent.bits.payload_bits, 30u);
  EXPECT_EQ(sent.bits.overhead_bits, 2u + 48u * 8u);
}

TEST(Packet, NonZeroPaddingIsMalformed) {
  LinkFrame f;
  f.meta.width = f.meta.full_width = 1;
  f.meta.height = f.meta.full_height = 1;
  f.meta.bits = 10;
  f.codes = cv::Mat(1, 1, CV_16UC3, cv::Scalar(1, 2, 3));
  Transmitter tx;
  std::vector<std::uint8_t> p = tx.send(f).packets[0];
  p[47] |= 0x01;
  fix_crc(p);
  Receiver rx;
  EXPECT_EQ(rx.push(p), PushResult::Malformed);
  EXPECT_EQ(rx.counters().malformed, 1u);
  rx.flush();
  EXPECT_TRUE(rx.take_frames().empty()) << "a malformed packet starts no view";
}

TEST(Packet, MalformedPacketLeavesTheViewItLandsInUntouched) {
  LinkFrame f;
  f.meta.width = f.meta.full_width = 1;
  f.meta.height = f.meta.full_height = 2;
  f.meta.bits = 10;
  f.codes = cv::Mat(2, 1, CV_16UC3, cv::Scalar(1, 2, 3));
  f.codes.at<cv::Vec3w>(1, 0) = cv::Vec3w(700, 800, 900);
  Transmitter tx;
  const std::vector<std::vector<std::uint8_t>> packets = tx.send(f).packets;
  ASSERT_EQ(packets.size(), 2u);  // one line each
  std::vector<std::uint8_t> bad = packets[1];
  bad[kPacketHeaderBytes] ^= 0xFF;  // other codes
  bad[kPacketHeaderBytes + 3] |= 0x01;  // and a padding bit set
  fix_crc(bad);
  Receiver rx;
  EXPECT_EQ(rx.push(packets[0]), PushResult::Accepted);
  EXPECT_EQ(rx.push(bad), PushResult::Malformed);
  rx.flush();
  std::vector<ReceivedFrame> frames = rx.take_frames();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].line_intact, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(frames[0].codes.at<cv::Vec3w>(0, 0), cv::Vec3w(1, 2, 3));
  EXPECT_EQ(frames[0].codes.at<cv::Vec3w>(1, 0), cv::Vec3w(0, 0, 0)) << "the lost line is zeroed, not half written";

  Receiver again;  // the good packet after the bad one completes the view
  EXPECT_EQ(again.push(packets[0]), PushResult::Accepted);
  EXPECT_EQ(again.push(bad), PushResult::Malformed);
  EXPECT_EQ(again.push(packets[1]), PushResult::Accepted);
  again.flush();
  frames = again.take_frames();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(frames[0].complete());
  EXPECT_EQ(cv::norm(frames[0].codes, f.codes, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace trm::link
