// Mean Temporal Color Difference (Kim et al. Eq. 6).
#include "trm/mtcd.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "perception_checks.hpp"

namespace trm {

namespace {

using perception_detail::reject;

void require_frames(const std::vector<cv::Mat>& frames) {
  if (frames.size() < 2) {
    reject("mtcd", "frames", "must hold at least 2 frames (Eq. 6 divides by t - 1), got " +
                                 std::to_string(frames.size()));
  }
  const cv::Mat& first = frames.front();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const cv::Mat& frame = frames[k];
    const std::string which = "frame " + std::to_string(k);
    if (frame.empty()) reject("mtcd", "frames", which + " is empty");
    if (frame.channels() != 1 && frame.channels() != 3) {
      reject("mtcd", "frames", which + " has " + std::to_string(frame.channels()) + " channels, needs 3 (rgb) or 1");
    }
    if (frame.size() != first.size() || frame.type() != first.type()) {
      reject("mtcd", "frames", which + " differs in size or type from frame 0");
    }
    if (!cv::checkRange(frame, true)) reject("mtcd", "frames", which + " has a non-finite value");
  }
}

}  // namespace

double mtcd(const std::vector<cv::Mat>& frames) {
  require_frames(frames);
  const int rows = frames.front().rows;
  const int cols = frames.front().cols;
  const int channels = frames.front().channels();
  double total = 0.0;
  cv::Mat previous;
  frames.front().convertTo(previous, CV_64F);
  cv::Mat current;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    frames[k].convertTo(current, CV_64F);
    for (int j = 0; j < rows; ++j) {
      const double* before = previous.ptr<double>(j);
      const double* now = current.ptr<double>(j);
      for (int i = 0; i < cols; ++i) {
        double squared = 0.0;
        for (int c = 0; c < channels; ++c) {
          const double step = before[i * channels + c] - now[i * channels + c];
          squared += step * step;
        }
        total += std::sqrt(squared);  // d_ijk
      }
    }
    std::swap(previous, current);
  }
  return total / (static_cast<double>(rows) * cols * static_cast<double>(frames.size() - 1));
}

}  // namespace trm
