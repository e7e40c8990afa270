// The viewer's eye and the perceptual measures on its images: smooth pursuit (supplement Eq. 3), the Kelly-Daly
// stCSF, the visual difference energy (supplement Eqs. 1, 2, 4) and MTCD (Kim et al. Eq. 6), each against an
// oracle computed here by another route.
#include <gtest/gtest.h>

#include "hw_models_test_support.hpp"

#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "trm/csf.hpp"
#include "trm/mtcd.hpp"
#include "trm/pursuit.hpp"
#include "trm/visual_difference.hpp"

namespace trm {
namespace {

using test::expect_invalid;
using test::kPi;
using test::kNaN;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Smooth pursuit (Eq. 3) ----

TEST(Pursuit, SlowTargetsAreFollowedWithGainAndDrift) {
  for (const double v : {0.0, 0.5, 1.0, 10.0, 50.0, 97.0}) {
    EXPECT_NEAR(eye_velocity_deg_s(v), 0.82 * v + 0.15, 1e-12) << v;
    EXPECT_NEAR(retinal_velocity_deg_s(v), 0.18 * v - 0.15, 1e-12) << v;
  }
  // The eye lags by v_r = 0 at v = 0.15 / 0.18: below it the drift outruns the target.
  EXPECT_NEAR(retinal_velocity_deg_s(0.15 / 0.18), 0.0, 1e-12);
}

TEST(Pursuit, FastTargetsSaturateAtEightyDegreesPerSecond) {
  for (const double v : {98.0, 100.0, 200.0, 1000.0}) {
    EXPECT_EQ(eye_velocity_deg_s(v), 80.0) << v;
    EXPECT_EQ(retinal_velocity_deg_s(v), v - 80.0) << v;
  }
}

TEST(Pursuit, BranchesMeetAtTheSaturationVelocity) {
  const double crossover = (80.0 - 0.15) / 0.82;
  EXPECT_DOUBLE_EQ(kPursuitSaturationVelocity, crossover);
  EXPECT_NEAR(crossover, 97.37804878048780, 1e-12);
  EXPECT_NEAR(eye_velocity_deg_s(crossover), 80.0, 1e-12);
  const double below = crossover - 1e-6;
  EXPECT_NEAR(eye_velocity_deg_s(below), 0.82 * below + 0.15, 1e-12);
  EXPECT_LT(eye_velocity_deg_s(below), 80.0);
  EXPECT_EQ(eye_velocity_deg_s(crossover + 1e-6), 80.0);
}

TEST(Pursuit, LeftwardMotionMirrorsRightwardAndStillnessLeavesTheDrift) {
  for (const double v : {0.5, 10.0, 150.0}) {
    EXPECT_EQ(eye_velocity_deg_s(-v), -eye_velocity_deg_s(v)) << v;
    EXPECT_EQ(retinal_velocity_deg_s(-v), -retinal_velocity_deg_s(v)) << v;
  }
  EXPECT_EQ(eye_velocity_deg_s(0.0), kPursuitMinVelocity);
  EXPECT_EQ(eye_velocity_deg_s(-0.0), kPursuitMinVelocity);
  EXPECT_EQ(retinal_velocity_deg_s(0.0), -kPursuitMinVelocity);
}

TEST(Pursuit, NonFiniteVelocityIsRejected) {
  for (const double v : {kNaN, kInf, -kInf}) {
    expect_invalid([v] { eye_velocity_deg_s(v); }, "target_velocity_deg_s");
    expect_invalid([v] { retinal_velocity_deg_s(v); }, "target_velocity_deg_s");
  }
}

// ---- Kelly-Daly stCSF ----

// Kelly 1979's surface in his own variables: α = 2πρ rad/deg, v deg/s.
double kelly_1979(double alpha, double v) {
  const double k = 6.1 + 7.3 * std::pow(std::abs(std::log10(v / 3.0)), 3.0);
  return k * v * alpha * alpha * std::exp(-2.0 * alpha * (v + 2.0) / 45.9);
}

// Daly 1998 is Kelly's surface with frequency scaled by c1, velocity by c2 and sensitivity by c0.
double daly_1998(double rho, double v) { return 1.14 * kelly_1979(0.67 * 2.0 * kPi * rho, 1.7 * v); }

TEST(Csf, IsKellysSurfaceRescaledByDalysConstants) {
  for (const double rho : {0.05, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 60.0}) {
    for (const double v : {0.15, 0.3, 1.0, 1.7647, 2.0, 5.0, 10.0, 40.0, 80.0}) {
      const double expected = daly_1998(rho, v);
      EXPECT_NEAR(csf_spatiovelocity(rho, v), expected, 1e-12 * expected + 1e-300) << rho << " " << v;
      EXPECT_NEAR(csf_spatiotemporal(rho, rho * v), expected, 1e-12 * expected + 1e-300) << rho << " " << v;
    }
  }
}

// The peak of each constant-velocity curve: Kelly's α_max = 45.9 / (v + 2) is the peak of α² e^{−2α/α_max};
// in Daly's variables it lies at ρ = p1 / (2π c1 (c2 v + 2)) with S = k c0 c2 v ρ_max² e⁻². Found here by a
// golden-section search on the function itself.
TEST(Csf, PeakOfEachConstantVelocityCurveIsWhereKellyPutsIt) {
  for (const double v : {0.15, 1.0, 3.0 / 1.7, 10.0, 40.0}) {
    double lo = 0.01;
    double hi = 60.0;
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int i = 0; i < 200; ++i) {
      const double a = hi - phi * (hi - lo);
      const double b = lo + phi * (hi - lo);
      if (csf_spatiovelocity(a, v) < csf_spatiovelocity(b, v)) {
        lo = a;
      } else {
        hi = b;
      }
    }
    const double rho_max = 45.9 / (1.7 * v + 2.0);
    const double rho_peak = rho_max / (2.0 * kPi * 0.67);
    const double k = 6.1 + 7.3 * std::pow(std::abs(std::log10(1.7 * v / 3.0)), 3.0);
    EXPECT_NEAR(0.5 * (lo + hi), rho_peak, 1e-6 * rho_peak) << v;
    EXPECT_NEAR(csf_spatiovelocity(rho_peak, v), k * 1.14 * 1.7 * v * rho_max * rho_max * std::exp(-2.0), 1e-9) << v;
  }
}

// Values of the formula evaluated independently in double precision (Python): the static CSF at the drift
// velocity peaks near 245 at 4.8 cpd, a typical photopic static CSF; faster retinal motion moves the peak to lower
// frequencies and lowers it (Kelly 1979: the passband shifts toward low spatial frequencies with velocity).
TEST(Csf, PeakValuesAtFourVelocities) {
  struct Point {
    double v, rho_peak, s_peak;
  };
  for (const Point& p : {Point{0.15, 4.8351668848118585, 245.43589713633725},
                         Point{1.0, 2.9468381960137133, 250.63869875946037},
                         Point{3.0 / 1.7, 2.1806602650501477, 237.93171756463343},
                         Point{10.0, 0.573857964486881, 141.14143109047228}}) {
    EXPECT_NEAR(csf_spatiovelocity(p.rho_peak, p.v), p.s_peak, 1e-9 * p.s_peak) << p.v;
  }
}

TEST(Csf, FallsMonotonicallyAboveThePeak) {
  for (const double v : {0.15, 1.0, 10.0}) {
    const double rho_peak = 45.9 / (1.7 * v + 2.0) / (2.0 * kPi * 0.67);
    double previous = csf_spatiovelocity(rho_peak, v);
    for (double rho = rho_peak + 0.01; rho <= 60.0; rho += 0.01) {
      const double s = csf_spatiovelocity(rho, v);
      ASSERT_LT(s, previous) << rho << " " << v;
      previous = s;
    }
  }
  for (const double nu : {0.0, 5.0, 30.0}) {
    double previous = csf_spatiotemporal(10.0, nu);
    for (double rho = 10.01; rho <= 60.0; rho += 0.01) {
      const double s = csf_spatiotemporal(rho, nu);
      ASSERT_LT(s, previous) << rho << " " << nu;
      previous = s;
    }
  }
  EXPECT_LT(csf_spatiotemporal(60.0, 0.0), 1e-3 * csf_spatiotemporal(4.8, 0.0));
}

TEST(Csf, StillImagesAreSeenAtTheDriftVelocity) {
  EXPECT_EQ(kCsfDriftVelocity, 0.15);
  for (const double rho : {0.5, 4.8, 20.0}) {
    const double at_drift = daly_1998(rho, 0.15);
    EXPECT_NEAR(csf_spatiotemporal(rho, 0.0), at_drift, 1e-12 * at_drift);
    EXPECT_NEAR(csf_spatiovelocity(rho, 0.0), at_drift, 1e-12 * at_drift);
    EXPECT_NEAR(csf_spatiovelocity(rho, 0.05), at_drift, 1e-12 * at_drift);
    EXPECT_NEAR(csf_spatiotemporal(rho, 0.1 * rho), at_drift, 1e-12 * at_drift);
    EXPECT_GT(csf_spatiotemporal(rho, 0.2 * rho), 0.0);
  }
}

TEST(Csf, ZeroSpatialFrequencyHasNoSensitivityAndTheLimitIsContinuous) {
  for (const double nu : {0.0, 1.0, 60.0}) EXPECT_EQ(csf_spatiotemporal(0.0, nu), 0.0);
  EXPECT_EQ(csf_spatiovelocity(0.0, 1.0), 0.0);
  // At fixed ν the fall is slow, ρ · log³(1/ρ), but it is a fall.
  double previous = csf_spatiotemporal(1e-3, 10.0);
  for (const double rho : {1e-6, 1e-9, 1e-12}) {
    EXPECT_LT(csf_spatiotemporal(rho, 10.0), previous) << rho;
    previous = csf_spatiotemporal(rho, 10.0);
  }
  EXPECT_LT(previous, 1e-5);
  EXPECT_LT(csf_spatiotemporal(1e-6, 0.0), 1e-9);
  EXPECT_EQ(csf_spatiotemporal(std::numeric_limits<double>::denorm_min(), 10.0), 0.0);
  EXPECT_EQ(csf_spatiovelocity(1.0, 1e300), 0.0);
}

TEST(Csf, SignsOfFrequencyAndVelocityDoNotMatter) {
  EXPECT_EQ(csf_spatiotemporal(-3.0, -7.0), csf_spatiotemporal(3.0, 7.0));
  EXPECT_EQ(csf_spatiovelocity(-3.0, -2.0), csf_spatiovelocity(3.0, 2.0));
}

TEST(Csf, NonFiniteArgumentsAreRejected) {
  expect_invalid([] { csf_spatiotemporal(kNaN, 1.0); }, "rho_cpd");
  expect_invalid([] { csf_spatiotemporal(1.0, kInf); }, "nu_hz");
  expect_invalid([] { csf_spatiovelocity(kInf, 1.0); }, "rho_cpd");
  expect_invalid([] { csf_spatiovelocity(1.0, kNaN); }, "velocity_deg_s");
}

// ---- Visual difference energy (Eqs. 1, 2, 4) ----

// Renderings a and b whose Eq. 1 contrast is exactly c: L = L0 (1 ± c).
std::pair<cv::Mat, cv::Mat> pair_with_contrast(const cv::Mat& c, double l0 = 50.0) {
  return {l0 * (1.0 + c), l0 * (1.0 - c)};
}

cv::Mat image_of(int rows, int cols, const std::function<double(int, int)>& value) {
  cv::Mat image(rows, cols, CV_64FC1);
  for (int t = 0; t < rows; ++t) {
    for (int x = 0; x < cols; ++x) image.at<double>(t, x) = value(t, x);
  }
  return image;
}

double sum_abs_pow(const cv::Mat& image, double beta) {
  double sum = 0.0;
  for (int t = 0; t < image.rows; ++t) {
    for (int x = 0; x < image.cols; ++x) sum += std::pow(std::abs(image.at<double>(t, x)), beta);
  }
  return sum;
}

TEST(DftFrequency, SignedAxesForEvenAndOddLengths) {
  const std::vector<double> even{0, 2, 4, 6, 8, -6, -4, -2};
  for (int i = 0; i < 8; ++i) EXPECT_DOUBLE_EQ(dft_frequency(i, 8, 16.0), even[i]) << i;
  const std::vector<double> odd{0, 1, 2, 3, -3, -2, -1};
  for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(dft_frequency(i, 7, 7.0), odd[i]) << i;
  EXPECT_DOUBLE_EQ(dft_frequency(0, 1, 30.0), 0.0);
  expect_invalid([] { dft_frequency(8, 8, 1.0); }, "index");
  expect_invalid([] { dft_frequency(-1, 8, 1.0); }, "index");
  expect_invalid([] { dft_frequency(0, 0, 1.0); }, "length");
  expect_invalid([] { dft_frequency(0, 8, 0.0); }, "sample_rate");
}

TEST(ContrastDifference, IsEquationOneAndZeroOnBlack) {
  const cv::Mat a = (cv::Mat_<double>(1, 4) << 3.0, 0.0, 1.0, 0.0);
  const cv::Mat b = (cv::Mat_<double>(1, 4) << 1.0, 2.0, 1.0, 0.0);
  const cv::Mat c = contrast_difference(a, b);
  EXPECT_DOUBLE_EQ(c.at<double>(0, 0), 0.5);
  EXPECT_DOUBLE_EQ(c.at<double>(0, 1), -1.0);
  EXPECT_DOUBLE_EQ(c.at<double>(0, 2), 0.0);
  EXPECT_DOUBLE_EQ(c.at<double>(0, 3), 0.0);
}

TEST(PooledEnergy, IsTheBetaNorm) {
  const cv::Mat c = (cv::Mat_<double>(1, 2) << 3.0, -4.0);
  EXPECT_NEAR(pooled_energy(c, 2.0), 5.0, 1e-14);
  EXPECT_NEAR(pooled_energy(c), std::pow(std::pow(3.0, 2.6) + std::pow(4.0, 2.6), 1.0 / 2.6), 1e-13);
  EXPECT_EQ(pooled_energy(cv::Mat::zeros(3, 3, CV_64FC1)), 0.0);
  const cv::Mat huge = (cv::Mat_<double>(1, 2) << 3e200, -4e200);
  EXPECT_NEAR(pooled_energy(huge, 2.0), 5e200, 1e186);
  EXPECT_EQ(kVisualDifferenceBeta, 2.6);
}

TEST(VisualDifference, IdenticalRenderingsHaveNoEnergy) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> luminance(0.0, 100.0);
  const cv::Mat l = image_of(24, 40, [&](int, int) { return luminance(random); });
  EXPECT_EQ(visual_difference_energy(l, l, 30.0, 90.0, 1.2), 0.0);
  EXPECT_EQ(visual_difference_energy(cv::Mat::zeros(4, 4, CV_64FC1), cv::Mat::zeros(4, 4, CV_64FC1), 30.0, 90.0, 0.0),
            0.0);
}

