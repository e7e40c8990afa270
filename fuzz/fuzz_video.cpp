// libFuzzer target for video input: the bytes are written to a file and opened with open_video
// (cv::VideoCapture, FFmpeg when built in). The source must throw std::runtime_error naming the file, or
// deliver linear CV_64FC3 frames of its announced size with every value in [0, 1]; the first few frames
// are read in order, then frame 0 again (the restart path taken when a caller goes back).
#include "fuzz_support.hpp"
#include "opencv_limits.hpp"
#include "trm/scene.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

using trm::fuzz::check;

namespace {

void check_frame(const cv::Mat& frame, const trm::FrameSource& source) {
  check(frame.type() == CV_64FC3 && frame.cols == source.width() && frame.rows == source.height(),
        "frame type or size differs from the source's");
  for (int y = 0; y < frame.rows; ++y) {
    const double* row = frame.ptr<double>(y);
    for (int i = 0; i < frame.cols * 3; ++i) check(row[i] >= 0.0 && row[i] <= 1.0, "linear value outside [0, 1]");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char*** argv) {
  trm::fuzz::limit_opencv_or_reexec(*argv);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = trm::fuzz::write_scratch_file("input_video.avi", data, size).string();
  try {
    const auto source = trm::open_video(path);
    check(source->width() >= 1 && source->height() >= 1, "empty frame size");
    check(!source->frame_count() || *source->frame_count() >= 1, "a frame count below 1");
    const std::int64_t frames = std::min<std::int64_t>(source->frame_count().value_or(3), 3);
    for (std::int64_t t = 0; t < frames; ++t) check_frame(source->linear_frame(t), *source);
    check_frame(source->linear_frame(0), *source);
  } catch (const std::runtime_error& e) {
    check(std::string(e.what()).find(path) != std::string::npos, "message does not name the file");
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_video");
  }
  trm::fuzz::close_leaked_descriptors(path);
  return 0;
}
