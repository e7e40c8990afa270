// The resampling operators D (polyphase Gaussian decimator) and U (bilinear), DESIGN §3.
#pragma once

#include <opencv2/core.hpp>

#include <functional>
#include <vector>

namespace trm {

// w = max(1, floor(r * full + 0.5)); throws std::invalid_argument unless full >= 1 and 0 < r <= 1.
int reduced_size(int full, double r);

// Default sigma = 1.25 / r full-resolution pixels.
double default_sigma(double r);

// Exact centre, in full-resolution pixel coordinates, of reduced sample x_low:
// c = ((2 x_low + 1) W - w) / (2 w).
double reduced_centre(int x_low, int full, int reduced);

// The taps of D for one reduced sample along one axis: weights exp(-(i - c)^2 / 2 sigma^2) for every
// integer i with |i - c| <= R, R = ceil(3 sigma), normalised to sum 1. Indices are NOT clamped here
// (first_index may be negative, first_index + size may exceed full): callers clamp (replicate).
struct GaussianTaps {
  int first_index = 0;
  std::vector<double> weights;
};
GaussianTaps gaussian_taps(int x_low, int full, int reduced, double sigma);
int gaussian_radius(double sigma);  // R = ceil(3 sigma)

// Bilinear source position for full-resolution pixel x: x_low = (x + 0.5) / s - 0.5 with s = full / reduced,
// computed exactly: ((2x + 1) w - W) / (2 W). Returns the lower index i0 (clamped) and i1 = min(i0 + 1, w - 1)
// with weight frac for i1.
struct BilinearTap {
  int i0 = 0;
  int i1 = 0;
  double frac = 0.0;  // weight of i1; weight of i0 is 1 - frac
};
BilinearTap bilinear_tap(int x, int full, int reduced);

// D: full (CV_64F, any channels) -> reduced size w x h.
cv::Mat downsample(const cv::Mat& full, int reduced_width, int reduced_height, double sigma);
// D of a frame that comes a row at a time: full_row(y, scratch) gives row y (full_size.width x channels doubles),
// either a pointer into a plane the caller keeps or `scratch` filled with the row. The same doubles as downsample()
// of the frame those rows make, without a full-size plane of it. Rows are asked for on OpenCV's threads, each once.
using FullRow = std::function<const double*(int y, double* scratch)>;
cv::Mat downsample(cv::Size full_size, int channels, const FullRow& full_row, int reduced_width, int reduced_height,
                   double sigma);
// U: reduced (CV_64F, any channels) -> full size W x H.
cv::Mat upsample(const cv::Mat& reduced, int full_width, int full_height);
// U in two parts, for callers that consume it a row at a time: the horizontal pass of every reduced row (reduced
// height x W), then output row y (of H) as the vertical blend of two of its rows, written to `out` (W x channels
// doubles). upsample() is exactly these two.
cv::Mat upsample_horizontal(const cv::Mat& reduced, int full_width);
void upsample_row(const cv::Mat& horizontal, int y, int full_height, double* out);

}  // namespace trm
