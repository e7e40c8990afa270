// The OpenCV float32 TRM decoder (opencv_trm.hpp).
#include "opencv_trm.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

namespace trm::bench {

namespace {

// A scalar on every channel (a bare double is a Scalar of channel 0 alone in OpenCV's matrix expressions).
cv::Scalar all(double v) { return cv::Scalar::all(v); }

cv::Mat encoded_of_codes(const cv::Mat& codes, int bits) {
  cv::Mat encoded;
  codes.convertTo(encoded, CV_32F, 1.0 / ((1 << bits) - 1));
  return encoded;
}

}  // namespace

OpencvTrmDecoder::OpencvTrmDecoder(const DecoderConfig& config) : config_(config) {
  config_.validate();
  code_lut_.create(1, 256, CV_32F);
  for (int code = 0; code < 256; ++code) {
    code_lut_.at<float>(0, code) = static_cast<float>(to_linear(code / 255.0, config_.link.transfer));
  }
}

cv::Mat OpencvTrmDecoder::linear_of_encoded(const cv::Mat& encoded) const {
  const cv::Mat x = encoded.reshape(1);  // one channel, so that scalars and masks apply to every sample
  cv::Mat linear;
  if (config_.link.transfer == Transfer::Srgb) {
    // x / 12.92 below 0.04045, ((x + 0.055) / 1.055)^2.4 above.
    cv::Mat power;
    cv::pow((x + 0.055) / 1.055, 2.4, power);
    linear = x / 12.92;
    power.copyTo(linear, x > 0.04045);
  } else {
    cv::pow(cv::max(x, 0.0), 2.2, linear);
  }
  return linear.reshape(encoded.channels());
}

cv::Mat OpencvTrmDecoder::drive_codes(const cv::Mat& wanted, Eye& eye) const {
  const Panel& panel = config_.panel;
  const double top = (1 << config_.output_bits) - 1;
  cv::Mat drive;
  if (!panel.has_history()) {
    std::vector<cv::Mat> channels;
    cv::split(wanted, channels);
    const std::array<double, 3> gammas = panel.channel_gammas();
    for (std::size_t ch = 0; ch < 3; ++ch) cv::pow(channels[ch], 1.0 / gammas[ch], channels[ch]);
    cv::merge(channels, drive);
  } else {
    // Eq. 7 inverse: p1 v^2 + (p2 vp + p3) v + (p1 vp^2 + p3 vp + p4 - m) = 0 with m = ((x_t + x_{t-1}) / 2)^(1/gamma),
    // the increasing root in the stable form v = -2C / (B + sqrt(B^2 - 4AC)), clamped to [0, 1].
    const LcdPanel& lcd = panel.lcd;
    if (eye.previous_drive.empty()) {
      cv::pow(wanted, 1.0 / lcd.gamma, eye.previous_drive);  // first frame: the pixel held (M(v, v) = v)
      eye.previous_linear = wanted.clone();
    }
    const cv::Mat& vp = eye.previous_drive;
    cv::Mat m;
    cv::pow((wanted + eye.previous_linear) * 0.5, 1.0 / lcd.gamma, m);
    const cv::Mat b = vp * lcd.p2 + all(lcd.p3);
    const cv::Mat c = vp.mul(vp) * lcd.p1 + vp * lcd.p3 + all(lcd.p4) - m;
    cv::Mat root;
    cv::sqrt(cv::max(b.mul(b) - c * (4.0 * lcd.p1), all(0.0)), root);
    cv::divide(c * -2.0, b + root, drive);
    drive = cv::min(cv::max(drive, all(0.0)), all(1.0));
    eye.previous_drive = drive;
    eye.previous_linear = wanted;
  }
  cv::Mat codes;
  drive.convertTo(codes, CV_16U, top);  // rounds to nearest
  return codes;
}

cv::Mat OpencvTrmDecoder::decode(const LinkFrame& frame) {
  const FrameMeta& meta = frame.meta;
  const cv::Size full(meta.full_width, meta.full_height);
  Eye& eye = eyes_[meta.eye];
  const int bits = config_.link.bits;
  const cv::Mat encoded = encoded_of_codes(frame.codes, bits);
  if (meta.parity == Parity::Full) {
    cv::Mat linear;
    if (bits == 8) {
      cv::Mat codes8;
      frame.codes.convertTo(codes8, CV_8U);
      cv::LUT(codes8, code_lut_, linear);
    } else {
      linear = linear_of_encoded(encoded);
    }
    // d_t = Q_b(D(E_t)): the blur, a resize to the reduced size, the link quantisation.
    const double sigma = config_.link.effective_sigma();
    cv::Mat blurred;
    cv::GaussianBlur(encoded, blurred, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
    const cv::Size reduced(reduced_size(full.width, config_.link.reduction),
                           reduced_size(full.height, config_.link.reduction));
    cv::Mat low;
    cv::resize(blurred, low, reduced, 0, 0, cv::INTER_LINEAR);
    const double top = (1 << bits) - 1;
    low.convertTo(low, CV_16U, top);
    low.convertTo(low, CV_32F, 1.0 / top);
    cv::Mat up;
    cv::resize(low, up, full, 0, 0, cv::INTER_LINEAR);
    eye.low = linear_of_encoded(up);  // L_t
    const cv::Mat beta = linear * 2.0 - eye.low;  // Eq. 2
    const cv::Mat shown = cv::min(cv::max(beta, all(0.0)), all(1.0));
    eye.residual = beta - shown;
    eye.residual_index = meta.index;
    return drive_codes(shown, eye);
  }
  cv::Mat up;
  cv::resize(encoded, up, full, 0, 0, cv::INTER_LINEAR);
  const cv::Mat alpha = linear_of_encoded(up);  // Eq. 1
  if (eye.residual.empty() || eye.residual_index != meta.index - 1) return drive_codes(alpha, eye);
  // Eqs. 4-6 on Rec. 709 luma.
  const cv::Matx13f rgb_luma(0.2126f, 0.7152f, 0.0722f);  // channels are R, G, B
  cv::Mat y_previous;
  cv::Mat y_alpha;
  cv::transform(eye.low, y_previous, rgb_luma);
  cv::transform(alpha, y_alpha, rgb_luma);
  cv::Mat difference;
  cv::absdiff(y_previous, y_alpha, difference);
  cv::Mat contrast;
  cv::divide(difference, y_previous + y_alpha + 1e-12, contrast);
  cv::Mat weight;
  cv::exp(contrast * -config_.sensitivity, weight);
  cv::Mat weight3;
  cv::cvtColor(weight, weight3, cv::COLOR_GRAY2BGR);
  const cv::Mat alpha_prime = cv::min(cv::max(alpha + weight3.mul(eye.residual), all(0.0)), all(1.0));
  eye.residual.release();
  return drive_codes(alpha_prime, eye);
}

}  // namespace trm::bench
