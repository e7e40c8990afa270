// Image and video files: OpenCV's imgcodecs and videoio behind trm's media plugin (libtrm_media.so), loaded the
// first time a file is read or written. Those two modules bring about 230 shared libraries (GDAL, GStreamer,
// FFmpeg and theirs), which cost every process that links them about 0.3 s of dynamic loading at start; a run of
// a built-in scene, a decoder in a testbench or a test never pays it.
//
// The plugin is found, in order: linked into the program (as the fuzz targets link it), the file named by
// $TRM_MEDIA_PLUGIN, libtrm_media.so on the program's run path (the build tree's lib/, an installed prefix's
// lib/trm/) or the loader's search path. When none loads, the first call throws std::runtime_error naming what was
// tried.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace trm::media {

// cv::imread(path, flags): an empty matrix when the file cannot be read.
cv::Mat read_image(const std::string& path, int flags);
// cv::imwrite: false when OpenCV cannot write the file.
bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params = {});
// cv::imencode: the file's bytes for extension `ext` (".png").
bool encode_image(const std::string& ext, const cv::Mat& image, std::vector<std::uint8_t>& bytes,
                  const std::vector<int>& params = {});
// cv::videoio_registry::hasBackend.
bool has_video_backend(int api);

// cv::VideoCapture of a file.
class VideoReader {
 public:
  VideoReader();
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;
  bool open(const std::string& path, int api);  // false: unsupported format or codec
  void release();
  bool is_open() const { return handle_ != nullptr; }
  bool read(cv::Mat& frame);          // false at the end or on a decoding error
  double get(int property) const;     // cv::CAP_PROP_*, 0 when unknown
 private:
  void* handle_ = nullptr;
};

// cv::VideoWriter of a file.
class VideoWriter {
 public:
  VideoWriter();
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;
  bool open(const std::string& path, int fourcc, double fps, cv::Size size);  // false: no backend writes it
  void release();
  bool is_open() const { return handle_ != nullptr; }
  void write(const cv::Mat& frame);
 private:
  void* handle_ = nullptr;
};

}  // namespace trm::media
