// `trm feed --list` content: says plainly when nothing is there, shows VID:PID, strings, endpoints.
#include "emulated_bench.hpp"
#include "rig/device_list.hpp"
#include "rig/hid_transport.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>

namespace trm::rig::testing {
namespace {

TEST(RigDeviceList, NoDevicesSaysSoPlainly) {
  EmulatedBench bench;
  const DeviceListing listing = list_devices(linked_hidapi());
  EXPECT_TRUE(listing.usb.empty());
  EXPECT_TRUE(listing.hid.empty());
  const std::string text = format_listing(listing);
  EXPECT_NE(text.find("No USB or HID devices found"), std::string::npos) << text;
}

TEST(RigDeviceList, ShowsBothRigsWithEndpointsAndStrings) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  bench.add_hid_rig();
  const std::string text = format_listing(list_devices(linked_hidapi()));
  for (const char* expected : {"1234:5678  bus-port 1-1  high speed \"trm bench\" \"Bulk rig\" serial \"RIG-0001\"",
                               "interface 0  endpoint 0x01 bulk OUT, 512-byte packets", "endpoint 0x81 bulk IN",
                               "interface 0 (HID)  endpoint 0x02 interrupt OUT, 64-byte packets", "1234:5679  /dev/hidraw0",
                               "serial \"HID-0002\""})
    EXPECT_NE(text.find(expected), std::string::npos) << "missing '" << expected << "' in\n" << text;
}

#if !defined(__SANITIZE_ADDRESS__)
// trm links hidapi-hidraw; --hid-backend libusb loads the other backend at run time.
TEST(RigHidBackends, LibusbBackendLoadedAtRunTimeDeliversByteExact) {
  const HidApi* libusb_backend = nullptr;
  try {
    libusb_backend = &hidapi_backend("libusb");
  } catch (const std::exception& e) {
    GTEST_SKIP() << e.what();
  }
  ASSERT_EQ(libusb_backend->backend, "libusb");
  EmulatedBench bench;
  HidRigConfig config;
  config.with_hidraw_node = false;
  bench.add_hid_rig(config);
  const std::vector<RigFrame> frames = {synthetic_frame(0, 0, 9, 5, 8), synthetic_frame(1, 0, 7, 3, 10)};
  {
    HidOptions o;
    o.id = kHidRigId;
    o.api = libusb_backend;
    HidTransport transport(o);
    EXPECT_NE(transport.description().find("hidapi libusb backend"), std::string::npos);
    feed_all(transport, frames);
  }
  EXPECT_EQ(bench.hid_reports_received(), expected_hid_reports(frames, HidReportFormat{}, false));
}
#endif

}  // namespace
}  // namespace trm::rig::testing
