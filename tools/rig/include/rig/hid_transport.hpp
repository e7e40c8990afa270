// HID output (or feature) reports through hidapi; the rig's answers arrive as input reports.
#pragma once

#include "rig/hid_api.hpp"
#include "rig/hid_report.hpp"
#include "rig/transport.hpp"

#include <optional>
#include <string>

namespace trm::rig {

struct HidOptions {
  std::optional<UsbId> id;  // select by VID:PID (first match, or the one with `serial`) ...
  std::string serial;
  std::string path;         // ... or by hidapi path (/dev/hidrawN for hidraw, "1-1:1.0" for libusb)
  HidReportFormat format;
  const HidApi* api = nullptr;  // nullptr: the linked backend
};

class HidTransport final : public RigTransport {
 public:
  explicit HidTransport(HidOptions options);  // opens; throws RigError
  ~HidTransport() override;

  std::string description() const override;
  std::size_t max_packet_size() const override { return options_.format.report_size; }
  std::size_t wire_bytes(std::size_t) const override {
    return options_.format.report_size + (options_.format.report_id != 0 ? 1 : 0);
  }
  void send(std::span<const std::uint8_t> packet) override;
  bool can_receive() const override { return true; }
  std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds timeout) override;
  TransportRate nominal_rate() const override;

 private:
  void open_device();
  [[noreturn]] void fail(const std::string& operation);
  bool still_present() const;
  std::string name() const;

  HidOptions options_;
  const HidApi* api_ = nullptr;
  hid_device* device_ = nullptr;
  std::string opened_path_;
  UsbId opened_id_;
};

}  // namespace trm::rig
