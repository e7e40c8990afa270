#include "rig/file_transport.hpp"

#include "rig/protocol.hpp"

namespace trm::rig {

FileTransport::FileTransport(FileTransportOptions options) : options_(std::move(options)) {
  if (options_.framing == FileTransportOptions::Framing::Hid) options_.hid.validate();
  else if (options_.bulk_packet_size < kMinPacketSize || options_.bulk_packet_size > kChunkHeaderSize + kMaxChunkData)
    throw std::invalid_argument("bulk packet size must be 64.." + std::to_string(kChunkHeaderSize + kMaxChunkData));
  try {
    file_ = std::make_unique<io::AtomicFile>(options_.path);
  } catch (const std::runtime_error& e) {
    throw RigError(RigErrorKind::Io, e.what());
  }
}

FileTransport::~FileTransport() = default;  // unfinished: the staging file is removed

void FileTransport::finish() {
  if (!file_) return;
  try {
    file_->commit();
  } catch (const std::runtime_error& e) {
    file_.reset();
    throw RigError(RigErrorKind::Io, e.what());
  }
  file_.reset();
}

std::string FileTransport::description() const {
  if (options_.framing == FileTransportOptions::Framing::Hid)
    return "file " + options_.path + " (HID reports of " + std::to_string(options_.hid.report_size) + " bytes, report ID " +
           std::to_string(options_.hid.report_id) + ")";
  return "file " + options_.path + " (bulk stream, " + std::to_string(options_.bulk_packet_size) + "-byte packets)";
}

std::size_t FileTransport::max_packet_size() const {
  return options_.framing == FileTransportOptions::Framing::Hid ? options_.hid.report_size : options_.bulk_packet_size;
}

std::size_t FileTransport::wire_bytes(std::size_t packet_size) const {
  if (options_.framing == FileTransportOptions::Framing::Bulk) return packet_size;
  return options_.hid.report_size + (options_.hid.report_id != 0 ? 1 : 0);
}

void FileTransport::send(std::span<const std::uint8_t> packet) {
  std::vector<std::uint8_t> report;
  std::span<const std::uint8_t> bytes = packet;
  if (options_.framing == FileTransportOptions::Framing::Hid) {
    report = hid_wire_report(options_.hid, packet);
    bytes = report;
  } else if (packet.size() > options_.bulk_packet_size) {
    throw std::invalid_argument("packet larger than the bulk packet size");
  }
  if (!file_) throw RigError(RigErrorKind::Io, "'" + options_.path + "' is already finished or failed");
  try {
    file_->write(bytes);
  } catch (const std::runtime_error& e) {
    file_.reset();  // the staging file is gone
    throw RigError(RigErrorKind::Io, e.what());
  }
}

}  // namespace trm::rig