TEST(VisualDifference, SwappingTheRenderingsChangesNothing) {
  std::mt19937 random(12);
  std::uniform_real_distribution<double> luminance(0.0, 100.0);
  const cv::Mat a = image_of(24, 40, [&](int, int) { return luminance(random); });
  const cv::Mat b = image_of(24, 40, [&](int, int) { return luminance(random); });
  const double ab = visual_difference_energy(a, b, 30.0, 90.0, 1.2);
  EXPECT_GT(ab, 0.0);
  EXPECT_EQ(visual_difference_energy(b, a, 30.0, 90.0, 1.2), ab);
  // Eq. 1 is a contrast: the same renderings at a quarter of the light differ as much.
  EXPECT_NEAR(visual_difference_energy(0.25 * a, 0.25 * b, 30.0, 90.0, 1.2), ab, 1e-12 * ab);
}

// A static grating C = a sin(2π ρ0 x) on DFT bins ±k0 is an eigenfunction of Eq. 2 with eigenvalue
// W = S(ρ0, ρ0 |v_r|), so C_n = W C and E = a W (K Σ_x |sin(2π k0 x / N)|^β)^(1/β).
TEST(VisualDifference, StaticGratingIsScaledByTheCsfAtItsRetinalFlicker) {
  const int n = 90;
  const int frames = 45;
  const double ppd = 30.0;
  const double fps = 90.0;
  const int k0 = 9;
  const double rho0 = k0 * ppd / n;  // 3 cpd
  const double v_r = retinal_velocity_deg_s(10.0);
  const double a = 0.01;
  const cv::Mat c = image_of(frames, n, [&](int, int x) { return a * std::sin(2.0 * kPi * k0 * x / n); });
  const auto [l_a, l_b] = pair_with_contrast(c);
  const double w = daly_1998(rho0, std::abs(v_r));
  double line = 0.0;
  for (int x = 0; x < n; ++x) line += std::pow(std::abs(std::sin(2.0 * kPi * k0 * x / n)), 2.6);
  const double expected = a * w * std::pow(frames * line, 1.0 / 2.6);
  EXPECT_NEAR(visual_difference_energy(l_a, l_b, ppd, fps, v_r), expected, 1e-6 * expected);
  // Linear in the contrast difference: twice the grating, twice the energy.
  const auto [l_a2, l_b2] = pair_with_contrast(2.0 * c);
  EXPECT_NEAR(visual_difference_energy(l_a2, l_b2, ppd, fps, v_r), 2.0 * expected, 1e-6 * expected);
}

