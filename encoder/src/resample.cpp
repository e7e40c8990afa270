// D (polyphase Gaussian decimator) and U (bilinear upsampler), DESIGN §3.
//
// All sample positions are derived from integers. A reduced sample x_low along an axis of full size W
// and reduced size w sits at c = ((2 x_low + 1) W - w) / (2 w) in full-resolution pixel coordinates;
// a full pixel x maps to x_low = ((2x + 1) w - W) / (2 W) in reduced coordinates. Keeping the
// numerators as integers makes tap membership (|i - c| <= R) and integer centres exact.
#include "trm/resample.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

// Floor division for a positive divisor (C++ '/' truncates towards zero).
std::int64_t floor_div(std::int64_t num, std::int64_t den) {
  std::int64_t q = num / den;
  if ((num % den != 0) && (num < 0)) --q;
  return q;
}

std::int64_t ceil_div(std::int64_t num, std::int64_t den) { return -floor_div(-num, den); }

void require_axis(int full, int reduced, const char* what) {
  if (full < 1 || reduced < 1 || reduced > full) {
    throw std::invalid_argument(std::string(what) + ": need 1 <= reduced <= full, got full=" +
                                std::to_string(full) + " reduced=" + std::to_string(reduced));
  }
}

// U's source and width, checked before any work by both upsample() and upsample_horizontal().
void require_upsample_source(const cv::Mat& reduced, int full_width) {
  if (reduced.depth() != CV_64F || reduced.empty()) throw std::invalid_argument("upsample: expected a non-empty CV_64F matrix");
  require_axis(full_width, reduced.cols, "upsample (width)");
}

void require_sigma(double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) {
    throw std::invalid_argument("Gaussian sigma must be finite and > 0, got " + std::to_string(sigma));
  }
}

// Taps of one output sample with indices already clamped into [0, full - 1] (replicate border).
struct ClampedTaps {
  std::vector<int> index;
  std::vector<double> weight;
};

std::vector<ClampedTaps> clamped_gaussian_taps(int full, int reduced, double sigma) {
  std::vector<ClampedTaps> all(static_cast<std::size_t>(reduced));
  for (int x = 0; x < reduced; ++x) {
    const GaussianTaps taps = gaussian_taps(x, full, reduced, sigma);
    ClampedTaps& out = all[static_cast<std::size_t>(x)];
    out.weight = taps.weights;
    out.index.resize(taps.weights.size());
    for (std::size_t k = 0; k < taps.weights.size(); ++k) {
      out.index[k] = std::clamp(taps.first_index + static_cast<int>(k), 0, full - 1);
    }
  }
  return all;
}

// The outputs of D's horizontal pass that one polyphase loop can compute: where the full width is f times the reduced
// one, the outputs [lo, hi) whose taps are the middle output's weights bit for bit over consecutive unclamped indexes
// that advance by f per output (the interior; the clamped borders keep the per-output loop).
struct PolyphaseRun {
  int factor = 0;  // f; 0: no run
  int lo = 0;
  int hi = 0;
  int first = 0;   // index of lo's first tap
  const std::vector<double>* weight = nullptr;
};

PolyphaseRun polyphase_run(const std::vector<ClampedTaps>& taps, int full, int reduced) {
  PolyphaseRun run;
  if (full % reduced != 0) return run;
  const int f = full / reduced;
  const int middle = reduced / 2;
  const ClampedTaps& model = taps[static_cast<std::size_t>(middle)];
  const auto regular = [&](int x) {
    const ClampedTaps& t = taps[static_cast<std::size_t>(x)];
    if (t.weight.size() != model.weight.size()) return false;
    const int first = model.index[0] + f * (x - middle);
    for (std::size_t k = 0; k < t.weight.size(); ++k) {
      if (t.index[k] != first + static_cast<int>(k)) return false;
      if (std::memcmp(&t.weight[k], &model.weight[k], sizeof(double)) != 0) return false;
    }
    return true;
  };
  if (!regular(middle)) return run;
  run.lo = middle;
  while (run.lo > 0 && regular(run.lo - 1)) --run.lo;
  run.hi = middle + 1;
  while (run.hi < reduced && regular(run.hi)) ++run.hi;
  run.factor = f;
  run.first = model.index[0] + f * (run.lo - middle);
  run.weight = &model.weight;
  return run;
}

}  // namespace

