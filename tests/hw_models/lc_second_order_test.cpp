// The second-order liquid crystal (lc_second_order.hpp) against the closed-form solutions of m x'' + k x' + x = p
// in its three regimes, written out here in long double; explicit Euler as the foil; its use by PanelLight and the
// retina.
#include <gtest/gtest.h>

#include "hw_models_test_support.hpp"

#include "trm/lc_second_order.hpp"
#include "trm/panel_light.hpp"
#include "trm/retina.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::expect_invalid;

using Real = long double;

// x(t) − p and its integral ∫₀^t (x − p) for m = τ², k = 2ζτ from x(0) − p = a, x'(0) = b.
struct Analytic {
  Real deviation = 0.0L;
  Real rate = 0.0L;
  Real integral = 0.0L;
};

Analytic analytic(Real tau, Real zeta, Real a, Real b, Real t) {
  Analytic out;
  if (zeta < 1.0L) {
    // Underdamped: e^{−σt} (a cos ωt + c sin ωt), σ = ζ/τ, ω = √(1 − ζ²)/τ, c = (b + σ a)/ω.
    const Real sigma = zeta / tau, omega = std::sqrt(1.0L - zeta * zeta) / tau;
    const Real c = (b + sigma * a) / omega;
    const Real e = std::exp(-sigma * t), cs = std::cos(omega * t), sn = std::sin(omega * t);
    out.deviation = e * (a * cs + c * sn);
    out.rate = e * ((c * omega - sigma * a) * cs - (a * omega + sigma * c) * sn);
    // ∫ e^{−σs} cos ωs = (σ − e(σ cos − ω sin)) / (σ² + ω²); ∫ e^{−σs} sin ωs = (ω − e(σ sin + ω cos)) / (σ² + ω²).
    const Real norm = sigma * sigma + omega * omega;
    out.integral = (a * (sigma - e * (sigma * cs - omega * sn)) + c * (omega - e * (sigma * sn + omega * cs))) / norm;
  } else if (zeta == 1.0L) {
    // Critical: e^{−t/τ} (a + (b + a/τ) t).
    const Real d = b + a / tau, e = std::exp(-t / tau);
    out.deviation = e * (a + d * t);
    out.rate = e * (d - (a + d * t) / tau);
    // ∫ e^{−s/τ} = τ (1 − e); ∫ s e^{−s/τ} = τ² (1 − e) − τ t e.
    out.integral = a * tau * (1.0L - e) + d * (tau * tau * (1.0L - e) - tau * t * e);
  } else {
    // Overdamped: A e^{r1 t} + B e^{r2 t}, r = (−ζ ± √(ζ² − 1))/τ.
    const Real root = std::sqrt(zeta * zeta - 1.0L);
    const Real r1 = (-zeta + root) / tau, r2 = (-zeta - root) / tau;
    const Real big_a = (b - r2 * a) / (r1 - r2), big_b = a - big_a;
    const Real e1 = std::exp(r1 * t), e2 = std::exp(r2 * t);
    out.deviation = big_a * e1 + big_b * e2;
    out.rate = big_a * r1 * e1 + big_b * r2 * e2;
    out.integral = big_a * (e1 - 1.0L) / r1 + big_b * (e2 - 1.0L) / r2;
  }
  return out;
}

constexpr double kPeriod90Hz = 1.0 / 90.0;