// A grating moving at u in the target frame moves at u + v_r over the retina, so it flickers there at ρ0 |u + v_r|:
// moving with the retina (u = −v_r, a negative DFT temporal frequency) leaves only the drift; moving against it
// (u = +v_r) doubles the flicker.
TEST(VisualDifference, MovingGratingsAreWeightedAtTheirRetinalVelocity) {
  const int n = 64;
  const int frames = 32;
  const double ppd = 32.0;  // 0.5 cpd per bin
  const double fps = 64.0;  // 2 Hz per bin
  const double rho0 = 4.0;
  const double v_r = 1.5;  // ρ0 v_r = 6 Hz, on a bin
  const double a = 0.02;
  for (const double u : {-v_r, 0.0, v_r, 2.0 * v_r}) {
    const cv::Mat c = image_of(frames, n, [&](int t, int x) {
      return a * std::cos(2.0 * kPi * (rho0 * x / ppd - rho0 * u * t / fps));
    });
    const auto [l_a, l_b] = pair_with_contrast(c);
    const double w = daly_1998(rho0, std::max(std::abs(u + v_r), 0.15));
    const double expected = a * w * std::pow(sum_abs_pow(c / a, 2.6), 1.0 / 2.6);
    EXPECT_NEAR(visual_difference_energy(l_a, l_b, ppd, fps, v_r), expected, 1e-6 * expected) << u;
  }
}

