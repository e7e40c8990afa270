// Fixed-gaze flicker visibility (trm/flicker.hpp).
#include "trm/flicker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "perception_checks.hpp"
#include "trm/csf.hpp"
#include "trm/visual_difference.hpp"

namespace trm {

using perception_detail::reject;
using perception_detail::require_positive;

FlickerSpectrum::FlickerSpectrum(double pixels_per_degree, Surround surround)
    : pixels_per_degree_(pixels_per_degree), surround_(surround) {
  require_positive("FlickerSpectrum", "pixels_per_degree", pixels_per_degree);
}

void FlickerSpectrum::add_pair(const cv::Mat& luma_a, const cv::Mat& luma_b) {
  const char* function = "FlickerSpectrum::add_pair";
  // contrast_difference checks type, finiteness, sign and equal sizes, naming l_a / l_b.
  cv::Mat alternation;
  try {
    alternation = contrast_difference(luma_a, luma_b);
  } catch (const std::invalid_argument& e) {
    reject(function, "luma_a, luma_b", std::string("are not a pair of luminance images: ") + e.what());
  }
  if (pairs_ == 0) {
    size_ = alternation.size();
  } else if (alternation.size() != size_) {
    reject(function, "luma_a", "must have the size of the first pair (" + std::to_string(size_.width) + "x" +
                                   std::to_string(size_.height) + ")");
  }
  cv::Mat padded = alternation;
  if (surround_ == Surround::Dark) {
    // At least a quarter of the view of dark surround on each axis, so the patch's spectrum is not wrapped onto
    // itself; the optimal DFT size keeps the transform fast.
    const int rows = cv::getOptimalDFTSize(alternation.rows + std::max(1, alternation.rows / 4));
    const int cols = cv::getOptimalDFTSize(alternation.cols + std::max(1, alternation.cols / 4));
    cv::copyMakeBorder(alternation, padded, 0, rows - alternation.rows, 0, cols - alternation.cols,
                       cv::BORDER_CONSTANT, cv::Scalar(0.0));
  }
  cv::Mat spectrum;
  cv::dft(padded, spectrum, cv::DFT_COMPLEX_OUTPUT);
  const int rows = spectrum.rows;
  const int cols = spectrum.cols;
  if (pairs_ == 0) {
    bin_width_cpd_ = pixels_per_degree_ / std::max(rows, cols);
    const double rho_max = std::hypot(pixels_per_degree_ / 2.0, pixels_per_degree_ / 2.0);
    power_.assign(static_cast<std::size_t>(rho_max / bin_width_cpd_) + 2, 0.0);
  }
  // Parseval for OpenCV's unnormalised DFT: Σ_x |a|² = Σ_k |Â|² / N_transform; the mean square is over the view.
  const double scale = 1.0 / (static_cast<double>(rows) * cols * static_cast<double>(size_.area()));
  for (int m = 0; m < rows; ++m) {
    const double rho_y = dft_frequency(m, rows, pixels_per_degree_);
    const auto* row = spectrum.ptr<cv::Vec2d>(m);
    for (int k = 0; k < cols; ++k) {
      const double rho = std::hypot(rho_y, dft_frequency(k, cols, pixels_per_degree_));
      const double power = row[k][0] * row[k][0] + row[k][1] * row[k][1];
      power_[static_cast<std::size_t>(std::lround(rho / bin_width_cpd_))] += power * scale;
    }
  }
  ++pairs_;
}

namespace {

// The spatial frequency where S_st(·, ν) peaks, on a log grid fine enough (0.25 % steps) for a smooth maximum.
double peak_frequency_cpd(double nu_hz) {
  double best_rho = 0.01, best = -1.0;
  for (double rho = 0.01; rho <= 60.0; rho *= 1.0025) {
    const double s = csf_spatiotemporal(rho, nu_hz);
    if (s > best) {
      best = s;
      best_rho = rho;
    }
  }
  return best_rho;
}

}  // namespace

double flicker_sensitivity(double rho_cpd, double nu_hz) {
  require_positive("flicker_sensitivity", "nu_hz", nu_hz);
  perception_detail::require_finite("flicker_sensitivity", "rho_cpd", rho_cpd);
  return csf_spatiotemporal(std::max(std::abs(rho_cpd), peak_frequency_cpd(nu_hz)), nu_hz);
}

double FlickerSpectrum::visibility(double refresh_hz) const {
  require_positive("FlickerSpectrum::visibility", "refresh_hz", refresh_hz);
  if (pairs_ == 0) return 0.0;
  const double pair_hz = refresh_hz / 2.0;
  const double peak_cpd = peak_frequency_cpd(pair_hz);
  double mean_square = 0.0;
  for (std::size_t bin = 0; bin < power_.size(); ++bin) {
    if (power_[bin] == 0.0) continue;
    const double rho = std::max(static_cast<double>(bin) * bin_width_cpd_, peak_cpd);
    const double sensitivity = csf_spatiotemporal(rho, pair_hz);
    mean_square += power_[bin] * sensitivity * sensitivity;
  }
  return std::sqrt(2.0 * mean_square / pairs_);
}

double FlickerSpectrum::invisible_from_hz(double min_hz, double max_hz) const {
  const char* function = "FlickerSpectrum::invisible_from_hz";
  require_positive(function, "min_hz", min_hz);
  require_positive(function, "max_hz", max_hz);
  if (max_hz < min_hz) reject(function, "max_hz", "must be >= min_hz");
  double from = min_hz;
  for (double hz = max_hz; hz >= min_hz; hz -= 1.0) {
    if (visibility(hz) >= 1.0) {
      if (hz == max_hz) return std::numeric_limits<double>::infinity();
      from = hz + 1.0;
      break;
    }
  }
  return from;
}

}  // namespace trm
