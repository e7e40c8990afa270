// Transfer functions, link quantisation and luma (DESIGN §3).
#include "trm/transfer.hpp"

#include "trm/vector_pow.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

// IEC 61966-2-1 piecewise sRGB curve. The break points (0.04045 encoded, 0.0031308 linear) are the
// standard's; the two branches meet to within 1e-7, which is far below a 16-bit code.
constexpr double kSrgbEncodedBreak = 0.04045;
constexpr double kSrgbLinearBreak = 0.0031308;
constexpr double kSrgbSlope = 12.92;
constexpr double kSrgbOffset = 0.055;
constexpr double kSrgbExponent = 2.4;
constexpr double kPureGamma = 2.2;

// std::clamp(x, 0, 1) (NaN and -0 pass through as with it) written as two selects, which GCC vectorises where the
// loops below call it (it branches on std::clamp's nested ternary).
inline double clamp01(double x) {
  const double above_zero = x < 0.0 ? 0.0 : x;
  return 1.0 < above_zero ? 1.0 : above_zero;
}

void require_double(const cv::Mat& m, const char* what) {
  if (m.depth() != CV_64F) {
    throw std::invalid_argument(std::string(what) + ": expected a CV_64F matrix");
  }
}

// Applies a row function (span in, span out) to every row of a CV_64F matrix of any channel count, returning a new
// matrix.
template <typename RowFunction>
cv::Mat map_rows(const cv::Mat& in, RowFunction row_function) {
  cv::Mat out(in.size(), in.type());
  const auto row_len = static_cast<std::size_t>(in.cols) * static_cast<std::size_t>(in.channels());
  // Rows on OpenCV's threads: every element is computed alone, so the doubles do not depend on the split.
  cv::parallel_for_(cv::Range(0, in.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      row_function(std::span<const double>(in.ptr<double>(y), row_len), std::span<double>(out.ptr<double>(y), row_len));
    }
  });
  return out;
}

// Runs `each` over [0, n) in chunks of at most kPowChunk elements, with a scratch array for the chunk's pows.
constexpr std::size_t kPowChunk = 256;
template <typename Chunk>
void in_pow_chunks(std::size_t n, Chunk each) {
  std::array<double, kPowChunk> scratch;
  for (std::size_t start = 0; start < n; start += kPowChunk) {
    each(start, std::min(kPowChunk, n - start), std::span<double>(scratch));
  }
}

void require_same_size(std::size_t in, std::size_t out, const char* what) {
  if (in != out) throw std::invalid_argument(std::string(what) + ": input and output differ in size");
}

void require_bits(int bits) {
  if (bits < 1 || bits > 16) {
    throw std::invalid_argument("quantisation bits must be in [1, 16], got " + std::to_string(bits));
  }
}

}  // namespace

double to_linear(double encoded, Transfer transfer) {
  const double v = clamp01(encoded);
  if (transfer == Transfer::Gamma22) return std::pow(v, kPureGamma);
  if (v <= kSrgbEncodedBreak) return v / kSrgbSlope;
  return std::pow((v + kSrgbOffset) / (1.0 + kSrgbOffset), kSrgbExponent);
}

double to_encoded(double linear, Transfer transfer) {
  const double l = clamp01(linear);
  if (transfer == Transfer::Gamma22) return std::pow(l, 1.0 / kPureGamma);
  if (l <= kSrgbLinearBreak) return l * kSrgbSlope;
  if (l == 1.0) return 1.0;  // 1.055 - 0.055 is 1 - 2^-53 in floating point; peak white must stay exact
  return (1.0 + kSrgbOffset) * std::pow(l, 1.0 / kSrgbExponent) - kSrgbOffset;
}

namespace transfer_detail {

// to_linear's element-wise steps around the pows, compiled for AVX2 too and chosen at run time (GCC's function
// multi-versioning): the compiler vectorises them four doubles wide there. Only the ISA's width changes (no FMA in
// the AVX2 clone: "avx2" does not enable it), so the doubles are the baseline's.
[[gnu::target_clones("avx2", "default")]] void srgb_pow_bases(const double* in, double* base, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) base[k] = clamp01(in[k]);
  for (std::size_t k = 0; k < n; ++k) base[k] = (base[k] + kSrgbOffset) / (1.0 + kSrgbOffset);
}

