// The GPU-side TRM encoder (DESIGN §3-4): per frame parity, a full frame or a reduced frame.
#pragma once

#include "trm/frame.hpp"

#include <vector>

namespace trm {

// The widest Gaussian of D that EncoderConfig accepts (sigma in full-resolution pixels, user-given or 1.25 / r, so
// r >= 1.25 / 256 = 0.0049 with the default sigma). Beyond it D's double rounding error could reach the reduced
// quantiser's tie tolerance (quantise_reduced: 4 n u (2^b - 1) codes with n = 2 ceil(3 sigma) + 1 taps per axis,
// 7.0e-10 code at 256 against 1e-9), so exact half-code ties would no longer be told apart from rounding noise. It
// also keeps R = ceil(3 sigma) <= 768 and the taps of one reduced sample at most 1537 per axis.
inline constexpr double kMaxSigma = 256.0;
// The smallest sigma accepted: far below a pixel D is already the nearest taps averaged, and 1 / (2 sigma^2) must stay
// a finite double (it overflows below about 1e-154).
inline constexpr double kMinSigma = 1e-6;

struct EncoderConfig {
  double reduction = 0.5;      // r in (0, 1]
  double sigma = 0.0;          // <= 0 means default_sigma(r); a user-given sigma must be > 0
  int phase = 0;               // 0: even t full, odd t reduced; 1: swapped
  Transfer transfer = Transfer::Srgb;
  ResampleSpace resample_space = ResampleSpace::Encoded;
  int bits = 8;                // link bits, 8 or 10
  bool stereo = false;         // two eyes off-phase: every link frame carries one full and one reduced view

  double effective_sigma() const;
  // Throws std::invalid_argument with a clear message for r outside (0, 1], sigma < 0, NaN or infinite, an
  // effective sigma above kMaxSigma, bits other than 8/10, phase other than 0/1.
  void validate() const;
};

Parity parity_of(std::int64_t t, int eye, const EncoderConfig& config);

// The reduced frame the encoder sends for an encoded, quantised full frame: Q_b(D(E)), with D in the
// configured resample space and Q_b = quantise_reduced (exact half-code ties round up). Shared with the decoder,
// which recomputes d_t = Q_b(D(E_t)) from the full frame. The view is at most kMaxViewSide per side.
cv::Mat reduce_codes(const cv::Mat& full_codes, const EncoderConfig& config);

class TrmEncoder {
 public:
  explicit TrmEncoder(EncoderConfig config);
  const EncoderConfig& config() const { return config_; }
  // Encodes linear frame t of one eye (CV_64FC3 in [0, 1]) into the view the link carries.
  LinkFrame encode(const cv::Mat& linear_full, std::int64_t t, int eye = 0) const;
  // The same view at a given parity, whatever parity_of says: the display methods other than TRM send full views
  // in every slot they send (or derive theirs from one).
  LinkFrame encode_as(Parity parity, const cv::Mat& linear_full, std::int64_t t, int eye = 0) const;

 private:
  EncoderConfig config_;
};

}  // namespace trm
