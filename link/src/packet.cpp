#include "trm/packet.hpp"
#include "trm/crc32.hpp"

#include "byte_io.hpp"

#include <cstring>
#include <limits>
#include <stdexcept>

namespace trm::link {

namespace {

// Header byte offsets (docs/link.md, "Packet format").
constexpr std::size_t kOffMagic = 0;
constexpr std::size_t kOffVersion = 4;
constexpr std::size_t kOffHeaderLength = 5;
constexpr std::size_t kOffStream = 6;
constexpr std::size_t kOffFlags = 7;
constexpr std::size_t kOffFrameIndex = 8;
constexpr std::size_t kOffWidth = 16;
constexpr std::size_t kOffHeight = 18;
constexpr std::size_t kOffFullWidth = 20;
constexpr std::size_t kOffFullHeight = 22;
constexpr std::size_t kOffPixelFormat = 24;
constexpr std::size_t kOffBits = 25;
constexpr std::size_t kOffTransfer = 26;
constexpr std::size_t kOffCoding = 27;
constexpr std::size_t kOffFirstLine = 28;
constexpr std::size_t kOffLineCount = 30;
constexpr std::size_t kOffFirstColumn = 32;
constexpr std::size_t kOffColumnCount = 34;
constexpr std::size_t kOffPayloadLength = 36;
constexpr std::size_t kOffSequence = 40;
static_assert(kOffSequence + 4 == kPacketHeaderBytes);

constexpr std::uint8_t kFlagReduced = 0x01;
bool fits_u16(int v) { return v >= 0 && v <= kMaxDimension; }

}  // namespace

const char* to_string(PayloadCoding coding) {
  switch (coding) {
    case PayloadCoding::Raw: return "raw";
    case PayloadCoding::JpegLs: return "jpeg-ls";
  }
  return "?";
}

PayloadCoding parse_payload_coding(const std::string& name) {
  if (name == "raw") return PayloadCoding::Raw;
  if (name == "jpeg-ls" || name == "jpegls") return PayloadCoding::JpegLs;
  throw std::invalid_argument("unknown link payload coding '" + name + "' (expected raw or jpeg-ls)");
}

const char* to_string(PacketError error) {
  switch (error) {
    case PacketError::None: return "none";
    case PacketError::TooShort: return "shorter than header + CRC";
    case PacketError::CrcMismatch: return "CRC mismatch";
    case PacketError::BadMagic: return "bad magic";
    case PacketError::BadVersion: return "unsupported packet format version";
    case PacketError::BadField: return "header field out of range";
    case PacketError::BadRectangle: return "line/column range outside the view";
    case PacketError::BadLength: return "payload length disagrees with packet size or rectangle";
    case PacketError::TooLarge: return "view exceeds receiver limits";
  }
  return "?";
}

FrameMeta PacketHeader::frame_meta() const {
  FrameMeta meta;
  meta.index = frame_index;
  meta.eye = stream;
  meta.parity = parity;
  meta.width = width;
  meta.height = height;
  meta.full_width = full_width;
  meta.full_height = full_height;
  meta.bits = bits;
  meta.transfer = transfer;
  return meta;
}

std::uint64_t raw_payload_bytes(int columns, int lines, int bits) {
  // 64-bit throughout: 65535 * 65535 * 3 * 10 bits does not fit 32 bits.
  const std::uint64_t payload_bits =
      static_cast<std::uint64_t>(columns) * static_cast<std::uint64_t>(lines) * 3u * static_cast<std::uint64_t>(bits);
  return (payload_bits + 7u) / 8u;
}

std::uint32_t packet_crc(std::span<const std::uint8_t> packet) {
  if (packet.size() < kPacketCrcBytes) return 0;
  return crc32_ieee(packet.first(packet.size() - kPacketCrcBytes));
}

std::vector<std::uint8_t> build_packet(PacketHeader h, std::span<const std::uint8_t> payload) {
  if (payload.size() > std::numeric_limits<std::uint32_t>::max() - kPacketOverheadBytes)
    throw std::invalid_argument("packet payload too large for the 32-bit length field");
  if (h.stream < 0 || h.stream >= kMaxStreams) throw std::invalid_argument("packet stream must be 0 or 1");
  if (h.frame_index < 0) throw std::invalid_argument("packet frame index must be >= 0");
  for (int v : {h.width, h.height, h.full_width, h.full_height, h.first_line, h.line_count, h.first_column,
                h.column_count})
    if (!fits_u16(v)) throw std::invalid_argument("packet size/position field outside 0..65535");
  h.payload_length = static_cast<std::uint32_t>(payload.size());

  std::vector<std::uint8_t> out(kPacketHeaderBytes + payload.size() + kPacketCrcBytes);
  std::uint8_t* p = out.data();
  std::memcpy(p + kOffMagic, kPacketMagic, 4);
  p[kOffVersion] = kPacketFormatVersion;
  p[kOffHeaderLength] = static_cast<std::uint8_t>(kPacketHeaderBytes);
  p[kOffStream] = static_cast<std::uint8_t>(h.stream);
  p[kOffFlags] = h.parity == Parity::Reduced ? kFlagReduced : 0;
  detail::put_u64(p + kOffFrameIndex, static_cast<std::uint64_t>(h.frame_index));
  detail::put_u16(p + kOffWidth, static_cast<std::uint32_t>(h.width));
  detail::put_u16(p + kOffHeight, static_cast<std::uint32_t>(h.height));
  detail::put_u16(p + kOffFullWidth, static_cast<std::uint32_t>(h.full_width));
  detail::put_u16(p + kOffFullHeight, static_cast<std::uint32_t>(h.full_height));
  p[kOffPixelFormat] = static_cast<std::uint8_t>(h.pixel_format);
  p[kOffBits] = static_cast<std::uint8_t>(h.bits);
  p[kOffTransfer] = static_cast<std::uint8_t>(h.transfer);
  p[kOffCoding] = static_cast<std::uint8_t>(h.coding);
  detail::put_u16(p + kOffFirstLine, static_cast<std::uint32_t>(h.first_line));
  detail::put_u16(p + kOffLineCount, static_cast<std::uint32_t>(h.line_count));
  detail::put_u16(p + kOffFirstColumn, static_cast<std::uint32_t>(h.first_column));
  detail::put_u16(p + kOffColumnCount, static_cast<std::uint32_t>(h.column_count));
  detail::put_u32(p + kOffPayloadLength, h.payload_length);
  detail::put_u32(p + kOffSequence, h.sequence);
  if (!payload.empty()) std::memcpy(p + kPacketHeaderBytes, payload.data(), payload.size());
  const std::uint32_t crc = packet_crc(out);
  detail::put_u32(p + out.size() - kPacketCrcBytes, crc);
  return out;
}

std::optional<ParsedPacket> parse_packet(std::span<const std::uint8_t> bytes, const ReceiverLimits& limits,
                                         PacketError* error) {
  PacketError local_error = PacketError::None;
  PacketError& err = error ? *error : local_error;
  err = PacketError::None;
  auto fail = [&](PacketError e) -> std::optional<ParsedPacket> {
    err = e;
    return std::nullopt;
  };

  if (bytes.size() < kPacketOverheadBytes) return fail(PacketError::TooShort);
  // CRC before anything else: until it matches, no field of the header means anything.
  const std::uint8_t* p = bytes.data();
  if (detail::get_u32(p + bytes.size() - kPacketCrcBytes) != packet_crc(bytes)) return fail(PacketError::CrcMismatch);
  if (std::memcmp(p + kOffMagic, kPacketMagic, 4) != 0) return fail(PacketError::BadMagic);
  if (p[kOffVersion] != kPacketFormatVersion || p[kOffHeaderLength] != kPacketHeaderBytes)
    return fail(PacketError::BadVersion);

  PacketHeader h;
  h.stream = p[kOffStream];
  if (h.stream >= kMaxStreams) return fail(PacketError::BadField);
  const std::uint8_t flags = p[kOffFlags];
  if ((flags & ~kFlagReduced) != 0) return fail(PacketError::BadField);
  h.parity = (flags & kFlagReduced) ? Parity::Reduced : Parity::Full;
  const std::uint64_t index = detail::get_u64(p + kOffFrameIndex);
  if (index > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) return fail(PacketError::BadField);
  h.frame_index = static_cast<std::int64_t>(index);
  h.width = detail::get_u16(p + kOffWidth);
  h.height = detail::get_u16(p + kOffHeight);
  h.full_width = detail::get_u16(p + kOffFullWidth);
  h.full_height = detail::get_u16(p + kOffFullHeight);
  if (h.width < 1 || h.height < 1 || h.full_width < h.width || h.full_height < h.height)
    return fail(PacketError::BadField);
  // A full frame is the full view; a reduced frame is at most that (r = 1 sends reduced frames at full size).
  if (h.parity == Parity::Full && (h.width != h.full_width || h.height != h.full_height))
    return fail(PacketError::BadField);
  if (p[kOffPixelFormat] != static_cast<std::uint8_t>(PixelFormat::Rgb)) return fail(PacketError::BadField);
  h.pixel_format = PixelFormat::Rgb;
  h.bits = p[kOffBits];
  if (h.bits != 8 && h.bits != 10) return fail(PacketError::BadField);
  if (p[kOffTransfer] > static_cast<std::uint8_t>(Transfer::Gamma22)) return fail(PacketError::BadField);
  h.transfer = static_cast<Transfer>(p[kOffTransfer]);
  if (p[kOffCoding] > static_cast<std::uint8_t>(PayloadCoding::JpegLs)) return fail(PacketError::BadField);
  h.coding = static_cast<PayloadCoding>(p[kOffCoding]);

  // Limits before the rectangle: a view too large for this receiver is refused whatever it carries.
  if (h.width > limits.max_width || h.height > limits.max_height ||
      static_cast<std::uint64_t>(h.width) * static_cast<std::uint64_t>(h.height) > limits.max_pixels)
    return fail(PacketError::TooLarge);

  h.first_line = detail::get_u16(p + kOffFirstLine);
  h.line_count = detail::get_u16(p + kOffLineCount);
  h.first_column = detail::get_u16(p + kOffFirstColumn);
  h.column_count = detail::get_u16(p + kOffColumnCount);
  // int arithmetic cannot overflow: every term is at most 65535.
  if (h.line_count < 1 || h.column_count < 1 || h.first_line + h.line_count > h.height ||
      h.first_column + h.column_count > h.width)
    return fail(PacketError::BadRectangle);

  h.payload_length = detail::get_u32(p + kOffPayloadLength);
  h.sequence = detail::get_u32(p + kOffSequence);
  if (static_cast<std::uint64_t>(h.payload_length) != bytes.size() - kPacketOverheadBytes)
    return fail(PacketError::BadLength);
  if (h.coding == PayloadCoding::Raw && h.payload_length != raw_payload_bytes(h.column_count, h.line_count, h.bits))
    return fail(PacketError::BadLength);
  if (h.coding == PayloadCoding::JpegLs && h.payload_length == 0) return fail(PacketError::BadLength);

  return ParsedPacket{h, bytes.subspan(kPacketHeaderBytes, h.payload_length)};
}

}  // namespace trm::link
