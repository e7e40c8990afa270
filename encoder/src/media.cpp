// The media plugin (trm/media.hpp) loaded once, on first use, and every call forwarded to it.
#include "trm/media.hpp"

#include "media_plugin_abi.hpp"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

// Defined when the plugin's source is linked into the program itself (the fuzz targets); null otherwise.
extern "C" const trm::media::plugin::Api* trm_media_plugin_api() __attribute__((weak));

namespace trm::media {
namespace {

using plugin::Api;

constexpr const char* kPluginFile = "libtrm_media.so";
constexpr const char* kPluginVariable = "TRM_MEDIA_PLUGIN";

std::string last_dl_error() {
  const char* e = dlerror();
  return e ? e : "unknown dynamic loader error";
}

// A table from another build (an older install found first, say) is refused: its cv::Mat may not be ours.
bool compatible(const Api* api, const std::string& where, std::string& tried) {
  if (api && api->abi_version == plugin::kAbiVersion && std::strcmp(api->opencv_version, CV_VERSION) == 0) return true;
  tried += "; " + where + ": a plugin of another build (" +
           (api ? "entry table version " + std::to_string(api->abi_version) + ", OpenCV " + api->opencv_version
                : std::string("no entry table")) +
           "; this program: version " + std::to_string(plugin::kAbiVersion) + ", OpenCV " CV_VERSION ")";
  return false;
}

const Api* open_plugin(const std::string& file, std::string& tried) {
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    tried += "; " + last_dl_error();
    return nullptr;
  }
  const auto entry = reinterpret_cast<const Api* (*)()>(dlsym(handle, plugin::kEntryPoint));
  if (!entry) {
    tried += "; " + file + ": no symbol " + plugin::kEntryPoint;
    dlclose(handle);
    return nullptr;
  }
  const Api* api = entry();
  if (!compatible(api, file, tried)) {
    dlclose(handle);
    return nullptr;
  }
  return api;  // the handle stays open for the life of the process
}

// The directories the dynamic loader searches for a library needed by the object this code is linked into (the
// program, or a shared object such as the Python module): LD_LIBRARY_PATH, that object's run path, the system's.
// Read with dlinfo rather than left to dlopen, whose search uses the run path of the object that calls it, which is
// not this one where a sanitizer's interceptor stands between.
std::vector<std::string> search_directories() {
  Dl_info self_info{};
  void* self = nullptr;
  if (dladdr(reinterpret_cast<void*>(&search_directories), &self_info) != 0 && self_info.dli_fname != nullptr) {
    self = dlopen(self_info.dli_fname, RTLD_LAZY | RTLD_NOLOAD);
  }
  if (self == nullptr) self = dlopen(nullptr, RTLD_LAZY);  // the program itself
  std::vector<std::string> directories;
  if (self == nullptr) return directories;
  Dl_serinfo size{};
  if (dlinfo(self, RTLD_DI_SERINFOSIZE, &size) == 0) {
    std::vector<std::max_align_t> storage(size.dls_size / sizeof(std::max_align_t) + 1);
    auto* info = reinterpret_cast<Dl_serinfo*>(storage.data());
    info->dls_size = size.dls_size;
    info->dls_cnt = size.dls_cnt;
    if (dlinfo(self, RTLD_DI_SERINFOSIZE, info) == 0 && dlinfo(self, RTLD_DI_SERINFO, info) == 0) {
      for (unsigned int i = 0; i < info->dls_cnt; ++i) directories.emplace_back(info->dls_serpath[i].dls_name);
    }
  }
  dlclose(self);  // both opens only counted a reference to an object already loaded
  return directories;
}

const Api* load() {
  std::string tried;
  if (trm_media_plugin_api != nullptr) {
    const Api* api = trm_media_plugin_api();
    if (compatible(api, "the plugin linked into this program", tried)) return api;
  } else if (const char* chosen = std::getenv(kPluginVariable); chosen != nullptr && *chosen != '\0') {
    // A plugin chosen by name is not replaced by another one found elsewhere.
    if (const Api* api = open_plugin(chosen, tried)) return api;
    tried += " (" + std::string(kPluginVariable) + "=" + chosen + ")";
  } else {
    for (const std::string& directory : search_directories()) {
      const std::string candidate = (directory.empty() ? std::string(".") : directory) + "/" + kPluginFile;
      if (::access(candidate.c_str(), F_OK) != 0) continue;
      if (const Api* api = open_plugin(candidate, tried)) return api;
    }
    if (const Api* api = open_plugin(kPluginFile, tried)) return api;  // the loader's cache
  }
  throw std::runtime_error(std::string("cannot load trm's image and video plugin ") + kPluginFile +
                           " (it reads and writes image and video files through OpenCV)" + tried + "; set " +
                           kPluginVariable + " to its path (the build tree's lib/" + kPluginFile +
                           ", an installed prefix's lib/trm/" + kPluginFile + ")");
}

// A failed load throws out of the initialiser, so the next call tries again.
const Api& plugin_api() {
  static const Api* const api = load();
  return *api;
}

}  // namespace

cv::Mat read_image(const std::string& path, int flags) { return plugin_api().read_image(path, flags); }

bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return plugin_api().write_image(path, image, params);
}

bool encode_image(const std::string& ext, const cv::Mat& image, std::vector<std::uint8_t>& bytes,
                  const std::vector<int>& params) {
  return plugin_api().encode_image(ext, image, bytes, params);
}

bool has_video_backend(int api) { return plugin_api().has_video_backend(api); }

VideoReader::VideoReader() = default;
VideoReader::~VideoReader() { release(); }

bool VideoReader::open(const std::string& path, int api) {
  release();
  handle_ = plugin_api().video_open(path, api);
  return handle_ != nullptr;
}

void VideoReader::release() {
  if (handle_ == nullptr) return;
  plugin_api().video_close(handle_);
  handle_ = nullptr;
}

bool VideoReader::read(cv::Mat& frame) { return handle_ != nullptr && plugin_api().video_read(handle_, frame); }

double VideoReader::get(int property) const {
  return handle_ != nullptr ? plugin_api().video_get(handle_, property) : 0.0;
}

VideoWriter::VideoWriter() = default;
VideoWriter::~VideoWriter() { release(); }

bool VideoWriter::open(const std::string& path, int fourcc, double fps, cv::Size size) {
  release();
  handle_ = plugin_api().writer_open(path, fourcc, fps, size);
  return handle_ != nullptr;
}

void VideoWriter::release() {
  if (handle_ == nullptr) return;
  plugin_api().writer_close(handle_);
  handle_ = nullptr;
}

void VideoWriter::write(const cv::Mat& frame) {
  if (handle_ == nullptr) throw std::logic_error("trm::media::VideoWriter::write: no file open");
  plugin_api().writer_write(handle_, frame);
}

}  // namespace trm::media
