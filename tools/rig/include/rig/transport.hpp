// One small interface for everything a frame can be fed into: a USB bulk OUT endpoint (libusb), a HID
// device (hidapi) or a file holding exactly the bytes such a device would receive.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm::rig {

// Every failure a rig operator can meet, each with its own exit code of `trm feed`
// (docs/rig_protocol.md, "Errors").
enum class RigErrorKind {
  NoDevice = 2,          // nothing with that VID:PID / path / serial / bus-port
  PermissionDenied = 3,  // device node not writable: udev rule needed
  Busy = 4,              // interface claimed by a kernel driver or another program
  EndpointMissing = 5,   // the interface has no such (bulk OUT / IN) endpoint
  Timeout = 6,           // the rig stopped accepting data or stopped answering
  Disconnected = 7,      // the device went away mid-stream
  Stalled = 8,           // the endpoint stalled (rig refused the transfer)
  RigReported = 9,       // the rig answered ERROR, or asked for too many resends
  Io = 10,               // anything else the OS or library reported
};
const char* to_string(RigErrorKind kind);

class RigError : public std::runtime_error {
 public:
  RigError(RigErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  RigErrorKind kind() const { return kind_; }
  int exit_code() const { return static_cast<int>(kind_); }

 private:
  RigErrorKind kind_;
};

// Nominal sustained rate of a transport, used for the up-front time estimate and the summary.
struct TransportRate {
  double bytes_per_second = 0.0;  // 0: unbounded (file)
  std::string basis;              // how it was derived, e.g. "full-speed HID: 64-byte report per 1 ms"
};

class RigTransport {
 public:
  virtual ~RigTransport() = default;
  RigTransport() = default;
  RigTransport(const RigTransport&) = delete;
  RigTransport& operator=(const RigTransport&) = delete;

  // e.g. "USB bulk 1234:5678 bus 1 port 1 interface 0 endpoint 0x01".
  virtual std::string description() const = 0;
  // Largest protocol packet send() accepts (HID: the report size; bulk / file: the chunk packet size).
  virtual std::size_t max_packet_size() const = 0;
  // Bytes the device receives for a packet of `packet_size` bytes (HID pads to the report size).
  virtual std::size_t wire_bytes(std::size_t packet_size) const { return packet_size; }
  // Delivers one protocol packet; throws RigError. Blocks at most the transport's timeout.
  virtual void send(std::span<const std::uint8_t> packet) = 0;
  // Whether the rig can answer (bulk IN endpoint, HID input reports).
  virtual bool can_receive() const = 0;
  // One answer from the rig, or nullopt when none arrived within `timeout` (may return early).
  virtual std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds timeout) = 0;
  virtual TransportRate nominal_rate() const = 0;
  // After the last view of a successful feed: a file transport moves its file into place (nothing before).
  virtual void finish() {}
};

// "1234:5678" (hex) -> {0x1234, 0x5678}; throws std::invalid_argument with the expected form.
struct UsbId {
  std::uint16_t vendor = 0, product = 0;
  std::string to_string() const;
};
UsbId parse_usb_id(const std::string& text);

}  // namespace trm::rig