namespace resample_detail {

// The element-wise loops of D and U, compiled for AVX2 too and chosen at run time (GCC's function multi-versioning):
// four doubles a vector there, two on the x86-64 baseline. "avx2" enables no FMA, so every product and sum is
// rounded as in the baseline: the same doubles.
[[gnu::target_clones("avx2", "default")]] void add_weighted(double* sum, const double* in, double w, int n) {
  for (int j = 0; j < n; ++j) sum[j] += w * in[j];
}

[[gnu::target_clones("avx2", "default")]] void blend(double* out, const double* a, const double* b, double frac,
                                                     int n) {
  for (int i = 0; i < n; ++i) out[i] = (1.0 - frac) * a[i] + frac * b[i];
}

}  // namespace resample_detail

int reduced_size(int full, double r) {
  if (full < 1) throw std::invalid_argument("reduced_size: full size must be >= 1, got " + std::to_string(full));
  if (!(r > 0.0 && r <= 1.0)) {
    throw std::invalid_argument("reduced_size: reduction r must be in (0, 1], got " + std::to_string(r));
  }
  // Round half up (97 x 0.5 -> 49), never below one pixel.
  return std::max(1, static_cast<int>(std::floor(r * full + 0.5)));
}

double default_sigma(double r) {
  if (!(r > 0.0 && r <= 1.0)) {
    throw std::invalid_argument("default_sigma: reduction r must be in (0, 1], got " + std::to_string(r));
  }
  return 1.25 / r;  // sigma = 2.5 full pixels at r = 1/2 (paper Sec. 4.3)
}

double reduced_centre(int x_low, int full, int reduced) {
  const std::int64_t num = (2 * static_cast<std::int64_t>(x_low) + 1) * full - reduced;
  return static_cast<double>(num) / (2.0 * reduced);
}

int gaussian_radius(double sigma) {
  require_sigma(sigma);
  // R must fit an int with room for the tap arithmetic (EncoderConfig bounds sigma far lower, kMaxSigma).
  if (sigma > 1e8) {
    throw std::invalid_argument("Gaussian sigma must be <= 1e8 (R = ceil(3 sigma) as an int), got " +
                                std::to_string(sigma));
  }
  // R = ceil(3 sigma). sigma usually arrives as 1.25 / r, whose last-bit rounding can push 3 sigma just
  // above an integer (e.g. 5.000000000000001); a relative slack of 1e-12 keeps such cases at the
  // intended integer without affecting any sigma that is meaningfully above it.
  return static_cast<int>(std::ceil(3.0 * sigma * (1.0 - 1e-12)));
}

GaussianTaps gaussian_taps(int x_low, int full, int reduced, double sigma) {
  require_axis(full, reduced, "gaussian_taps");
  const int radius = gaussian_radius(sigma);
  // c = num / den exactly. |i - c| <= R  <=>  num - R den <= i den <= num + R den.
  const std::int64_t den = 2 * static_cast<std::int64_t>(reduced);
  const std::int64_t num = (2 * static_cast<std::int64_t>(x_low) + 1) * full - reduced;
  const std::int64_t first = ceil_div(num - radius * den, den);
  const std::int64_t last = floor_div(num + radius * den, den);

  GaussianTaps taps;
  taps.first_index = static_cast<int>(first);
  taps.weights.reserve(static_cast<std::size_t>(last - first + 1));
  // Every weight relative to the largest (the tap nearest c): exp(-((i - c)^2 - d^2) / 2 sigma^2) with d the
  // nearest tap's distance. The normalised taps are the same Gaussian, but the sum is >= 1 for every sigma > 0, so
  // a sigma far below a pixel (where every absolute weight exp(-(i - c)^2 / 2 sigma^2) underflows to 0) cannot
  // make it 0 / 0. Mirror-image taps keep equal weights.
  std::int64_t nearest = std::abs(first * den - num);
  for (std::int64_t i = first + 1; i <= last; ++i) nearest = std::min(nearest, std::abs(i * den - num));
  const double nearest_offset = static_cast<double>(nearest) / static_cast<double>(den);
  const double inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  double sum = 0.0;
  for (std::int64_t i = first; i <= last; ++i) {
    const double offset = static_cast<double>(i * den - num) / static_cast<double>(den);  // i - c
    const double w = std::exp(-(offset * offset - nearest_offset * nearest_offset) * inv_two_sigma2);
    taps.weights.push_back(w);
    sum += w;
  }
  for (double& w : taps.weights) w /= sum;
  return taps;
}

