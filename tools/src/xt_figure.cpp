#include "xt_figure.hpp"

#include "trm/visual_difference.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace trm::cli {

namespace {

constexpr int kScale = 2;          // each sample drawn as kScale × kScale pixels
constexpr int kHeader = 28;        // rows for a panel's caption
constexpr int kGap = 12;           // columns between panels
constexpr int kPerceptRows = 96;   // the percept strip's height, in samples

// Luminance (>= 0) as 8-bit grey: the panel's peak white at 255, sRGB-encoded as a monitor would show it.
cv::Mat grey(const cv::Mat& luminance, double peak) {
  cv::Mat out(luminance.size(), CV_8UC3);
  for (int y = 0; y < luminance.rows; ++y) {
    const double* in = luminance.ptr<double>(y);
    auto* px = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < luminance.cols; ++x) {
      const double v = std::clamp(in[x] / peak, 0.0, 1.0);
      const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      const auto g = static_cast<unsigned char>(std::lround(255.0 * encoded));
      px[x] = cv::Vec3b(g, g, g);
    }
  }
  return out;
}

// Moves the zero frequency of an OpenCV DFT layout to the centre: the first half of each axis (rounded down)
// after the rest, done as four block copies.
cv::Mat centred(const cv::Mat& in) {
  cv::Mat out(in.size(), in.type());
  const int cy = in.rows / 2, cx = in.cols / 2;        // the leading part of each axis
  const int ry = in.rows - cy, rx = in.cols - cx;      // the rest
  const auto move = [&](int x, int y, int w, int h, int to_x, int to_y) {
    if (w > 0 && h > 0) in(cv::Rect(x, y, w, h)).copyTo(out(cv::Rect(to_x, to_y, w, h)));
  };
  move(0, 0, cx, cy, rx, ry);
  move(cx, 0, rx, cy, 0, ry);
  move(0, cy, cx, ry, rx, 0);
  move(cx, cy, rx, ry, 0, 0);
  return out;
}

cv::Mat fourier_view(const cv::Mat& physical, const XtFigureInput& input, double samples_per_second) {
  cv::Mat spectrum;
  cv::dft(physical - cv::mean(physical)[0], spectrum, cv::DFT_COMPLEX_OUTPUT);
  std::vector<cv::Mat> parts;
  cv::split(spectrum, parts);
  cv::Mat magnitude;
  cv::magnitude(parts[0], parts[1], magnitude);
  cv::log(magnitude + 1.0, magnitude);
  double top = 0.0;
  cv::minMaxLoc(magnitude, nullptr, &top);
  if (top > 0.0) magnitude /= top;
  const cv::Mat weights = stcsf_weights(physical.size(), input.viewer.pixels_per_degree, samples_per_second,
                                        -input.gaze.eye_velocity_deg_s);
  const cv::Mat shown = centred(magnitude);
  const cv::Mat visible = centred(weights);
  cv::Mat out(physical.size(), CV_8UC3);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      const double m = std::pow(shown.at<double>(y, x), 2.0);
      const bool in_window = visible.at<double>(y, x) >= 1.0;
      const auto g = static_cast<unsigned char>(std::lround(255.0 * m));
      // Tinted amber inside the window of visibility, so energy there stands out against it.
      out.at<cv::Vec3b>(y, x) = in_window ? cv::Vec3b(static_cast<unsigned char>(std::max<int>(g, 90)),
                                                       static_cast<unsigned char>(g * 0.8 + 30),
                                                       static_cast<unsigned char>(g * 0.6))
                                          : cv::Vec3b(g, g, g);
    }
  }
  return out;
}

cv::Mat captioned(const cv::Mat& panel, const std::string& caption) {
  cv::Mat big;
  cv::resize(panel, big, cv::Size(panel.cols * kScale, panel.rows * kScale), 0, 0, cv::INTER_NEAREST);
  cv::Mat out(big.rows + kHeader, std::max(big.cols, 8 * static_cast<int>(caption.size())), CV_8UC3,
              cv::Scalar(255, 255, 255));
  big.copyTo(out(cv::Rect(0, kHeader, big.cols, big.rows)));
  cv::putText(out, caption, cv::Point(2, kHeader - 9), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  return out;
}

}  // namespace

cv::Mat xt_figure(const XtFigureInput& input) {
  if (input.levels.empty() || input.levels.type() != CV_64FC1) {
    throw std::invalid_argument("xt_figure: levels must be a non-empty CV_64FC1 x-t image");
  }
  const int width = std::min(input.window_width, input.levels.cols);
  if (width < 2 || input.window_begin < 0 || input.window_begin + width > input.levels.cols) {
    throw std::invalid_argument("xt_figure: the window [" + std::to_string(input.window_begin) + ", " +
                                std::to_string(input.window_begin + width) + ") is not within the line's " +
                                std::to_string(input.levels.cols) + " pixels");
  }
  const cv::Rect window(input.window_begin, 0, width, 0);
  const cv::Mat physical_line = retinal_xt(input.levels, input.light, input.viewer, 0.0, input.retina);
  const cv::Mat retinal_line =
      retinal_xt(input.levels, input.light, input.viewer, input.gaze, input.retina);
  const cv::Rect rows_window(window.x, 0, width, physical_line.rows);
  const cv::Mat physical = physical_line(rows_window).clone();
  const cv::Mat retinal = retinal_line(rows_window).clone();
  cv::Mat percept;
  cv::reduce(retinal, percept, 0, cv::REDUCE_AVG, CV_64F);
  double peak = 0.0;
  cv::minMaxLoc(input.levels, nullptr, &peak);
  peak = std::max(peak, 1e-12);
  const double rate = xt_samples_per_second(input.light, input.retina.substeps);

  const std::vector<cv::Mat> panels = {
      captioned(grey(physical, peak), "physical x-t (time down)"),
      captioned(grey(retinal, peak), "retina, pursuing eye"),
      captioned(grey(cv::repeat(percept, kPerceptRows, 1), peak), "percept (time average)"),
      captioned(fourier_view(physical, input, rate), "Fourier |F| + window of visibility"),
  };
  int total_width = 0, height = 0;
  for (const cv::Mat& p : panels) {
    total_width += p.cols + kGap;
    height = std::max(height, p.rows);
  }
  const int title_rows = 34;
  cv::Mat out(height + title_rows, total_width, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(out, input.title, cv::Point(4, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  int x = 0;
  for (const cv::Mat& p : panels) {
    p.copyTo(out(cv::Rect(x, title_rows, p.cols, p.rows)));
    x += p.cols + kGap;
  }
  return out;
}

}  // namespace trm::cli
