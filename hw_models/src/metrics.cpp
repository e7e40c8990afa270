// Metrics over images (DESIGN §6, §7).
#include "trm/metrics.hpp"

#include "trm/transfer.hpp"

#include <opencv2/quality/qualityssim.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {

cv::Mat perceived_pair(const cv::Mat& linear_a, const cv::Mat& linear_b) {
  if (linear_a.size() != linear_b.size() || linear_a.type() != linear_b.type() || linear_a.depth() != CV_64F) {
    throw std::invalid_argument("perceived_pair: the two frames must be CV_64F of the same size and channels");
  }
  cv::Mat sum = linear_a + linear_b;
  return sum * 0.5;
}

cv::Mat perceived_pair(const Panel& panel, const cv::Mat& emitted_previous, const cv::Mat& emitted) {
  return panel.has_history() ? emitted.clone() : perceived_pair(emitted_previous, emitted);
}

cv::Mat full_rate_emission(const cv::Mat& linear, const Panel& panel, int output_bits) {
  const double levels = std::ldexp(1.0, output_bits) - 1.0;
  cv::Mat out(linear.size(), CV_64FC3);
  for (int y = 0; y < linear.rows; ++y) {
    const auto* src = linear.ptr<cv::Vec3d>(y);
    auto* dst = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < linear.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = panel.drive_from_linear(src[x][c], c);
        const double code = std::floor(std::clamp(v, 0.0, 1.0) * levels + 0.5);
        dst[x][c] = panel.linear_from_drive(code / levels, c);
      }
    }
  }
  return out;
}

FullRateEmission::FullRateEmission(const Panel& panel, int output_bits) : panel_(panel) {
  if (output_bits < 1 || output_bits > 16) {
    throw std::invalid_argument("FullRateEmission: output bits must be in [1, 16], got " + std::to_string(output_bits));
  }
  top_ = (1 << output_bits) - 1;
  if (panel.kind == PanelKind::Oled) oled_codes_.emplace(panel.oled, output_bits);
  for (int c = 0; c < 3; ++c) {
    for (int code = 0; code <= top_; ++code) {
      held_light_[static_cast<std::size_t>(c)].push_back(panel.linear_from_drive(static_cast<double>(code) / top_, c));
    }
  }
}

cv::Mat FullRateEmission::operator()(const cv::Mat& linear) const {
  if (linear.type() != CV_64FC3) throw std::invalid_argument("FullRateEmission: the frame must be CV_64FC3");
  cv::Mat out(linear.size(), CV_64FC3);
  const auto samples = static_cast<std::size_t>(3 * linear.cols);
  std::vector<std::uint16_t> codes(samples);
  // full_rate_emission's expression, where a drive value is NaN (the tables have no code for it).
  const auto per_sample = [&](double x, int c) {
    const double v = panel_.drive_from_linear(x, c);
    const double code = std::floor(std::clamp(v, 0.0, 1.0) * top_ + 0.5);
    return panel_.linear_from_drive(code / top_, c);
  };
  for (int y = 0; y < linear.rows; ++y) {
    const double* src = linear.ptr<double>(y);
    double* dst = out.ptr<double>(y);
    if (oled_codes_) {
      if (oled_codes_->codes(std::span<const double>(src, samples), codes)) {
        for (std::size_t k = 0; k < samples; ++k) dst[k] = held_light_[k % 3][codes[k]];
      } else {
        for (std::size_t k = 0; k < samples; ++k) dst[k] = per_sample(src[k], static_cast<int>(k % 3));
      }
      continue;
    }
    for (std::size_t k = 0; k < samples; ++k) {
      const int c = static_cast<int>(k % 3);
      const double v = panel_.drive_from_linear(src[k], c);
      if (std::isnan(v)) {
        dst[k] = per_sample(src[k], c);
        continue;
      }
      dst[k] = held_light_[static_cast<std::size_t>(c)][quantise(v, top_)];  // quantise: floor(clamp(v) top + 1/2)
    }
  }
  return out;
}

