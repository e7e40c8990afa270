// D and U against independent oracles: OpenCV GaussianBlur / resize(INTER_LINEAR), and a direct,
// non-separable evaluation of the DESIGN §3 formulas.
#include "trm/resample.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace trm {
namespace {

cv::Mat random_image(int w, int h, int channels, std::uint64_t seed) {
  cv::Mat m(h, w, CV_MAKETYPE(CV_64F, channels));
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0.0, 1.0);
  return m;
}

double max_abs_diff(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

// Direct 2-D evaluation of D: sum over all (i, j) in the closed square around the exact centre, with the
// 2-D weight being the product of the normalised 1-D weights (what separability promises).
cv::Mat direct_downsample(const cv::Mat& full, int w, int h, double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma - 1e-9));
  auto taps_1d = [&](int x_low, int full_n, int red_n, std::vector<int>& idx, std::vector<double>& wt) {
    idx.clear();
    wt.clear();
    const long double c = ((2.0L * x_low + 1.0L) * full_n - red_n) / (2.0L * red_n);
    double sum = 0.0;
    for (int i = static_cast<int>(std::floor(c)) - radius - 1; i <= static_cast<int>(std::ceil(c)) + radius + 1; ++i) {
      // Membership tested on integers: |2 w i - ((2x+1) W - w)| <= 2 w R.
      const long long lhs = std::llabs(2LL * red_n * i - ((2LL * x_low + 1) * full_n - red_n));
      if (lhs > 2LL * red_n * radius) continue;
      const double d = static_cast<double>(i - c);
      const double g = std::exp(-d * d / (2 * sigma * sigma));
      idx.push_back(std::clamp(i, 0, full_n - 1));
      wt.push_back(g);
      sum += g;
    }
    for (double& g : wt) g /= sum;
  };
  cv::Mat out(h, w, full.type(), cv::Scalar::all(0));
  std::vector<int> xi, yi;
  std::vector<double> xw, yw;
  const int ch = full.channels();
  for (int y = 0; y < h; ++y) {
    taps_1d(y, full.rows, h, yi, yw);
    for (int x = 0; x < w; ++x) {
      taps_1d(x, full.cols, w, xi, xw);
      for (int c = 0; c < ch; ++c) {
        double acc = 0.0;
        for (std::size_t a = 0; a < yi.size(); ++a)
          for (std::size_t b = 0; b < xi.size(); ++b) acc += yw[a] * xw[b] * full.ptr<double>(yi[a])[xi[b] * ch + c];
        out.ptr<double>(y)[x * ch + c] = acc;
      }
    }
  }
  return out;
}

TEST(ReducedSize, RoundsHalfUpAndNeverVanishes) {
  EXPECT_EQ(reduced_size(97, 0.5), 49);
  EXPECT_EQ(reduced_size(96, 0.5), 48);
  EXPECT_EQ(reduced_size(1080, 0.5), 540);
  EXPECT_EQ(reduced_size(1200, 0.25), 300);
  EXPECT_EQ(reduced_size(1, 0.5), 1);   // floor(0.5 + 0.5) = 1
  EXPECT_EQ(reduced_size(1, 0.01), 1);  // never below one pixel
  EXPECT_EQ(reduced_size(5, 1.0), 5);
  EXPECT_THROW(reduced_size(0, 0.5), std::invalid_argument);
  EXPECT_THROW(reduced_size(10, 0.0), std::invalid_argument);
  EXPECT_THROW(reduced_size(10, 1.5), std::invalid_argument);
  EXPECT_THROW(reduced_size(10, std::nan("")), std::invalid_argument);
}

