// The image and video targets decode through OpenCV, whose pixel limit (OPENCV_IO_MAX_IMAGE_PIXELS,
// 2^30 by default) is read once when the library loads, before any fuzzer hook runs. A decompression
// bomb within that default would be a multi-gigabyte allocation: an out-of-memory report about the
// fuzzer's budget, not about trm. So the target re-executes itself once with a smaller limit set, and
// with OpenCV's own logging silenced (it would print a line for every rejected input).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace trm::fuzz {

inline constexpr const char* kMaxImagePixels = "262144";  // 2^18 pixels: 6 MB as linear CV_64FC3, well under a second

inline void limit_opencv_or_reexec(char** argv) {
  if (std::getenv("OPENCV_IO_MAX_IMAGE_PIXELS") != nullptr) return;
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", kMaxImagePixels, 1);
  setenv("OPENCV_LOG_LEVEL", "SILENT", 0);
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);  // AV_LOG_QUIET
  execv("/proc/self/exe", argv);
  std::perror("re-executing with the OpenCV limits set");
  std::abort();
}

}  // namespace trm::fuzz