// Eq. 2 by direct summation: the DFT written out, each bin weighted by S_st at its own frequencies (a bin at half
// a sampling rate by the mean over its two aliases), and the inverse written out.
cv::Mat naive_weighted_contrast(const cv::Mat& c, double ppd, double fps, double v_r, double* largest_imaginary) {
  const int n = c.cols;
  const int frames = c.rows;
  const auto signed_frequencies = [](int index, int length, double rate) {
    std::vector<double> out;
    if (2 * index == length) {
      out = {index * rate / length, -index * rate / length};
    } else {
      out = {(2 * index < length ? index : index - length) * rate / length};
    }
    return out;
  };
  std::vector<std::complex<double>> spectrum(static_cast<std::size_t>(n) * frames);
  for (int m = 0; m < frames; ++m) {
    for (int k = 0; k < n; ++k) {
      std::complex<double> sum = 0.0;
      for (int t = 0; t < frames; ++t) {
        for (int x = 0; x < n; ++x) {
          sum += c.at<double>(t, x) * std::polar(1.0, -2.0 * kPi * (double(k) * x / n + double(m) * t / frames));
        }
      }
      // Travelling-wave ν = −(DFT frequency) for a pattern cos 2π(ρx − νt).
      const std::vector<double> rhos = signed_frequencies(k, n, ppd);
      const std::vector<double> nus = signed_frequencies(m, frames, fps);
      double weight = 0.0;
      const std::size_t aliases = std::max(rhos.size(), nus.size());
      for (std::size_t i = 0; i < aliases; ++i) {
        const double rho = rhos[std::min(i, rhos.size() - 1)];
        const double nu = -nus[std::min(i, nus.size() - 1)];
        weight += rho == 0.0 ? 0.0 : daly_1998(std::abs(rho), std::max(std::abs(nu + rho * v_r) / std::abs(rho), 0.15));
      }
      spectrum[static_cast<std::size_t>(m) * n + k] = sum * (weight / double(aliases));
    }
  }
  cv::Mat out(frames, n, CV_64FC1);
  *largest_imaginary = 0.0;
  for (int t = 0; t < frames; ++t) {
    for (int x = 0; x < n; ++x) {
      std::complex<double> sum = 0.0;
      for (int m = 0; m < frames; ++m) {
        for (int k = 0; k < n; ++k) {
          sum += spectrum[static_cast<std::size_t>(m) * n + k] *
                 std::polar(1.0, 2.0 * kPi * (double(k) * x / n + double(m) * t / frames));
        }
      }
      sum /= double(n) * frames;
      out.at<double>(t, x) = sum.real();
      *largest_imaginary = std::max(*largest_imaginary, std::abs(sum.imag()));
    }
  }
  return out;
}

