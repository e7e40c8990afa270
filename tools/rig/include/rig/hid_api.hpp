// The hidapi entry points the HID transport uses, as a table, so one binary can drive either backend:
// the backend it links (trm links hidapi-hidraw) or hidapi-libusb loaded at run time in its own symbol
// scope. The two backends export the same symbol names, so they can never both be linked.
#pragma once

#include <hidapi/hidapi.h>

#include <string>

namespace trm::rig {

struct HidApi {
  std::string backend;  // "hidraw" or "libusb"
  int (*init)();
  int (*exit)();
  hid_device_info* (*enumerate)(unsigned short vendor, unsigned short product);
  void (*free_enumeration)(hid_device_info* list);
  hid_device* (*open_path)(const char* path);
  int (*write)(hid_device* device, const unsigned char* data, size_t length);
  int (*send_feature_report)(hid_device* device, const unsigned char* data, size_t length);
  int (*read_timeout)(hid_device* device, unsigned char* data, size_t length, int milliseconds);
  const wchar_t* (*error)(hid_device* device);
  void (*close)(hid_device* device);
};

// The backend this binary was linked with (its name found from the library that defines hid_open_path).
const HidApi& linked_hidapi();

// "hidraw" or "libusb": the linked table when it is that backend, otherwise the other backend's shared
// library loaded with RTLD_DEEPBIND so its internal calls stay inside it. Throws std::runtime_error
// when the library is missing or cannot be isolated (sanitizer builds).
const HidApi& hidapi_backend(const std::string& name);

std::string narrow(const wchar_t* text);  // hidapi strings -> UTF-8 (ASCII in practice); null -> ""

}  // namespace trm::rig
