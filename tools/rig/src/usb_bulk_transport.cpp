#include "rig/usb_bulk_transport.hpp"

#include "rig/protocol.hpp"

#include <libusb.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace trm::rig {
namespace {

std::string hex_endpoint(int endpoint) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02x", endpoint & 0xFF);
  return text;
}

std::string libusb_message(int code) { return std::string(libusb_error_name(code)) + ": " + libusb_strerror(code); }

// "B-P.P.P", the name sysfs gives the device (bus number, then the hub port chain).
std::string bus_port_of(libusb_device* device) {
  std::uint8_t ports[8];
  const int depth = libusb_get_port_numbers(device, ports, static_cast<int>(sizeof ports));
  std::string text = std::to_string(libusb_get_bus_number(device));
  if (depth <= 0) return text + "-0";  // a root hub
  for (int i = 0; i < depth; ++i) {
    text += i == 0 ? '-' : '.';
    text += std::to_string(ports[i]);
  }
  return text;
}

struct ConfigDescriptor {
  libusb_config_descriptor* config = nullptr;
  ~ConfigDescriptor() {
    if (config) libusb_free_config_descriptor(config);
  }
};

bool is_bulk(const libusb_endpoint_descriptor& e) {
  return (e.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) == LIBUSB_TRANSFER_TYPE_BULK;
}
bool is_out(const libusb_endpoint_descriptor& e) { return (e.bEndpointAddress & LIBUSB_ENDPOINT_IN) == 0; }

std::string endpoint_list(const libusb_interface_descriptor& alt) {
  std::string text;
  for (int i = 0; i < alt.bNumEndpoints; ++i) {
    const auto& e = alt.endpoint[i];
    static const char* const kTypes[] = {"control", "isochronous", "bulk", "interrupt"};
    text += (text.empty() ? "" : ", ") + hex_endpoint(e.bEndpointAddress) + " " +
            kTypes[e.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK] + (is_out(e) ? " OUT" : " IN");
  }
  return text.empty() ? "none" : text;
}

TransportRate bulk_rate(int speed) {
  switch (speed) {
    case LIBUSB_SPEED_LOW:
    case LIBUSB_SPEED_FULL:
      return {19.0 * 64 * 1000, "full-speed bulk: at most 19 x 64-byte packets per 1 ms frame"};
    case LIBUSB_SPEED_SUPER:
    case LIBUSB_SPEED_SUPER_PLUS:
      return {400e6, "SuperSpeed bulk: ~400 MB/s in practice"};
    default:
      return {13.0 * 512 * 8000, "high-speed bulk: at most 13 x 512-byte packets per 125 us microframe"};
  }
}

}  // namespace

std::string udev_rule_hint(const UsbId& id, const char* subsystem) {
  char vendor[8], product[8];
  std::snprintf(vendor, sizeof vendor, "%04x", id.vendor);
  std::snprintf(product, sizeof product, "%04x", id.product);
  const std::string match = std::string(subsystem) == "hidraw"
                                ? std::string("KERNEL==\"hidraw*\", ATTRS{idVendor}==\"") + vendor + "\", ATTRS{idProduct}==\"" + product + "\""
                                : std::string("SUBSYSTEM==\"usb\", ATTR{idVendor}==\"") + vendor + "\", ATTR{idProduct}==\"" + product + "\"";
  return "add a udev rule, e.g. /etc/udev/rules.d/70-trm-rig.rules containing\n  " + match +
         ", MODE=\"0660\", TAG+=\"uaccess\"\nthen run 'sudo udevadm control --reload && sudo udevadm trigger' and replug the rig";
}