[[gnu::target_clones("avx2", "default")]] void srgb_linear_select(const double* in, const double* power, double* out,
                                                                  std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) out[k] = clamp01(in[k]);
  for (std::size_t k = 0; k < n; ++k) {
    const double v = out[k];
    const double linear_segment = v / kSrgbSlope;
    const double curve = power[k];
    out[k] = v <= kSrgbEncodedBreak ? linear_segment : curve;
  }
}

}  // namespace transfer_detail

// The scalar functions' expressions with their pows taken a chunk at a time; elements on the linear segment or at
// peak white discard the pow computed for them.
void to_linear(std::span<const double> encoded, std::span<double> linear, Transfer transfer) {
  require_same_size(encoded.size(), linear.size(), "to_linear");
  const bool gamma = transfer == Transfer::Gamma22;
  in_pow_chunks(encoded.size(), [&](std::size_t start, std::size_t count, std::span<double> power) {
    const double* in = encoded.data() + start;
    double* out = linear.data() + start;
    if (gamma) {
      for (std::size_t k = 0; k < count; ++k) power[k] = clamp01(in[k]);
      pow_elements(power.first(count), kPureGamma, std::span<double>(out, count));
      return;
    }
    transfer_detail::srgb_pow_bases(in, power.data(), count);
    pow_elements(power.first(count), kSrgbExponent, power.first(count));
    transfer_detail::srgb_linear_select(in, power.data(), out, count);
  });
}

void to_encoded(std::span<const double> linear, std::span<double> encoded, Transfer transfer) {
  require_same_size(linear.size(), encoded.size(), "to_encoded");
  const bool gamma = transfer == Transfer::Gamma22;
  in_pow_chunks(linear.size(), [&](std::size_t start, std::size_t count, std::span<double> power) {
    const double* in = linear.data() + start;
    for (std::size_t k = 0; k < count; ++k) power[k] = clamp01(in[k]);
    pow_elements(power.first(count), gamma ? 1.0 / kPureGamma : 1.0 / kSrgbExponent, power.first(count));
    double* out = encoded.data() + start;
    for (std::size_t k = 0; k < count; ++k) {
      const double l = clamp01(in[k]);
      if (gamma) {
        out[k] = power[k];
      } else if (l <= kSrgbLinearBreak) {
        out[k] = l * kSrgbSlope;
      } else {
        out[k] = l == 1.0 ? 1.0 : (1.0 + kSrgbOffset) * power[k] - kSrgbOffset;
      }
    }
  });
}

cv::Mat to_linear(const cv::Mat& encoded, Transfer transfer) {
  require_double(encoded, "to_linear");
  return map_rows(encoded, [transfer](std::span<const double> in, std::span<double> out) {
    to_linear(in, out, transfer);
  });
}

cv::Mat to_encoded(const cv::Mat& linear, Transfer transfer) {
  require_double(linear, "to_encoded");
  return map_rows(linear, [transfer](std::span<const double> in, std::span<double> out) {
    to_encoded(in, out, transfer);
  });
}

cv::Mat quantise(const cv::Mat& values, int bits) {
  require_double(values, "quantise");
  require_bits(bits);
  const int max_code = (1 << bits) - 1;
  cv::Mat codes(values.size(), CV_MAKETYPE(CV_16U, values.channels()));
  const int row_len = values.cols * values.channels();
  for (int y = 0; y < values.rows; ++y) {
    const double* src = values.ptr<double>(y);
    std::uint16_t* dst = codes.ptr<std::uint16_t>(y);
    for (int i = 0; i < row_len; ++i) {
      // NaN would survive the clamp and make the integer conversion undefined: reject it here.
      if (std::isnan(src[i])) throw std::invalid_argument("quantise: NaN value");
      dst[i] = quantise(src[i], max_code);
    }
  }
  return codes;
}

