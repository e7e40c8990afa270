// The TRM link packet, format version 1 (docs/link.md, "Packet format").
//
// A view (one eye of one link frame) is sent as packets that each carry a rectangle of it: whole lines
// by default, or a slice of one line when a line does not fit the payload limit. Every packet is
//
//   header (44 bytes, little-endian) | payload (payload_length bytes) | CRC-32 (4 bytes)
//
// and the CRC-32 (zlib's crc32, the IEEE 802.3 polynomial) covers the header and the payload.
#pragma once

#include "trm/frame.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm::link {

inline constexpr std::uint8_t kPacketMagic[4] = {'T', 'R', 'M', 'P'};
inline constexpr std::uint8_t kPacketFormatVersion = 1;
inline constexpr std::size_t kPacketHeaderBytes = 44;
inline constexpr std::size_t kPacketCrcBytes = 4;
inline constexpr std::size_t kPacketOverheadBytes = kPacketHeaderBytes + kPacketCrcBytes;
inline constexpr int kMaxStreams = 2;  // stream = eye: 0 left (or mono), 1 right
inline constexpr int kMaxDimension = 0xFFFF;  // the header's 16-bit size fields

// Byte 24 of the header. Only interleaved RGB exists today; the field is there so that a future
// format (e.g. YCbCr 4:2:0) is a new value, not a new packet version.
enum class PixelFormat : std::uint8_t { Rgb = 1 };

// Byte 27 of the header: how the payload encodes the rectangle's codes.
enum class PayloadCoding : std::uint8_t {
  Raw = 0,     // components R, G, B per pixel in raster order, each `bits` wide, packed MSB first,
               // the last byte zero-padded
  JpegLs = 1,  // one lossless JPEG-LS image (ISO/IEC 14495-1) of the rectangle, sample-interleaved RGB
};

const char* to_string(PayloadCoding coding);
PayloadCoding parse_payload_coding(const std::string& name);  // "raw" | "jpeg-ls"; throws std::invalid_argument

// Every header field, as host values. Field order and widths are those of the wire layout.
struct PacketHeader {
  int stream = 0;                 // eye
  Parity parity = Parity::Full;
  std::int64_t frame_index = 0;   // t
  int width = 0;                  // the view as sent (reduced size for reduced frames)
  int height = 0;
  int full_width = 0;             // the full-resolution view it reconstructs to
  int full_height = 0;
  PixelFormat pixel_format = PixelFormat::Rgb;
  int bits = 8;                   // per component: 8 or 10
  Transfer transfer = Transfer::Srgb;
  PayloadCoding coding = PayloadCoding::Raw;
  int first_line = 0;             // the rectangle this packet carries
  int line_count = 0;
  int first_column = 0;
  int column_count = 0;
  std::uint32_t payload_length = 0;
  std::uint32_t sequence = 0;     // per stream, +1 per packet, wraps at 2^32: gaps reveal lost packets

  FrameMeta frame_meta() const;
};

// Bytes of a raw payload for a rectangle: ceil(columns * lines * 3 * bits / 8).
std::uint64_t raw_payload_bytes(int columns, int lines, int bits);

// Serialises header + payload + CRC. The header's payload_length is set from the payload.
std::vector<std::uint8_t> build_packet(PacketHeader header, std::span<const std::uint8_t> payload);

// The CRC-32 over every byte but the last four, as the packet should carry it.
std::uint32_t packet_crc(std::span<const std::uint8_t> packet);

// Why a packet was not accepted. Checked in this order: length, CRC, then every field.
enum class PacketError : std::uint8_t {
  None = 0,
  TooShort,          // fewer bytes than header + CRC
  CrcMismatch,       // damaged on the wire (or not a packet at all)
  BadMagic,
  BadVersion,
  BadField,          // a field outside its range (stream, flags, size, depth, format, coding, ...)
  BadRectangle,      // lines/columns empty or outside the view
  BadLength,         // payload_length disagrees with the packet size or with the rectangle
  TooLarge,          // the view exceeds the receiver's limits
};
const char* to_string(PacketError error);

// Limits a receiver enforces before it allocates anything for a view.
struct ReceiverLimits {
  int max_width = 16384;
  int max_height = 16384;
  std::uint64_t max_pixels = std::uint64_t{1} << 25;  // per view: 33.5 Mpixel = 201 MB of CV_16UC3 codes
};

struct ParsedPacket {
  PacketHeader header;
  std::span<const std::uint8_t> payload;  // points into the parsed bytes
};

// Parses and validates a whole packet; on failure returns nullopt and sets *error. Never reads
// outside `bytes`, never trusts a field: CRC first, then every field against its range, the
// rectangle against the view, and the payload length against both the packet size and (for raw
// payloads) the rectangle.
std::optional<ParsedPacket> parse_packet(std::span<const std::uint8_t> bytes, const ReceiverLimits& limits,
                                         PacketError* error);

}  // namespace trm::link
