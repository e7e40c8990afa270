// Writes exactly the bytes a device would receive, for offline rigs and for diffing against a capture:
// stream framing = the concatenated bulk OUT data; HID framing = one wire report after another.
// Written through io::AtomicFile: the file appears by finish() only, so a failed feed (bad argument, full
// disk, interrupt) leaves no file behind.
#pragma once

#include "rig/hid_report.hpp"
#include "rig/transport.hpp"

#include "trm/atomic_file.hpp"

#include <memory>
#include <string>

namespace trm::rig {

struct FileTransportOptions {
  std::string path;
  enum class Framing { Bulk, Hid } framing = Framing::Bulk;
  std::size_t bulk_packet_size = 16384;  // must match the USB transport's --chunk to diff byte for byte
  HidReportFormat hid;
};

class FileTransport final : public RigTransport {
 public:
  explicit FileTransport(FileTransportOptions options);  // throws RigError(Io) when it cannot create the file
  ~FileTransport() override;
  void finish() override;  // throws RigError(Io)

  std::string description() const override;
  std::size_t max_packet_size() const override;
  std::size_t wire_bytes(std::size_t packet_size) const override;
  void send(std::span<const std::uint8_t> packet) override;
  bool can_receive() const override { return false; }
  std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds) override { return std::nullopt; }
  TransportRate nominal_rate() const override { return {0.0, "file: limited by the disk only"}; }

 private:
  FileTransportOptions options_;
  std::unique_ptr<io::AtomicFile> file_;
};

}  // namespace trm::rig
