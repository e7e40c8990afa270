// The rig wire protocol, version 1 (docs/rig_protocol.md is the normative description; the layouts
// below mirror it byte for byte). A frame travels as FRAME_START, CHUNK 0..n-1, FRAME_END; every
// multi-byte field is little-endian. The rig may answer each frame with READY / RESEND / ERROR.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trm/crc32.hpp"

namespace trm::rig {

inline constexpr std::uint8_t kProtocolVersion = 1;
inline constexpr std::array<std::uint8_t, 3> kStartMagic = {'T', 'R', 'M'};

enum class PacketType : std::uint8_t {
  FrameStart = 0x01,
  Chunk = 0x02,
  FrameEnd = 0x03,
  // Rig -> feeder answers (flow control).
  Ready = 0x81,
  Resend = 0x82,
  Error = 0x83,
};

inline constexpr std::size_t kFrameStartSize = 64;
inline constexpr std::size_t kChunkHeaderSize = 8;
inline constexpr std::size_t kFrameEndSize = 24;
inline constexpr std::size_t kAnswerSize = 16;
// Smallest packet a transport must carry: FRAME_START must fit whole, and a chunk must carry data.
inline constexpr std::size_t kMinPacketSize = kFrameStartSize;
inline constexpr std::size_t kMaxChunkData = 0xFFFF;  // the chunk length field is 16 bits

enum class ChannelOrder : std::uint8_t { Rgb = 0 };

// What a panel drive frame is, without its codes.
struct RigFrameHeader {
  std::int64_t index = 0;
  int eye = 0;                 // 0 = left (or mono), 1 = right
  int width = 0, height = 0;   // size of the image carried (after region / downscale)
  int bits = 8;                // bits per channel of the drive codes, 1..16
  // Where the carried image sits in the full view (lets the rig place a region or a decimated view).
  int view_width = 0, view_height = 0;  // 0: same as width / height
  int region_x = 0, region_y = 0;
  int step = 1;                // every step-th pixel of the region in both directions

  int bytes_per_sample() const { return bits <= 8 ? 1 : 2; }
  std::size_t payload_size() const;
};

// One panel drive frame as the feeder sends it: codes row-major, pixel-interleaved R, G, B.
// Codes of up to 8 bits travel as one byte, 9..16 bits as two bytes little-endian.
struct RigFrame : RigFrameHeader {
  std::vector<std::uint16_t> samples;   // width * height * 3 codes