UsbBulkTransport::UsbBulkTransport(UsbBulkOptions options) : options_(std::move(options)) {
  if (options_.packet_size < kMinPacketSize || options_.packet_size > kChunkHeaderSize + kMaxChunkData)
    throw std::invalid_argument("bulk packet size must be 64.." + std::to_string(kChunkHeaderSize + kMaxChunkData) + " bytes");
  const std::string id = options_.id.to_string();
  if (const int rc = libusb_init(&context_); rc != 0) {
    context_ = nullptr;
    throw RigError(RigErrorKind::NoDevice, "no USB device " + id + " found: libusb could not start (" + libusb_message(rc) +
                                               "; is /dev/bus/usb available?)");
  }
  try {
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(context_, &list);
    if (count < 0) throw RigError(RigErrorKind::Io, "cannot list USB devices: " + libusb_message(static_cast<int>(count)));
    libusb_device* chosen = nullptr;
    std::vector<std::string> near_misses;  // same VID:PID, other serial / port
    bool serial_unreadable = false;
    for (ssize_t i = 0; i < count && !chosen; ++i) {
      libusb_device_descriptor desc{};
      if (libusb_get_device_descriptor(list[i], &desc) != 0) continue;
      if (desc.idVendor != options_.id.vendor || desc.idProduct != options_.id.product) continue;
      const std::string port = bus_port_of(list[i]);
      if (!options_.bus_port.empty() && port != options_.bus_port) {
        near_misses.push_back("at " + port);
        continue;
      }
      if (!options_.serial.empty()) {
        libusb_device_handle* probe = nullptr;
        std::string serial;
        if (libusb_open(list[i], &probe) == 0) {
          unsigned char text[256] = {};
          if (desc.iSerialNumber && libusb_get_string_descriptor_ascii(probe, desc.iSerialNumber, text, sizeof text) > 0)
            serial = reinterpret_cast<const char*>(text);
          libusb_close(probe);
        } else {
          serial_unreadable = true;
        }
        if (serial != options_.serial) {
          near_misses.push_back("at " + port + (serial.empty() ? " (serial unreadable)" : " with serial " + serial));
          continue;
        }
      }
      chosen = libusb_ref_device(list[i]);
      location_ = port;
    }
    libusb_free_device_list(list, 1);
    if (!chosen) {
      std::string message = "no USB device " + id + " found";
      if (!options_.serial.empty()) message += " with serial '" + options_.serial + "'";
      if (!options_.bus_port.empty()) message += " at bus-port " + options_.bus_port;
      if (!near_misses.empty()) {
        message += " (" + id + " present";
        for (const auto& m : near_misses) message += " " + m;
        message += ")";
      }
      if (serial_unreadable) message += "; serial numbers could not be read: permission denied, " + udev_rule_hint(options_.id, "usb");
      throw RigError(RigErrorKind::NoDevice, message + "; 'trm feed --list' shows what is connected");
    }
    rate_ = bulk_rate(libusb_get_device_speed(chosen));

    ConfigDescriptor cfg;
    if (libusb_get_active_config_descriptor(chosen, &cfg.config) != 0 &&
        libusb_get_config_descriptor(chosen, 0, &cfg.config) != 0) {
      libusb_unref_device(chosen);
      throw RigError(RigErrorKind::Io, "cannot read the configuration descriptor of USB device " + id);
    }
    const int open_rc = libusb_open(chosen, &handle_);
    libusb_unref_device(chosen);
    if (open_rc == LIBUSB_ERROR_ACCESS)
      throw RigError(RigErrorKind::PermissionDenied, "permission denied opening USB device " + id + " at bus-port " + location_ +
                                                         ": " + udev_rule_hint(options_.id, "usb"));
    if (open_rc == LIBUSB_ERROR_NO_DEVICE)
      throw RigError(RigErrorKind::Disconnected, "USB device " + id + " disappeared while it was being opened");
    if (open_rc != 0) throw RigError(RigErrorKind::Io, "cannot open USB device " + id + ": " + libusb_message(open_rc));

    // Interface and endpoints: as given, else the first bulk OUT (and bulk IN) found.
    const libusb_interface_descriptor* chosen_alt = nullptr;
    std::string interfaces;
    for (int i = 0; i < cfg.config->bNumInterfaces; ++i) {
      if (cfg.config->interface[i].num_altsetting < 1) continue;
      const libusb_interface_descriptor& alt = cfg.config->interface[i].altsetting[0];
      interfaces += (interfaces.empty() ? "" : "; ") + std::string("interface ") + std::to_string(alt.bInterfaceNumber) +
                    ": " + endpoint_list(alt);
      if (chosen_alt) continue;
      if (options_.interface_number >= 0) {
        if (alt.bInterfaceNumber == options_.interface_number) chosen_alt = &alt;
        continue;
      }
      for (int e = 0; e < alt.bNumEndpoints; ++e) {
        const auto& ep = alt.endpoint[e];
        const bool wanted = options_.endpoint_out >= 0 ? ep.bEndpointAddress == options_.endpoint_out : is_bulk(ep) && is_out(ep);
        if (wanted) chosen_alt = &alt;
      }
    }
    if (!chosen_alt) {
      const std::string what = options_.interface_number >= 0 ? "interface " + std::to_string(options_.interface_number)
                               : options_.endpoint_out >= 0  ? "endpoint " + hex_endpoint(options_.endpoint_out)
                                                             : "bulk OUT endpoint";
      throw RigError(RigErrorKind::EndpointMissing,
                     "USB device " + id + " has no " + what + " (" + (interfaces.empty() ? "no interfaces" : interfaces) + ")");
    }
    interface_ = chosen_alt->bInterfaceNumber;
    for (int e = 0; e < chosen_alt->bNumEndpoints; ++e) {
      const auto& ep = chosen_alt->endpoint[e];
      if (!is_bulk(ep)) continue;
      if (is_out(ep) && endpoint_out_ < 0 && (options_.endpoint_out < 0 || ep.bEndpointAddress == options_.endpoint_out))
        endpoint_out_ = ep.bEndpointAddress;
      if (!is_out(ep) && endpoint_in_ < 0 && (options_.endpoint_in < 0 || ep.bEndpointAddress == options_.endpoint_in))
        endpoint_in_ = ep.bEndpointAddress;
    }
    if (endpoint_out_ < 0)
      throw RigError(RigErrorKind::EndpointMissing,
                     "interface " + std::to_string(interface_) + " of USB device " + id + " has no bulk OUT endpoint" +
                         (options_.endpoint_out >= 0 ? " " + hex_endpoint(options_.endpoint_out) : std::string()) +
                         " (it has: " + endpoint_list(*chosen_alt) + ")");
    if (options_.endpoint_in >= 0 && endpoint_in_ < 0)
      throw RigError(RigErrorKind::EndpointMissing, "interface " + std::to_string(interface_) + " of USB device " + id +
                                                        " has no bulk IN endpoint " + hex_endpoint(options_.endpoint_in) +
                                                        " (it has: " + endpoint_list(*chosen_alt) + ")");

    if (libusb_kernel_driver_active(handle_, interface_) == 1) {
      if (!options_.detach_kernel_driver)
        throw RigError(RigErrorKind::Busy, "interface " + std::to_string(interface_) + " of USB device " + id +
                                               " is bound to a kernel driver; pass --detach-kernel-driver to take it over "
                                               "(it is given back when trm exits)");
      if (const int rc = libusb_detach_kernel_driver(handle_, interface_); rc != 0)
        throw RigError(rc == LIBUSB_ERROR_ACCESS ? RigErrorKind::PermissionDenied : RigErrorKind::Busy,
                       "cannot detach the kernel driver from interface " + std::to_string(interface_) + " of " + id + ": " +
                           libusb_message(rc));
      reattach_driver_ = true;
    }
    if (const int rc = libusb_claim_interface(handle_, interface_); rc != 0) {
      if (rc == LIBUSB_ERROR_BUSY)
        throw RigError(RigErrorKind::Busy, "interface " + std::to_string(interface_) + " of USB device " + id +
                                               " is claimed by another program or driver; close it, or pass "
                                               "--detach-kernel-driver if a kernel driver holds it");
      if (rc == LIBUSB_ERROR_NO_DEVICE)
        throw RigError(RigErrorKind::Disconnected, "USB device " + id + " disappeared while its interface was claimed");
      throw RigError(RigErrorKind::Io, "cannot claim interface " + std::to_string(interface_) + " of " + id + ": " +
                                           libusb_message(rc));
    }
    claimed_ = true;
  } catch (...) {
    close();
    throw;
  }
}

