// The level-dependent liquid-crystal response (lc_response.hpp) and its use by PanelLight and the retina.
#include <gtest/gtest.h>

#include "hw_models_test_support.hpp"

#include "trm/lc_response.hpp"
#include "trm/panel.hpp"
#include "trm/panel_light.hpp"
#include "trm/retina.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::expect_invalid;

constexpr double kRefresh = 120.0;
constexpr double kPeriod = 1.0 / kRefresh;

// τ_on from the Jakeman–Raynes form, written out again here rather than taken from the model.
double jakeman_raynes_rise_tau(const LcResponseParams& p, double level) {
  const double v_over_vth = 1.0 + (p.drive_ratio - 1.0) * std::pow(level, 1.0 / p.drive_gamma);
  return p.tau_off_s / (v_over_vth * v_over_vth - 1.0);
}

PanelLight lc_light(const LcResponseParams& params, double refresh_hz = kRefresh) {
  PanelLightConfig config;
  config.refresh_hz = refresh_hz;
  config.lc_response = params;
  return PanelLight(config);
}

// The ODE's right-hand side with τ chosen per segment by the sign of the step, as the model defines it.
double rhs(const LcResponseParams& p, double x0, double drive, double x) {
  const double tau = drive > x0 ? jakeman_raynes_rise_tau(p, drive) : p.tau_off_s;
  return (drive - x) / tau;
}

