#include "rig/hid_transport.hpp"

#include "rig/usb_bulk_transport.hpp"  // udev_rule_hint

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <sys/stat.h>
#include <sys/sysmacros.h>

namespace trm::rig {
namespace {

bool contains(const std::string& text, const char* what) { return text.find(what) != std::string::npos; }

// hidapi's hidraw backend looks the node up in udev by its device number and does not survive a path that is not a
// hidraw character device (a regular file, /dev/zero): refuse such a path before handing it over.
void require_hidraw_node(const std::string& path) {
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT)
      throw RigError(RigErrorKind::NoDevice, "no HID device at " + path + " (it does not exist); 'trm feed --list' shows what is connected");
    return;  // unreadable metadata: let hidapi report why it cannot open the node
  }
  const auto refuse = [&](const std::string& what) {
    throw RigError(RigErrorKind::NoDevice, "--hid " + path + " is " + what +
                                               ", not a hidraw device node (/dev/hidrawN); 'trm feed --list' shows what is connected");
  };
  if (!S_ISCHR(st.st_mode)) refuse(S_ISDIR(st.st_mode) ? "a directory" : S_ISREG(st.st_mode) ? "a regular file" : "not a character device");
  const std::string sys = "/sys/dev/char/" + std::to_string(major(st.st_rdev)) + ":" + std::to_string(minor(st.st_rdev));
  char subsystem[4096];
  const ssize_t n = ::readlink((sys + "/subsystem").c_str(), subsystem, sizeof subsystem - 1);
  if (n <= 0) refuse("a character device unknown to sysfs");
  const std::string target(subsystem, static_cast<std::size_t>(n));
  if (!target.ends_with("/hidraw")) refuse("a character device of the '" + target.substr(target.rfind('/') + 1) + "' subsystem");
}

struct Enumeration {
  const HidApi* api;
  hid_device_info* list;
  Enumeration(const HidApi& a, unsigned short vendor, unsigned short product) : api(&a), list(a.enumerate(vendor, product)) {}
  ~Enumeration() {
    if (list) api->free_enumeration(list);
  }
};

}  // namespace

HidTransport::HidTransport(HidOptions options) : options_(std::move(options)) {
  options_.format.validate();
  api_ = options_.api ? options_.api : &linked_hidapi();
  if (!options_.id && options_.path.empty()) throw std::invalid_argument("HID device: give a VID:PID or a path");
  if (api_->init() != 0)
    throw RigError(RigErrorKind::Io, "hidapi (" + api_->backend + " backend) could not start: " + narrow(api_->error(nullptr)));
  try {
    open_device();
  } catch (...) {
    // hid_exit even when opening failed: a later hid_init must start from scratch (it would otherwise
    // keep the old device list of the libusb backend).
    api_->exit();
    throw;
  }
}

void HidTransport::open_device() {
  std::string path = options_.path;
  if (path.empty()) {
    const Enumeration devices(*api_, options_.id->vendor, options_.id->product);
    std::string serials;
    for (const hid_device_info* d = devices.list; d; d = d->next) {
      const std::string serial = narrow(d->serial_number);
      if (!options_.serial.empty() && serial != options_.serial) {
        serials += (serials.empty() ? "" : ", ") + (serial.empty() ? std::string("(none)") : serial);
        continue;
      }
      path = d->path;
      break;
    }
    if (path.empty()) {
      std::string message = "no HID device " + options_.id->to_string() + " found";
      if (!options_.serial.empty()) message += " with serial '" + options_.serial + "'";
      if (!serials.empty()) message += " (present with serial " + serials + ")";
      throw RigError(RigErrorKind::NoDevice, message + " by the hidapi " + api_->backend + " backend; 'trm feed --list' shows what is connected");
    }
  }
  opened_path_ = path;
  if (options_.id) opened_id_ = *options_.id;
  if (!options_.path.empty() && api_->backend == "hidraw") require_hidraw_node(path);

  device_ = api_->open_path(path.c_str());
  if (!device_) {
    const std::string reason = narrow(api_->error(nullptr));
    const UsbId hint_id = options_.id.value_or(UsbId{});
    const bool is_node = path.rfind("/dev/", 0) == 0;
    struct stat st{};
    if (is_node && ::stat(path.c_str(), &st) != 0 && errno == ENOENT)
      throw RigError(RigErrorKind::NoDevice, "no HID device at " + path + " (it does not exist); 'trm feed --list' shows what is connected");
    if ((is_node && ::access(path.c_str(), R_OK | W_OK) != 0 && errno == EACCES) || contains(reason, "ACCESS") ||
        contains(reason, "ermission"))
      throw RigError(RigErrorKind::PermissionDenied, "permission denied opening HID device " + path + ": " +
                                                         udev_rule_hint(hint_id, api_->backend == "hidraw" ? "hidraw" : "usb"));
    if (contains(reason, "BUSY") || contains(reason, "busy"))
      throw RigError(RigErrorKind::Busy, "HID device " + path + " is busy (claimed by another program): " + reason);
    throw RigError(RigErrorKind::Io, "cannot open HID device " + path + " with the hidapi " + api_->backend + " backend" +
                                         (reason.empty() ? std::string() : ": " + reason));
  }
}

