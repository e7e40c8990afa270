#include "rig/hid_api.hpp"

#include <dlfcn.h>

#include <cwchar>
#include <mutex>
#include <stdexcept>

namespace trm::rig {
namespace {

std::string backend_of_linked_library() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&hid_open_path), &info) && info.dli_fname) {
    const std::string file = info.dli_fname;
    if (file.find("hidraw") != std::string::npos) return "hidraw";
    if (file.find("libusb") != std::string::npos) return "libusb";
  }
  return "unknown";
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kCanIsolateLibraries = false;  // the ASan runtime rejects RTLD_DEEPBIND
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kCanIsolateLibraries = false;
#else
constexpr bool kCanIsolateLibraries = true;
#endif
#else
constexpr bool kCanIsolateLibraries = true;
#endif

template <typename Fn>
void resolve(void* library, const char* name, Fn& slot) {
  void* symbol = dlsym(library, name);
  if (!symbol) throw std::runtime_error(std::string("hidapi backend library lacks ") + name);
  slot = reinterpret_cast<Fn>(symbol);
}

}  // namespace

const HidApi& linked_hidapi() {
  static const HidApi api{backend_of_linked_library(), &hid_init, &hid_exit, &hid_enumerate, &hid_free_enumeration,
                          &hid_open_path, &hid_write, &hid_send_feature_report, &hid_read_timeout, &hid_error, &hid_close};
  return api;
}

const HidApi& hidapi_backend(const std::string& name) {
  if (name != "hidraw" && name != "libusb")
    throw std::invalid_argument("unknown hidapi backend '" + name + "' (expected hidraw or libusb)");
  if (linked_hidapi().backend == name) return linked_hidapi();

  static std::mutex mutex;
  static HidApi loaded{};
  static void* library = nullptr;
  std::lock_guard lock(mutex);
  if (library) return loaded;
  if (!kCanIsolateLibraries)
    throw std::runtime_error("the hidapi " + name + " backend cannot be loaded next to the linked " + linked_hidapi().backend +
                             " backend in a sanitizer build; use --hid-backend " + linked_hidapi().backend);
  const std::string file = "libhidapi-" + name + ".so.0";
  // RTLD_DEEPBIND: the library's calls to its own hid_* functions must not bind to the linked backend.
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
  if (!handle)
    throw std::runtime_error("cannot load " + file + " for --hid-backend " + name + ": " + dlerror() +
                             " (Debian package libhidapi-" + name + "0)");
  HidApi api{};
  api.backend = name;
  try {
    resolve(handle, "hid_init", api.init);
    resolve(handle, "hid_exit", api.exit);
    resolve(handle, "hid_enumerate", api.enumerate);
    resolve(handle, "hid_free_enumeration", api.free_enumeration);
    resolve(handle, "hid_open_path", api.open_path);
    resolve(handle, "hid_write", api.write);
    resolve(handle, "hid_send_feature_report", api.send_feature_report);
    resolve(handle, "hid_read_timeout", api.read_timeout);
    resolve(handle, "hid_error", api.error);
    resolve(handle, "hid_close", api.close);
  } catch (...) {
    dlclose(handle);
    throw;
  }
  // Kept loaded for the life of the process: hidapi-libusb may leave threads behind until hid_exit.
  library = handle;
  loaded = api;
  return loaded;
}

std::string narrow(const wchar_t* text) {
  std::string out;
  if (!text) return out;
  for (; *text; ++text) {
    const auto c = static_cast<std::uint32_t>(*text);
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else if (c < 0x800) {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
      out += static_cast<char>(0xE0 | (c >> 12));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (c >> 18));
      out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

}  // namespace trm::rig
