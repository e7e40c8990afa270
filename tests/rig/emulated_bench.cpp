#include "emulated_bench.hpp"

#include "rig/hid_report.hpp"

#include <umockdev.h>

#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>
#include <linux/hidraw.h>
#include <linux/usbdevice_fs.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

namespace trm::rig::testing {
namespace {

constexpr std::uint8_t kBulk = 2, kInterrupt = 3;  // bmAttributes transfer types

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string text;
  for (std::uint8_t b : bytes) {
    text += digits[b >> 4];
    text += digits[b & 15];
  }
  return text;
}

void append_u16(std::vector<std::uint8_t>& v, unsigned value) {
  v.push_back(static_cast<std::uint8_t>(value));
  v.push_back(static_cast<std::uint8_t>(value >> 8));
}

std::vector<std::uint8_t> device_descriptor(UsbId id, std::uint8_t device_class) {
  std::vector<std::uint8_t> d = {18, 1, 0x00, 0x02, device_class, 0, 0, 64};
  append_u16(d, id.vendor);
  append_u16(d, id.product);
  append_u16(d, 0x0100);
  d.insert(d.end(), {1, 2, 3, 1});  // iManufacturer, iProduct, iSerialNumber, one configuration
  return d;
}

std::vector<std::uint8_t> configuration(const std::vector<std::uint8_t>& interface_and_endpoints) {
  std::vector<std::uint8_t> c = {9, 2};
  append_u16(c, static_cast<unsigned>(9 + interface_and_endpoints.size()));
  c.insert(c.end(), {1, 1, 0, 0x80, 50});
  c.insert(c.end(), interface_and_endpoints.begin(), interface_and_endpoints.end());
  return c;
}

void append_endpoint(std::vector<std::uint8_t>& v, std::uint8_t address, std::uint8_t type, unsigned max_packet) {
  v.insert(v.end(), {7, 5, address, type});
  append_u16(v, max_packet);
  v.push_back(type == kInterrupt ? 1 : 0);
}

std::vector<std::uint8_t> vendor_report_descriptor(std::size_t report_size, std::uint8_t report_id) {
  std::vector<std::uint8_t> r = {0x06, 0x00, 0xFF, 0x09, 0x01, 0xA1, 0x01};
  if (report_id) r.insert(r.end(), {0x85, report_id});
  r.insert(r.end(), {0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08});
  for (std::uint8_t main_item : {std::uint8_t{0x91}, std::uint8_t{0x81}, std::uint8_t{0xB1}}) {  // output, input, feature
    r.push_back(0x96);
    append_u16(r, static_cast<unsigned>(report_size));
    r.insert(r.end(), {0x09, 0x01, main_item, 0x02});
  }
  r.push_back(0xC0);
  return r;
}

std::vector<std::uint8_t> string_descriptor(const std::string& text) {
  std::vector<std::uint8_t> s = {static_cast<std::uint8_t>(2 + 2 * text.size()), 3};
  for (char c : text) append_u16(s, static_cast<unsigned char>(c));
  return s;
}

}  // namespace

struct EmulatedBench::Device : std::enable_shared_from_this<EmulatedBench::Device> {
  UMockdevTestbed* testbed = nullptr;
  bool is_hid = false;
  HidRigConfig hid;
  RigBehaviour behaviour;
  std::vector<std::string> sys_paths;  // deepest first, for unplugging
  std::vector<std::string> strings;    // string descriptors 1..3
  std::vector<std::uint8_t> report_descriptor;
  std::uint8_t out_endpoint = 0, in_endpoint = 0;
  UMockdevIoctlBase* usb_handler = nullptr;
  UMockdevIoctlBase* hidraw_handler = nullptr;

