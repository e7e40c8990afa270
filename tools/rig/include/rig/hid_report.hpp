// How protocol packets map onto HID reports: one packet per report, zero-padded to the report size.
// hidapi always takes the report ID as the first byte (0 when the device does not number its reports);
// what reaches the device depends on that ID, not on the hidapi backend (docs/rig_protocol.md, "HID").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace trm::rig {

inline constexpr std::size_t kFullSpeedReportSize = 64;
inline constexpr std::size_t kMaxReportSize = 1024;

struct HidReportFormat {
  std::size_t report_size = kFullSpeedReportSize;  // report payload bytes, without the ID (64 .. 1024)
  std::uint8_t report_id = 0;                      // 0: unnumbered reports
  bool feature = false;                            // feature reports (SET_REPORT) instead of output reports
  void validate() const;                           // throws std::invalid_argument
};

// The buffer handed to hid_write / hid_send_feature_report: [report ID] + packet + zero padding.
std::vector<std::uint8_t> hidapi_report_buffer(const HidReportFormat& format, std::span<const std::uint8_t> packet);

// The bytes the device's report handler receives: the padded packet, preceded by the report ID only
// when reports are numbered (USB carries the ID byte in the report only then).
std::vector<std::uint8_t> hid_wire_report(const HidReportFormat& format, std::span<const std::uint8_t> packet);

}  // namespace trm::rig