std::uint16_t quantise_reduced(double value, int bits) {
  require_bits(bits);
  if (std::isnan(value)) throw std::invalid_argument("quantise_reduced: NaN value");
  const double max_code = static_cast<double>((1 << bits) - 1);
  // clamp01(value) max_code + 1/2 + tol < max_code + 1: the top code cannot be exceeded.
  return static_cast<std::uint16_t>(std::floor(clamp01(value) * max_code + 0.5 + kReducedTieTolerance));
}

cv::Mat quantise_reduced(const cv::Mat& values, int bits) {
  require_double(values, "quantise_reduced");
  require_bits(bits);
  cv::Mat codes(values.size(), CV_MAKETYPE(CV_16U, values.channels()));
  const int row_len = values.cols * values.channels();
  for (int y = 0; y < values.rows; ++y) {
    const double* src = values.ptr<double>(y);
    std::uint16_t* dst = codes.ptr<std::uint16_t>(y);
    for (int i = 0; i < row_len; ++i) dst[i] = quantise_reduced(src[i], bits);
  }
  return codes;
}

DequantisedRows::DequantisedRows(const cv::Mat& codes, int bits) : codes_(codes), max_code_(0) {
  if (codes.depth() != CV_16U) throw std::invalid_argument("dequantise: expected a CV_16U matrix");
  require_bits(bits);
  max_code_ = (1 << bits) - 1;
  // Every code's value once (the same division), then a lookup per sample; a view with fewer samples than codes
  // (a small one at 16 bits) divides per sample instead.
  const bool by_table = codes.total() * static_cast<std::size_t>(codes.channels()) > static_cast<std::size_t>(max_code_);
  value_of_.resize(by_table ? static_cast<std::size_t>(max_code_) + 1 : 0);
  for (std::size_t code = 0; code < value_of_.size(); ++code) {
    value_of_[code] = dequantise(static_cast<std::uint16_t>(code), max_code_);
  }
  // Codes above the maximum cannot come from quantise(); they indicate a bit-depth mix-up. Checked before any work,
  // so that the rows, read on OpenCV's threads, throw nothing.
  const int row_len = codes.cols * codes.channels();
  for (int y = 0; y < codes.rows; ++y) {
    const std::uint16_t* src = codes.ptr<std::uint16_t>(y);
    if (*std::max_element(src, src + row_len) > max_code_) {
      const std::uint16_t first = *std::find_if(src, src + row_len, [&](std::uint16_t c) { return c > max_code_; });
      throw std::invalid_argument("dequantise: code " + std::to_string(first) + " exceeds " + std::to_string(bits) +
                                  "-bit range");
    }
  }
}

void DequantisedRows::row(int y, double* out) const {
  const std::uint16_t* src = codes_.ptr<std::uint16_t>(y);
  const int row_len = codes_.cols * codes_.channels();
  if (!value_of_.empty()) {
    for (int i = 0; i < row_len; ++i) out[i] = value_of_[src[i]];
  } else {
    for (int i = 0; i < row_len; ++i) out[i] = dequantise(src[i], max_code_);
  }
}

cv::Mat dequantise(const cv::Mat& codes, int bits) {
  const DequantisedRows rows_of(codes, bits);
  cv::Mat values(codes.size(), CV_MAKETYPE(CV_64F, codes.channels()));
  cv::parallel_for_(cv::Range(0, codes.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) rows_of.row(y, values.ptr<double>(y));
  });
  return values;
}

cv::Mat luma(const cv::Mat& linear_rgb) {
  if (linear_rgb.type() != CV_64FC3) throw std::invalid_argument("luma: expected CV_64FC3 (RGB)");
  cv::Mat y(linear_rgb.size(), CV_64FC1);
  for (int r = 0; r < linear_rgb.rows; ++r) {
    const double* src = linear_rgb.ptr<double>(r);
    double* dst = y.ptr<double>(r);
    for (int x = 0; x < linear_rgb.cols; ++x) {
      dst[x] = 0.2126 * src[3 * x] + 0.7152 * src[3 * x + 1] + 0.0722 * src[3 * x + 2];
    }
  }
  return y;
}

}  // namespace trm