  mutable std::mutex mutex;
  std::vector<std::uint8_t> bulk_bytes;
  std::vector<std::vector<std::uint8_t>> reports;
  std::vector<std::string> report_kinds;
  std::size_t accepted_bytes = 0;
  bool gone = false;
  std::vector<std::uint8_t> partial_packet;  // bulk stream not yet a whole packet
  std::map<std::int64_t, int> ends_seen;
  std::deque<std::vector<std::uint8_t>> answers;
  int answers_sent = 0;
  int protocol_errors = 0;
  // URBs belong to the connection (one per open file descriptor) that submitted them: a second handle
  // on the same device (hidapi enumerating while a device is open) must never reap the first's.
  struct Urb {
    UMockdevIoctlData* data;
    UMockdevIoctlClient* owner;
  };
  std::deque<Urb> completed_urbs;
  std::vector<Urb> pending_in_urbs;
  std::vector<Urb> hanging_urbs;
  int hidraw_master_fd = -1;

  ~Device() {
    for (auto* list : {&pending_in_urbs, &hanging_urbs})
      for (auto& urb : *list) g_object_unref(urb.data);
    for (auto& urb : completed_urbs) g_object_unref(urb.data);
    if (usb_handler) g_object_unref(usb_handler);
    if (hidraw_handler) g_object_unref(hidraw_handler);
  }

  // --- the rig model ---------------------------------------------------------------------------
  bool fault_due() const { return behaviour.fault != Fault::None && accepted_bytes >= behaviour.fault_after_bytes; }

  void unplug() {
    gone = true;
    for (const auto& path : sys_paths) {
      umockdev_testbed_uevent(testbed, path.c_str(), "remove");
      umockdev_testbed_remove_device(testbed, path.c_str());
    }
  }

  void on_packet(std::span<const std::uint8_t> packet) {
    if (packet.empty() || packet[0] != static_cast<std::uint8_t>(PacketType::FrameEnd) || !behaviour.answer) return;
    FrameEnd end;
    try {
      end = decode_frame_end(packet);
    } catch (const std::exception&) {
      ++protocol_errors;
      return;
    }
    const std::optional<Answer> answer = behaviour.answer(end, ++ends_seen[end.frame_index]);
    if (!answer) return;
    std::vector<std::uint8_t> bytes = encode_answer(*answer);
    if (is_hid) bytes = hid_wire_report(HidReportFormat{hid.report_size, hid.report_id, false}, bytes);
    answers.push_back(std::move(bytes));
    deliver_answers();
  }

  void on_bulk_data(const std::uint8_t* data, std::size_t size) {
    bulk_bytes.insert(bulk_bytes.end(), data, data + size);
    partial_packet.insert(partial_packet.end(), data, data + size);
    for (;;) {
      std::size_t n = 0;
      try {
        n = packet_size_in_stream(partial_packet);
      } catch (const std::exception&) {  // not protocol data: record it, parse nothing more
        ++protocol_errors;
        partial_packet.clear();
        return;
      }
      if (n == 0 || n > partial_packet.size()) break;
      on_packet(std::span(partial_packet).first(n));
      partial_packet.erase(partial_packet.begin(), partial_packet.begin() + static_cast<std::ptrdiff_t>(n));
    }
  }

  // `wire` is the report as the USB wire carries it (ID first only when numbered).
  void on_report(std::vector<std::uint8_t> wire, const char* kind) {
    std::span<const std::uint8_t> packet(wire);
    if (hid.report_id) packet = packet.subspan(1);
    reports.push_back(wire);
    report_kinds.emplace_back(kind);
    on_packet(packet);
  }

  void deliver_answers() {
    while (!answers.empty() && !pending_in_urbs.empty()) {
      const Urb pending = pending_in_urbs.front();
      UMockdevIoctlData* urb_data = pending.data;
      pending_in_urbs.erase(pending_in_urbs.begin());
      auto* urb = static_cast<usbdevfs_urb*>(static_cast<void*>(urb_data->data));
      const std::size_t n = std::min<std::size_t>(answers.front().size(), static_cast<std::size_t>(urb->buffer_length));
      std::memcpy(urb->buffer, answers.front().data(), n);
      urb->actual_length = static_cast<int>(n);
      urb->status = 0;
      answers.pop_front();
      ++answers_sent;
      completed_urbs.push_back(pending);
    }
    // hidraw reads are left to the pseudo-terminal behind the node (no handle-read handler), so that
    // hidapi's poll() blocks until a report is there: input reports go to its master end.
    while (!answers.empty() && hidraw_master_fd >= 0) {
      const auto& a = answers.front();
      if (::write(hidraw_master_fd, a.data(), a.size()) != static_cast<ssize_t>(a.size())) break;
      answers.pop_front();
      ++answers_sent;
    }
  }

