// A test bench of emulated rigs: umockdev provides the sysfs tree and device nodes, and this class
// answers the kernel interfaces behind them (usbdevfs for libusb, hidraw for hidapi-hidraw) the way a
// rig would, recording every byte it receives. The handlers run on umockdev's worker thread.
#pragma once

#include "rig/protocol.hpp"
#include "rig/transport.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

typedef struct _UMockdevTestbed UMockdevTestbed;
typedef struct _UMockdevIoctlBase UMockdevIoctlBase;
typedef struct _UMockdevIoctlClient UMockdevIoctlClient;
typedef struct _UMockdevIoctlData UMockdevIoctlData;

namespace trm::rig::testing {

inline constexpr UsbId kBulkRigId{0x1234, 0x5678};
inline constexpr UsbId kHidRigId{0x1234, 0x5679};
inline constexpr const char* kBulkRigSerial = "RIG-0001";
inline constexpr const char* kHidRigSerial = "HID-0002";
inline constexpr const char* kHidrawNode = "/dev/hidraw0";

enum class Fault {
  None,
  Stall,   // the OUT endpoint halts: transfers fail with EPIPE
  Vanish,  // the device is unplugged: ENODEV, and it leaves sysfs
  Hang,    // the rig stops taking data: transfers never complete (NAK forever)
};

struct RigBehaviour {
  // Called on every FRAME_END the rig receives (times_seen counts repeats of that frame's end, from
  // 1); the returned answer is queued for the feeder (bulk IN / HID input report).
  std::function<std::optional<Answer>(const FrameEnd& end, int times_seen)> answer;
  Fault fault = Fault::None;
  std::size_t fault_after_bytes = 0;  // OUT payload bytes accepted before the fault strikes
  bool claim_busy = false;            // CLAIMINTERFACE fails with EBUSY
  std::string kernel_driver;          // non-empty: a kernel driver is bound to the interface
};

struct HidRigConfig {
  std::size_t report_size = 64;
  std::uint8_t report_id = 0;
  bool with_hidraw_node = true;  // the hidraw backend needs it; the libusb backend must not see it bound
  RigBehaviour behaviour;
};

class EmulatedBench {
 public:
  EmulatedBench();
  ~EmulatedBench();
  EmulatedBench(const EmulatedBench&) = delete;
  EmulatedBench& operator=(const EmulatedBench&) = delete;

  void add_bulk_rig(RigBehaviour behaviour = {});
  void add_hid_rig(HidRigConfig config = {});

  // Everything the bulk rig's OUT endpoint accepted, in order.
  std::vector<std::uint8_t> bulk_received() const;
  // Output reports as the HID rig's report handler sees them: report ID first only when numbered
  // (the USB wire form, whatever the backend: hidraw's extra leading 0 is removed).
  std::vector<std::vector<std::uint8_t>> hid_reports_received() const;
  // How the reports arrived: "interrupt" (output reports), "feature" (SET_REPORT / HIDIOCSFEATURE).
  std::vector<std::string> hid_report_kinds() const;
  int answers_sent() const;

  struct Device;  // one emulated rig (public for the C callbacks)

 private:
  UMockdevTestbed* testbed_ = nullptr;
  std::vector<std::shared_ptr<Device>> devices_;
};

}  // namespace trm::rig::testing
