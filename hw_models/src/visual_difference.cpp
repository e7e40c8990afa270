// Spatio-temporal visual difference energy (supplement §1.1, Eqs. 1, 2, 4).
#include "trm/visual_difference.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "perception_checks.hpp"
#include "trm/csf.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;
using perception_detail::require_finite;
using perception_detail::require_positive;

std::string size_text(const cv::Mat& image) {
  return std::to_string(image.rows) + "x" + std::to_string(image.cols);
}

enum class Range { Any, NonNegative };

void require_image(const char* function, const char* argument, const cv::Mat& image, Range range) {
  if (image.empty()) reject(function, argument, "must be a non-empty x-t image");
  if (image.type() != CV_64FC1) reject(function, argument, "must be CV_64FC1 (one double per sample)");
  for (int row = 0; row < image.rows; ++row) {
    const double* values = image.ptr<double>(row);
    for (int col = 0; col < image.cols; ++col) {
      const double value = values[col];
      const auto where = [row, col] { return " at row " + std::to_string(row) + ", column " + std::to_string(col); };
      if (!std::isfinite(value)) reject(function, argument, "has a non-finite value" + where());
      if (range == Range::NonNegative && value < 0.0) {
        reject(function, argument, "has a negative luminance " + number_text(value) + where());
      }
    }
  }
}

void require_same_size(const char* function, const cv::Mat& l_a, const cv::Mat& l_b) {
  if (l_a.size() != l_b.size()) {
    reject(function, "l_b", "must have the size of l_a (" + size_text(l_a) + " rows x cols), got " + size_text(l_b));
  }
}

// The other alias of a bin at exactly half the sampling rate; every other bin has one frequency.
double alias_of(int index, int length, double frequency) {
  return length % 2 == 0 && index == length / 2 ? -frequency : frequency;
}

cv::Mat weights_unchecked(cv::Size size, double ppd, double fps, double v_r) {
  cv::Mat weights(size, CV_64FC1);
  // Eq. 2: S_st(ρ, ν + ρ v_r), with the travelling-wave ν = −ν' of the DFT's e^{+2πi(ρx + ν't)}.
  const auto weight = [v_r](double rho, double nu_dft) { return csf_spatiotemporal(rho, -nu_dft + rho * v_r); };
  for (int m = 0; m < size.height; ++m) {
    const double nu = dft_frequency(m, size.height, fps);
    const double nu_alias = alias_of(m, size.height, nu);
    double* row = weights.ptr<double>(m);
    for (int k = 0; k < size.width; ++k) {
      const double rho = dft_frequency(k, size.width, ppd);
      const double rho_alias = alias_of(k, size.width, rho);
      const double direct = weight(rho, nu);
      row[k] = rho_alias == rho && nu_alias == nu ? direct : 0.5 * (direct + weight(rho_alias, nu_alias));
    }
  }
  return weights;
}

cv::Mat weighted_unchecked(const cv::Mat& contrast, double ppd, double fps, double v_r) {
  cv::Mat spectrum;
  cv::dft(contrast, spectrum, cv::DFT_COMPLEX_OUTPUT);
  const cv::Mat weights = weights_unchecked(contrast.size(), ppd, fps, v_r);
  const cv::Mat complex_weights[] = {weights, weights};
  cv::Mat weights2;
  cv::merge(complex_weights, 2, weights2);
  spectrum = spectrum.mul(weights2);
  // The weights are conjugate-symmetric, so the inverse is real up to rounding; keep its real part.
  cv::Mat inverse;
  cv::dft(spectrum, inverse, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_COMPLEX_OUTPUT);
  cv::Mat real;
  cv::extractChannel(inverse, real, 0);
  return real;
}

double pooled_unchecked(const cv::Mat& image, double beta) {
  double largest = 0.0;
  for (int row = 0; row < image.rows; ++row) {
    const double* values = image.ptr<double>(row);
    for (int col = 0; col < image.cols; ++col) largest = std::max(largest, std::abs(values[col]));
  }
  if (largest == 0.0) return 0.0;
  // Scaled by the largest |C_n| so that |C_n|^β can neither overflow nor vanish.
  double sum = 0.0;
  for (int row = 0; row < image.rows; ++row) {
    const double* values = image.ptr<double>(row);
    for (int col = 0; col < image.cols; ++col) sum += std::pow(std::abs(values[col]) / largest, beta);
  }
  return largest * std::pow(sum, 1.0 / beta);
}

void require_luminance_pair(const char* function, const cv::Mat& l_a, const cv::Mat& l_b) {
  require_image(function, "l_a", l_a, Range::NonNegative);
  require_image(function, "l_b", l_b, Range::NonNegative);
  require_same_size(function, l_a, l_b);
}