  void validate() const;  // throws std::invalid_argument
};

// A rectangle of the view in view pixels.
struct Region {
  int x = 0, y = 0, width = 0, height = 0;
};

// Keeps region (clamped to nothing: it must lie inside the view) and every step-th pixel of it,
// copying drive codes unchanged so the rig sees exactly what the panel would get there.
RigFrame crop_and_decimate(const RigFrame& view, const Region& region, int step);

struct FrameStart {
  std::uint8_t version = kProtocolVersion;
  ChannelOrder channel_order = ChannelOrder::Rgb;
  std::uint8_t bits = 8;
  std::uint8_t bytes_per_sample = 1;
  std::int64_t frame_index = 0;
  std::uint8_t eye = 0;
  std::uint8_t flags = 0;                 // kFlagAnswerExpected
  std::uint16_t chunk_data_size = 0;      // payload bytes in every chunk but the last
  std::uint32_t width = 0, height = 0;
  std::uint32_t view_width = 0, view_height = 0;
  std::uint32_t region_x = 0, region_y = 0;
  std::uint16_t step = 1;
  std::uint32_t payload_length = 0;
  std::uint32_t chunk_count = 0;
  std::uint32_t payload_crc = 0;
};
inline constexpr std::uint8_t kFlagAnswerExpected = 0x01;  // the feeder waits for READY after FRAME_END

struct ChunkHeader {
  bool last = false;
  std::uint16_t length = 0;
  std::uint32_t sequence = 0;
};
inline constexpr std::uint8_t kChunkFlagLast = 0x01;

struct FrameEnd {
  std::uint32_t chunk_count = 0;
  std::int64_t frame_index = 0;
  std::uint32_t payload_crc = 0;
};

// Rig -> feeder.
enum class AnswerKind : std::uint8_t { Ready = 0x81, Resend = 0x82, Error = 0x83 };
struct Answer {
  AnswerKind kind = AnswerKind::Ready;
  std::uint8_t error_code = 0;   // Error: rig-defined reason (codes 1..4 are reserved, see the doc)
  std::uint32_t sequence = 0;    // Resend: first chunk to send again
  std::int64_t frame_index = 0;
};
const char* describe_rig_error_code(std::uint8_t code);

// The protocol's CRC-32 (IEEE 802.3, the same as zlib, PNG and Ethernet) is trm::crc32_ieee.
using trm::crc32_ieee;

// Payload bytes of a frame in wire order; throws std::invalid_argument where RigFrame::validate() would.
std::vector<std::uint8_t> pack_samples(const RigFrame& frame);
// The same for a header and codes held elsewhere (a decoder's output plane: no copy into a RigFrame).
std::vector<std::uint8_t> pack_samples(const RigFrameHeader& header, std::span<const std::uint16_t> samples);
// The same into `out`, resized to the payload (a buffer of that size already is neither reallocated nor cleared).
void pack_samples(const RigFrameHeader& header, std::span<const std::uint16_t> samples, std::vector<std::uint8_t>& out);

std::vector<std::uint8_t> encode_frame_start(const FrameStart& start);
std::vector<std::uint8_t> encode_chunk(const ChunkHeader& header, std::span<const std::uint8_t> data);
std::vector<std::uint8_t> encode_frame_end(const FrameEnd& end);
std::vector<std::uint8_t> encode_answer(const Answer& answer);

// Decoders throw std::runtime_error on a malformed packet (bad magic, version, CRC, length).
FrameStart decode_frame_start(std::span<const std::uint8_t> packet);
ChunkHeader decode_chunk_header(std::span<const std::uint8_t> packet);
FrameEnd decode_frame_end(std::span<const std::uint8_t> packet);
std::optional<Answer> decode_answer(std::span<const std::uint8_t> bytes);  // nullopt: not an answer

// Number of wire bytes a packet occupies in a stream (bulk / file): its own size, from its header.
// Returns 0 when more bytes are needed to tell.
std::size_t packet_size_in_stream(std::span<const std::uint8_t> bytes);

// All packets of one frame, in the order they are sent. The chunk size is the transport's packet
// size minus the chunk header; the last chunk carries the remainder.
struct EncodedFrame {
  FrameStart start;
  std::vector<std::uint8_t> payload;
  std::vector<std::uint8_t> start_packet;
  std::vector<std::uint8_t> end_packet;
  std::size_t chunk_data_size = 0;
  std::uint32_t chunk_count() const { return start.chunk_count; }
  std::vector<std::uint8_t> chunk_packet(std::uint32_t sequence) const;
  void chunk_packet(std::uint32_t sequence, std::vector<std::uint8_t>& out) const;  // into a reused buffer
  std::size_t wire_size() const;  // sum of all packet sizes (before transport padding)
};
EncodedFrame encode_frame(const RigFrame& frame, std::size_t max_packet_size, bool answer_expected);
EncodedFrame encode_frame(const RigFrameHeader& header, std::span<const std::uint16_t> samples, std::size_t max_packet_size,
                          bool answer_expected);
// The same into `out`, reusing its payload buffer: a feeder encoding frames of one size allocates and clears nothing
// per frame once the first is encoded.
void encode_frame(const RigFrameHeader& header, std::span<const std::uint16_t> samples, std::size_t max_packet_size,
                  bool answer_expected, EncodedFrame& out);

// Reference receiver: reassembles frames from a stream of packets the way a rig does, checking every
// header CRC, sequence number and the payload CRC. Used by the tests and as executable documentation.
class StreamReceiver {
 public:
  // Feeds one packet (bulk / file: call split_stream first; HID: one report's payload, padding allowed).
  void accept_packet(std::span<const std::uint8_t> packet);
  const std::vector<RigFrame>& frames() const { return frames_; }
  const std::vector<std::uint32_t>& sequences_seen() const { return sequences_; }

 private:
  std::optional<FrameStart> open_;
  std::vector<std::uint8_t> payload_;
  std::uint32_t next_sequence_ = 0;
  std::vector<RigFrame> frames_;
  std::vector<std::uint32_t> sequences_;
};

// Splits a byte stream (bulk transfers concatenated, or a --file in stream framing) into packets.
std::vector<std::vector<std::uint8_t>> split_stream(std::span<const std::uint8_t> stream);

}  // namespace trm::rig
