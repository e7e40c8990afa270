#include "rig/device_list.hpp"

#include "rig/transport.hpp"

#include <libusb.h>

#include <cstdio>
#include <sstream>

namespace trm::rig {
namespace {

std::string speed_name(int speed) {
  switch (speed) {
    case LIBUSB_SPEED_LOW: return "low";
    case LIBUSB_SPEED_FULL: return "full";
    case LIBUSB_SPEED_HIGH: return "high";
    case LIBUSB_SPEED_SUPER: return "super";
    case LIBUSB_SPEED_SUPER_PLUS: return "super+";
    default: return "unknown";
  }
}

std::string read_string(libusb_device_handle* handle, std::uint8_t index) {
  if (!index) return {};
  unsigned char text[256] = {};
  return libusb_get_string_descriptor_ascii(handle, index, text, sizeof text) > 0 ? reinterpret_cast<const char*>(text) : "";
}

void list_usb(DeviceListing& out) {
  libusb_context* context = nullptr;
  if (const int rc = libusb_init(&context); rc != 0) {
    out.notes.push_back(std::string("libusb could not start (") + libusb_error_name(rc) + "): no USB devices visible");
    return;
  }
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context, &list);
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device* device = list[i];
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(device, &desc) != 0) continue;
    if (desc.bDeviceClass == LIBUSB_CLASS_HUB) continue;  // hubs are never rigs
    UsbDeviceInfo info;
    info.vendor = desc.idVendor;
    info.product = desc.idProduct;
    std::uint8_t ports[8];
    const int depth = libusb_get_port_numbers(device, ports, static_cast<int>(sizeof ports));
    info.bus_port = std::to_string(libusb_get_bus_number(device));
    for (int p = 0; p < depth; ++p) {
      info.bus_port += p == 0 ? '-' : '.';
      info.bus_port += std::to_string(ports[p]);
    }
    info.speed = speed_name(libusb_get_device_speed(device));
    if (desc.iManufacturer || desc.iProduct || desc.iSerialNumber) {
      libusb_device_handle* handle = nullptr;
      const int rc = libusb_open(device, &handle);
      if (rc == 0) {
        info.manufacturer = read_string(handle, desc.iManufacturer);
        info.product_name = read_string(handle, desc.iProduct);
        info.serial = read_string(handle, desc.iSerialNumber);
        libusb_close(handle);
      } else {
        info.strings_note = rc == LIBUSB_ERROR_ACCESS ? "strings unreadable: permission denied (udev rule needed)"
                                                      : std::string("strings unreadable: ") + libusb_error_name(rc);
      }
    }
    libusb_config_descriptor* config = nullptr;
    if (libusb_get_active_config_descriptor(device, &config) == 0 || libusb_get_config_descriptor(device, 0, &config) == 0) {
      for (int n = 0; n < config->bNumInterfaces; ++n) {
        if (config->interface[n].num_altsetting < 1) continue;
        const libusb_interface_descriptor& alt = config->interface[n].altsetting[0];
        for (int e = 0; e < alt.bNumEndpoints; ++e) {
          static const char* const kTypes[] = {"control", "isochronous", "bulk", "interrupt"};
          const auto& ep = alt.endpoint[e];
          info.endpoints.push_back({alt.bInterfaceNumber, alt.bInterfaceClass, ep.bEndpointAddress,
                                    kTypes[ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK], ep.wMaxPacketSize});
        }
      }
      libusb_free_config_descriptor(config);
    }
    out.usb.push_back(std::move(info));
  }
  if (list) libusb_free_device_list(list, 1);  // allocated even when empty
  libusb_exit(context);
}

void list_hid(DeviceListing& out, const HidApi& api) {
  out.hid_backend = api.backend;
  if (api.init() != 0) {
    out.notes.push_back("hidapi (" + api.backend + ") could not start: no HID devices visible");
    return;
  }
  hid_device_info* list = api.enumerate(0, 0);
  for (const hid_device_info* d = list; d; d = d->next) {
    HidDeviceInfo info;
    info.vendor = d->vendor_id;
    info.product = d->product_id;
    info.path = d->path ? d->path : "";
    info.manufacturer = narrow(d->manufacturer_string);
    info.product_name = narrow(d->product_string);
    info.serial = narrow(d->serial_number);
    info.interface_number = d->interface_number;
    info.usage_page = d->usage_page;
    info.usage = d->usage;
    out.hid.push_back(std::move(info));
  }
  if (list) api.free_enumeration(list);
  api.exit();
}

std::string strings_of(const std::string& manufacturer, const std::string& product, const std::string& serial) {
  std::string text;
  if (!manufacturer.empty()) text += " \"" + manufacturer + "\"";
  if (!product.empty()) text += " \"" + product + "\"";
  if (!serial.empty()) text += " serial \"" + serial + "\"";
  return text;
}

}  // namespace

DeviceListing list_devices(const HidApi& hid_api) {
  DeviceListing listing;
  list_hid(listing, hid_api);
  list_usb(listing);
  return listing;
}

std::string format_listing(const DeviceListing& listing) {
  std::ostringstream out;
  for (const auto& note : listing.notes) out << "note: " << note << "\n";
  if (listing.usb.empty() && listing.hid.empty()) {
    out << "No USB or HID devices found (libusb and hidapi " << listing.hid_backend << " backend). "
        << "Plug in the rig, or feed a file with --file OUT.\n";
    return out.str();
  }
  out << "USB devices (libusb), for --usb VID:PID [--bus-port B-P] [--interface N] [--ep 0xNN]:\n";
  if (listing.usb.empty()) out << "  none\n";
  for (const auto& d : listing.usb) {
    out << "  " << UsbId{d.vendor, d.product}.to_string() << "  bus-port " << d.bus_port << "  " << d.speed << " speed"
        << strings_of(d.manufacturer, d.product_name, d.serial);
    if (!d.strings_note.empty()) out << "  (" << d.strings_note << ")";
    out << "\n";
    for (const auto& e : d.endpoints) {
      char address[8];
      std::snprintf(address, sizeof address, "0x%02x", e.address);
      out << "      interface " << e.interface_number << (e.interface_class == LIBUSB_CLASS_HID ? " (HID)" : "") << "  endpoint "
          << address << " " << e.type << ((e.address & 0x80) ? " IN" : " OUT") << ", " << e.max_packet_size << "-byte packets\n";
    }
  }
  out << "HID devices (hidapi " << listing.hid_backend << " backend), for --hid VID:PID or --hid PATH:\n";
  if (listing.hid.empty()) out << "  none\n";
  for (const auto& d : listing.hid) {
    char usage[32];
    std::snprintf(usage, sizeof usage, "usage %04x:%04x", d.usage_page, d.usage);
    out << "  " << UsbId{d.vendor, d.product}.to_string() << "  " << d.path << "  interface " << d.interface_number << "  "
        << usage << strings_of(d.manufacturer, d.product_name, d.serial) << "\n";
  }
  return out.str();
}

}  // namespace trm::rig
