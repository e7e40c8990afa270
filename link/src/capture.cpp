#include "trm/capture.hpp"
#include "trm/crc32.hpp"

#include "byte_io.hpp"
#include "trm/packet.hpp"

#include <cstring>
#include <sstream>

namespace trm::link {

namespace {

// File header offsets (docs/link.md, "Capture format").
constexpr std::size_t kOffMagic = 0;
constexpr std::size_t kOffVersion = 8;
constexpr std::size_t kOffHeaderLength = 10;
constexpr std::size_t kOffPacketVersion = 12;
constexpr std::size_t kOffReserved16 = 14;
constexpr std::size_t kOffMetadataLength = 16;
constexpr std::size_t kOffMetadataCrc = 20;
constexpr std::size_t kOffReserved64 = 24;
static_assert(kOffReserved64 + 8 == kCaptureHeaderBytes);

constexpr std::uint8_t kRecordPacket[4] = {'P', 'K', 'T', ' '};
constexpr std::uint8_t kRecordEnd[4] = {'E', 'N', 'D', ' '};
constexpr std::uint32_t kEndRecordBytes = 16;  // u64 packet count, u64 packet bytes

}  // namespace

// ---------------------------------------------------------------------------------------------- writer

CaptureWriter::CaptureWriter(const std::filesystem::path& path, const std::string& metadata) : path_(path) {
  if (metadata.size() > kCaptureMaxMetadataBytes)
    throw CaptureError("capture metadata is " + std::to_string(metadata.size()) + " bytes, more than the " +
                       std::to_string(kCaptureMaxMetadataBytes) + " allowed");
  try {
    file_ = std::make_unique<io::AtomicFile>(path);
  } catch (const std::runtime_error& e) {
    throw CaptureError(e.what());
  }
  std::uint8_t header[kCaptureHeaderBytes] = {};
  std::memcpy(header + kOffMagic, kCaptureMagic, sizeof kCaptureMagic);
  detail::put_u16(header + kOffVersion, kCaptureFormatVersion);
  detail::put_u16(header + kOffHeaderLength, kCaptureHeaderBytes);
  detail::put_u16(header + kOffPacketVersion, kPacketFormatVersion);
  detail::put_u32(header + kOffMetadataLength, static_cast<std::uint32_t>(metadata.size()));
  detail::put_u32(header + kOffMetadataCrc,
                  crc32_ieee({reinterpret_cast<const std::uint8_t*>(metadata.data()), metadata.size()}));
  write(header);
  write({reinterpret_cast<const std::uint8_t*>(metadata.data()), metadata.size()});
}

CaptureWriter::~CaptureWriter() = default;  // an unclosed AtomicFile removes its staging file

void CaptureWriter::write(std::span<const std::uint8_t> bytes) {
  try {
    file_->write(bytes);
  } catch (const std::runtime_error& e) {
    closed_ = true;  // the staging file is gone
    throw CaptureError(e.what());
  }
}

void CaptureWriter::write_packet(std::span<const std::uint8_t> packet) {
  if (closed_) throw CaptureError("capture '" + path_.string() + "' is already closed");
  if (packet.empty() || packet.size() > kCaptureMaxPacketBytes)
    throw CaptureError("capture packet of " + std::to_string(packet.size()) + " bytes outside 1.." +
                       std::to_string(kCaptureMaxPacketBytes));
  std::uint8_t record[kCaptureRecordHeaderBytes];
  std::memcpy(record, kRecordPacket, 4);
  detail::put_u32(record + 4, static_cast<std::uint32_t>(packet.size()));
  write(record);
  write(packet);
  ++packets_;
  packet_bytes_ += packet.size();
}

void CaptureWriter::close() {
  if (closed_) return;
  std::uint8_t record[kCaptureRecordHeaderBytes + kEndRecordBytes];
  std::memcpy(record, kRecordEnd, 4);
  detail::put_u32(record + 4, kEndRecordBytes);
  detail::put_u64(record + 8, packets_);
  detail::put_u64(record + 16, packet_bytes_);
  write(record);
  closed_ = true;
  try {
    file_->commit();
  } catch (const std::runtime_error& e) {
    throw CaptureError(e.what());
  }
}

// ---------------------------------------------------------------------------------------------- reader

CaptureReader::CaptureReader(const std::filesystem::path& path) : name_(path.string()) {
  // A buffer of 1 MiB rather than the stream's 8 KiB: a capture is read in packets of a few KiB, and each refill is
  // a system call (27,000 of them for 90 views at 1080x1200).
  read_buffer_.resize(std::size_t{1} << 20);
  auto file = std::make_unique<std::ifstream>();
  file->rdbuf()->pubsetbuf(read_buffer_.data(), static_cast<std::streamsize>(read_buffer_.size()));
  file->open(path, std::ios::binary);
  if (!*file) throw CaptureError("cannot open capture file '" + name_ + "'");
  in_ = std::move(file);
  read_header();
}

CaptureReader::CaptureReader(std::unique_ptr<std::istream> stream) : in_(std::move(stream)), name_("<stream>") {
  if (!in_ || !*in_) throw CaptureError("capture stream is not readable");
  read_header();
}

void CaptureReader::read_exact(void* destination, std::uint64_t count, const char* what) {
  // Checked against the known size first, so that a length field can never make us read (or allocate)
  // past the end of the file.
  if (count > size_ - offset_)
    throw CaptureError("capture '" + name_ + "' is truncated: " + what + " at byte " + std::to_string(offset_) +
                       " needs " + std::to_string(count) + " bytes, only " + std::to_string(size_ - offset_) + " left");
  in_->read(static_cast<char*>(destination), static_cast<std::streamsize>(count));
  if (static_cast<std::uint64_t>(in_->gcount()) != count)
    throw CaptureError("capture '" + name_ + "': read error at byte " + std::to_string(offset_));
  offset_ += count;
}

void CaptureReader::read_header() {
  in_->seekg(0, std::ios::end);
  const std::streamoff end = in_->tellg();
  in_->seekg(0, std::ios::beg);
  if (end < 0 || !*in_) throw CaptureError("capture '" + name_ + "': cannot determine its size");
  size_ = static_cast<std::uint64_t>(end);

  std::uint8_t header[kCaptureHeaderBytes];
  if (size_ < kCaptureHeaderBytes)
    throw CaptureError("capture '" + name_ + "' is truncated: " + std::to_string(size_) +
                       " bytes, shorter than the " + std::to_string(kCaptureHeaderBytes) + "-byte file header");
  read_exact(header, kCaptureHeaderBytes, "file header");
  if (std::memcmp(header + kOffMagic, kCaptureMagic, sizeof kCaptureMagic) != 0)
    throw CaptureError("'" + name_ + "' is not a TRM capture (bad magic)");
  const std::uint16_t version = detail::get_u16(header + kOffVersion);
  if (version != kCaptureFormatVersion)
    throw CaptureError("capture '" + name_ + "' has format version " + std::to_string(version) +
                       "; this build reads version " + std::to_string(kCaptureFormatVersion));
  if (detail::get_u16(header + kOffHeaderLength) != kCaptureHeaderBytes)
    throw CaptureError("capture '" + name_ + "': corrupt file header (header length)");
  const std::uint16_t packet_version = detail::get_u16(header + kOffPacketVersion);
  if (packet_version != kPacketFormatVersion)
    throw CaptureError("capture '" + name_ + "' holds packet format version " + std::to_string(packet_version) +
                       "; this build reads version " + std::to_string(kPacketFormatVersion));
  if (detail::get_u16(header + kOffReserved16) != 0 || detail::get_u64(header + kOffReserved64) != 0)
    throw CaptureError("capture '" + name_ + "': corrupt file header (reserved fields not zero)");
  const std::uint32_t metadata_length = detail::get_u32(header + kOffMetadataLength);
  if (metadata_length > kCaptureMaxMetadataBytes)
    throw CaptureError("capture '" + name_ + "': corrupt file header (metadata length " +
                       std::to_string(metadata_length) + ")");
  metadata_.resize(metadata_length);
  if (metadata_length > 0) read_exact(metadata_.data(), metadata_length, "metadata");
  const std::uint32_t crc =
      crc32_ieee({reinterpret_cast<const std::uint8_t*>(metadata_.data()), metadata_.size()});
  if (crc != detail::get_u32(header + kOffMetadataCrc))
    throw CaptureError("capture '" + name_ + "': metadata CRC mismatch (file corrupted)");
}

std::optional<std::vector<std::uint8_t>> CaptureReader::next_packet() {
  std::vector<std::uint8_t> packet;
  if (!next_packet(packet)) return std::nullopt;
  return packet;
}

bool CaptureReader::next_packet(std::vector<std::uint8_t>& packet) {
  if (ended_) return false;
  if (offset_ == size_)
    throw CaptureError("capture '" + name_ + "' is truncated: no end record after " + std::to_string(packets_) +
                       " packets (byte " + std::to_string(offset_) + ")");
  std::uint8_t record[kCaptureRecordHeaderBytes];
  read_exact(record, kCaptureRecordHeaderBytes, "record header");
  const std::uint32_t length = detail::get_u32(record + 4);
  const std::uint64_t record_offset = offset_ - kCaptureRecordHeaderBytes;

  if (std::memcmp(record, kRecordPacket, 4) == 0) {
    if (length == 0 || length > kCaptureMaxPacketBytes)
      throw CaptureError("capture '" + name_ + "': corrupt packet record at byte " + std::to_string(record_offset) +
                         " (length " + std::to_string(length) + ")");
    if (length > size_ - offset_)
      throw CaptureError("capture '" + name_ + "' is truncated: packet record at byte " +
                         std::to_string(record_offset) + " needs " + std::to_string(length) + " bytes, only " +
                         std::to_string(size_ - offset_) + " left");
    packet.resize(length);
    read_exact(packet.data(), length, "packet");
    ++packets_;
    packet_bytes_ += length;
    return true;
  }
  if (std::memcmp(record, kRecordEnd, 4) == 0) {
    if (length != kEndRecordBytes)
      throw CaptureError("capture '" + name_ + "': corrupt end record at byte " + std::to_string(record_offset));
    std::uint8_t body[kEndRecordBytes];
    read_exact(body, kEndRecordBytes, "end record");
    const std::uint64_t packets = detail::get_u64(body), bytes = detail::get_u64(body + 8);
    if (packets != packets_ || bytes != packet_bytes_)
      throw CaptureError("capture '" + name_ + "': end record says " + std::to_string(packets) + " packets / " +
                         std::to_string(bytes) + " bytes, the file holds " + std::to_string(packets_) + " / " +
                         std::to_string(packet_bytes_) + " (file corrupted)");
    if (offset_ != size_)
      throw CaptureError("capture '" + name_ + "': " + std::to_string(size_ - offset_) +
                         " unexpected bytes after the end record");
    ended_ = true;
    return false;
  }
  throw CaptureError("capture '" + name_ + "': unknown record type at byte " + std::to_string(record_offset) +
                     " (file corrupted)");
}

}  // namespace trm::link
