// What `trm feed --list` shows: USB devices (libusb) with their bulk endpoints and HID devices (hidapi).
#pragma once

#include "rig/hid_api.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace trm::rig {

struct UsbEndpointInfo {
  int interface_number = 0;
  int interface_class = 0;
  int address = 0;            // bit 7 set: IN
  std::string type;           // "bulk", "interrupt", ...
  int max_packet_size = 0;
};

struct UsbDeviceInfo {
  std::uint16_t vendor = 0, product = 0;
  std::string bus_port;       // "1-4.2"
  std::string speed;          // "full", "high", ...
  std::string manufacturer, product_name, serial;
  std::string strings_note;   // why strings are missing, e.g. "permission denied"
  std::vector<UsbEndpointInfo> endpoints;
};

struct HidDeviceInfo {
  std::uint16_t vendor = 0, product = 0;
  std::string path;
  std::string manufacturer, product_name, serial;
  int interface_number = -1;
  std::uint16_t usage_page = 0, usage = 0;
};

struct DeviceListing {
  std::vector<UsbDeviceInfo> usb;
  std::vector<HidDeviceInfo> hid;
  std::string hid_backend;
  std::vector<std::string> notes;   // e.g. "libusb could not start: ..."
};

DeviceListing list_devices(const HidApi& hid_api);
std::string format_listing(const DeviceListing& listing);

}  // namespace trm::rig