cv::Mat contrast_unchecked(const cv::Mat& l_a, const cv::Mat& l_b) {
  cv::Mat contrast(l_a.size(), CV_64FC1);
  for (int row = 0; row < l_a.rows; ++row) {
    const double* a = l_a.ptr<double>(row);
    const double* b = l_b.ptr<double>(row);
    double* c = contrast.ptr<double>(row);
    for (int col = 0; col < l_a.cols; ++col) {
      const double sum = a[col] + b[col];
      // Eq. 1; with both luminances >= 0 a zero sum means both are black: no difference.
      c[col] = sum > 0.0 ? (a[col] - b[col]) / sum : 0.0;
    }
  }
  return contrast;
}

void require_sampling(const char* function, double ppd, double fps, double v_r) {
  require_positive(function, "pixels_per_degree", ppd);
  require_positive(function, "samples_per_second", fps);
  require_finite(function, "retinal_velocity_deg_s", v_r);
}

}  // namespace

double dft_frequency(int index, int length, double sample_rate) {
  if (length < 1) reject("dft_frequency", "length", "must be >= 1, got " + std::to_string(length));
  if (index < 0 || index >= length) {
    reject("dft_frequency", "index", "must be in [0, " + std::to_string(length) + "), got " + std::to_string(index));
  }
  require_positive("dft_frequency", "sample_rate", sample_rate);
  const int signed_index = index <= length / 2 ? index : index - length;
  return signed_index * sample_rate / length;
}

cv::Mat contrast_difference(const cv::Mat& l_a, const cv::Mat& l_b) {
  require_luminance_pair("contrast_difference", l_a, l_b);
  return contrast_unchecked(l_a, l_b);
}

cv::Mat stcsf_weights(cv::Size size, double pixels_per_degree, double samples_per_second,
                      double retinal_velocity_deg_s) {
  if (size.width < 1 || size.height < 1) {
    reject("stcsf_weights", "size",
           "must be at least 1x1, got " + std::to_string(size.height) + "x" + std::to_string(size.width) +
               " rows x cols");
  }
  require_sampling("stcsf_weights", pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
  return weights_unchecked(size, pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
}

cv::Mat csf_weighted_contrast(const cv::Mat& contrast, double pixels_per_degree, double samples_per_second,
                              double retinal_velocity_deg_s) {
  require_image("csf_weighted_contrast", "contrast", contrast, Range::Any);
  require_sampling("csf_weighted_contrast", pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
  return weighted_unchecked(contrast, pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
}

double pooled_energy(const cv::Mat& normalised_contrast, double beta) {
  require_image("pooled_energy", "normalised_contrast", normalised_contrast, Range::Any);
  require_positive("pooled_energy", "beta", beta);
  return pooled_unchecked(normalised_contrast, beta);
}

double visual_difference_energy(const cv::Mat& l_a, const cv::Mat& l_b, double pixels_per_degree,
                                double samples_per_second, double retinal_velocity_deg_s) {
  require_luminance_pair("visual_difference_energy", l_a, l_b);
  require_sampling("visual_difference_energy", pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
  const cv::Mat contrast = contrast_unchecked(l_a, l_b);
  return pooled_unchecked(
      weighted_unchecked(contrast, pixels_per_degree, samples_per_second, retinal_velocity_deg_s),
      kVisualDifferenceBeta);
}

namespace {

// l minus each column's time average: what changes over time.
cv::Mat changing_part(const cv::Mat& l) {
  cv::Mat still;
  cv::reduce(l, still, 0, cv::REDUCE_AVG, CV_64F);
  return l - cv::repeat(still, l.rows, 1);
}

}  // namespace

double temporal_alias_energy(const cv::Mat& l, double pixels_per_degree, double samples_per_second,
                             double retinal_velocity_deg_s, const cv::Mat& reference) {
  require_image("temporal_alias_energy", "l", l, Range::NonNegative);
  if (!reference.empty()) {
    require_image("temporal_alias_energy", "reference", reference, Range::NonNegative);
    if (reference.size() != l.size()) {
      reject("temporal_alias_energy", "reference", "must have the size of l (" + size_text(l) + " rows x cols), got " +
                                                       size_text(reference));
    }
  }
  require_sampling("temporal_alias_energy", pixels_per_degree, samples_per_second, retinal_velocity_deg_s);
  const double adaptation = cv::mean(l)[0];
  if (adaptation <= 0.0) return 0.0;
  cv::Mat change = changing_part(l);
  if (!reference.empty()) change -= changing_part(reference);
  const cv::Mat contrast = change / adaptation;
  return pooled_unchecked(weighted_unchecked(contrast, pixels_per_degree, samples_per_second, retinal_velocity_deg_s),
                          kVisualDifferenceBeta);
}

}  // namespace trm