double psnr_srgb(const cv::Mat& linear_a, const cv::Mat& linear_b) {
  const cv::Mat a = to_encoded(linear_a, Transfer::Srgb);
  const cv::Mat b = to_encoded(linear_b, Transfer::Srgb);
  const double sq = cv::norm(a, b, cv::NORM_L2SQR);
  const double mse = sq / static_cast<double>(a.total() * a.channels());
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(1.0 / mse);
}

double CodeAgreement::identical_fraction() const {
  return compared > 0 ? static_cast<double>(identical) / static_cast<double>(compared) : 0.0;
}

double CodeAgreement::identical_percent() const {
  return compared > 0 ? 100.0 * static_cast<double>(identical) / static_cast<double>(compared) : 0.0;
}

double CodeAgreement::mean_lsb() const { return compared > 0 ? sum_lsb / static_cast<double>(compared) : 0.0; }

double CodeAgreement::rms_lsb() const {
  return compared > 0 ? std::sqrt(sum_squared_lsb / static_cast<double>(compared)) : 0.0;
}

CodeAgreement& CodeAgreement::operator+=(const CodeAgreement& other) {
  compared += other.compared;
  identical += other.identical;
  max_lsb = std::max(max_lsb, other.max_lsb);
  sum_lsb += other.sum_lsb;
  sum_squared_lsb += other.sum_squared_lsb;
  return *this;
}

CodeAgreement compare_codes(const cv::Mat& codes, const cv::Mat& reference_codes) {
  if (codes.size() != reference_codes.size() || codes.type() != reference_codes.type() ||
      codes.depth() == CV_32F || codes.depth() == CV_64F) {
    throw std::invalid_argument("compare_codes: the two code images must be integer images of one size and type");
  }
  cv::Mat difference;
  cv::absdiff(codes, reference_codes, difference);
  CodeAgreement a;
  if (difference.empty()) return a;
  cv::Mat flat;
  difference.reshape(1).convertTo(flat, CV_64F);
  a.compared = static_cast<std::int64_t>(flat.total());
  a.identical = a.compared - cv::countNonZero(flat);
  a.max_lsb = cv::norm(flat, cv::NORM_INF);
  a.sum_lsb = cv::sum(flat)[0];
  a.sum_squared_lsb = cv::norm(flat, cv::NORM_L2SQR);
  return a;
}

double ssim_srgb(const cv::Mat& linear_a, const cv::Mat& linear_b) {
  if (linear_a.size() != linear_b.size() || linear_a.type() != linear_b.type() || linear_a.empty()) {
    throw std::invalid_argument("ssim_srgb: the two images must be non-empty, of the same size and type");
  }
  const cv::Mat a = to_encoded(linear_a, Transfer::Srgb) * 255.0;
  const cv::Mat b = to_encoded(linear_b, Transfer::Srgb) * 255.0;
  const cv::Scalar per_channel = cv::quality::QualitySSIM::compute(a, b, cv::noArray());
  double sum = 0.0;
  for (int c = 0; c < a.channels(); ++c) sum += per_channel[c];
  return sum / a.channels();
}

std::optional<PairTracker::Pair> PairTracker::add(int eye, std::int64_t t, const cv::Mat& emitted,
                                                  const cv::Mat& reference_emitted) {
  Previous& previous = previous_[eye];
  std::optional<Pair> pair;
  if (t % 2 == 1 && previous.t == t - 1) {
    pair.emplace();
    pair->first = t - 1;
    pair->perceived = perceived_pair(panel_, previous.emitted, emitted);
    pair->reference = perceived_pair(previous.reference, reference_emitted);
  }
  previous.t = t;
  previous.emitted = emitted;
  previous.reference = reference_emitted;
  return pair;
}

double max_merge_difference_codes(const cv::Mat& emitted_linear, const cv::Mat& reference_emitted_linear,
                                  const LcdPanel& lcd, int output_bits) {
  return cv::norm(lcd.merged_of_emission(emitted_linear), lcd.merged_of_emission(reference_emitted_linear),
                 cv::NORM_INF) *
         ((1 << output_bits) - 1);
}

}  // namespace trm