TEST(VisualDifference, MatchesDirectSummationOffGridAndAtNyquist) {
  std::mt19937 random(13);
  std::uniform_real_distribution<double> noise(-0.3, 0.3);
  struct Case {
    int frames, n;
    double ppd, fps, v_r;
  };
  for (const Case& s : {Case{10, 12, 30.0, 90.0, 1.3}, Case{7, 9, 17.5, 72.0, -2.1}, Case{8, 11, 40.0, 120.0, 0.0}}) {
    // An off-grid moving grating (2.37 cycles over the line, 1.61 over the time window) plus noise reaching every
    // bin, half-rate bins included.
    const cv::Mat c = image_of(s.frames, s.n, [&](int t, int x) {
      return 0.2 * std::cos(2.0 * kPi * (2.37 * x / s.n - 1.61 * t / s.frames) + 0.4) + noise(random);
    });
    double largest_imaginary = 0.0;
    const cv::Mat expected = naive_weighted_contrast(c, s.ppd, s.fps, s.v_r, &largest_imaginary);
    const cv::Mat got = csf_weighted_contrast(c, s.ppd, s.fps, s.v_r);
    double scale = 0.0;
    cv::minMaxLoc(cv::abs(expected), nullptr, &scale);
    EXPECT_LT(largest_imaginary, 1e-9 * scale);
    EXPECT_LT(cv::norm(got, expected, cv::NORM_INF), 1e-9 * scale) << s.frames << "x" << s.n;
    const auto [l_a, l_b] = pair_with_contrast(c);
    const double energy = std::pow(sum_abs_pow(expected, 2.6), 1.0 / 2.6);
    EXPECT_NEAR(visual_difference_energy(l_a, l_b, s.ppd, s.fps, s.v_r), energy, 1e-6 * energy);
  }
}

