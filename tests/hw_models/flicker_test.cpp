// Fixed-gaze flicker visibility and judder energy against answers worked out from their definitions: a flickering
// grating's visibility is its contrast times the stCSF at its frequency and the pair frequency; a still pair does
// not flicker; a black-frame alternation stops being visible at a refresh rate the CSF alone sets; a still x-t
// image has no temporal aliases, an edge held for two frames has more than one moving every frame.
#include <gtest/gtest.h>

#include "hw_models_test_support.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "trm/csf.hpp"
#include "trm/flicker.hpp"
#include "trm/visual_difference.hpp"

namespace trm {
namespace {

using test::kPi;


// A view whose two frames carry a grating of `cycles` periods across `cols` in opposite phase, so the alternation
// contrast (Y_a - Y_b) / (Y_a + Y_b) is exactly c cos(2 pi cycles x / cols).
void grating_pair(int cols, int rows, int cycles, double contrast, cv::Mat& a, cv::Mat& b) {
  a.create(rows, cols, CV_64FC1);
  b.create(rows, cols, CV_64FC1);
  for (int x = 0; x < cols; ++x) {
    const double wave = contrast * std::cos(2.0 * kPi * cycles * x / cols);
    a.col(x).setTo(0.5 * (1.0 + wave));
    b.col(x).setTo(0.5 * (1.0 - wave));
  }
}

TEST(FlickerSpectrum, FlickeringGratingIsItsContrastTimesTheCsfAtThePairFrequency) {
  const double ppd = 20.0;
  const int cols = 200, rows = 40, cycles = 10;  // 1 cpd
  const double contrast = 0.3;
  cv::Mat a, b;
  grating_pair(cols, rows, cycles, contrast, a, b);
  FlickerSpectrum flicker(ppd, Surround::Periodic);
  flicker.add_pair(a, b);
  flicker.add_pair(b, a);  // the phase of the alternation does not matter
  const double rho = cycles * ppd / cols;
  for (const double refresh : {40.0, 60.0, 90.0, 144.0}) {
    const double expected = contrast * flicker_sensitivity(rho, refresh / 2.0);
    EXPECT_NEAR(flicker.visibility(refresh), expected, 1e-9 * expected) << refresh << " Hz";
  }
}

TEST(FlickerSensitivity, IsTheStCsfAboveItsPeakFrequencyAndItsPeakBelow) {
  for (const double nu : {5.0, 15.0, 30.0, 45.0}) {
    double peak = 0.0, peak_rho = 0.0;
    for (double rho = 0.01; rho < 60.0; rho *= 1.001) {
      if (csf_spatiotemporal(rho, nu) > peak) {
        peak = csf_spatiotemporal(rho, nu);
        peak_rho = rho;
      }
    }
    EXPECT_NEAR(flicker_sensitivity(0.0, nu), peak, 1e-4 * peak) << nu;
    EXPECT_NEAR(flicker_sensitivity(peak_rho / 4.0, nu), peak, 1e-4 * peak) << nu;
    EXPECT_DOUBLE_EQ(flicker_sensitivity(peak_rho * 3.0, nu), csf_spatiotemporal(peak_rho * 3.0, nu)) << nu;
    EXPECT_GT(flicker_sensitivity(0.0, nu), flicker_sensitivity(0.0, nu + 10.0));  // falls with frequency
  }
  EXPECT_THROW((void)flicker_sensitivity(1.0, 0.0), std::invalid_argument);
}

TEST(FlickerSpectrum, InvisibleFromIsWhereVisibilityLastCrossesOne) {
  // Full contrast at the CSF's most sensitive low frequencies: visible at a slow refresh, invisible at a fast one.
  cv::Mat a, b;
  grating_pair(240, 8, 2, 1.0, a, b);  // 2 cycles over 240 px at 24 ppd: 0.2 cpd
  FlickerSpectrum flicker(24.0, Surround::Periodic);
  flicker.add_pair(a, b);
  const double from = flicker.invisible_from_hz(30.0, 480.0);
  ASSERT_TRUE(std::isfinite(from));
  ASSERT_GT(from, 30.0);
  EXPECT_LT(flicker.visibility(from), 1.0);
  EXPECT_GE(flicker.visibility(from - 1.0), 1.0);
  for (double hz = from; hz <= 480.0; hz += 7.0) EXPECT_LT(flicker.visibility(hz), 1.0) << hz;
}

TEST(FlickerSpectrum, StillPairDoesNotFlicker) {
  cv::Mat a, b;
  grating_pair(64, 16, 3, 0.5, a, b);
  FlickerSpectrum flicker(11.42);
  flicker.add_pair(a, a.clone());
  EXPECT_EQ(flicker.visibility(60.0), 0.0);
  EXPECT_EQ(flicker.invisible_from_hz(30.0, 480.0), 30.0);
  EXPECT_EQ(FlickerSpectrum(11.42).visibility(90.0), 0.0);  // no pair yet
}

TEST(FlickerSpectrum, BlackFrameFlickerIsVisibleAtSlowRefreshOnly) {
  // A lit view alternating with black (BFI): its alternation contrast is 1 everywhere, visible at a slow enough rate.
  const cv::Mat lit(120, 160, CV_64FC1, cv::Scalar(0.5));
  const cv::Mat black = cv::Mat::zeros(120, 160, CV_64FC1);
  FlickerSpectrum periodic(11.42, Surround::Periodic);
  periodic.add_pair(lit, black);
  // A view-filling uniform alternation of contrast 1 has a mean square of 1 at rho = 0, twice a unit grating's.
  EXPECT_NEAR(periodic.visibility(60.0), std::sqrt(2.0) * flicker_sensitivity(0.0, 30.0), 1e-9);
  FlickerSpectrum dark(11.42, Surround::Dark);
  dark.add_pair(lit, black);
  EXPECT_GT(dark.visibility(40.0), dark.visibility(90.0));
  EXPECT_GT(dark.visibility(90.0), dark.visibility(144.0));
  EXPECT_GT(dark.visibility(40.0), 1.0);
  EXPECT_LT(dark.visibility(240.0), 1.0);
}

TEST(FlickerSpectrum, RejectsBadInput) {
  EXPECT_THROW(FlickerSpectrum(0.0), std::invalid_argument);
  EXPECT_THROW(FlickerSpectrum(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  FlickerSpectrum flicker(10.0);
  const cv::Mat a(8, 8, CV_64FC1, cv::Scalar(0.5));
  EXPECT_THROW(flicker.add_pair(a, cv::Mat(8, 9, CV_64FC1, cv::Scalar(0.5))), std::invalid_argument);
  EXPECT_THROW(flicker.add_pair(a, cv::Mat(8, 8, CV_64FC1, cv::Scalar(-1.0))), std::invalid_argument);
  flicker.add_pair(a, a);
  try {
    flicker.add_pair(cv::Mat(4, 4, CV_64FC1, cv::Scalar(0.5)), cv::Mat(4, 4, CV_64FC1, cv::Scalar(0.5)));
    ADD_FAILURE() << "a pair of another size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("size of the first pair"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)flicker.visibility(0.0), std::invalid_argument);
  EXPECT_THROW((void)flicker.invisible_from_hz(100.0, 50.0), std::invalid_argument);
}

// An x-t image (one row per sample) of an edge at `position(t)` columns: 1 left of it, 0.2 right of it.
cv::Mat edge_xt(int rows, int cols, double (*position)(int row)) {
  cv::Mat xt(rows, cols, CV_64FC1);
  for (int t = 0; t < rows; ++t) {
    for (int x = 0; x < cols; ++x) xt.at<double>(t, x) = x < position(t) ? 1.0 : 0.2;
  }
  return xt;
}

TEST(TemporalAliasEnergy, StillImageHasNoneAndAHeldEdgeJuddersMoreThanAMovingOne) {
  // In the target's frame a pursued edge shown at full rate steps back by one frame's travel each frame (4 samples
  // per frame, 2 px per frame); at half rate it is held two frames and steps back twice as far.
  const auto still = [](int) { return 32.0; };
  const auto full_rate = [](int t) { return 32.0 + 2.0 * ((t % 4) / 4.0) - 1.0; };
  const auto half_rate = [](int t) { return 32.0 + 4.0 * ((t % 8) / 8.0) - 2.0; };
  const double ppd = 11.42, rate = 90.0 * 4;
  EXPECT_LT(temporal_alias_energy(edge_xt(64, 64, +still), ppd, rate, 0.0), 1e-9);
  const double full = temporal_alias_energy(edge_xt(64, 64, +full_rate), ppd, rate, 0.0);
  const double half = temporal_alias_energy(edge_xt(64, 64, +half_rate), ppd, rate, 0.0);
  EXPECT_GT(full, 0.0);
  EXPECT_GT(half, 2.0 * full);
  EXPECT_THROW((void)temporal_alias_energy(cv::Mat(), ppd, rate, 0.0), std::invalid_argument);
  // Against a reference: its own aliases cancel, the extra ones remain.
  const cv::Mat held = edge_xt(64, 64, +half_rate);
  EXPECT_EQ(temporal_alias_energy(held, ppd, rate, 0.0, held), 0.0);
  EXPECT_GT(temporal_alias_energy(held, ppd, rate, 0.0, edge_xt(64, 64, +full_rate)), 0.0);
  EXPECT_THROW((void)temporal_alias_energy(held, ppd, rate, 0.0, cv::Mat(8, 8, CV_64FC1, cv::Scalar(0.0))),
               std::invalid_argument);
}

}  // namespace
}  // namespace trm
