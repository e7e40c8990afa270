// libFuzzer target for image input: the bytes are written to a file and opened as a one-image sequence
// through open_image_sequence (cv::imread with IMREAD_UNCHANGED, every format OpenCV decodes, chosen by
// the file's signature). The source must throw std::runtime_error / std::invalid_argument naming the
// file, or deliver a linear CV_64FC3 frame of its announced size with every value in [0, 1].
#include "fuzz_support.hpp"
#include "opencv_limits.hpp"
#include "trm/scene.hpp"

#include <stdexcept>
#include <string>

using trm::fuzz::check;

extern "C" int LLVMFuzzerInitialize(int*, char*** argv) {
  trm::fuzz::limit_opencv_or_reexec(*argv);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = trm::fuzz::write_scratch_file("input_frame.png", data, size).string();
  try {
    const auto source = trm::open_image_sequence(path);
    check(source->frame_count() == 1, "one file, not one frame");
    check(source->width() >= 1 && source->height() >= 1, "empty frame size");
    const cv::Mat frame = source->linear_frame(0);
    check(frame.type() == CV_64FC3 && frame.cols == source->width() && frame.rows == source->height(),
          "frame type or size differs from the source's");
    for (int y = 0; y < frame.rows; ++y) {
      const double* row = frame.ptr<double>(y);
      for (int i = 0; i < frame.cols * 3; ++i) check(row[i] >= 0.0 && row[i] <= 1.0, "linear value outside [0, 1]");
    }
  } catch (const std::runtime_error& e) {
    check(std::string(e.what()).find(path) != std::string::npos, "message does not name the file");
  } catch (const std::invalid_argument& e) {
    check(std::string(e.what()).find(path) != std::string::npos, "message does not name the file");
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_image");
  }
  trm::fuzz::close_leaked_descriptors(path);
  return 0;
}