TEST(ReducedSize, PixelCountRatioOverAPair) {
  struct Case { int w, h; double r; };
  for (const Case& c : {Case{1080, 1200, 0.5}, Case{1080, 1200, 0.25}, Case{97, 61, 0.5}, Case{101, 33, 1.0 / 3},
                        Case{1, 1, 0.5}, Case{7, 3, 0.1}}) {
    const int w = reduced_size(c.w, c.r), h = reduced_size(c.h, c.r);
    const double ratio = (double(c.w) * c.h + double(w) * h) / (2.0 * c.w * c.h);
    const double expected_w = std::max(1.0, std::floor(c.r * c.w + 0.5));
    const double expected_h = std::max(1.0, std::floor(c.r * c.h + 0.5));
    EXPECT_DOUBLE_EQ(ratio, (c.w * c.h + expected_w * expected_h) / (2.0 * c.w * c.h));
    if (std::floor(c.r * c.w) == c.r * c.w && std::floor(c.r * c.h) == c.r * c.h) {
      EXPECT_DOUBLE_EQ(ratio, (1 + c.r * c.r) / 2) << c.w << "x" << c.h << " r=" << c.r;  // DESIGN §6
    }
  }
  // 97 x 61 at r = 1/2: 49 x 31 reduced, not (1 + r^2)/2.
  EXPECT_DOUBLE_EQ((97.0 * 61 + 49.0 * 31) / (2.0 * 97 * 61), (97.0 * 61 + reduced_size(97, 0.5) * reduced_size(61, 0.5)) / (2.0 * 97 * 61));
}

TEST(Centres, AreExactAndIntegerWhenTheRatioIsAnOddInteger) {
  // W = 3w: c = 3x + 1, exactly.
  for (int x = 0; x < 100; ++x) EXPECT_EQ(reduced_centre(x, 300, 100), 3.0 * x + 1.0);
  // W = 2w: c = 2x + 0.5.
  for (int x = 0; x < 100; ++x) EXPECT_EQ(reduced_centre(x, 200, 100), 2.0 * x + 0.5);
  // Same size: c = x.
  for (int x = 0; x < 10; ++x) EXPECT_EQ(reduced_centre(x, 10, 10), double(x));
  // 97 -> 49: c = ((2x + 1) 97 - 49) / 98.
  EXPECT_DOUBLE_EQ(reduced_centre(0, 97, 49), 48.0 / 98.0);
  EXPECT_DOUBLE_EQ(reduced_centre(48, 97, 49), (97.0 * 97 - 49) / 98.0);
}

TEST(GaussianTaps, CountIs2RAtHalfIntegerAnd2RPlus1AtIntegerCentres) {
  const double sigma = 2.5;  // R = ceil(7.5) = 8
  ASSERT_EQ(gaussian_radius(sigma), 8);
  EXPECT_EQ(gaussian_radius(1.25), 4);       // ceil(3.75)
  EXPECT_EQ(gaussian_radius(1.25 / 0.75), 5);  // 3 sigma = 5 exactly (up to the last bit): closed interval keeps R = 5
  for (int x = 0; x < 20; ++x) {
    const GaussianTaps half = gaussian_taps(x, 40, 20, sigma);  // c = 2x + 0.5
    EXPECT_EQ(half.weights.size(), 16u);
    EXPECT_EQ(half.first_index, 2 * x + 1 - 8);
    const GaussianTaps integer = gaussian_taps(x, 60, 20, sigma);  // c = 3x + 1
    EXPECT_EQ(integer.weights.size(), 17u);
    EXPECT_EQ(integer.first_index, 3 * x + 1 - 8);
  }
  // A tap exactly at distance R is included (closed interval): sigma = 2 -> R = 6, integer centre.
  const GaussianTaps edge = gaussian_taps(0, 3, 1, 2.0);  // c = 1
  EXPECT_EQ(edge.first_index, -5);
  EXPECT_EQ(edge.weights.size(), 13u);
}

