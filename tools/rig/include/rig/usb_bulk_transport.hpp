// USB bulk OUT (and optional bulk IN for the rig's answers) through libusb-1.0.
#pragma once

#include "rig/transport.hpp"

#include <memory>
#include <string>

struct libusb_context;
struct libusb_device_handle;

namespace trm::rig {

struct UsbBulkOptions {
  UsbId id;
  std::string serial;        // optional: match the iSerialNumber string
  std::string bus_port;      // optional: "B-P[.P...]" as in sysfs, e.g. "1-4.2"
  int interface_number = -1; // -1: the first interface that has a bulk OUT endpoint
  int endpoint_out = -1;     // -1: the first bulk OUT endpoint of the interface
  int endpoint_in = -1;      // -1: the first bulk IN endpoint of the interface, if any
  std::chrono::milliseconds timeout{1000};  // per transfer
  bool detach_kernel_driver = false;
  std::size_t packet_size = 16384;  // protocol packet (= one bulk transfer) size, 64 .. 65543
};

class UsbBulkTransport final : public RigTransport {
 public:
  explicit UsbBulkTransport(UsbBulkOptions options);  // opens and claims; throws RigError
  ~UsbBulkTransport() override;

  std::string description() const override;
  std::size_t max_packet_size() const override { return options_.packet_size; }
  void send(std::span<const std::uint8_t> packet) override;
  bool can_receive() const override { return endpoint_in_ >= 0; }
  std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds timeout) override;
  TransportRate nominal_rate() const override { return rate_; }

 private:
  [[noreturn]] void fail_transfer(int code, const char* direction, int endpoint, int transferred, std::size_t length);
  void close();

  UsbBulkOptions options_;
  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int interface_ = -1;
  int endpoint_out_ = -1;
  int endpoint_in_ = -1;
  bool claimed_ = false;
  bool reattach_driver_ = false;
  std::string location_;  // "bus 1 port 1-4"
  TransportRate rate_;
};

// The udev rule that grants the logged-in user access to a device (quoted in permission errors).
std::string udev_rule_hint(const UsbId& id, const char* subsystem);

}  // namespace trm::rig