  // --- usbdevfs -------------------------------------------------------------------------------
  bool handle_usb(UMockdevIoctlClient* client) {
    std::lock_guard lock(mutex);
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    if (gone && request != USBDEVFS_REAPURBNDELAY && request != USBDEVFS_REAPURB && request != USBDEVFS_DISCARDURB) {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return true;
    }
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), nullptr);
        *reinterpret_cast<guint32*>(d->data) = USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                               USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
        g_object_unref(d);
        umockdev_ioctl_client_complete(client, 0, 0);
        return true;
      }
      case USBDEVFS_CLAIMINTERFACE:
        umockdev_ioctl_client_complete(client, behaviour.claim_busy ? -1 : 0, behaviour.claim_busy ? EBUSY : 0);
        return true;
      case USBDEVFS_RELEASEINTERFACE:
      case USBDEVFS_SETINTERFACE:
      case USBDEVFS_CLEAR_HALT:
      case USBDEVFS_RESET:
      case USBDEVFS_RESETEP:
        umockdev_ioctl_client_complete(client, 0, 0);
        return true;
      case USBDEVFS_IOCTL:  // DISCONNECT / CONNECT of the kernel driver
        behaviour.kernel_driver.clear();
        umockdev_ioctl_client_complete(client, 0, 0);
        return true;
      case USBDEVFS_GETDRIVER: {
        if (behaviour.kernel_driver.empty()) {
          umockdev_ioctl_client_complete(client, -1, ENODATA);
          return true;
        }
        UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_getdriver), nullptr);
        auto* g = reinterpret_cast<usbdevfs_getdriver*>(d->data);
        std::snprintf(g->driver, sizeof g->driver, "%s", behaviour.kernel_driver.c_str());
        g_object_unref(d);
        umockdev_ioctl_client_complete(client, 0, 0);
        return true;
      }
      case USBDEVFS_SUBMITURB: return submit_urb(client, arg);
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY: return reap_urb(client, arg);
      case USBDEVFS_DISCARDURB: {
        void* address = *reinterpret_cast<void**>(arg->data);
        for (auto* list : {&pending_in_urbs, &hanging_urbs}) {
          for (auto it = list->begin(); it != list->end(); ++it) {
            if (it->owner != client || reinterpret_cast<void*>(it->data->client_addr) != address) continue;
            auto* urb = reinterpret_cast<usbdevfs_urb*>(it->data->data);
            urb->status = -ENOENT;
            urb->actual_length = 0;
            completed_urbs.push_back(*it);
            list->erase(it);
            umockdev_ioctl_client_complete(client, 0, 0);
            return true;
          }
        }
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return true;
      }
      default:
        umockdev_ioctl_client_complete(client, -1, ENOTTY);
        return true;
    }
  }

  bool submit_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
    UMockdevIoctlData* urb_data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
    auto* urb = reinterpret_cast<usbdevfs_urb*>(urb_data->data);
    UMockdevIoctlData* buffer = urb->buffer_length > 0
        ? umockdev_ioctl_data_resolve(urb_data, G_STRUCT_OFFSET(usbdevfs_urb, buffer), static_cast<gsize>(urb->buffer_length), nullptr)
        : nullptr;
    if (buffer) g_object_unref(buffer);  // owned by urb_data from here on
    auto* bytes = static_cast<std::uint8_t*>(urb->buffer);
    const bool is_in = (urb->endpoint & 0x80) != 0;
    urb->status = 0;
    urb->actual_length = 0;

    if (urb->type == USBDEVFS_URB_TYPE_CONTROL) {
      handle_control(urb, bytes);
      completed_urbs.push_back({urb_data, client});
    } else if (is_in) {
      pending_in_urbs.push_back({urb_data, client});
      deliver_answers();
    } else if (fault_due() && behaviour.fault == Fault::Vanish) {
      unplug();
      g_object_unref(urb_data);
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return true;
    } else if (fault_due() && behaviour.fault == Fault::Stall) {
      urb->status = -EPIPE;
      completed_urbs.push_back({urb_data, client});
    } else if (fault_due() && behaviour.fault == Fault::Hang) {
      hanging_urbs.push_back({urb_data, client});
    } else {
      urb->actual_length = urb->buffer_length;
      accepted_bytes += static_cast<std::size_t>(urb->buffer_length);
      if (is_hid) on_report(std::vector<std::uint8_t>(bytes, bytes + urb->buffer_length), "interrupt");
      else on_bulk_data(bytes, static_cast<std::size_t>(urb->buffer_length));
      completed_urbs.push_back({urb_data, client});
    }
    umockdev_ioctl_client_complete(client, 0, 0);
    return true;
  }

  void handle_control(usbdevfs_urb* urb, std::uint8_t* bytes) {
    const std::uint8_t request_type = bytes[0], request = bytes[1];
    const unsigned value = bytes[2] | (bytes[3] << 8), length = bytes[6] | (bytes[7] << 8);
    std::uint8_t* data = bytes + 8;
    auto reply = [&](const std::vector<std::uint8_t>& payload) {
      const std::size_t n = std::min<std::size_t>(payload.size(), length);
      std::memcpy(data, payload.data(), n);
      urb->actual_length = static_cast<int>(n);
    };
    if ((request_type & 0x80) && request == 6 && (value >> 8) == 3) {  // GET_DESCRIPTOR string
      const unsigned index = value & 0xFF;
      if (index == 0) reply({4, 3, 0x09, 0x04});  // LANGID en-US
      else if (index <= strings.size()) reply(string_descriptor(strings[index - 1]));
      else urb->status = -EPIPE;
    } else if (request_type == 0x81 && request == 6 && (value >> 8) == 0x22) {  // HID report descriptor
      reply(report_descriptor);
    } else if (request_type == 0x21 && request == 0x09) {  // SET_REPORT
      if (fault_due() && behaviour.fault == Fault::Stall) {
        urb->status = -EPIPE;
        return;
      }
      accepted_bytes += length;
      urb->actual_length = static_cast<int>(length);
      on_report(std::vector<std::uint8_t>(data, data + length), (value >> 8) == 3 ? "feature" : "output-control");
    } else if (request_type == 0x21 && request == 0x0A) {  // SET_IDLE
      urb->actual_length = 0;
    } else {
      urb->status = -EPIPE;  // what a device does with a request it does not know
    }
  }

  bool has_completed(UMockdevIoctlClient* client) const {
    for (const auto& urb : completed_urbs)
      if (urb.owner == client) return true;
    return false;
  }

  bool reap_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
    const auto mine = std::find_if(completed_urbs.begin(), completed_urbs.end(), [&](const Urb& u) { return u.owner == client; });
    if (mine != completed_urbs.end()) {
      UMockdevIoctlData* urb_data = mine->data;
      completed_urbs.erase(mine);
      UMockdevIoctlData* pointer = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), nullptr);
      umockdev_ioctl_data_set_ptr(pointer, 0, urb_data);
      g_object_unref(pointer);
      g_object_unref(urb_data);
      umockdev_ioctl_client_complete(client, 0, 0);
      return true;
    }
    if (gone) {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return true;
    }
    // Nothing to reap: the emulated node always polls ready, so answer EAGAIN only after ~1 ms to keep
    // libusb's event loop from spinning.
    struct Retry {
      std::shared_ptr<Device> device;
      UMockdevIoctlClient* client;
    };
    auto* retry = new Retry{shared_from_this(), static_cast<UMockdevIoctlClient*>(g_object_ref(client))};
    GSource* source = g_timeout_source_new(1);
    g_source_set_callback(
        source,
        [](gpointer data) -> gboolean {
          auto* r = static_cast<Retry*>(data);
          std::lock_guard lock(r->device->mutex);
          if (r->device->has_completed(r->client)) {
            r->device->reap_urb(r->client, umockdev_ioctl_client_get_arg(r->client));
          } else {
            umockdev_ioctl_client_complete(r->client, -1, EAGAIN);
          }
          return G_SOURCE_REMOVE;
        },
        retry,
        [](gpointer data) {
          auto* r = static_cast<Retry*>(data);
          g_object_unref(r->client);
          delete r;
        });
    g_source_attach(source, g_main_context_get_thread_default());
    g_source_unref(source);
    return true;
  }

  // --- hidraw ---------------------------------------------------------------------------------
  bool handle_hidraw_ioctl(UMockdevIoctlClient* client) {
    std::lock_guard lock(mutex);
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    if (gone) {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return true;
    }
    if (request == HIDIOCGRDESCSIZE) {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(int), nullptr);
      *reinterpret_cast<int*>(d->data) = static_cast<int>(report_descriptor.size());
      g_object_unref(d);
      umockdev_ioctl_client_complete(client, 0, 0);
    } else if (request == HIDIOCGRDESC) {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(hidraw_report_descriptor), nullptr);
      auto* desc = reinterpret_cast<hidraw_report_descriptor*>(d->data);
      desc->size = static_cast<__u32>(report_descriptor.size());
      std::memcpy(desc->value, report_descriptor.data(), report_descriptor.size());
      g_object_unref(d);
      umockdev_ioctl_client_complete(client, 0, 0);
    } else if (request == HIDIOCGRAWINFO) {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(hidraw_devinfo), nullptr);
      auto* info = reinterpret_cast<hidraw_devinfo*>(d->data);
      info->bustype = 3;  // BUS_USB
      info->vendor = static_cast<__s16>(kHidRigId.vendor);
      info->product = static_cast<__s16>(kHidRigId.product);
      g_object_unref(d);
      umockdev_ioctl_client_complete(client, 0, 0);
    } else if (_IOC_TYPE(request) == 'H' && _IOC_NR(request) == 0x06) {  // HIDIOCSFEATURE(len)
      const gsize length = _IOC_SIZE(request);
      if (fault_due() && behaviour.fault != Fault::None) return fail_hidraw(client);
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, length, nullptr);
      std::vector<std::uint8_t> report(d->data, d->data + length);
      g_object_unref(d);
      accepted_bytes += length;
      if (hid.report_id == 0) report.erase(report.begin());  // hidraw always passes the ID byte
      on_report(std::move(report), "feature");
      umockdev_ioctl_client_complete(client, static_cast<glong>(length), 0);
    } else {
      umockdev_ioctl_client_complete(client, -1, ENOTTY);
    }
    return true;
  }

  bool fail_hidraw(UMockdevIoctlClient* client) {
    switch (behaviour.fault) {
      case Fault::Vanish:
        unplug();
        umockdev_ioctl_client_complete(client, -1, ENODEV);
        break;
      case Fault::Stall:
        umockdev_ioctl_client_complete(client, -1, EPIPE);
        break;
      default:  // usbhid gives up on a report the device does not take after its own timeout
        umockdev_ioctl_client_complete(client, -1, ETIMEDOUT);
        break;
    }
    return true;
  }

  bool handle_hidraw_write(UMockdevIoctlClient* client) {
    std::lock_guard lock(mutex);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    if (gone) {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return true;
    }
    if (fault_due()) return fail_hidraw(client);
    std::vector<std::uint8_t> report(arg->data, arg->data + arg->data_len);
    accepted_bytes += report.size();
    if (hid.report_id == 0 && !report.empty()) report.erase(report.begin());
    on_report(std::move(report), "interrupt");
    umockdev_ioctl_client_complete(client, arg->data_len, 0);
    return true;
  }
};

