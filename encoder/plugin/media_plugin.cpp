// trm's media plugin (libtrm_media.so): the only code that calls OpenCV's imgcodecs and videoio, so that only a
// process that reads or writes an image or a video loads them (trm/media.hpp says why).
#include "media_plugin_abi.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <memory>

namespace {

using trm::media::plugin::Api;

cv::Mat read_image(const std::string& path, int flags) { return cv::imread(path, flags); }

bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return cv::imwrite(path, image, params);
}

bool encode_image(const std::string& ext, const cv::Mat& image, std::vector<std::uint8_t>& bytes,
                  const std::vector<int>& params) {
  return cv::imencode(ext, image, bytes, params);
}

bool has_video_backend(int api) { return cv::videoio_registry::hasBackend(static_cast<cv::VideoCaptureAPIs>(api)); }

void* video_open(const std::string& path, int api) {
  auto capture = std::make_unique<cv::VideoCapture>();
  if (!capture->open(path, api)) return nullptr;
  return capture.release();
}

bool video_read(void* video, cv::Mat& frame) { return static_cast<cv::VideoCapture*>(video)->read(frame); }
double video_get(void* video, int property) { return static_cast<cv::VideoCapture*>(video)->get(property); }
void video_close(void* video) { delete static_cast<cv::VideoCapture*>(video); }

void* writer_open(const std::string& path, int fourcc, double fps, cv::Size size) {
  auto writer = std::make_unique<cv::VideoWriter>(path, fourcc, fps, size);
  if (!writer->isOpened()) return nullptr;
  return writer.release();
}

void writer_write(void* writer, const cv::Mat& frame) { static_cast<cv::VideoWriter*>(writer)->write(frame); }
void writer_close(void* writer) { delete static_cast<cv::VideoWriter*>(writer); }

constexpr Api kApi = {trm::media::plugin::kAbiVersion,
                      CV_VERSION,
                      read_image,
                      write_image,
                      encode_image,
                      has_video_backend,
                      video_open,
                      video_read,
                      video_get,
                      video_close,
                      writer_open,
                      writer_write,
                      writer_close};

}  // namespace

extern "C" __attribute__((visibility("default"))) const Api* trm_media_plugin_api();
extern "C" const Api* trm_media_plugin_api() { return &kApi; }