TEST(StcsfWeights, AreConjugateSymmetricAndZeroWithoutSpatialFrequency) {
  for (const cv::Size size : {cv::Size(12, 10), cv::Size(9, 7)}) {
    const double ppd = 30.0;
    const double fps = 90.0;
    const double v_r = 1.7;
    const cv::Mat w = stcsf_weights(size, ppd, fps, v_r);
    ASSERT_EQ(w.size(), size);
    ASSERT_EQ(w.type(), CV_64FC1);
    for (int m = 0; m < size.height; ++m) {
      EXPECT_EQ(w.at<double>(m, 0), 0.0);
      for (int k = 0; k < size.width; ++k) {
        EXPECT_EQ(w.at<double>(m, k), w.at<double>((size.height - m) % size.height, (size.width - k) % size.width));
      }
    }
    // Bin (m = 1, k = 2): ρ = 2 ppd / N, DFT frequency fps / K, travelling ν = −fps / K; bin (m = K − 1, k = 2)
    // is the opposite temporal frequency.
    const double rho = 2.0 * ppd / size.width;
    for (const auto& [m, nu] : {std::pair{1, -fps / size.height}, std::pair{size.height - 1, fps / size.height}}) {
      const double expected = daly_1998(rho, std::max(std::abs(nu + rho * v_r) / rho, 0.15));
      EXPECT_NEAR(w.at<double>(m, 2), expected, 1e-12 * expected) << m;
    }
  }
}

