// Plain value types that cross module boundaries: link frames and their metadata.
//
// Images are cv::Mat with channels in RGB order (never BGR): image I/O converts at the edge.
//   linear / encoded values: CV_64FC3 (or CV_64FC1), normalised to [0, 1]
//   link codes and drive codes: CV_16UC3, q = floor(x * (2^bits - 1) + 0.5)
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace trm {

enum class Parity : std::uint8_t { Full = 0, Reduced = 1 };

// The largest view side the encoder and the decoders accept (pixels). A frame's metadata claims the size of the view
// it reconstructs to; the decoders build taps and frame stores of that size, so a corrupted header must be rejected
// before anything of that size is allocated. 65535 is what a 16-bit line or column counter addresses (far above any
// headset panel), and keeps every index product of the resampling arithmetic ((2x + 1) W, 3 W H) well inside 64 bits.
inline constexpr int kMaxViewSide = 65535;

// The refresh rates trm accepts anywhere (Hz). 1 Hz to 1 kHz spans every panel (TRM itself wants >= 90 Hz); the
// bounds keep frame periods, scene motion per frame and per-frame link budgets finite.
inline constexpr double kMinRefreshHz = 1.0;
inline constexpr double kMaxRefreshHz = 1000.0;
// Throws std::invalid_argument naming `what` unless hz is within [kMinRefreshHz, kMaxRefreshHz].
void validate_refresh_hz(double hz, const std::string& what);

enum class Transfer : std::uint8_t { Srgb = 0, Gamma22 = 1 };

// Space in which D and U act (DESIGN §3): encoded values (default, paper Sec. 4.2) or linear.
enum class ResampleSpace : std::uint8_t { Encoded = 0, Linear = 1 };

const char* to_string(Parity p);
const char* to_string(Transfer t);
const char* to_string(ResampleSpace s);
Transfer parse_transfer(const std::string& name);            // "srgb" | "gamma2.2"; throws std::invalid_argument
ResampleSpace parse_resample_space(const std::string& name);  // "encoded" | "linear"

struct FrameMeta {
  std::int64_t index = 0;    // t = 0, 1, 2, ...
  int eye = 0;               // 0 = left (or mono), 1 = right
  Parity parity = Parity::Full;
  int width = 0;             // size of this frame as sent (reduced size for reduced frames)
  int height = 0;
  int full_width = 0;        // size of the full-resolution view it reconstructs to
  int full_height = 0;
  int bits = 8;              // link bits per channel (8 or 10)
  Transfer transfer = Transfer::Srgb;
};

// The metadata every decoder needs of a view, also of a lost one: index >= 0 (the residual adjacency test compares
// the stored index with index - 1), eye >= 0, and a full size of 1x1 .. kMaxViewSide^2, so that a corrupted header
// is rejected before taps or frame stores of that size are built. Throws std::invalid_argument starting with `what`.
void check_view_meta(const FrameMeta& meta, const std::string& what);

// One view of one link frame: encoded, quantised codes (CV_16UC3, RGB).
struct LinkFrame {
  FrameMeta meta;
  cv::Mat codes;
};

// The largest code of a CV_16U image of any channel count (0 if empty): the range check of every frame a decoder or
// the link takes, in one pass over the rows that the compiler vectorises (cv::minMaxLoc also finds the smallest and
// both locations, several times slower on a headset-size view). Throws std::invalid_argument on another depth.
std::uint16_t highest_code(const cv::Mat& codes);

}  // namespace trm
