#include "rig/hid_report.hpp"

#include "rig/protocol.hpp"

#include <stdexcept>
#include <string>

namespace trm::rig {

void HidReportFormat::validate() const {
  if (report_size < kMinPacketSize || report_size > kMaxReportSize)
    throw std::invalid_argument("HID report size must be 64..1024 bytes (64 at full speed), got " +
                                std::to_string(report_size));
}

std::vector<std::uint8_t> hidapi_report_buffer(const HidReportFormat& format, std::span<const std::uint8_t> packet) {
  if (packet.size() > format.report_size)
    throw std::invalid_argument("packet of " + std::to_string(packet.size()) + " bytes exceeds the " +
                                std::to_string(format.report_size) + "-byte HID report");
  std::vector<std::uint8_t> buffer(1 + format.report_size, 0);
  buffer[0] = format.report_id;
  std::copy(packet.begin(), packet.end(), buffer.begin() + 1);
  return buffer;
}

std::vector<std::uint8_t> hid_wire_report(const HidReportFormat& format, std::span<const std::uint8_t> packet) {
  std::vector<std::uint8_t> buffer = hidapi_report_buffer(format, packet);
  if (format.report_id == 0) buffer.erase(buffer.begin());
  return buffer;
}

}  // namespace trm::rig