TEST(VisualDifference, BadInputNamesTheArgument) {
  const cv::Mat l = cv::Mat::ones(4, 6, CV_64FC1);
  expect_invalid([&] { visual_difference_energy(l, cv::Mat::ones(4, 5, CV_64FC1), 30, 90, 0); }, "'l_b'");
  expect_invalid([&] { visual_difference_energy(l, l, 0.0, 90, 0); }, "'pixels_per_degree'");
  expect_invalid([&] { visual_difference_energy(l, l, -1.0, 90, 0); }, "'pixels_per_degree'");
  expect_invalid([&] { visual_difference_energy(l, l, kNaN, 90, 0); }, "'pixels_per_degree'");
  expect_invalid([&] { visual_difference_energy(l, l, 30, 0.0, 0); }, "'samples_per_second'");
  expect_invalid([&] { visual_difference_energy(l, l, 30, kInf, 0); }, "'samples_per_second'");
  expect_invalid([&] { visual_difference_energy(l, l, 30, 90, kNaN); }, "'retinal_velocity_deg_s'");
  cv::Mat with_nan = l.clone();
  with_nan.at<double>(2, 3) = kNaN;
  expect_invalid([&] { visual_difference_energy(with_nan, l, 30, 90, 0); }, "'l_a' has a non-finite value at row 2");
  cv::Mat negative = l.clone();
  negative.at<double>(1, 1) = -0.5;
  expect_invalid([&] { visual_difference_energy(l, negative, 30, 90, 0); }, "'l_b' has a negative luminance");
  const cv::Mat single = cv::Mat::ones(4, 6, CV_32FC1);
  expect_invalid([&] { visual_difference_energy(single, l, 30, 90, 0); }, "'l_a' must be CV_64FC1");
  expect_invalid([&] { visual_difference_energy(cv::Mat(), l, 30, 90, 0); }, "'l_a' must be a non-empty");
  expect_invalid([&] { contrast_difference(l, cv::Mat::ones(3, 6, CV_64FC1)); }, "contrast_difference: argument 'l_b'");
  expect_invalid([&] { csf_weighted_contrast(with_nan, 30, 90, 0); }, "'contrast'");
  expect_invalid([&] { csf_weighted_contrast(l, 30, -90, 0); }, "'samples_per_second'");
  expect_invalid([&] { stcsf_weights(cv::Size(0, 4), 30, 90, 0); }, "'size'");
  expect_invalid([&] { pooled_energy(l, 0.0); }, "'beta'");
  expect_invalid([&] { pooled_energy(with_nan); }, "'normalised_contrast'");
}