// Classical Runge–Kutta over one frame of constant drive in n steps: the independent fine-step reference.
double rk4_frame(const LcResponseParams& p, double x0, double drive, int n) {
  const double h = kPeriod / n;
  double x = x0;
  for (int i = 0; i < n; ++i) {
    const double k1 = rhs(p, x0, drive, x);
    const double k2 = rhs(p, x0, drive, x + h / 2 * k1);
    const double k3 = rhs(p, x0, drive, x + h / 2 * k2);
    const double k4 = rhs(p, x0, drive, x + h * k3);
    x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return x;
}

// The foil: explicit Euler of the same ODE with step h.
double euler_frame(const LcResponseParams& p, double x0, double drive, double h, int steps) {
  double x = x0;
  for (int i = 0; i < steps; ++i) x += h * rhs(p, x0, drive, x);
  return x;
}

TEST(LcResponse, RisingAndFallingTransitionsAreTheirClosedForms) {
  const LcResponseParams params;
  const PanelLight light = lc_light(params);
  for (const auto& [x0, level] : {std::pair{0.1, 0.8}, std::pair{0.0, 0.05}, std::pair{0.9, 0.2}, std::pair{1.0, 0.0}}) {
    const double tau = level > x0 ? jakeman_raynes_rise_tau(params, level) : params.tau_off_s;
    const auto exact = [&](double t) { return level + (x0 - level) * std::exp(-t / tau); };
    EXPECT_NEAR(light.end_state(x0, level), exact(kPeriod), 1e-15) << x0 << " -> " << level;
    EXPECT_NEAR(light.level_at(0.003, x0, level), exact(0.003), 1e-15);
    const double integral = level * kPeriod + (x0 - level) * tau * (1.0 - std::exp(-kPeriod / tau));
    EXPECT_NEAR(light.integral(0.0, kPeriod, x0, level), integral, 1e-15 * kPeriod);
  }
  // Falling does not depend on the level: the elastic constant alone sets it.
  const LcResponse lc(params, kPeriod);
  EXPECT_EQ(lc.tau_s(0.9, 0.1), params.tau_off_s);
  EXPECT_EQ(lc.tau_s(0.5, 0.0), params.tau_off_s);
}

TEST(LcResponse, FineStepReferenceConvergesToTheExactUpdate) {
  const LcResponseParams params;
  const PanelLight light = lc_light(params);
  const std::vector<double> levels{0.02, 0.7, 0.3, 1.0, 0.0, 0.45};
  double errors[3] = {};
  const int steps[3] = {20, 40, 2000};
  for (int s = 0; s < 3; ++s) {
    double exact = 0.0, reference = 0.0;
    for (double level : levels) {
      // Each frame starts both from the exact state so that only this frame's error is measured.
      reference = rk4_frame(params, exact, level, steps[s]);
      exact = light.end_state(exact, level);
      errors[s] = std::max(errors[s], std::abs(reference - exact));
    }
  }
  // RK4 is fourth order: doubling the steps divides the error by about 16; at T/2000 it agrees to rounding.
  EXPECT_GT(errors[0] / errors[1], 12.0) << errors[0] << " " << errors[1];
  EXPECT_LT(errors[2], 1e-13);
}

TEST(LcResponse, StiffCrystalReachesTheLevelWhereExplicitEulerBlowsUp) {
  LcResponseParams params;
  params.tau_off_s = 1e-9;
  const PanelLight light = lc_light(params, 90.0);
  const double period = 1.0 / 90.0;
  const double h = period / kDefaultRetinaSubsteps;  // the retina's sub-step
  for (const auto& [x0, level] : {std::pair{0.0, 1.0}, std::pair{1.0, 0.25}, std::pair{0.1, 0.6}}) {
    EXPECT_EQ(light.end_state(x0, level), level);
    for (int i = 0; i < 64; ++i) {
      const double value = light.level_at(period * i / 64.0, x0, level);
      ASSERT_TRUE(std::isfinite(value));
      // No overshoot (1e-16: the rounding of p + (x0 − p) at t = 0).
      EXPECT_GE(value, std::min(x0, level) - 1e-16);
      EXPECT_LE(value, std::max(x0, level) + 1e-16);
    }
    const double euler = euler_frame(params, x0, level, h, kDefaultRetinaSubsteps);
    EXPECT_FALSE(std::isfinite(euler) && std::abs(euler - level) < 1.0) << euler;
  }
  // The eye model on it: an instant panel, finite everywhere.
  cv::Mat frames(4, 32, CV_64F);
  for (int f = 0; f < frames.rows; ++f) {
    for (int x = 0; x < frames.cols; ++x) frames.at<double>(f, x) = ((x + 3 * f) % 8) < 4 ? 1.0 : 0.02;
  }
  const Viewer viewer = custom_viewer(20.0);
  const cv::Mat stiff = retinal_row(frames, light, viewer, 30.0);
  const cv::Mat instant = retinal_row(frames, PanelLight(PanelLightConfig{90.0, 1.0, 0.0, 0.0}), viewer, 30.0);
  EXPECT_TRUE(cv::checkRange(stiff));
  EXPECT_LT(cv::norm(stiff, instant, cv::NORM_INF), 1e-6);
}

TEST(LcResponse, ExactForStepsFromAMillionthToAMillionTimeConstants) {
  // dt/τ from 1e-6 to 1e6 (τ from a million frames down to a millionth of one): the frame's end state, its light
  // and the light of a part of it against the closed form in long double, for the constant τ and for the
  // level-dependent response (τ_off scaled, τ_on(p) by Jakeman–Raynes). Errors in units of the step and of T.
  double worst_state = 0.0, worst_light = 0.0;
  const std::vector<std::pair<double, double>> steps = {{0.0, 1.0}, {1.0, 0.0}, {0.3, 0.75}, {0.8, 0.05}};
  for (int decade = -6; decade <= 6; ++decade) {
    const double dt_over_tau = std::pow(10.0, decade);
    LcResponseParams params;
    params.tau_off_s = kPeriod / dt_over_tau;
    PanelLightConfig constant;
    constant.refresh_hz = kRefresh;
    constant.lc_tau_s = kPeriod / dt_over_tau;
    for (const PanelLight& light : {PanelLight(constant), lc_light(params)}) {
      const bool level_dependent = light.lc_response().has_value();
      for (const auto& [x0, level] : steps) {
        const long double tau =
            !level_dependent ? constant.lc_tau_s : level > x0 ? jakeman_raynes_rise_tau(params, level) : params.tau_off_s;
        const auto state_at = [&](long double t) { return level + (x0 - level) * std::exp(-t / tau); };
        const auto light_over = [&](long double t0, long double t1) {
          // e^{−t0/τ} − e^{−t1/τ} through expm1: the plain difference loses the digits of a slow crystal.
          return level * (t1 - t0) + (x0 - level) * tau * std::exp(-t0 / tau) * -std::expm1(-(t1 - t0) / tau);
        };
        SCOPED_TRACE(testing::Message() << "dt/tau " << dt_over_tau << (level_dependent ? " level-dependent " : " ")
                                        << x0 << " -> " << level);
        const double state_error = std::abs(light.end_state(x0, level) - static_cast<double>(state_at(kPeriod)));
        const double frame_error =
            std::abs(light.integral(0.0, kPeriod, x0, level) - static_cast<double>(light_over(0.0L, kPeriod))) / kPeriod;
        const double part_error = std::abs(light.integral(0.3 * kPeriod, 0.35 * kPeriod, x0, level) -
                                           static_cast<double>(light_over(0.3L * kPeriod, 0.35L * kPeriod))) / kPeriod;
        EXPECT_LT(state_error, 1e-15);
        EXPECT_LT(frame_error, 1e-15);
        EXPECT_LT(part_error, 1e-15);
        // First order: between the start and the level at every time, never beyond.
        for (int i = 0; i <= 16; ++i) {
          const double at = light.level_at(kPeriod * i / 17.0, x0, level);
          EXPECT_GE(at, std::min(x0, level) - 1e-16);
          EXPECT_LE(at, std::max(x0, level) + 1e-16);
        }
        worst_state = std::max(worst_state, state_error);
        worst_light = std::max({worst_light, frame_error, part_error});
      }
    }
  }
  std::printf("[ LC 1st order ] dt/tau 1e-6..1e6: max |x - x_exact| %.2e, max |light error| / T %.2e\n", worst_state,
              worst_light);
}

TEST(LcResponse, RiseIsFasterAtHigherDrive) {
  const LcResponseParams params;
  const LcResponse lc(params, kPeriod);
  double previous_tau = std::numeric_limits<double>::infinity();
  double previous_fraction = 0.0;
  for (double level = 0.05; level <= 1.0; level += 0.05) {
    const double tau = lc.rise_tau_s(level);
    EXPECT_LT(tau, previous_tau) << level;
    EXPECT_NEAR(tau, jakeman_raynes_rise_tau(params, level), 1e-15);
    // The share of the step from black reached after 1 ms grows with the drive.
    const double fraction = lc.advance(0.0, level, 0.001) / level;
    EXPECT_GT(fraction, previous_fraction) << level;
    previous_tau = tau;
    previous_fraction = fraction;
  }
  // Full drive rises τ_off / ((V_max/V_th)² − 1), well before the elastic fall.
  EXPECT_NEAR(lc.rise_tau_s(1.0), params.tau_off_s / 8.0, 1e-18);
  EXPECT_LT(lc.rise_tau_s(1.0), params.tau_off_s);
}

// The end of one frame from x0 at drive p, written out from the model's definition: the oracle of the overdrive.
double analytic_end(const LcResponseParams& p, double x0, double drive) {
  const double tau = drive > x0 ? jakeman_raynes_rise_tau(p, drive) : p.tau_off_s;
  return drive + (x0 - drive) * std::exp(-kPeriod / tau);
}

PanelLight overdriven_light(const LcResponseParams& params) {
  PanelLightConfig config;
  config.refresh_hz = kRefresh;
  config.lc_response = params;
  config.overdrive = true;
  return PanelLight(config);
}

TEST(LcResponse, OverdriveEndsTheFrameAtTheTargetWhereTheDriveRangeAllowsAndClampsElsewhere) {
  LcResponseParams params;
  params.tau_off_s = 0.006;  // slow enough that plain drive misses most grey targets within a 120 Hz frame
  const PanelLight without = lc_light(params);
  const PanelLight with = overdriven_light(params);
  const double fall = std::exp(-kPeriod / params.tau_off_s);
  int reached = 0, clamped = 0;
  double reached_worst = 0.0, plain_worst = 0.0;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const double x0 = i / 40.0, level = j / 40.0;
      const double drive = with.drive(x0, level);
      const double end = with.end_state(x0, level);
      if (level < x0) {
        // Falling: invert p + (x0 − p) e^{−T/τ_off} = L by hand.
        const double needed = (level - x0 * fall) / (1.0 - fall);
        if (needed >= 0.0) {
          EXPECT_NEAR(drive, needed, 1e-12) << x0 << " -> " << level;
        } else {
          EXPECT_EQ(drive, 0.0) << x0 << " -> " << level;
          EXPECT_NEAR(end, x0 * fall, 1e-15) << "the deepest fall a frame allows";
          ++clamped;
          continue;
        }
      } else if (analytic_end(params, x0, 1.0) < level) {
        // Rising beyond what full drive reaches in a frame: full drive, the nearest end.
        EXPECT_EQ(drive, 1.0) << x0 << " -> " << level;
        EXPECT_NEAR(end, analytic_end(params, x0, 1.0), 1e-15);
        ++clamped;
        continue;
      }
      ++reached;
      EXPECT_NEAR(analytic_end(params, x0, drive), level, 1e-12) << x0 << " -> " << level << " drive " << drive;
      reached_worst = std::max(reached_worst, std::abs(end - level));
      plain_worst = std::max(plain_worst, std::abs(without.end_state(x0, level) - level));
    }
  }
  EXPECT_GT(reached, 800);
  EXPECT_GT(clamped, 100);
  EXPECT_LT(reached_worst, 1e-12);
  EXPECT_GT(plain_worst, 0.1);  // without overdrive the same transitions miss by far more
  std::printf("[ overdrive ] tau_off 6 ms at 120 Hz: %d of 1681 transitions reached (worst %.1e), %d clamped; plain "
              "drive misses by up to %.3f\n", reached, reached_worst, clamped, plain_worst);
}