TEST(LcSecondOrder, MatchesTheAnalyticSolutionForStepsFromAThousandthToAMillionNaturalTimes) {
  // The state after one frame and the light over it, in all three regimes, for dt/τ from 1e-3 to 1e6 and starts at
  // rest and moving. Errors are in units of the step (level) and of the frame times the step (integral).
  struct Start {
    double level, rate_times_tau;
  };
  const std::vector<Start> starts = {{0.0, 0.0}, {0.9, 0.0}, {0.3, 2.0}, {0.7, -1.5}};
  double worst_level = 0.0, worst_rate = 0.0, worst_integral = 0.0;
  for (const double zeta : {0.2, 1.0, 5.0}) {
    for (int decade = -3; decade <= 6; ++decade) {
      const double dt_over_tau = std::pow(10.0, decade);
      const double tau = kPeriod90Hz / dt_over_tau;
      const LcSecondOrder lc({tau, zeta}, kPeriod90Hz);
      for (const double drive : {0.0, 1.0, 0.45}) {
        for (const Start& s : starts) {
          const LcMotion start{s.level, s.rate_times_tau / tau};
          const Analytic exact = analytic(tau, zeta, Real(s.level) - drive, Real(start.rate_per_s), kPeriod90Hz);
          const LcMotion end = lc.end_of_frame(start, drive);
          const LcMotion advanced = lc.advance(start, drive, kPeriod90Hz);
          const double level_error = std::abs(end.level - static_cast<double>(drive + exact.deviation));
          const double rate_error = std::abs(end.rate_per_s - static_cast<double>(exact.rate)) * tau;
          const double integral_error =
              std::abs(lc.integral(start, drive, 0.0, kPeriod90Hz) - static_cast<double>(drive * Real(kPeriod90Hz) +
                                                                                      exact.integral)) / kPeriod90Hz;
          SCOPED_TRACE(testing::Message() << "zeta " << zeta << " dt/tau " << dt_over_tau << " drive " << drive
                                          << " from " << s.level << ", " << s.rate_times_tau);
          EXPECT_LT(level_error, 1e-14);
          EXPECT_LT(rate_error, 1e-14);
          EXPECT_LT(integral_error, 1e-14);
          EXPECT_NEAR(advanced.level, end.level, 1e-14);
          worst_level = std::max(worst_level, level_error);
          worst_rate = std::max(worst_rate, rate_error);
          worst_integral = std::max(worst_integral, integral_error);
        }
      }
    }
  }
  std::printf("[ LC 2nd order ] dt/tau 1e-3..1e6, zeta 0.2/1/5: max |x - x_exact| %.2e, max tau |x' - x'_exact| %.2e, "
              "max |integral error| / T %.2e\n",
              worst_level, worst_rate, worst_integral);
}

TEST(LcSecondOrder, PartialIntegralsAddUpAndMatchTheClosedForm) {
  // ∫_{t0}^{t1} from the weights against the difference of the closed-form integrals, for windows inside the frame.
  const double tau = 0.0021, zeta = 0.35;
  const LcSecondOrder lc({tau, zeta}, kPeriod90Hz);
  const LcMotion start{0.2, 40.0};
  const double drive = 0.8;
  for (const auto& [t0, t1] : {std::pair{0.0, 0.001}, std::pair{0.002, 0.0071}, std::pair{0.0105, kPeriod90Hz}}) {
    const Real exact = drive * Real(t1 - t0) + analytic(tau, zeta, Real(start.level) - drive, start.rate_per_s, t1).integral -
                       analytic(tau, zeta, Real(start.level) - drive, start.rate_per_s, t0).integral;
    EXPECT_NEAR(lc.integral(start, drive, t0, t1), static_cast<double>(exact), 1e-15) << t0 << " " << t1;
  }
  double sum = 0.0;
  for (int k = 0; k < 7; ++k) sum += lc.integral(start, drive, kPeriod90Hz * k / 7, kPeriod90Hz * (k + 1) / 7);
  EXPECT_NEAR(sum, lc.integral(start, drive, 0.0, kPeriod90Hz), 1e-17);
}