// ---- MTCD (Kim et al. Eq. 6) ----

TEST(Mtcd, HandComputedRgbSequence) {
  // n = 2, m = 1, t = 3. Pixel 0: (0,0,0) → (3,4,0) → (4,6,2): d = 5, then 3. Pixel 1: (10,10,10) → (10,10,10) →
  // (16,2,10): d = 0, then 10 (a fall of 8 in green: no 8-bit saturation). MTCD = (5 + 0 + 3 + 10) / (2·1·2).
  std::vector<cv::Mat> frames(3);
  frames[0] = (cv::Mat_<cv::Vec3b>(1, 2) << cv::Vec3b(0, 0, 0), cv::Vec3b(10, 10, 10));
  frames[1] = (cv::Mat_<cv::Vec3b>(1, 2) << cv::Vec3b(3, 4, 0), cv::Vec3b(10, 10, 10));
  frames[2] = (cv::Mat_<cv::Vec3b>(1, 2) << cv::Vec3b(4, 6, 2), cv::Vec3b(16, 2, 10));
  EXPECT_DOUBLE_EQ(mtcd(frames), 4.5);
  // The same in double-precision 2x1 (m = 2, n = 1): only the pixel count matters, not the shape.
  std::vector<cv::Mat> column;
  for (const cv::Mat& frame : frames) {
    cv::Mat f;
    frame.reshape(3, 2).convertTo(f, CV_64FC3);
    column.push_back(f);
  }
  EXPECT_DOUBLE_EQ(mtcd(column), 4.5);
}

TEST(Mtcd, GreySequenceAndStillSequence) {
  const std::vector<cv::Mat> grey{(cv::Mat_<double>(1, 2) << 0.0, 5.0), (cv::Mat_<double>(1, 2) << 2.0, 1.0)};
  EXPECT_DOUBLE_EQ(mtcd(grey), 3.0);
  const cv::Mat still(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  EXPECT_EQ(mtcd({still, still, still}), 0.0);
}

TEST(Mtcd, BadSequencesNameTheFrames) {
  const cv::Mat a(2, 2, CV_8UC3, cv::Scalar::all(1));
  expect_invalid([&] { mtcd({a}); }, "'frames' must hold at least 2");
  expect_invalid([&] { mtcd({a, cv::Mat(2, 3, CV_8UC3)}); }, "frame 1 differs");
  expect_invalid([&] { mtcd({a, cv::Mat(2, 2, CV_16UC3)}); }, "frame 1 differs");
  expect_invalid([&] { mtcd({a, cv::Mat()}); }, "frame 1 is empty");
  expect_invalid([&] { mtcd({cv::Mat(2, 2, CV_8UC4), cv::Mat(2, 2, CV_8UC4)}); }, "4 channels");
  cv::Mat nan(2, 2, CV_64FC3, cv::Scalar::all(0.0));
  nan.at<cv::Vec3d>(1, 0)[2] = kNaN;
  expect_invalid([&] { mtcd({cv::Mat(2, 2, CV_64FC3, cv::Scalar::all(0.0)), nan}); }, "frame 1 has a non-finite");
}

}  // namespace
}  // namespace trm