TEST(GaussianTaps, AreNormalisedSymmetricAndGaussian) {
  for (auto [full, red] : {std::pair{97, 49}, std::pair{40, 20}, std::pair{1080, 540}, std::pair{5, 1}, std::pair{7, 7}}) {
    const double sigma = 1.25 * full / red;
    for (int x = 0; x < red; ++x) {
      const GaussianTaps t = gaussian_taps(x, full, red, sigma);
      double sum = 0;
      for (double w : t.weights) sum += w;
      EXPECT_NEAR(sum, 1.0, 1e-14);
      const double c = reduced_centre(x, full, red);
      const int radius = gaussian_radius(sigma);
      // Every tap inside the closed interval, the next index on either side outside it.
      EXPECT_LE(c - t.first_index, radius + 1e-12);
      EXPECT_GT(c - (t.first_index - 1), radius);
      const int last = t.first_index + int(t.weights.size()) - 1;
      EXPECT_LE(last - c, radius + 1e-12);
      EXPECT_GT(last + 1 - c, radius);
      // Ratio of any two weights follows the Gaussian.
      const double d0 = t.first_index - c, d1 = t.first_index + 1 - c;
      EXPECT_NEAR(t.weights[1] / t.weights[0], std::exp(-(d1 * d1 - d0 * d0) / (2 * sigma * sigma)), 1e-12);
    }
  }
}

TEST(BilinearTap, MatchesTheHalfPixelMappingWithOpenCvClamping) {
  // 2x: x_low = (x + 0.5) / 2 - 0.5.
  const BilinearTap first = bilinear_tap(0, 8, 4);  // x_low = -0.25 -> clamped to sample 0
  EXPECT_EQ(first.i0, 0);
  EXPECT_EQ(first.frac, 0.0);
  const BilinearTap t1 = bilinear_tap(1, 8, 4);  // 0.25
  EXPECT_EQ(t1.i0, 0);
  EXPECT_EQ(t1.i1, 1);
  EXPECT_EQ(t1.frac, 0.25);
  const BilinearTap t2 = bilinear_tap(2, 8, 4);  // 0.75
  EXPECT_EQ(t2.frac, 0.75);
  const BilinearTap last = bilinear_tap(7, 8, 4);  // 3.25 -> clamped to sample 3
  EXPECT_EQ(last.i0, 3);
  EXPECT_EQ(last.i1, 3);
  EXPECT_EQ(last.frac, 0.0);
  // 3x: full pixel 3k + 1 lands exactly on reduced sample k.
  for (int k = 0; k < 10; ++k) {
    const BilinearTap t = bilinear_tap(3 * k + 1, 30, 10);
    EXPECT_EQ(t.i0, k);
    EXPECT_EQ(t.frac, 0.0);
  }
  // Reduced width 1: everything reads sample 0.
  for (int x = 0; x < 5; ++x) {
    const BilinearTap t = bilinear_tap(x, 5, 1);
    EXPECT_EQ(t.i0, 0);
    EXPECT_EQ(t.i1, 0);
  }
}

// U against cv::resize(INTER_LINEAR). OpenCV computes the source coordinate (x + 0.5) * scale - 0.5 in
// float and keeps the weights in float, so agreement is exact only where those are exactly representable
// (power-of-two ratios: measured 0 to 1.1e-16). Elsewhere the error is about half a float ulp of the source
// coordinate (2^-24 * coordinate): measured 2.5e-7 (10 -> 30), 4.7e-7 (13 -> 100), 1.7e-6 (49 -> 97), and
// 2e-8 for a 1x1 source, whose float weights do not sum to exactly 1. Bound for those: 4e-6.
TEST(Upsample, MatchesOpenCvResizeLinear) {
  struct Case { int rw, rh, fw, fh; double tol; };
  const Case cases[] = {
      {4, 3, 8, 6, 1e-12},        {37, 23, 74, 46, 1e-12},  {16, 9, 64, 36, 1e-12},   {33, 17, 264, 136, 1e-12},
      {540, 600, 1080, 1200, 1e-12},
      {10, 7, 30, 21, 4e-6},      {49, 31, 97, 61, 4e-6},   {13, 11, 100, 57, 4e-6},  {1, 1, 5, 3, 4e-6},
  };
  for (const Case& c : cases) {
    const cv::Mat small = random_image(c.rw, c.rh, 3, 7u + c.rw);
    const cv::Mat ours = upsample(small, c.fw, c.fh);
    cv::Mat theirs;
    cv::resize(small, theirs, cv::Size(c.fw, c.fh), 0, 0, cv::INTER_LINEAR);
    ASSERT_EQ(ours.size(), theirs.size());
    const double diff = max_abs_diff(ours, theirs);
    EXPECT_LE(diff, c.tol) << c.rw << "x" << c.rh << " -> " << c.fw << "x" << c.fh;
    std::printf("U vs resize %dx%d -> %dx%d: max |diff| = %.3g\n", c.rw, c.rh, c.fw, c.fh, diff);
  }
}