TEST(LcSecondOrder, UnderdampedStepOvershootsByTheTextbookFraction) {
  // A unit step from rest peaks at t = π τ / √(1 − ζ²) at 1 + e^{−πζ/√(1−ζ²)}; ζ >= 1 never passes the drive.
  for (const double zeta : {0.1, 0.5, 0.9}) {
    const double tau = 0.001;
    const LcSecondOrder lc({tau, zeta}, kPeriod90Hz);
    const double root = std::sqrt(1.0 - zeta * zeta);
    const LcMotion peak = lc.advance({0.0, 0.0}, 1.0, M_PI * tau / root);
    EXPECT_NEAR(peak.level, 1.0 + std::exp(-M_PI * zeta / root), 1e-13) << zeta;
    EXPECT_NEAR(peak.rate_per_s * tau, 0.0, 1e-12) << zeta;
  }
  for (const double zeta : {1.0, 1.5, 20.0}) {
    const LcSecondOrder lc({0.001, zeta}, kPeriod90Hz);
    for (int i = 0; i <= 200; ++i) {
      const double level = lc.advance({0.0, 0.0}, 1.0, kPeriod90Hz * i / 200.0).level;
      EXPECT_GE(level, 0.0);
      EXPECT_LE(level, 1.0);
    }
  }
}

TEST(LcSecondOrder, DampedCrystalStaysWithinTheDriveRangeWhereExplicitEulerDiverges) {
  // ζ >= 1: the impulse response is non-negative with unit area, so under any drive in [0, 1] the state stays in
  // [0, 1], frame after frame, for any dt/τ. Explicit Euler with one step per frame, the foil, is stable only for
  // dt/τ <= 2/ζ-ish and blows up beyond it.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const double zeta : {1.0, 3.0}) {
    for (const double dt_over_tau : {1e-3, 0.5, 10.0, 1e3, 1e6}) {
      const double tau = kPeriod90Hz / dt_over_tau;
      const LcSecondOrder lc({tau, zeta}, kPeriod90Hz);
      LcMotion exact{0.5, 0.0};
      double euler_x = 0.5, euler_v = 0.0;
      bool euler_diverged = false;
      for (int f = 0; f < 2000; ++f) {
        const double drive = f % 2 == 0 ? uniform(rng) : (f % 4 == 1 ? 1.0 : 0.0);
        exact = lc.end_of_frame(exact, drive);
        ASSERT_GE(exact.level, -1e-15) << zeta << " " << dt_over_tau << " frame " << f;
        ASSERT_LE(exact.level, 1.0 + 1e-15) << zeta << " " << dt_over_tau << " frame " << f;
        // x'' = (p − x − k x') / m.
        const double accel = (drive - euler_x - 2.0 * zeta * tau * euler_v) / (tau * tau);
        euler_x += kPeriod90Hz * euler_v;
        euler_v += kPeriod90Hz * accel;
        euler_diverged = euler_diverged || !(std::abs(euler_x) < 1e6);
      }
      if (dt_over_tau >= 10.0) {
        EXPECT_TRUE(euler_diverged) << zeta << " " << dt_over_tau;
      } else if (dt_over_tau <= 1e-3) {
        EXPECT_FALSE(euler_diverged) << zeta << " " << dt_over_tau;
      }
    }
  }
}