HidTransport::~HidTransport() {
  if (device_) api_->close(device_);
  api_->exit();
}

std::string HidTransport::name() const {
  return "HID device " + (options_.id ? options_.id->to_string() + " at " : std::string()) + opened_path_;
}

std::string HidTransport::description() const {
  return name() + " (hidapi " + api_->backend + " backend, " + (options_.format.feature ? "feature" : "output") +
         " reports of " + std::to_string(options_.format.report_size) + " bytes, report ID " +
         std::to_string(options_.format.report_id) + ")";
}

TransportRate HidTransport::nominal_rate() const {
  const double size = static_cast<double>(options_.format.report_size);
  if (options_.format.report_size <= kFullSpeedReportSize)
    return {size * 1000.0, "full-speed HID: one " + std::to_string(options_.format.report_size) + "-byte report per 1 ms frame"};
  return {size * 8000.0, "high-speed HID: one " + std::to_string(options_.format.report_size) + "-byte report per 125 us microframe"};
}

bool HidTransport::still_present() const {
  // Enumerate by VID:PID when known (cheap), else everything, and look for the path we opened.
  const Enumeration devices(*api_, opened_id_.vendor, opened_id_.product);
  for (const hid_device_info* d = devices.list; d; d = d->next)
    if (opened_path_ == d->path) return true;
  return false;
}

void HidTransport::fail(const std::string& operation) {
  const std::string reason = narrow(api_->error(device_));
  if (!still_present())
    throw RigError(RigErrorKind::Disconnected, name() + " disappeared (unplugged or reset) during " + operation);
  if (contains(reason, "timed out") || contains(reason, "TIMEOUT"))
    throw RigError(RigErrorKind::Timeout, "the rig stopped taking reports: " + operation + " on " + name() + " timed out");
  // Still there but refusing: an endpoint stall, or (hidapi-libusb, which does not say why) a device
  // that NAKed for longer than the 1 s hidapi allows per report.
  throw RigError(RigErrorKind::Stalled, "the rig refused " + operation + " on " + name() +
                                            (reason.empty() || contains(reason, "not implemented") ? std::string(" (stalled or stopped taking reports)")
                                                                                                   : ": " + reason));
}

void HidTransport::send(std::span<const std::uint8_t> packet) {
  const std::vector<std::uint8_t> buffer = hidapi_report_buffer(options_.format, packet);
  const int written = options_.format.feature ? api_->send_feature_report(device_, buffer.data(), buffer.size())
                                              : api_->write(device_, buffer.data(), buffer.size());
  if (written < 0) fail(options_.format.feature ? "a feature report" : "an output report");
  if (static_cast<std::size_t>(written) < buffer.size())
    throw RigError(RigErrorKind::Io, name() + " took " + std::to_string(written) + " of " + std::to_string(buffer.size()) +
                                         " bytes of a report");
}

std::optional<std::vector<std::uint8_t>> HidTransport::receive(std::chrono::milliseconds timeout) {
  std::vector<std::uint8_t> buffer(options_.format.report_size + 1);
  const int wait_ms = static_cast<int>(std::clamp<std::int64_t>(timeout.count(), 0, 1 << 30));
  const int got = api_->read_timeout(device_, buffer.data(), buffer.size(), wait_ms);
  if (got < 0) fail("reading an input report");
  if (got == 0) return std::nullopt;
  buffer.resize(static_cast<std::size_t>(got));
  // Numbered reports arrive with their ID first; unnumbered ones without.
  if (options_.format.report_id != 0 && !buffer.empty()) buffer.erase(buffer.begin());
  return buffer;
}

}  // namespace trm::rig