namespace {

gboolean on_usb_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer device) {
  return static_cast<EmulatedBench::Device*>(device)->handle_usb(client);
}
gboolean on_hidraw_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer device) {
  return static_cast<EmulatedBench::Device*>(device)->handle_hidraw_ioctl(client);
}
gboolean on_hidraw_write(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer device) {
  return static_cast<EmulatedBench::Device*>(device)->handle_hidraw_write(client);
}

void add_from_string(UMockdevTestbed* testbed, const std::string& description) {
  GError* error = nullptr;
  if (!umockdev_testbed_add_from_string(testbed, description.c_str(), &error)) {
    const std::string message = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    throw std::runtime_error("umockdev rejected a device description: " + message);
  }
}

void attach(UMockdevTestbed* testbed, const char* node, UMockdevIoctlBase* handler) {
  GError* error = nullptr;
  if (!umockdev_testbed_attach_ioctl(testbed, node, handler, &error)) {
    const std::string message = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    throw std::runtime_error(std::string("cannot attach an ioctl handler to ") + node + ": " + message);
  }
}

std::string usb_device_record(const std::string& sys_path, int devnum, int speed, const std::vector<std::string>& strings,
                              const std::vector<std::uint8_t>& descriptors) {
  char node[32];
  std::snprintf(node, sizeof node, "bus/usb/001/%03d", devnum);
  return "P: " + sys_path + "\nN: " + node + "\nE: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DEVNAME=/dev/" + node +
         "\nE: BUSNUM=001\nE: DEVNUM=" + std::string(node + 12) + "\nA: busnum=1\\n\nA: devnum=" + std::to_string(devnum) +
         "\\n\nA: speed=" + std::to_string(speed) + "\\n\nA: bConfigurationValue=1\\n\nA: manufacturer=" + strings[0] +
         "\\n\nA: product=" + strings[1] + "\\n\nA: serial=" + strings[2] + "\\n\nH: descriptors=" + hex(descriptors) + "\n";
}

}  // namespace

