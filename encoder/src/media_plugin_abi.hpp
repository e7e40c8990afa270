// The table of entry points the media plugin (encoder/plugin/media_plugin.cpp) exports to the loader
// (media.cpp). The plugin is ours, built with the same compiler and OpenCV, so C++ types cross: the table's
// version and the OpenCV version it was built against are checked before any entry is called.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace trm::media::plugin {

inline constexpr int kAbiVersion = 1;
// The plugin's one exported symbol: extern "C" const Api* trm_media_plugin_api().
inline constexpr const char* kEntryPoint = "trm_media_plugin_api";

struct Api {
  int abi_version;
  const char* opencv_version;  // CV_VERSION: cv::Mat's layout crosses the boundary
  cv::Mat (*read_image)(const std::string& path, int flags);
  bool (*write_image)(const std::string& path, const cv::Mat& image, const std::vector<int>& params);
  bool (*encode_image)(const std::string& ext, const cv::Mat& image, std::vector<std::uint8_t>& bytes,
                       const std::vector<int>& params);
  bool (*has_video_backend)(int api);
  void* (*video_open)(const std::string& path, int api);  // nullptr when it cannot be opened
  bool (*video_read)(void* video, cv::Mat& frame);
  double (*video_get)(void* video, int property);
  void (*video_close)(void* video);
  void* (*writer_open)(const std::string& path, int fourcc, double fps, cv::Size size);
  void (*writer_write)(void* writer, const cv::Mat& frame);
  void (*writer_close)(void* writer);
};

}  // namespace trm::media::plugin
