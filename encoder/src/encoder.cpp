// The GPU-side TRM encoder (DESIGN §3-4, paper Sec. 4 and Fig. 4).
#include "trm/encoder.hpp"

#include "exact_text.hpp"
#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>

namespace trm {

double EncoderConfig::effective_sigma() const { return sigma > 0.0 ? sigma : default_sigma(reduction); }

using detail::exact_text;

void EncoderConfig::validate() const {
  if (!(reduction > 0.0 && reduction <= 1.0)) {
    throw std::invalid_argument("reduction r (--reduction) must be in (0, 1], got " + exact_text(reduction));
  }
  // sigma == 0 selects the default; a user-given sigma must be a finite number in [kMinSigma, kMaxSigma].
  if (std::isnan(sigma) || sigma < 0.0 || !std::isfinite(sigma) || (sigma > 0.0 && sigma < kMinSigma)) {
    throw std::invalid_argument("sigma (--sigma) must be >= " + exact_text(kMinSigma) +
                                " full-resolution pixels when given (0 selects 1.25 / r), got " + exact_text(sigma));
  }
  if (effective_sigma() > kMaxSigma) {
    std::string message = "sigma (--sigma) must be <= ";
    message.append(exact_text(kMaxSigma))
        .append(" full-resolution pixels (D's rounding error must stay below the reduced frame's tie tolerance), got ")
        .append(exact_text(effective_sigma()));
    if (sigma == 0.0) message.append(" (the default 1.25 / r at r = ").append(exact_text(reduction)).append(")");
    throw std::invalid_argument(message);
  }
  if (bits != 8 && bits != 10) throw std::invalid_argument("link bits must be 8 or 10, got " + std::to_string(bits));
  if (phase != 0 && phase != 1) throw std::invalid_argument("phase must be 0 or 1, got " + std::to_string(phase));
  if (transfer != Transfer::Srgb && transfer != Transfer::Gamma22) throw std::invalid_argument("unknown transfer function");
  if (resample_space != ResampleSpace::Encoded && resample_space != ResampleSpace::Linear) {
    throw std::invalid_argument("unknown resample space");
  }
}

Parity parity_of(std::int64_t t, int eye, const EncoderConfig& config) {
  if (t < 0) throw std::invalid_argument("frame index must be >= 0, got " + std::to_string(t));
  if (eye != 0 && eye != 1) throw std::invalid_argument("eye must be 0 or 1, got " + std::to_string(eye));
  // Even t full by default; --phase swaps. In stereo the right eye is off-phase so that every link frame
  // carries one full and one reduced view (poster: binocular off-phase).
  int odd = static_cast<int>(t % 2) ^ config.phase;
  if (config.stereo && eye == 1) odd ^= 1;
  return odd ? Parity::Reduced : Parity::Full;
}

cv::Mat reduce_codes(const cv::Mat& full_codes, const EncoderConfig& config) {
  config.validate();
  if (full_codes.depth() != CV_16U || full_codes.empty()) {
    throw std::invalid_argument("reduce_codes: expected non-empty CV_16U link codes");
  }
  if (full_codes.cols > kMaxViewSide || full_codes.rows > kMaxViewSide) {
    throw std::invalid_argument("reduce_codes: the view is " + std::to_string(full_codes.cols) + "x" +
                                std::to_string(full_codes.rows) + ", at most " + std::to_string(kMaxViewSide) +
                                " per side is supported");
  }
  const int w = reduced_size(full_codes.cols, config.reduction);
  const int h = reduced_size(full_codes.rows, config.reduction);
  const double sigma = config.effective_sigma();
  // E (or lin(E)) a row at a time as D reads it: no full-size plane of doubles.
  const DequantisedRows encoded(full_codes, config.bits);
  const bool linear_space = config.resample_space == ResampleSpace::Linear;
  const auto row_len = static_cast<std::size_t>(full_codes.cols) * full_codes.channels();
  const cv::Mat reduced = downsample(
      full_codes.size(), full_codes.channels(),
      [&](int y, double* scratch) {
        encoded.row(y, scratch);
        if (linear_space) {
          to_linear(std::span<const double>(scratch, row_len), std::span<double>(scratch, row_len), config.transfer);
        }
        return static_cast<const double*>(scratch);
      },
      w, h, sigma);
  if (!linear_space) return quantise_reduced(reduced, config.bits);                    // Q_b(D(E))
  return quantise_reduced(to_encoded(reduced, config.transfer), config.bits);  // Q_b(enc(D(lin(E))))
}

TrmEncoder::TrmEncoder(EncoderConfig config) : config_(config) { config_.validate(); }

LinkFrame TrmEncoder::encode(const cv::Mat& linear_full, std::int64_t t, int eye) const {
  return encode_as(parity_of(t, eye, config_), linear_full, t, eye);
}

LinkFrame TrmEncoder::encode_as(Parity parity, const cv::Mat& linear_full, std::int64_t t, int eye) const {
  if (t < 0) throw std::invalid_argument("encode: frame index must be >= 0, got " + std::to_string(t));
  if (eye != 0 && eye != 1) throw std::invalid_argument("encode: eye must be 0 or 1, got " + std::to_string(eye));
  if (linear_full.type() != CV_64FC3 || linear_full.empty()) {
    throw std::invalid_argument("encode: expected a non-empty CV_64FC3 linear RGB frame");
  }
  if (linear_full.cols > kMaxViewSide || linear_full.rows > kMaxViewSide) {
    throw std::invalid_argument("encode: frame " + std::to_string(t) + " is " + std::to_string(linear_full.cols) +
                                "x" + std::to_string(linear_full.rows) + ", at most " + std::to_string(kMaxViewSide) +
                                " per side is supported");
  }
  if (!cv::checkRange(linear_full, true, nullptr, 0.0, 1.0 + 1e-12)) {
    throw std::invalid_argument("encode: frame " + std::to_string(t) + " has NaN, Inf or values outside [0, 1]");
  }
  LinkFrame frame;
  frame.meta.index = t;
  frame.meta.eye = eye;
  frame.meta.parity = parity;
  frame.meta.full_width = linear_full.cols;
  frame.meta.full_height = linear_full.rows;
  frame.meta.bits = config_.bits;
  frame.meta.transfer = config_.transfer;

  // What the GPU would send at full resolution; a reduced frame is derived from exactly these codes.
  cv::Mat full_codes = quantise(to_encoded(linear_full, config_.transfer), config_.bits);
  frame.codes = frame.meta.parity == Parity::Full ? full_codes : reduce_codes(full_codes, config_);
  frame.meta.width = frame.codes.cols;
  frame.meta.height = frame.codes.rows;
  return frame;
}

}  // namespace trm
