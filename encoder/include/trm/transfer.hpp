// Transfer functions and link quantisation (DESIGN §3), in double precision.
#pragma once

#include "trm/frame.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

namespace trm {

// Encoded value -> linear light, and back. Inputs outside [0, 1] are clamped first.
double to_linear(double encoded, Transfer transfer);
double to_encoded(double linear, Transfer transfer);
cv::Mat to_linear(const cv::Mat& encoded, Transfer transfer);   // CV_64F, any channel count
cv::Mat to_encoded(const cv::Mat& linear, Transfer transfer);
// The same doubles for every element of an array (out may be in; the sizes must match), the pows a vector at a time
// (trm/vector_pow.hpp): what the reference decoder calls on each row.
void to_linear(std::span<const double> encoded, std::span<double> linear, Transfer transfer);
void to_encoded(std::span<const double> linear, std::span<double> encoded, Transfer transfer);

// q = floor(x * (2^bits - 1) + 0.5) after clamping x to [0, 1]; returns CV_16U with the same channels.
cv::Mat quantise(const cv::Mat& values, int bits);
// The same for one value not NaN, with max_code = 2^bits - 1 (inline: the reference decoder quantises every sample).
inline std::uint16_t quantise(double value, int max_code) {
  // The sum is >= 0.5, where truncation is floor: one conversion instead of floor's rounding-mode sequence.
  return static_cast<std::uint16_t>(static_cast<int>(std::clamp(value, 0.0, 1.0) * max_code + 0.5));
}
// Q_b of the reduced frame (DESIGN §3 quantisation, deterministic at exact half-code ties). D of symmetric content
// lands exactly on k + 1/2 codes (two codes averaged, a Nyquist checkerboard, an edge midway between two rows); D in
// doubles lands within its rounding error of that half, on either side by floating-point noise, and floor(v + 1/2)
// would round such a tie either way from sample to sample. Here a value within kReducedTieTolerance of a half code
// counts as the half, and halves round up: q = floor(v + 1/2 + tol) with v = clamp(x, 0, 1) (2^bits - 1).
// The tolerance: D is two passes of normalised Gaussian taps over values <= 1; its double rounding error (the tap
// sums, the normalisation and the two dot products) is below 4 n u (2^b - 1) codes for n taps per axis and
// u = 2^-53: 7.7e-12 codes at the default sigma = 2.5 (n = 17, 10-bit link), ~1e-13 in practice, and 7.0e-10 at the
// largest sigma EncoderConfig accepts (kMaxSigma, n = 1537). 1e-9 code lies above that worst case and far below any
// difference the link can carry (a code is 1; the fixed-point decoder's D resolves 2^-40 codes and rounds exact ties
// up, so both sides agree on every tie). A value that is not a tie but within 1e-9 code of a half is rounded up too.
inline constexpr double kReducedTieTolerance = 1e-9;
std::uint16_t quantise_reduced(double value, int bits);
// The same for every element: CV_64F in, CV_16U with the same channels out; NaN is rejected.
cv::Mat quantise_reduced(const cv::Mat& values, int bits);
// code / (2^bits - 1), CV_64F.
cv::Mat dequantise(const cv::Mat& codes, int bits);
// The same for one code, with max_code = 2^bits - 1.
inline double dequantise(std::uint16_t code, int max_code) { return code / static_cast<double>(max_code); }
// dequantise() a row at a time, for a caller that consumes the values row by row and needs no plane of them: the
// codes are checked when it is made (throwing as dequantise() does), and row(y, out) writes row y's cols x channels
// values, the same doubles. row() may be called from several threads at once.
class DequantisedRows {
 public:
  DequantisedRows(const cv::Mat& codes, int bits);
  void row(int y, double* out) const;

 private:
  cv::Mat codes_;
  int max_code_;
  std::vector<double> value_of_;  // every code's value, when the codes outnumber the values
};

// Rec. 709 luma on linear RGB: Y = 0.2126 R + 0.7152 G + 0.0722 B (CV_64FC3 -> CV_64FC1).
cv::Mat luma(const cv::Mat& linear_rgb);

}  // namespace trm