TEST(LcResponse, OverdriveRecoversTheDriveOfAKnownFrame) {
  // A frame driven at p from x0 ends at L (the closed form); the overdrive for (x0, L) must be p again.
  const LcResponseParams params;
  const PanelLight light = overdriven_light(params);
  for (double x0 : {0.0, 0.05, 0.3, 0.7}) {
    for (double drive = 0.01; drive <= 1.0; drive += 0.01) {
      const double level = analytic_end(params, x0, drive);
      EXPECT_NEAR(light.drive(x0, level), drive, 1e-9) << x0 << " drive " << drive;
    }
  }
}

TEST(LcResponse, OverdriveNeverOvershootsInTheFirstOrderModel) {
  // A run of targets (black, white, greys and repeats) through the level-dependent and the constant-τ crystal: within
  // every frame the light moves from where the last frame left it toward the target and never past it.
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> targets = {0.0, 1.0, 1.0, 0.0, 0.5, 0.5, 0.02, 0.98, 0.3};
  for (int i = 0; i < 60; ++i) targets.push_back(uniform(random));
  PanelLightConfig constant;
  constant.refresh_hz = kRefresh;
  constant.lc_tau_s = 0.004;
  constant.overdrive = true;
  LcResponseParams slow;
  slow.tau_off_s = 0.006;
  for (const PanelLight& light : {overdriven_light(LcResponseParams{}), overdriven_light(slow), PanelLight(constant)}) {
    double state = 0.0;
    for (double level : targets) {
      double last = state;
      for (int k = 1; k <= 200; ++k) {
        const double value = light.level_at(kPeriod * k / 200.0 - 1e-12, state, level);
        if (level >= state) {
          EXPECT_GE(value, last - 1e-15);
          EXPECT_LE(value, level + 1e-12) << "overshoot rising from " << state << " to " << level;
        } else {
          EXPECT_LE(value, last + 1e-15);
          EXPECT_GE(value, level - 1e-12) << "overshoot falling from " << state << " to " << level;
        }
        last = value;
      }
      const double end = light.end_state(state, level);
      const double drive = light.drive(state, level);
      if (drive > 0.0 && drive < 1.0) {
        EXPECT_NEAR(end, level, 1e-12) << state << " -> " << level;
      }
      state = end;
    }
  }
}

