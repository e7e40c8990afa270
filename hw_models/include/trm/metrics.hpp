// Metrics (DESIGN §6 "What correct means", §7): what the viewer sees against what full-rate rendering would show,
// and how closely a decoder's output codes agree with the double-precision reference's. Each metric is a function
// over cv::Mat (or a running record of them) so that reports, the sweep and the tests measure with the same code.
#pragma once

#include "trm/oled_drive_codes.hpp"
#include "trm/panel.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

namespace trm {

// ---- light the eye sees ----

// Talbot-Plateau: the eye sees the time average of linear light over a pair.
cv::Mat perceived_pair(const cv::Mat& linear_a, const cv::Mat& linear_b);

// The pair frames t-1 and t make on `panel`, from the light it emitted in each. OLED: their Talbot-Plateau average.
// LCD: the emission of frame t, which the merge M(v_t, v_{t-1}) (Eq. 7) already makes the pair's.
cv::Mat perceived_pair(const Panel& panel, const cv::Mat& emitted_previous, const cv::Mat& emitted);

// What `panel` emits for the linear frame (CV_64FC3, [0, 1]) when every frame is rendered and shown at full
// resolution: the double-precision drive of each value, rounded to output_bits like any decoder's, emitted back.
// The pair of two such frames is the full-rate reference a reduced-rate method's perceived pair is held to.
cv::Mat full_rate_emission(const cv::Mat& linear, const Panel& panel, int output_bits);

// full_rate_emission of one panel and output depth with its tables built once, the same doubles: an OLED's codes from
// where each code begins (OledDriveCodes) instead of a pow per sample, and the light of every code held
// (Panel::linear_from_drive of code / (2^bits - 1), per channel) instead of a second one. For a report that takes the
// reference of every view. output_bits in [1, 16] (else std::invalid_argument).
class FullRateEmission {
 public:
  FullRateEmission(const Panel& panel, int output_bits);
  cv::Mat operator()(const cv::Mat& linear) const;

 private:
  Panel panel_;
  int top_;
  std::optional<OledDriveCodes> oled_codes_;  // an OLED's
  std::array<std::vector<double>, 3> held_light_;  // [channel][code]
};

// Frame pairs as the eye sees them at a fixed gaze, per eye. Views come in slot order with their emitted light and
// the full-rate reference's emission (full_rate_emission of the scene at that t); a view that completes a pair
// (frames 2k and 2k + 1 of one eye) returns the perceived pair and the full-rate reference pair.
class PairTracker {
 public:
  explicit PairTracker(Panel panel) : panel_(std::move(panel)) {}
  struct Pair {
    std::int64_t first = 0;  // t of the pair's first frame
    cv::Mat perceived;
    cv::Mat reference;
  };
  std::optional<Pair> add(int eye, std::int64_t t, const cv::Mat& emitted, const cv::Mat& reference_emitted);

 private:
  struct Previous {
    std::int64_t t = -1;
    cv::Mat emitted, reference;
  };
  Panel panel_;
  std::map<int, Previous> previous_;
};

// PSNR in dB (peak 1) of two linear-light images measured on their sRGB encodings, where equal steps are about
// equally visible; +inf when the encodings are identical.
double psnr_srgb(const cv::Mat& linear_a, const cv::Mat& linear_b);

// SSIM (Wang et al. 2004, OpenCV's quality module: 11x11 Gaussian window, sigma 1.5, K1 = 0.01, K2 = 0.03) of two
// linear-light images on their 8-bit-scale sRGB encodings (display values, as SSIM is defined on), the mean over
// channels; 1 for identical images. Throws std::invalid_argument for images of different sizes or types.
double ssim_srgb(const cv::Mat& linear_a, const cv::Mat& linear_b);

// ---- output codes against the reference ----

// Drive codes of a decoder against the reference's (rounded to the same output depth), over one or many views.
struct CodeAgreement {
  std::int64_t compared = 0;   // codes: pixels x channels
  std::int64_t identical = 0;
  double max_lsb = 0.0;        // max |Δ| in output LSB
  double sum_lsb = 0.0;        // Σ |Δ|
  double sum_squared_lsb = 0.0;

  std::int64_t differing() const { return compared - identical; }
  double identical_fraction() const;  // 0 when nothing was compared
  double identical_percent() const;
  double mean_lsb() const;
  double rms_lsb() const;
  // Adds the codes of further views.
  CodeAgreement& operator+=(const CodeAgreement& other);
};

// One view's codes (any integer type, any number of channels, same size and type as reference_codes). Throws
// std::invalid_argument when the two do not match.
CodeAgreement compare_codes(const cv::Mat& codes, const cv::Mat& reference_codes);

// LCD: the largest difference of the merge M(v_t, v_{t-1}) (Eq. 7) the eye sees, recovered from two emissions of
// the panel (luminance M^gamma), in output codes. Codes may differ by a few LSB while M stays within one code (a
// difference in v_{t-1} is answered by the opposite one in v_t), so this is what free-running LCD decoders are
// compared on.
double max_merge_difference_codes(const cv::Mat& emitted_linear, const cv::Mat& reference_emitted_linear,
                                  const LcdPanel& lcd, int output_bits);

// How closely output codes must agree with the reference: at least min_identical_fraction of them identical, none
// more than max_lsb away.
struct AgreementCriterion {
  double min_identical_fraction = 1.0;
  double max_lsb = 0.0;

  constexpr double min_identical_percent() const { return 100.0 * min_identical_fraction; }
  // `identical` of `compared` codes, the largest difference max_difference_lsb. An empty comparison fails.
  constexpr bool met_by(std::int64_t identical, std::int64_t compared, double max_difference_lsb) const {
    return compared > 0 &&
           static_cast<double>(identical) / static_cast<double>(compared) >= min_identical_fraction &&
           max_difference_lsb <= max_lsb;
  }
  constexpr bool met_by(const CodeAgreement& agreement) const {
    return met_by(agreement.identical, agreement.compared, agreement.max_lsb);
  }
};

// DESIGN §6: at the default formats the fixed-point decoder leaves at least 99.9 % of its output codes identical to
// the reference rounded to the output depth, the rest within 1 LSB.
inline constexpr AgreementCriterion kReferenceAgreementCriterion{0.999, 1.0};

}  // namespace trm
