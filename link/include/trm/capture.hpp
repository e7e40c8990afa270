// .trmcap capture files, format version 1 (docs/link.md, "Capture format"): a file header with
// magic, version and a metadata text, then the packet stream as sent, then an end record.
#pragma once

#include "trm/atomic_file.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm::link {

inline constexpr std::uint8_t kCaptureMagic[8] = {0x89, 'T', 'R', 'M', 'C', 'A', 'P', '\n'};
inline constexpr std::uint16_t kCaptureFormatVersion = 1;
inline constexpr std::size_t kCaptureHeaderBytes = 32;
inline constexpr std::size_t kCaptureRecordHeaderBytes = 8;
inline constexpr std::uint32_t kCaptureMaxMetadataBytes = 1u << 20;
inline constexpr std::uint32_t kCaptureMaxPacketBytes = 1u << 28;

// Any structural problem of a capture file: the message says what and at which byte offset.
class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Writes a capture through io::AtomicFile (a staging name beside `path`); close() writes the end record and
// renames it into place, so an interrupted run never leaves a file that looks complete. Destroying an unclosed
// writer removes the staging file. Throws CaptureError on I/O failure or a target that is not a regular file.
class CaptureWriter {
 public:
  // `metadata` is free text stored verbatim (`trm run` writes its configuration as JSON).
  CaptureWriter(const std::filesystem::path& path, const std::string& metadata);
  ~CaptureWriter();
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  void write_packet(std::span<const std::uint8_t> packet);
  void close();
  std::uint64_t packets_written() const { return packets_; }

 private:
  void write(std::span<const std::uint8_t> bytes);

  std::filesystem::path path_;
  std::unique_ptr<io::AtomicFile> file_;
  std::uint64_t packets_ = 0;
  std::uint64_t packet_bytes_ = 0;
  bool closed_ = false;
};

// Reads a capture record by record, validating the structure as it goes: magic, versions, reserved
// fields, metadata length and CRC, record types and lengths against the bytes left, the end record's
// counts, and nothing after it. Packets themselves are returned as stored; their CRC is the receiver's
// business (a capture may hold damaged packets on purpose). Throws CaptureError.
class CaptureReader {
 public:
  explicit CaptureReader(const std::filesystem::path& path);
  explicit CaptureReader(std::unique_ptr<std::istream> stream);  // e.g. an istringstream (fuzzing, tests)

  const std::string& metadata() const { return metadata_; }
  // The next packet, or nullopt after a valid end record.
  std::optional<std::vector<std::uint8_t>> next_packet();
  // The same into `packet` (its memory reused from call to call); false after a valid end record.
  bool next_packet(std::vector<std::uint8_t>& packet);
  std::uint64_t packets_read() const { return packets_; }

 private:
  void read_exact(void* destination, std::uint64_t count, const char* what);
  void read_header();

  std::vector<char> read_buffer_;  // the file stream's buffer: declared first, so that it outlives the stream
  std::unique_ptr<std::istream> in_;
  std::string name_;          // for messages
  std::uint64_t size_ = 0;    // total bytes
  std::uint64_t offset_ = 0;  // bytes consumed
  std::string metadata_;
  std::uint64_t packets_ = 0;
  std::uint64_t packet_bytes_ = 0;
  bool ended_ = false;
};

}  // namespace trm::link