TEST(Upsample, SameSizeIsIdentityAndConstantsStayConstant) {
  const cv::Mat img = random_image(13, 9, 3, 3);
  EXPECT_EQ(max_abs_diff(upsample(img, 13, 9), img), 0.0);
  const cv::Mat flat(5, 7, CV_64FC3, cv::Scalar(0.25, 0.5, 0.75));
  const cv::Mat up = upsample(flat, 19, 13);
  EXPECT_LE(max_abs_diff(up, cv::Mat(13, 19, CV_64FC3, cv::Scalar(0.25, 0.5, 0.75))), 1e-15);
  const cv::Mat dot(1, 1, CV_64FC1, cv::Scalar(0.3));
  EXPECT_LE(max_abs_diff(upsample(dot, 4, 6), cv::Mat(6, 4, CV_64FC1, cv::Scalar(0.3))), 0.0);
}

// With W = 3w every reduced centre is the integer 3x + 1, so D equals a full-resolution Gaussian blur
// with BORDER_REPLICATE sampled at those pixels. ksize = 2R + 1 makes OpenCV's kernel the same truncated,
// normalised Gaussian. Measured max difference ~1e-16 (summation order only); bound 1e-13.
TEST(Downsample, EqualsGaussianBlurAtIntegerCentres) {
  struct Case { int w, h; double r; };
  for (const Case& c : {Case{20, 15, 1.0 / 3}, Case{9, 7, 1.0 / 3}, Case{31, 17, 1.0}, Case{1, 1, 1.0}}) {
    const int fw = c.r == 1.0 ? c.w : 3 * c.w, fh = c.r == 1.0 ? c.h : 3 * c.h;
    const int step = c.r == 1.0 ? 1 : 3, offset = c.r == 1.0 ? 0 : 1;
    const double sigma = default_sigma(c.r);
    const int radius = gaussian_radius(sigma);
    const cv::Mat full = random_image(fw, fh, 3, 11u + fw);
    cv::Mat blurred;
    cv::GaussianBlur(full, blurred, cv::Size(2 * radius + 1, 2 * radius + 1), sigma, sigma, cv::BORDER_REPLICATE);
    const cv::Mat ours = downsample(full, c.w, c.h, sigma);
    ASSERT_EQ(ours.size(), cv::Size(c.w, c.h));
    double diff = 0;
    for (int y = 0; y < c.h; ++y)
      for (int x = 0; x < c.w; ++x)
        diff = std::max(diff, cv::norm(ours.at<cv::Vec3d>(y, x) - blurred.at<cv::Vec3d>(step * y + offset, step * x + offset), cv::NORM_INF));
    EXPECT_LE(diff, 1e-13) << fw << "x" << fh << " r=" << c.r;
    std::printf("D vs GaussianBlur %dx%d r=%.4g sigma=%.4g ksize=%d: max |diff| = %.3g\n", fw, fh, c.r, sigma, 2 * radius + 1, diff);
  }
}

