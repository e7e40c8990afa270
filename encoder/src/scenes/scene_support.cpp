#include "scenes/scene_support.hpp"

#include "trm/media.hpp"
#include "trm/transfer.hpp"

#include <opencv2/imgcodecs.hpp>  // the IMREAD_* flags; the calls go through trm/media.hpp
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace trm::scene_support {

void validate_params(const SceneParams& params, const std::string& scene) {
  const std::string prefix = "scene '" + scene + "': ";
  if (params.width < 1 || params.height < 1) {
    throw std::invalid_argument(prefix + "size must be at least 1x1, got " + std::to_string(params.width) + "x" +
                                std::to_string(params.height));
  }
  validate_refresh_hz(params.refresh_hz, prefix + "the scene's refresh");
  if (params.supersample < 1 || params.supersample > 64) {
    throw std::invalid_argument(prefix + "supersample must be in [1, 64], got " + std::to_string(params.supersample));
  }
}

double frame_time(std::int64_t t, double refresh_hz) {
  if (t < 0) throw std::invalid_argument("frame index must be >= 0, got " + std::to_string(t));
  return static_cast<double>(t) / refresh_hz;
}

std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double hash_unit(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
  std::uint64_t h = mix64(seed);
  h = mix64(h ^ a);
  h = mix64(h ^ b);
  h = mix64(h ^ c);
  h = mix64(h ^ d);
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

double NormalStream::next() {
  const double u1 = 1.0 - hash_unit(seed_, counter_, 0x4e4f524dULL, 1, 0);  // (0, 1]: log is finite
  const double u2 = hash_unit(seed_, counter_, 0x4e4f524dULL, 2, 0);
  ++counter_;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

namespace {

// Uniform cubic B-spline: smooth (C2) and non-negative, so interpolated noise never overshoots its lattice.
double bspline(double u) {
  u = std::abs(u);
  if (u < 1.0) return (4.0 - 6.0 * u * u + 3.0 * u * u * u) / 6.0;
  if (u < 2.0) {
    const double v = 2.0 - u;
    return v * v * v / 6.0;
  }
  return 0.0;
}

// Box-filtered B-spline weights of the lattice (spacing `spacing` pixels) for every pixel along one axis:
// pixel p covers [p, p + 1); its weight on lattice node i is the mean of B(X / spacing - i) over
// `supersample` evenly spread sample points X in the pixel.
constexpr int kMaxTaps = 6;  // a pixel spans <= 1 lattice cell (spacing >= 1), the B-spline 4 cells
struct AxisWeights {
  std::vector<int> first;                            // first lattice node per pixel
  std::vector<std::array<double, kMaxTaps>> weight;  // weights of nodes first .. first + kMaxTaps - 1
};

AxisWeights axis_weights(int pixels, int spacing, int supersample) {
  AxisWeights aw;
  aw.first.resize(static_cast<std::size_t>(pixels));
  aw.weight.resize(static_cast<std::size_t>(pixels));
  for (int p = 0; p < pixels; ++p) {
    const int first = static_cast<int>(std::floor(static_cast<double>(p) / spacing)) - 2;
    std::array<double, kMaxTaps> w{};
    for (int k = 0; k < supersample; ++k) {
      const double u = (p + (k + 0.5) / supersample) / spacing;
      for (int m = 0; m < kMaxTaps; ++m) w[static_cast<std::size_t>(m)] += bspline(u - (first + m)) / supersample;
    }
    aw.first[static_cast<std::size_t>(p)] = first;
    aw.weight[static_cast<std::size_t>(p)] = w;
  }
  return aw;
}

// One octave of value noise, box-filtered per pixel: width x height CV_64FC1, periodic in x with period
// `period_nodes` lattice nodes.
cv::Mat noise_octave(int width, int height, int spacing, int period_nodes, std::uint64_t seed, std::uint64_t octave,
                     std::uint64_t channel, int supersample) {
  const AxisWeights wx = axis_weights(width, spacing, supersample);
  const AxisWeights wy = axis_weights(height, spacing, supersample);
  const int first_row = wy.first.front();
  const int rows = wy.first.back() + kMaxTaps - first_row;
  // Horizontal pass: interpolate every lattice row at every pixel column.
  cv::Mat lattice_rows(rows, width, CV_64FC1);
  std::vector<double> nodes(static_cast<std::size_t>(period_nodes));
  for (int r = 0; r < rows; ++r) {
    const int j = first_row + r;
    for (int i = 0; i < period_nodes; ++i) {
      nodes[static_cast<std::size_t>(i)] = hash_unit(seed, octave, channel, static_cast<std::uint64_t>(i),
                                                     static_cast<std::uint64_t>(static_cast<std::int64_t>(j)));
    }
    double* dst = lattice_rows.ptr<double>(r);
    for (int x = 0; x < width; ++x) {
      double acc = 0.0;
      const auto& w = wx.weight[static_cast<std::size_t>(x)];
      for (int m = 0; m < kMaxTaps; ++m) {
        const int i = ((wx.first[static_cast<std::size_t>(x)] + m) % period_nodes + period_nodes) % period_nodes;
        acc += w[static_cast<std::size_t>(m)] * nodes[static_cast<std::size_t>(i)];
      }
      dst[x] = acc;
    }
  }
  // Vertical pass.
  cv::Mat out(height, width, CV_64FC1, cv::Scalar(0.0));
  for (int y = 0; y < height; ++y) {
    double* dst = out.ptr<double>(y);
    const auto& w = wy.weight[static_cast<std::size_t>(y)];
    for (int m = 0; m < kMaxTaps; ++m) {
      const double* src = lattice_rows.ptr<double>(wy.first[static_cast<std::size_t>(y)] + m - first_row);
      const double wm = w[static_cast<std::size_t>(m)];
      if (wm == 0.0) continue;
      for (int x = 0; x < width; ++x) dst[x] += wm * src[x];
    }
  }
  return out;
}

constexpr int kCoarsestSpacing = 256;
constexpr std::array<int, 7> kLumaSpacings{256, 128, 64, 32, 16, 8, 4};
constexpr std::array<int, 2> kChromaSpacings{256, 64};

}  // namespace

int procedural_texture_period_quantum() { return kCoarsestSpacing; }

cv::Mat procedural_texture(int width, int height, std::uint64_t seed, int supersample) {
  if (width < 1 || height < 1 || supersample < 1) throw std::invalid_argument("procedural_texture: bad size");
  const int period = (width + kCoarsestSpacing - 1) / kCoarsestSpacing * kCoarsestSpacing;

  // Brightness: octaves with amplitude growing as spacing^0.6. A value-noise octave already concentrates
  // its energy near its own scale, so this gives a falling (roughly 1/f) spectrum while keeping visible
  // fine detail. Mean-free sum, then a soft sigmoid for photographic contrast without hard clipping.
  cv::Mat brightness(height, width, CV_64FC1, cv::Scalar(0.0));
  double amplitude_sum = 0.0;
  for (std::size_t k = 0; k < kLumaSpacings.size(); ++k) {
    const int s = kLumaSpacings[k];
    const double a = std::pow(static_cast<double>(s), 0.6);
    brightness += a * (noise_octave(width, height, s, period / s, seed, k, 0, supersample) - 0.5);
    amplitude_sum += a;
  }
  brightness /= amplitude_sum;

  // Colour: slowly varying per-channel tints.
  std::array<cv::Mat, 3> tint;
  for (std::uint64_t c = 0; c < 3; ++c) {
    tint[c] = cv::Mat(height, width, CV_64FC1, cv::Scalar(0.0));
    for (std::size_t k = 0; k < kChromaSpacings.size(); ++k) {
      const int s = kChromaSpacings[k];
      tint[c] += (noise_octave(width, height, s, period / s, seed, 100 + k, 1 + c, supersample) - 0.5) /
                 static_cast<double>(kChromaSpacings.size());
    }
  }

  cv::Mat texture(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y) {
    const double* b = brightness.ptr<double>(y);
    cv::Vec3f* dst = texture.ptr<cv::Vec3f>(y);
    for (int x = 0; x < width; ++x) {
      // The sigmoid acts on an sRGB-like encoded value, which is then linearised: the texture has the
      // dark-heavy linear histogram of real photographs.
      const double encoded_grey = 0.5 + 0.5 * std::tanh(9.0 * b[x]);
      for (int c = 0; c < 3; ++c) {
        const double encoded = std::clamp(encoded_grey * (1.0 + 2.0 * tint[static_cast<std::size_t>(c)].ptr<double>(y)[x]), 0.0, 1.0);
        dst[x][c] = static_cast<float>(to_linear(encoded, Transfer::Srgb));
      }
    }
  }
  return texture;
}

cv::Mat box_shift(const cv::Mat& texture, double ox, double oy, int width, int height, bool wrap_x) {
  if (texture.type() != CV_32FC3 || texture.empty()) throw std::invalid_argument("box_shift: expected CV_32FC3 texture");
  const double fx_floor = std::floor(ox), fy_floor = std::floor(oy);
  const double fx = ox - fx_floor, fy = oy - fy_floor;
  const std::int64_t nx = static_cast<std::int64_t>(fx_floor), ny = static_cast<std::int64_t>(fy_floor);
  const std::int64_t tw = texture.cols, th = texture.rows;
  auto col = [&](std::int64_t c) {
    return static_cast<int>(wrap_x ? ((c % tw) + tw) % tw : std::clamp<std::int64_t>(c, 0, tw - 1));
  };
  std::vector<int> c0(static_cast<std::size_t>(width)), c1(static_cast<std::size_t>(width));
  for (int x = 0; x < width; ++x) {
    c0[static_cast<std::size_t>(x)] = col(x + nx);
    c1[static_cast<std::size_t>(x)] = col(x + nx + 1);
  }
  const double w00 = (1 - fy) * (1 - fx), w01 = (1 - fy) * fx, w10 = fy * (1 - fx), w11 = fy * fx;
  cv::Mat out(height, width, CV_64FC3);
  for (int y = 0; y < height; ++y) {
    const cv::Vec3f* r0 = texture.ptr<cv::Vec3f>(static_cast<int>(std::clamp<std::int64_t>(y + ny, 0, th - 1)));
    const cv::Vec3f* r1 = texture.ptr<cv::Vec3f>(static_cast<int>(std::clamp<std::int64_t>(y + ny + 1, 0, th - 1)));
    cv::Vec3d* dst = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < width; ++x) {
      const cv::Vec3f& a = r0[c0[static_cast<std::size_t>(x)]];
      const cv::Vec3f& b = r0[c1[static_cast<std::size_t>(x)]];
      const cv::Vec3f& c = r1[c0[static_cast<std::size_t>(x)]];
      const cv::Vec3f& d = r1[c1[static_cast<std::size_t>(x)]];
      for (int ch = 0; ch < 3; ++ch) {
        // Clamp guards against the last-bit excursions of the blend; the blend itself is convex.
        dst[x][ch] = std::clamp(w00 * a[ch] + w01 * b[ch] + w10 * c[ch] + w11 * d[ch], 0.0, 1.0);
      }
    }
  }
  return out;
}

namespace {

// Lookup table from n-bit sRGB codes to linear light.
std::vector<double> srgb_lut(int max_code) {
  std::vector<double> lut(static_cast<std::size_t>(max_code) + 1);
  for (int i = 0; i <= max_code; ++i) lut[static_cast<std::size_t>(i)] = to_linear(static_cast<double>(i) / max_code, Transfer::Srgb);
  return lut;
}

const std::vector<double>& srgb_lut8() {
  static const std::vector<double> lut = srgb_lut(255);
  return lut;
}
const std::vector<double>& srgb_lut16() {
  static const std::vector<double> lut = srgb_lut(65535);
  return lut;
}

// Channel index in an OpenCV (BGR / BGRA / grey / grey+alpha) image for output RGB channel c.
int source_channel(int channels, int rgb) {
  if (channels <= 2) return 0;  // grey, or grey + alpha (alpha dropped)
  return 2 - rgb;               // BGR(A) -> RGB
}

template <typename T>
cv::Mat linearise_integer(const cv::Mat& img, const std::vector<double>& lut) {
  const int channels = img.channels();
  cv::Mat out(img.size(), CV_64FC3);
  for (int y = 0; y < img.rows; ++y) {
    const T* src = img.ptr<T>(y);
    cv::Vec3d* dst = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < img.cols; ++x)
      for (int c = 0; c < 3; ++c) dst[x][c] = lut[src[x * channels + source_channel(channels, c)]];
  }
  return out;
}

// OpenCV gives a file with "DICM" at byte 128 (the DICOM signature) to its GDCM decoder, and GDCM aborts
// the whole process on a failed assertion when such a file is malformed (found by fuzz/fuzz_image.cpp:
// 128 zero bytes and "DICM" are enough). No headset content is DICOM, so such files are refused first.
bool has_dicom_signature(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[132];
  return in.read(head, sizeof head) && std::memcmp(head + 128, "DICM", 4) == 0;
}

}  // namespace

cv::Mat load_linear_image(const std::string& path) {
  if (has_dicom_signature(path))
    throw std::runtime_error("image '" + path + "' is a DICOM file (\"DICM\" at byte 128); DICOM images are not supported");
  cv::Mat img;
  try {
    img = media::read_image(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot read image '" + path + "': " + e.what());
  }
  if (img.empty()) throw std::runtime_error("cannot read image '" + path + "' (missing, unreadable or not an image)");
  const int channels = img.channels();
  if (channels < 1 || channels > 4) {
    throw std::runtime_error("image '" + path + "' has an unsupported channel count " + std::to_string(channels));
  }
  switch (img.depth()) {
    case CV_8U: return linearise_integer<std::uint8_t>(img, srgb_lut8());
    case CV_16U: return linearise_integer<std::uint16_t>(img, srgb_lut16());
    case CV_32F:
    case CV_64F: {
      cv::Mat as_double;
      img.convertTo(as_double, CV_64F);
      cv::Point bad;
      if (!cv::checkRange(as_double, true, &bad, 0.0, 1.0 + 1e-12)) {
        throw std::invalid_argument("image '" + path + "' has NaN, Inf or values outside [0, 1] (first at x=" +
                                    std::to_string(bad.x) + ", y=" + std::to_string(bad.y) + ")");
      }
      cv::Mat out(img.size(), CV_64FC3);
      for (int y = 0; y < img.rows; ++y) {
        const double* src = as_double.ptr<double>(y);
        cv::Vec3d* dst = out.ptr<cv::Vec3d>(y);
        for (int x = 0; x < img.cols; ++x)
          for (int c = 0; c < 3; ++c) dst[x][c] = std::min(1.0, src[x * channels + source_channel(channels, c)]);
      }
      return out;  // floating-point files carry linear light
    }
    default:
      throw std::runtime_error("image '" + path + "' has an unsupported sample type (need 8/16-bit or float)");
  }
}

cv::Mat linear_from_bgr8(const cv::Mat& bgr8) {
  if (bgr8.depth() != CV_8U) throw std::runtime_error("video frame is not 8-bit");
  return linearise_integer<std::uint8_t>(bgr8, srgb_lut8());
}

namespace {
cv::Mat resize_linear_light(const cv::Mat& linear, cv::Size size) {
  if (size == linear.size()) return linear.clone();
  const bool shrinking = size.width < linear.cols || size.height < linear.rows;
  cv::Mat out;
  cv::resize(linear, out, size, 0, 0, shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
  cv::min(cv::max(out, 0.0), 1.0, out);  // both filters are convex; this only removes rounding excursions
  return out;
}
}  // namespace

cv::Mat fit_cover(const cv::Mat& linear, int width, int height) {
  const double scale = std::max(static_cast<double>(width) / linear.cols, static_cast<double>(height) / linear.rows);
  const int sw = std::max(width, static_cast<int>(std::lround(linear.cols * scale)));
  const int sh = std::max(height, static_cast<int>(std::lround(linear.rows * scale)));
  const cv::Mat scaled = resize_linear_light(linear, cv::Size(sw, sh));
  return scaled(cv::Rect((sw - width) / 2, (sh - height) / 2, width, height)).clone();
}

cv::Mat fit_height(const cv::Mat& linear, int height) {
  const double scale = static_cast<double>(height) / linear.rows;
  const int sw = std::max(1, static_cast<int>(std::lround(linear.cols * scale)));
  return resize_linear_light(linear, cv::Size(sw, height));
}

}  // namespace trm::scene_support