UsbBulkTransport::~UsbBulkTransport() { close(); }

void UsbBulkTransport::close() {
  if (handle_) {
    if (claimed_) libusb_release_interface(handle_, interface_);
    if (reattach_driver_) libusb_attach_kernel_driver(handle_, interface_);
    libusb_close(handle_);
    handle_ = nullptr;
  }
  claimed_ = false;
  if (context_) {
    libusb_exit(context_);
    context_ = nullptr;
  }
}

std::string UsbBulkTransport::description() const {
  std::string text = "USB bulk " + options_.id.to_string() + " at bus-port " + location_ + ", interface " +
                     std::to_string(interface_) + ", OUT endpoint " + hex_endpoint(endpoint_out_);
  if (endpoint_in_ >= 0) text += ", IN endpoint " + hex_endpoint(endpoint_in_);
  return text;
}

void UsbBulkTransport::fail_transfer(int code, const char* direction, int endpoint, int transferred, std::size_t length) {
  const std::string where = std::string("bulk ") + direction + " endpoint " + hex_endpoint(endpoint) + " of " + options_.id.to_string();
  const std::string progress = " (" + std::to_string(transferred) + " of " + std::to_string(length) + " bytes of the packet taken)";
  switch (code) {
    case LIBUSB_ERROR_TIMEOUT:
      throw RigError(RigErrorKind::Timeout, "the rig stopped accepting data: " + where + " timed out after " +
                                                std::to_string(options_.timeout.count()) + " ms" + progress);
    case LIBUSB_ERROR_PIPE:
      // Clearing the halt leaves the device usable for the next run.
      libusb_clear_halt(handle_, static_cast<unsigned char>(endpoint));
      throw RigError(RigErrorKind::Stalled, where + " stalled: the rig refused the transfer" + progress + "; halt cleared");
    case LIBUSB_ERROR_NO_DEVICE:
      throw RigError(RigErrorKind::Disconnected, "USB device " + options_.id.to_string() + " disappeared (unplugged or reset) during a transfer on " +
                                                     where + progress);
    default:
      throw RigError(RigErrorKind::Io, where + " failed: " + libusb_message(code) + progress);
  }
}