BilinearTap bilinear_tap(int x, int full, int reduced) {
  require_axis(full, reduced, "bilinear_tap");
  // x_low = num / den exactly, with num = (2x + 1) w - W and den = 2W.
  const std::int64_t den = 2 * static_cast<std::int64_t>(full);
  const std::int64_t num = (2 * static_cast<std::int64_t>(x) + 1) * reduced - full;
  BilinearTap tap;
  if (num < 0) {  // left of the first reduced centre: OpenCV INTER_LINEAR clamps to sample 0
    tap.i0 = 0;
    tap.i1 = std::min(1, reduced - 1);
    tap.frac = 0.0;
    return tap;
  }
  const std::int64_t i0 = num / den;
  if (i0 >= reduced - 1) {  // at or right of the last reduced centre
    tap.i0 = tap.i1 = reduced - 1;
    tap.frac = 0.0;
    return tap;
  }
  tap.i0 = static_cast<int>(i0);
  tap.i1 = tap.i0 + 1;
  tap.frac = static_cast<double>(num - i0 * den) / static_cast<double>(den);
  return tap;
}

cv::Mat downsample(const cv::Mat& full, int reduced_width, int reduced_height, double sigma) {
  if (full.depth() != CV_64F || full.empty()) throw std::invalid_argument("downsample: expected a non-empty CV_64F matrix");
  return downsample(
      full.size(), full.channels(), [&full](int y, double*) { return full.ptr<double>(y); }, reduced_width,
      reduced_height, sigma);
}

cv::Mat downsample(cv::Size full_size, int channels, const FullRow& full_row, int reduced_width, int reduced_height,
                   double sigma) {
  if (full_size.width < 1 || full_size.height < 1 || channels < 1 || channels > CV_CN_MAX) {
    throw std::invalid_argument("downsample: expected a non-empty frame");
  }
  require_axis(full_size.width, reduced_width, "downsample (width)");
  require_axis(full_size.height, reduced_height, "downsample (height)");
  require_sigma(sigma);
  const int type = CV_MAKETYPE(CV_64F, channels);
  const std::vector<ClampedTaps> col_taps = clamped_gaussian_taps(full_size.width, reduced_width, sigma);
  const std::vector<ClampedTaps> row_taps = clamped_gaussian_taps(full_size.height, reduced_height, sigma);

  // Horizontal pass: every full row -> reduced_width samples.
  // Both passes split their output rows over OpenCV's threads: each output sample is one sum in a fixed order, so the
  // doubles do not depend on the split.
  //
  // The interior (PolyphaseRun) is summed a tap at a time over all its outputs, from planes of the row by channel and
  // phase (sample f j + p of channel c at plane c f + p, index j), so each tap is one contiguous multiply-add over
  // the run that the compiler vectorises. Every output is still 0 + w_0 s_0 + w_1 s_1 + ... in tap order: the same
  // doubles as the per-output loop.
  const PolyphaseRun run = polyphase_run(col_taps, full_size.width, reduced_width);
  cv::Mat horizontal(full_size.height, reduced_width, type);
  cv::parallel_for_(cv::Range(0, full_size.height), [&](const cv::Range& rows) {
    const int f = run.factor;
    const int run_length = run.hi - run.lo;
    std::vector<double> planes(f > 0 ? static_cast<std::size_t>(channels) * full_size.width : 0);
    std::vector<double> sums(static_cast<std::size_t>(run_length));
    // Not initialised: a row source that uses it fills it.
    const auto scratch = std::make_unique_for_overwrite<double[]>(static_cast<std::size_t>(channels) * full_size.width);
    for (int y = rows.start; y < rows.end; ++y) {
      const double* src = full_row(y, scratch.get());
      double* dst = horizontal.ptr<double>(y);
      if (f > 0) {
        for (int ch = 0; ch < channels; ++ch) {
          for (int p = 0; p < f; ++p) {
            double* plane = planes.data() + static_cast<std::size_t>(ch * f + p) * reduced_width;
            for (int j = 0; j < reduced_width; ++j) plane[j] = src[(f * j + p) * channels + ch];
          }
        }
        for (int ch = 0; ch < channels; ++ch) {
          std::fill(sums.begin(), sums.end(), 0.0);
          double* sum = sums.data();
          for (std::size_t k = 0; k < run.weight->size(); ++k) {
            const int q = run.first + static_cast<int>(k);  // >= 0: the run's indexes are unclamped
            const double w = (*run.weight)[k];
            const double* in = planes.data() + static_cast<std::size_t>(ch * f + q % f) * reduced_width + q / f;
            resample_detail::add_weighted(sum, in, w, run_length);
          }
          for (int j = 0; j < run_length; ++j) dst[(run.lo + j) * channels + ch] = sum[j];
        }
      }
      for (int x = 0; x < reduced_width; ++x) {
        if (x == run.lo && run_length > 0) {
          x = run.hi - 1;
          continue;
        }
        const ClampedTaps& taps = col_taps[static_cast<std::size_t>(x)];
        for (int ch = 0; ch < channels; ++ch) {
          double acc = 0.0;
          for (std::size_t k = 0; k < taps.weight.size(); ++k) {
            acc += taps.weight[k] * src[taps.index[k] * channels + ch];
          }
          dst[x * channels + ch] = acc;
        }
      }
    }
  });

  // Vertical pass: whole-row multiply-accumulate keeps memory access sequential.
  cv::Mat reduced(reduced_height, reduced_width, type);
  const int row_len = reduced_width * channels;
  cv::parallel_for_(cv::Range(0, reduced_height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const ClampedTaps& taps = row_taps[static_cast<std::size_t>(y)];
      double* dst = reduced.ptr<double>(y);
      std::fill(dst, dst + row_len, 0.0);
      for (std::size_t k = 0; k < taps.weight.size(); ++k) {
        const double w = taps.weight[k];
        const double* src = horizontal.ptr<double>(taps.index[k]);
        resample_detail::add_weighted(dst, src, w, row_len);
      }
    }
  });
  return reduced;
}