TEST(Downsample, MatchesDirectEvaluationForOddSizesAndTinyR) {
  struct Case { int fw, fh; double r; };
  for (const Case& c : {Case{97, 61, 0.5}, Case{33, 20, 0.7}, Case{40, 25, 0.1}, Case{12, 5, 0.02}, Case{1, 1, 0.5},
                        Case{8, 1, 0.5}, Case{15, 9, 1.0}}) {
    const int w = reduced_size(c.fw, c.r), h = reduced_size(c.fh, c.r);
    const double sigma = default_sigma(c.r);
    const cv::Mat full = random_image(c.fw, c.fh, 3, 5u + c.fw);
    const cv::Mat ours = downsample(full, w, h, sigma);
    const cv::Mat direct = direct_downsample(full, w, h, sigma);
    EXPECT_LE(max_abs_diff(ours, direct), 1e-13) << c.fw << "x" << c.fh << " r=" << c.r;
  }
}

// D's passes in their defining order, one output at a time: each horizontal output 0 + w_0 s_0 + w_1 s_1 + ... over
// its taps (clamped indexes), then each vertical output the same over the horizontal rows. downsample() must give
// these doubles bit for bit whatever loop structure it computes them with (its interior runs a tap at a time).
cv::Mat separable_in_tap_order(const cv::Mat& full, int w, int h, double sigma) {
  const int ch = full.channels();
  cv::Mat horizontal(full.rows, w, full.type());
  for (int x = 0; x < w; ++x) {
    const GaussianTaps taps = gaussian_taps(x, full.cols, w, sigma);
    for (int y = 0; y < full.rows; ++y) {
      for (int c = 0; c < ch; ++c) {
        double acc = 0.0;
        for (std::size_t k = 0; k < taps.weights.size(); ++k) {
          const int i = std::clamp(taps.first_index + static_cast<int>(k), 0, full.cols - 1);
          acc += taps.weights[k] * full.ptr<double>(y)[i * ch + c];
        }
        horizontal.ptr<double>(y)[x * ch + c] = acc;
      }
    }
  }
  cv::Mat out(h, w, full.type());
  for (int y = 0; y < h; ++y) {
    const GaussianTaps taps = gaussian_taps(y, full.rows, h, sigma);
    for (int i = 0; i < w * ch; ++i) {
      double acc = 0.0;
      for (std::size_t k = 0; k < taps.weights.size(); ++k) {
        const int j = std::clamp(taps.first_index + static_cast<int>(k), 0, full.rows - 1);
        acc += taps.weights[k] * horizontal.ptr<double>(j)[i];
      }
      out.ptr<double>(y)[i] = acc;
    }
  }
  return out;
}

TEST(Downsample, IsTheSeparableSumInTapOrderBitForBit) {
  struct Case { int fw, fh; double r; int channels; };
  for (const Case& c : {Case{2160, 6, 0.5, 3}, Case{200, 9, 0.25, 3}, Case{99, 7, 1.0 / 3.0, 1}, Case{97, 9, 0.5, 3},
                        Case{64, 8, 0.5, 4}, Case{40, 5, 1.0, 3}, Case{12, 5, 0.5, 3}, Case{6, 4, 0.5, 2}}) {
    const int w = reduced_size(c.fw, c.r), h = reduced_size(c.fh, c.r);
    const double sigma = default_sigma(c.r);
    const cv::Mat full = random_image(c.fw, c.fh, c.channels, 11u + c.fw);
    const cv::Mat ours = downsample(full, w, h, sigma);
    const cv::Mat oracle = separable_in_tap_order(full, w, h, sigma);
    ASSERT_EQ(ours.size(), oracle.size());
    std::size_t differ = 0;
    for (int y = 0; y < h; ++y) {
      differ += std::memcmp(ours.ptr(y), oracle.ptr(y), ours.cols * ours.elemSize()) != 0 ? 1 : 0;
    }
    EXPECT_EQ(differ, 0U) << c.fw << "x" << c.fh << " r=" << c.r << " channels " << c.channels;
  }
}