void UsbBulkTransport::send(std::span<const std::uint8_t> packet) {
  if (packet.size() > options_.packet_size) throw std::invalid_argument("packet larger than the bulk packet size");
  int transferred = 0;
  // libusb takes a non-const buffer for both directions; OUT transfers do not write to it.
  const int rc = libusb_bulk_transfer(handle_, static_cast<unsigned char>(endpoint_out_), const_cast<std::uint8_t*>(packet.data()),
                                      static_cast<int>(packet.size()), &transferred, static_cast<unsigned>(options_.timeout.count()));
  if (rc != 0) fail_transfer(rc, "OUT", endpoint_out_, transferred, packet.size());
  if (static_cast<std::size_t>(transferred) != packet.size())
    throw RigError(RigErrorKind::Io, "bulk OUT endpoint " + hex_endpoint(endpoint_out_) + " took " + std::to_string(transferred) +
                                         " of " + std::to_string(packet.size()) + " bytes");
}

std::optional<std::vector<std::uint8_t>> UsbBulkTransport::receive(std::chrono::milliseconds timeout) {
  if (endpoint_in_ < 0) return std::nullopt;
  // A multiple of every bulk max packet size, so a rig sending more than asked cannot overflow.
  std::vector<std::uint8_t> buffer(1024);
  int transferred = 0;
  const auto wait_ms = static_cast<unsigned>(std::max<std::int64_t>(1, timeout.count()));
  const int rc = libusb_bulk_transfer(handle_, static_cast<unsigned char>(endpoint_in_), buffer.data(),
                                      static_cast<int>(buffer.size()), &transferred, wait_ms);
  if (rc == LIBUSB_ERROR_TIMEOUT && transferred == 0) return std::nullopt;
  if (rc != 0 && rc != LIBUSB_ERROR_TIMEOUT) fail_transfer(rc, "IN", endpoint_in_, transferred, buffer.size());
  buffer.resize(static_cast<std::size_t>(transferred));
  return buffer;
}

}  // namespace trm::rig