TEST(LcResponse, OverdrivenLightThroughTheRetinaIsTheSumOfItsFrames) {
  // A still eye sees the mean of the frames' light: each frame's closed-form integral from the state the frame
  // before left, with the overdriven drive (the retina's per-pixel segments).
  LcResponseParams params;
  params.tau_off_s = 0.006;
  const PanelLight light = overdriven_light(params);
  const std::vector<double> levels = {0.1, 0.9, 0.4, 0.4, 0.0, 0.6};
  cv::Mat frames(static_cast<int>(levels.size()), 1, CV_64FC1);
  for (std::size_t f = 0; f < levels.size(); ++f) frames.at<double>(static_cast<int>(f), 0) = levels[f];
  cv::Mat previous(1, 1, CV_64FC1, cv::Scalar(0.5));
  RetinaOptions options;
  options.substeps = 4;
  const cv::Mat seen = retinal_row(frames, light, viewer_preset("vive"), 0.0, options, previous);
  double state = 0.5, sum = 0.0;
  for (double level : levels) {
    sum += light.integral(0.0, kPeriod, state, level);
    state = light.end_state(state, level);
  }
  EXPECT_NEAR(seen.at<double>(0, 0), sum / (kPeriod * static_cast<double>(levels.size())), 1e-13);
  EXPECT_GT(std::abs(seen.at<double>(0, 0) - retinal_row(frames, lc_light(params), viewer_preset("vive"), 0.0,
                                                          options, previous).at<double>(0, 0)),
            1e-3);  // and it is not the plain drive's
}

