// Building blocks shared by the scenes and the file sources (private to the encoder module).
#pragma once

#include "trm/scene.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace trm::scene_support {

// Throws std::invalid_argument unless the size, refresh rate and supersampling factor are usable.
void validate_params(const SceneParams& params, const std::string& scene);

// Seconds since frame 0; throws std::invalid_argument for t < 0.
double frame_time(std::int64_t t, double refresh_hz);

// Deterministic, platform-independent randomness (std:: distributions are implementation-defined).
std::uint64_t mix64(std::uint64_t x);                                   // splitmix64 finaliser
double hash_unit(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d);  // [0, 1)
class NormalStream {  // standard normal variates by Box-Muller from a counter-based hash
 public:
  explicit NormalStream(std::uint64_t seed) : seed_(seed) {}
  double next();
 private:
  std::uint64_t seed_;
  std::uint64_t counter_ = 0;
};

// A natural-looking colour texture in linear light (CV_32FC3, values in [0, 1]): multi-octave value noise
// on a cubic B-spline lattice with a 1/f-like amplitude spectrum, box-filtered over each pixel by
// supersampling the (separable) interpolation weights. The noise is periodic in x with period `width`
// rounded up to the coarsest lattice spacing; `width` itself may be anything >= 1.
cv::Mat procedural_texture(int width, int height, std::uint64_t seed, int supersample);

// The coarsest lattice spacing of procedural_texture: widths that are multiples of it tile seamlessly.
int procedural_texture_period_quantum();

// The box filter of a piecewise-constant texture (one constant per texel) over the pixel square
// [x + ox, x + ox + 1) x [y + oy, y + oy + 1): because the shift is the same for every pixel, this is a
// bilinear blend of four texels with fixed weights. x wraps modulo the texture width when wrap_x is set;
// otherwise (and always in y) indices are clamped. Returns CV_64FC3 width x height.
cv::Mat box_shift(const cv::Mat& texture, double ox, double oy, int width, int height, bool wrap_x);

// Reads an image file as linear-light RGB (CV_64FC3 in [0, 1]). 8/16-bit data is sRGB-encoded and
// linearised; floating-point data (TIFF/EXR) is taken as linear light. Grey is replicated, alpha dropped.
// Throws std::runtime_error naming the file when it cannot be read or has an unsupported depth, and
// std::invalid_argument naming it for NaN, Inf, negative or > 1 content.
cv::Mat load_linear_image(const std::string& path);

// sRGB-encoded 8-bit BGR (as delivered by OpenCV video capture) -> linear RGB CV_64FC3.
cv::Mat linear_from_bgr8(const cv::Mat& bgr8);

// Scales (in linear light) to cover width x height and centre-crops; CV_64FC3 in [0, 1].
cv::Mat fit_cover(const cv::Mat& linear, int width, int height);
// Scales to the given height keeping the aspect ratio (width at least 1).
cv::Mat fit_height(const cv::Mat& linear, int height);

}  // namespace trm::scene_support