EmulatedBench::EmulatedBench() : testbed_(umockdev_testbed_new()) {
  if (!umockdev_in_mock_environment())
    throw std::runtime_error("not running under libumockdev-preload.so.0 (start the test binary directly or via ctest)");
}

EmulatedBench::~EmulatedBench() {
  // Transports (libusb_exit / hid_exit) are gone by now; the testbed goes before the handlers.
  g_object_unref(testbed_);
  devices_.clear();
}

void EmulatedBench::add_bulk_rig(RigBehaviour behaviour) {
  auto device = std::make_shared<Device>();
  device->testbed = testbed_;
  device->behaviour = std::move(behaviour);
  device->strings = {"trm bench", "Bulk rig", kBulkRigSerial};
  device->out_endpoint = 0x01;
  device->in_endpoint = 0x81;
  std::vector<std::uint8_t> body = {9, 4, 0, 0, 2, 0xFF, 0, 0, 0};
  append_endpoint(body, 0x01, kBulk, 512);
  append_endpoint(body, 0x81, kBulk, 512);
  std::vector<std::uint8_t> descriptors = device_descriptor(kBulkRigId, 0);
  const std::vector<std::uint8_t> config = configuration(body);
  descriptors.insert(descriptors.end(), config.begin(), config.end());
  const std::string sys_path = "/devices/pci0000:00/0000:00:14.0/usb1/1-1";
  device->sys_paths = {"/sys" + sys_path};

  device->usb_handler = umockdev_ioctl_base_new();
  g_signal_connect(device->usb_handler, "handle-ioctl", G_CALLBACK(on_usb_ioctl), device.get());
  attach(testbed_, "/dev/bus/usb/001/002", device->usb_handler);
  add_from_string(testbed_, usb_device_record(sys_path, 2, 480, device->strings, descriptors));
  devices_.push_back(std::move(device));
}