TEST(LcSecondOrder, PanelLightUsesItsStateAndRateAndTheRetinaAveragesIt) {
  PanelLightConfig config;
  config.refresh_hz = 90.0;
  config.lc_second_order = LcSecondOrderParams{0.0015, 1.0};
  const PanelLight light(config);
  ASSERT_TRUE(light.has_lc_state());
  const double tau = 0.0015;
  // Critical damping: the frame's end and its light are the closed form.
  const LcMotion start{0.1, 120.0};
  const Analytic exact = analytic(tau, 1.0L, Real(0.1) - 0.8, 120.0L, kPeriod90Hz);
  const LcMotion end = light.end_state(start, 0.8);
  EXPECT_NEAR(end.level, static_cast<double>(0.8L + exact.deviation), 1e-14);
  EXPECT_NEAR(light.integral(0.0, kPeriod90Hz, start, 0.8), static_cast<double>(0.8L * kPeriod90Hz + exact.integral), 1e-16);
  EXPECT_NEAR(light.level_at(0.004, start, 0.8),
              static_cast<double>(0.8L + analytic(tau, 1.0L, Real(0.1) - 0.8, 120.0L, 0.004).deviation), 1e-14);
  EXPECT_THROW(light.end_state(0.1, 0.8), std::logic_error);
  // A still eye sees each pixel's time average: the frames' integrals chained through the closed form.
  cv::Mat frames(5, 3, CV_64FC1);
  const double levels[5][3] = {{0.0, 1.0, 0.5}, {1.0, 0.0, 0.5}, {0.2, 0.9, 0.5}, {1.0, 1.0, 0.0}, {0.0, 0.3, 1.0}};
  for (int n = 0; n < 5; ++n) {
    for (int i = 0; i < 3; ++i) frames.at<double>(n, i) = levels[n][i];
  }
  for (int i = 0; i < 3; ++i) {
    Real x = levels[0][i], v = 0.0L, sum = 0.0L;
    for (int n = 0; n < 5; ++n) {
      const Real drive = levels[n][i];
      const Analytic a = analytic(tau, 1.0L, x - drive, v, kPeriod90Hz);
      sum += drive * Real(kPeriod90Hz) + a.integral;
      x = drive + a.deviation;
      v = a.rate;
    }
    RetinaOptions options;
    options.substeps = 5;
    const cv::Mat seen = retinal_row(frames, light, custom_viewer(11.42), 0.0, options);
    EXPECT_NEAR(seen.at<double>(0, i), static_cast<double>(sum / (5 * Real(kPeriod90Hz))), 1e-14) << i;
  }
}