TEST(LcResponse, StateIsMonotoneInTimeLevelAndStartWithoutOvershoot) {
  for (const PanelLight& light : {lc_light(LcResponseParams{}), overdriven_light(LcResponseParams{})}) {
    for (const auto& [x0, level] : {std::pair{0.0, 0.5}, std::pair{0.8, 0.1}, std::pair{0.3, 0.31}}) {
      const double drive = light.segment(x0, level).drive;
      double last = x0;
      for (int i = 1; i <= 100; ++i) {
        const double value = light.level_at(kPeriod * i / 100.0 - 1e-12, x0, level);
        if (level > x0) {
          EXPECT_GE(value, last);
          EXPECT_LE(value, drive);
        } else {
          EXPECT_LE(value, last);
          EXPECT_GE(value, drive);
        }
        last = value;
      }
    }
    for (double x0 : {0.0, 0.4, 1.0}) {
      double last = -1.0;
      for (int j = 0; j <= 64; ++j) {
        const double end = light.end_state(x0, j / 64.0);
        EXPECT_GE(end, last) << x0 << " " << j;
        last = end;
      }
    }
  }
}

TEST(LcResponse, BadParametersAreRejectedByName) {
  const auto with = [](const std::function<void(LcResponseParams&)>& change) {
    LcResponseParams p;
    change(p);
    return p;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_invalid([&] { LcResponse(with([](auto& p) { p.tau_off_s = 0.0; }), kPeriod); }, "'tau_off_s'");
  expect_invalid([&] { LcResponse(with([&](auto& p) { p.tau_off_s = nan; }), kPeriod); }, "'tau_off_s'");
  expect_invalid([&] { LcResponse(with([](auto& p) { p.drive_ratio = 1.0; }), kPeriod); }, "'drive_ratio'");
  expect_invalid([&] { LcResponse(with([](auto& p) { p.drive_gamma = 9.0; }), kPeriod); }, "'drive_gamma'");
  expect_invalid([&] { LcResponse(LcResponseParams{}, 0.0); }, "'frame_period_s'");
  PanelLightConfig both;
  both.lc_tau_s = 0.002;
  both.lc_response = LcResponseParams{};
  expect_invalid([&] { PanelLight{both}; }, "'lc_tau_s'");
  PanelLightConfig nothing_to_overdrive;
  nothing_to_overdrive.overdrive = true;
  expect_invalid([&] { PanelLight{nothing_to_overdrive}; }, "'overdrive'");
  Panel panel = parse_panel("lcd");
  panel.lcd.lc_response.drive_ratio = nan;
  expect_invalid([&] { panel_light(panel, 90.0); }, "'drive_ratio'");
}

}  // namespace
}  // namespace trm