cv::Mat upsample_horizontal(const cv::Mat& reduced, int full_width) {
  require_upsample_source(reduced, full_width);
  const int channels = reduced.channels();

  std::vector<BilinearTap> col_taps(static_cast<std::size_t>(full_width));
  for (int x = 0; x < full_width; ++x) col_taps[static_cast<std::size_t>(x)] = bilinear_tap(x, full_width, reduced.cols);

  // Output rows on OpenCV's threads (every sample computed alone: the same doubles for any split).
  cv::Mat horizontal(reduced.rows, full_width, reduced.type());
  cv::parallel_for_(cv::Range(0, reduced.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const double* src = reduced.ptr<double>(y);
      double* dst = horizontal.ptr<double>(y);
      for (int x = 0; x < full_width; ++x) {
        const BilinearTap& t = col_taps[static_cast<std::size_t>(x)];
        const double* a = src + t.i0 * channels;
        const double* b = src + t.i1 * channels;
        for (int ch = 0; ch < channels; ++ch) dst[x * channels + ch] = (1.0 - t.frac) * a[ch] + t.frac * b[ch];
      }
    }
  });
  return horizontal;
}

void upsample_row(const cv::Mat& horizontal, int y, int full_height, double* out) {
  const BilinearTap t = bilinear_tap(y, full_height, horizontal.rows);
  const double* a = horizontal.ptr<double>(t.i0);
  const double* b = horizontal.ptr<double>(t.i1);
  const int row_len = horizontal.cols * horizontal.channels();
  resample_detail::blend(out, a, b, t.frac, row_len);
}

cv::Mat upsample(const cv::Mat& reduced, int full_width, int full_height) {
  require_upsample_source(reduced, full_width);
  require_axis(full_height, reduced.rows, "upsample (height)");
  const cv::Mat horizontal = upsample_horizontal(reduced, full_width);
  cv::Mat full(full_height, full_width, reduced.type());
  cv::parallel_for_(cv::Range(0, full_height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) upsample_row(horizontal, y, full_height, full.ptr<double>(y));
  });
  return full;
}

}  // namespace trm