void EmulatedBench::add_hid_rig(HidRigConfig config) {
  auto device = std::make_shared<Device>();
  device->testbed = testbed_;
  device->is_hid = true;
  device->hid = config;
  device->behaviour = std::move(config.behaviour);
  device->strings = {"trm bench", "HID rig", kHidRigSerial};
  device->out_endpoint = 0x02;
  device->in_endpoint = 0x82;
  device->report_descriptor = vendor_report_descriptor(config.report_size, config.report_id);
  const bool full_speed = config.report_size <= 64;
  const unsigned max_packet = full_speed ? 64 : 1024;
  std::vector<std::uint8_t> body = {9, 4, 0, 0, 2, 3, 0, 0, 0, 9, 0x21, 0x11, 0x01, 0, 1, 0x22};
  append_u16(body, static_cast<unsigned>(device->report_descriptor.size()));
  append_endpoint(body, 0x82, kInterrupt, max_packet);
  append_endpoint(body, 0x02, kInterrupt, max_packet);
  std::vector<std::uint8_t> descriptors = device_descriptor(kHidRigId, 0);
  const std::vector<std::uint8_t> cfg = configuration(body);
  descriptors.insert(descriptors.end(), cfg.begin(), cfg.end());

  const std::string usb_path = "/devices/pci0000:00/0000:00:14.0/usb1/1-2";
  const std::string interface_path = usb_path + "/1-2:1.0";
  const std::string hid_path = interface_path + "/0003:1234:5679.0001";
  const std::string hidraw_path = hid_path + "/hidraw/hidraw0";

  device->usb_handler = umockdev_ioctl_base_new();
  g_signal_connect(device->usb_handler, "handle-ioctl", G_CALLBACK(on_usb_ioctl), device.get());
  attach(testbed_, "/dev/bus/usb/001/003", device->usb_handler);
  std::string records = usb_device_record(usb_path, 3, full_speed ? 12 : 480, device->strings, descriptors) + "\n";
  records += "P: " + interface_path + "\nE: SUBSYSTEM=usb\nE: DEVTYPE=usb_interface\nA: bInterfaceNumber=00\\n\nA: bInterfaceClass=03\\n\n\n";
  records += "P: " + hid_path + "\nE: SUBSYSTEM=hid\nE: HID_ID=0003:00001234:00005679\nE: HID_NAME=trm bench HID rig\nE: HID_UNIQ=" +
             std::string(kHidRigSerial) + "\nH: report_descriptor=" + hex(device->report_descriptor) + "\n";
  if (config.with_hidraw_node) {
    records += "\nP: " + hidraw_path + "\nN: hidraw0\nE: SUBSYSTEM=hidraw\nE: DEVNAME=/dev/hidraw0\nA: dev=240:0\\n\nL: device=../../../0003:1234:5679.0001\n";
    device->hidraw_handler = umockdev_ioctl_base_new();
    g_signal_connect(device->hidraw_handler, "handle-ioctl", G_CALLBACK(on_hidraw_ioctl), device.get());
    g_signal_connect(device->hidraw_handler, "handle-write", G_CALLBACK(on_hidraw_write), device.get());
    attach(testbed_, kHidrawNode, device->hidraw_handler);
    device->sys_paths.push_back("/sys" + hidraw_path);
  }
  device->sys_paths.push_back("/sys" + hid_path);
  device->sys_paths.push_back("/sys" + interface_path);
  device->sys_paths.push_back("/sys" + usb_path);
  add_from_string(testbed_, records);
  if (config.with_hidraw_node) {
    device->hidraw_master_fd = umockdev_testbed_get_dev_fd(testbed_, kHidrawNode);
    termios raw{};
    if (device->hidraw_master_fd >= 0 && ::tcgetattr(device->hidraw_master_fd, &raw) == 0) {
      ::cfmakeraw(&raw);  // reports are binary: no line discipline on the way to the reader
      ::tcsetattr(device->hidraw_master_fd, TCSANOW, &raw);
    }
  }
  devices_.push_back(std::move(device));
}

std::vector<std::uint8_t> EmulatedBench::bulk_received() const {
  for (const auto& d : devices_)
    if (!d->is_hid) {
      std::lock_guard lock(d->mutex);
      return d->bulk_bytes;
    }
  return {};
}

std::vector<std::vector<std::uint8_t>> EmulatedBench::hid_reports_received() const {
  for (const auto& d : devices_)
    if (d->is_hid) {
      std::lock_guard lock(d->mutex);
      return d->reports;
    }
  return {};
}

std::vector<std::string> EmulatedBench::hid_report_kinds() const {
  for (const auto& d : devices_)
    if (d->is_hid) {
      std::lock_guard lock(d->mutex);
      return d->report_kinds;
    }
  return {};
}

int EmulatedBench::answers_sent() const {
  int total = 0;
  for (const auto& d : devices_) {
    std::lock_guard lock(d->mutex);
    total += d->answers_sent;
  }
  return total;
}

}  // namespace trm::rig::testing