TEST(LcSecondOrder, OverdriveEndsTheFrameAtTheTargetFromTheLevelAndTheRateOrClampsToTheNearest) {
  // τ = 4 ms at 90 Hz (a frame is 2.8 natural times): many targets are out of one frame's reach. A run of targets,
  // the rate carried from frame to frame; the oracle is the closed form at the drive the panel chose.
  const double tau = 0.004;
  for (const Real zeta : {1.0L, 1.6L}) {
    PanelLightConfig config;
    config.refresh_hz = 90.0;
    config.lc_second_order = LcSecondOrderParams{tau, static_cast<double>(zeta)};
    config.overdrive = true;
    const PanelLight light(config);
    std::mt19937 random(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<double> targets = {1.0, 0.0, 0.5, 0.5, 0.5, 0.9, 0.1};
    for (int i = 0; i < 200; ++i) targets.push_back(uniform(random));
    LcMotion state{0.2, 0.0};
    int reached = 0, clamped = 0;
    for (double level : targets) {
      const double drive = light.drive(state, level);
      const auto end_at = [&](Real p) { return p + analytic(tau, zeta, state.level - p, state.rate_per_s, kPeriod90Hz).deviation; };
      if (drive > 0.0 && drive < 1.0) {
        EXPECT_NEAR(static_cast<double>(end_at(drive)), level, 1e-12) << "from " << state.level << " to " << level;
        ++reached;
      } else {
        // Clamped: even the whole drive range stops short, on the side the drive was clamped to.
        ASSERT_TRUE(drive == 0.0 || drive == 1.0) << drive;
        if (drive == 1.0) {
          EXPECT_LE(static_cast<double>(end_at(1.0L)), level + 1e-12);
        } else {
          EXPECT_GE(static_cast<double>(end_at(0.0L)), level - 1e-12);
        }
        ++clamped;
      }
      const LcMotion next = light.end_state(state, level);
      EXPECT_NEAR(next.level, static_cast<double>(end_at(drive)), 1e-13);
      // The light of the frame is the closed form's at that drive too, and stays within the drive range.
      EXPECT_NEAR(light.integral(0.0, kPeriod90Hz, state, level),
                  static_cast<double>(Real(drive) * Real(kPeriod90Hz) +
                                      analytic(tau, zeta, state.level - drive, state.rate_per_s, kPeriod90Hz).integral),
                  1e-15);
      EXPECT_GE(next.level, -1e-12);
      EXPECT_LE(next.level, 1.0 + 1e-12);
      state = next;
    }
    EXPECT_GT(reached, 50) << static_cast<double>(zeta);
    EXPECT_GT(clamped, 20) << static_cast<double>(zeta);
  }
}

TEST(LcSecondOrder, OverdrivenLightThroughTheRetinaCarriesTheDrive) {
  // The retina's shared weights multiply each pixel's drive: a still eye sees the frames' integrals chained through
  // end_state, with the rate of a moving start (previous_rate) carried in.
  PanelLightConfig config;
  config.refresh_hz = 90.0;
  config.lc_second_order = LcSecondOrderParams{0.003, 1.0};
  config.overdrive = true;
  const PanelLight light(config);
  cv::Mat frames(4, 1, CV_64FC3);
  const double levels[4][3] = {{0.0, 1.0, 0.5}, {1.0, 0.2, 0.5}, {0.3, 0.9, 0.1}, {0.6, 0.6, 0.6}};
  for (int n = 0; n < 4; ++n) {
    for (int c = 0; c < 3; ++c) frames.at<cv::Vec3d>(n, 0)[c] = levels[n][c];
  }
  const cv::Mat previous(1, 1, CV_64FC3, cv::Scalar(0.4, 0.4, 0.4));
  const cv::Mat previous_rate(1, 1, CV_64FC3, cv::Scalar(-50.0, 0.0, 80.0));
  std::vector<cv::Mat> images;
  for (int n = 0; n < 4; ++n) images.push_back(frames.row(n).clone());
  RetinaOptions options;
  options.substeps = 3;
  const cv::Mat seen = retinal_image(images, light, custom_viewer(11.42), 0.0, options, previous, previous_rate);
  for (int c = 0; c < 3; ++c) {
    LcMotion state{0.4, previous_rate.at<cv::Vec3d>(0, 0)[c]};
    double sum = 0.0;
    for (int n = 0; n < 4; ++n) {
      sum += light.integral(0.0, kPeriod90Hz, state, levels[n][c]);
      state = light.end_state(state, levels[n][c]);
    }
    EXPECT_NEAR(seen.at<cv::Vec3d>(0, 0)[c], sum / (4 * kPeriod90Hz), 1e-13) << c;
  }
  expect_invalid([&] { retinal_image(images, light, custom_viewer(11.42), 0.0, options, {}, previous_rate); },
                 "'previous_rate'");
}

TEST(LcSecondOrder, BadParametersAreRejectedByName) {
  expect_invalid([] { LcSecondOrder({0.0, 1.0}, kPeriod90Hz); }, "'tau_s'");
  expect_invalid([] { LcSecondOrder({std::nan(""), 1.0}, kPeriod90Hz); }, "'tau_s'");
  expect_invalid([] { LcSecondOrder({0.001, 0.0}, kPeriod90Hz); }, "'damping_ratio'");
  expect_invalid([] { LcSecondOrder({0.001, INFINITY}, kPeriod90Hz); }, "'damping_ratio'");
  expect_invalid([] { LcSecondOrder({0.001, 1.0}, 0.0); }, "'frame_period_s'");
  const LcSecondOrder lc({0.001, 1.0}, kPeriod90Hz);
  expect_invalid([&] { lc.weights(-1.0, 0.0); }, "'t0'");
  expect_invalid([&] { lc.weights(0.002, 0.001); }, "'t1'");
  expect_invalid([&] { lc.advance({}, 0.0, -1.0); }, "'seconds'");
  PanelLightConfig both;
  both.lc_response = LcResponseParams{};
  both.lc_second_order = LcSecondOrderParams{};
  expect_invalid([&] { PanelLight{both}; }, "'lc_second_order'");
  PanelLightConfig with_tau;
  with_tau.lc_tau_s = 0.001;
  with_tau.lc_second_order = LcSecondOrderParams{};
  expect_invalid([&] { PanelLight{with_tau}; }, "'lc_tau_s'");
}

}  // namespace
}  // namespace trm