// D of a frame given a row at a time (into the scratch it is handed, as reduce_codes gives it) is the same doubles as
// D of the frame's plane, each row asked for once.
TEST(Downsample, FromRowsIsTheSameDoublesAsFromThePlane) {
  struct Case { int fw, fh; double r; int channels; };
  for (const Case& c : {Case{2160, 6, 0.5, 3}, Case{99, 7, 1.0 / 3.0, 1}, Case{97, 9, 0.5, 3}, Case{12, 5, 0.5, 2}}) {
    const int w = reduced_size(c.fw, c.r), h = reduced_size(c.fh, c.r);
    const double sigma = default_sigma(c.r);
    const cv::Mat full = random_image(c.fw, c.fh, c.channels, 17u + c.fw);
    std::vector<int> asked(static_cast<std::size_t>(c.fh), 0);
    const cv::Mat from_rows = downsample(
        full.size(), c.channels,
        [&](int y, double* scratch) {
          ++asked[static_cast<std::size_t>(y)];  // rows are asked for on several threads, each row on one
          std::memcpy(scratch, full.ptr(y), full.cols * full.elemSize());
          return static_cast<const double*>(scratch);
        },
        w, h, sigma);
    const cv::Mat from_plane = downsample(full, w, h, sigma);
    ASSERT_EQ(from_rows.size(), from_plane.size());
    ASSERT_EQ(from_rows.type(), from_plane.type());
    for (int y = 0; y < h; ++y) {
      EXPECT_EQ(std::memcmp(from_rows.ptr(y), from_plane.ptr(y), from_rows.cols * from_rows.elemSize()), 0)
          << c.fw << "x" << c.fh << " row " << y;
    }
    EXPECT_EQ(std::count(asked.begin(), asked.end(), 1), c.fh) << c.fw << "x" << c.fh;
  }
  const auto no_row = [](int, double* scratch) { return static_cast<const double*>(scratch); };
  EXPECT_THROW(downsample(cv::Size(0, 4), 3, no_row, 1, 2, 2.5), std::invalid_argument);
  EXPECT_THROW(downsample(cv::Size(8, 4), 0, no_row, 4, 2, 2.5), std::invalid_argument);
}

TEST(Downsample, KeepsConstantsAndAcceptsAnyChannelCount) {
  for (int channels : {1, 2, 3, 4}) {
    const cv::Mat flat(23, 17, CV_MAKETYPE(CV_64F, channels), cv::Scalar(0.2, 0.4, 0.6, 0.8));
    const cv::Mat d = downsample(flat, 9, 12, 3.0);
    EXPECT_LE(max_abs_diff(d, cv::Mat(12, 9, flat.type(), cv::Scalar(0.2, 0.4, 0.6, 0.8))), 1e-15);
  }
  // r = 1 is still a blur, not the identity.
  cv::Mat impulse = cv::Mat::zeros(9, 9, CV_64FC1);
  impulse.at<double>(4, 4) = 1.0;
  const cv::Mat d = downsample(impulse, 9, 9, default_sigma(1.0));
  EXPECT_LT(d.at<double>(4, 4), 0.2);
  EXPECT_NEAR(cv::sum(d)[0], 1.0, 1e-14);  // interior impulse: mass preserved
}

TEST(Downsample, RejectsBadArguments) {
  const cv::Mat img = random_image(8, 8, 3, 1);
  EXPECT_THROW(downsample(img, 9, 4, 2.5), std::invalid_argument);
  EXPECT_THROW(downsample(img, 4, 4, 0.0), std::invalid_argument);
  EXPECT_THROW(downsample(img, 0, 4, 2.5), std::invalid_argument);
  cv::Mat f32;
  img.convertTo(f32, CV_32F);
  EXPECT_THROW(downsample(f32, 4, 4, 2.5), std::invalid_argument);
  EXPECT_THROW(upsample(img, 4, 4), std::invalid_argument);
}

}  // namespace
}  // namespace trm
