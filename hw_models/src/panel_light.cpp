// Panel light over a frame: emission window times the liquid-crystal state (constant or level-dependent τ), in
// closed form.
#include "trm/panel_light.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "perception_checks.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;

// A window that ends within this fraction of the frame end still fits (0.8 + 0.2 is not exactly 1 in binary).
constexpr double kWindowTolerance = 1e-12;

// Below this x the series of x − 1 + e^{−x} is used: x + expm1(−x) loses log2(x / φ(x)) bits, about 2 at x = 0.5.
constexpr double kSeriesLimit = 0.5;

// φ(x) = x − 1 + e^{−x} = ∫_0^x (1 − e^{−u}) du, the part of a unit step the LC has not yet delivered, >= 0.
double unreached(double x) {
  if (x >= kSeriesLimit) return x + std::expm1(-x);
  // Σ_{k>=2} (−x)^k / k!; at x = 0.5 the terms after k = 18 are below 1e-22 of the sum.
  double term = x * x / 2.0;
  double sum = term;
  for (int k = 3; k <= 18; ++k) {
    term *= -x / k;
    sum += term;
  }
  return sum;
}

}  // namespace

PanelLight::PanelLight(const PanelLightConfig& config) : config_(config) {
  constexpr const char* kWhere = "PanelLight";
  perception_detail::require_positive(kWhere, "refresh_hz", config.refresh_hz);
  if (!(config.duty > 0.0 && config.duty <= 1.0)) {
    reject(kWhere, "duty", "must be in (0, 1], got " + number_text(config.duty));
  }
  if (!(config.window_start >= 0.0 && config.window_start + config.duty <= 1.0 + kWindowTolerance)) {
    reject(kWhere, "window_start", "must be in [0, 1 - duty], got " + number_text(config.window_start));
  }
  if (!(std::isfinite(config.lc_tau_s) && config.lc_tau_s >= 0.0)) {
    reject(kWhere, "lc_tau_s", "must be finite and >= 0, got " + number_text(config.lc_tau_s));
  }
  if ((config.lc_response || config.lc_second_order) && config.lc_tau_s != 0.0) {
    reject(kWhere, "lc_tau_s",
           "must be 0 when lc_response or lc_second_order is set (one LC model), got " + number_text(config.lc_tau_s));
  }
  if (config.lc_response && config.lc_second_order) {
    reject(kWhere, "lc_second_order", "cannot be set together with lc_response (one LC model)");
  }
  if (config.overdrive && !(config.lc_tau_s > 0.0 || config.lc_response || config.lc_second_order)) {
    reject(kWhere, "overdrive", "needs a liquid crystal to overdrive (lc_tau_s > 0, lc_response or lc_second_order)");
  }
  period_ = 1.0 / config.refresh_hz;
  if (config.lc_response) response_.emplace(*config.lc_response, period_);
  if (config.lc_second_order) second_order_.emplace(*config.lc_second_order, period_);
  window_begin_ = config.window_start * period_;
  window_end_ = std::min(period_, (config.window_start + config.duty) * period_);
  decay_ = config.lc_tau_s > 0.0 ? std::exp(-period_ / config.lc_tau_s) : 0.0;
  reach_ = config.lc_tau_s > 0.0 ? -std::expm1(-period_ / config.lc_tau_s) : 1.0;
}

double PanelLight::row_delay_s(int y, int rows) const {
  if (rows < 1) reject("PanelLight::row_delay_s", "rows", "must be >= 1, got " + std::to_string(rows));
  if (y < 0 || y >= rows) {
    reject("PanelLight::row_delay_s", "y", "must be in [0, rows), got " + std::to_string(y));
  }
  return config_.scan_out == ScanOut::Rolling ? period_ * y / rows : 0.0;
}

double PanelLight::drive(const LcMotion& previous_state, double level) const {
  const double state = previous_state.level;
  if (!config_.overdrive || !(state >= 0.0 && state <= 1.0 && level >= 0.0 && level <= 1.0)) return level;
  if (second_order_) return second_order_->overdrive(previous_state, level);
  if (response_) return response_->overdrive(state, level);
  // One τ for every transition: the end state s0 + (p − s0)(1 − e^{−T/τ}) is linear in p.
  return reach_ > 0.0 ? std::clamp(state + (level - state) / reach_, 0.0, 1.0) : level;
}

LcSegment PanelLight::segment(double previous_state, double level) const {
  const double driven = drive(previous_state, level);
  if (response_) return response_->segment(previous_state, driven);
  return {driven, config_.lc_tau_s};
}

double PanelLight::level_at(double t, const LcMotion& previous_state, double level) const {
  if (!second_order_) return level_at(t, previous_state.level, level);
  if (!(t >= window_begin_ && t < window_end_)) return 0.0;
  return second_order_->advance(previous_state, drive(previous_state, level), t).level / config_.duty;
}

double PanelLight::level_at(double t, double previous_state, double level) const {
  if (second_order_) return level_at(t, LcMotion{previous_state, 0.0}, level);
  if (!(t >= window_begin_ && t < window_end_)) return 0.0;
  const LcSegment seg = segment(previous_state, level);
  const double state = seg.tau_s > 0.0 ? seg.drive + (previous_state - seg.drive) * std::exp(-t / seg.tau_s) : seg.drive;
  return state / config_.duty;
}

std::pair<double, double> PanelLight::lit_part(double t0, double t1) const {
  constexpr const char* kWhere = "PanelLight::weights";
  if (!(t0 >= 0.0 && t0 <= period_)) reject(kWhere, "t0", "must be in [0, T], got " + number_text(t0));
  if (!(t1 >= t0 && t1 <= period_)) reject(kWhere, "t1", "must be in [t0, T], got " + number_text(t1));
  return {std::max(t0, window_begin_), std::min(t1, window_end_)};
}

LightWeights PanelLight::weights(double t0, double t1) const {
  if (!second_order_) return weights(t0, t1, config_.lc_tau_s);
  const auto [u0, u1] = lit_part(t0, t1);
  if (!(u1 > u0)) return {};
  const LcMotionWeights w = second_order_->weights(u0, u1);
  const double duty = config_.duty;
  return {w.level / duty, w.previous / duty, w.previous_rate / duty};
}

LightWeights PanelLight::weights(double t0, double t1, double tau) const {
  const auto [u0, u1] = lit_part(t0, t1);
  if (!(tau >= 0.0)) reject("PanelLight::weights", "tau_s", "must be >= 0, got " + number_text(tau));
  if (!(u1 > u0)) return {};
  const double span = u1 - u0;
  const double duty = config_.duty;
  if (tau == 0.0) return {span / duty, 0.0};
  // ∫ s = L Δ + (s0 − L) τ e^{−u0/τ} (1 − e^{−Δ/τ}); the level part regrouped as
  // Δ (1 − e^{−u0/τ}) + e^{−u0/τ} τ φ(Δ/τ) so that a slow LC (Δ ≪ τ) does not subtract two near-equal terms.
  const double at_start = std::exp(-u0 / tau);
  const double x = span / tau;
  const double previous = tau * at_start * -std::expm1(-x);
  const double level = span * -std::expm1(-u0 / tau) + at_start * tau * unreached(x);
  return {level / duty, previous / duty};
}

double PanelLight::integral(double t0, double t1, const LcMotion& previous_state, double level) const {
  if (!second_order_) return integral(t0, t1, previous_state.level, level);
  const LightWeights w = weights(t0, t1);
  return w.level * drive(previous_state, level) + w.previous * previous_state.level +
         w.previous_rate * previous_state.rate_per_s;
}

double PanelLight::integral(double t0, double t1, double previous_state, double level) const {
  if (second_order_) return integral(t0, t1, LcMotion{previous_state, 0.0}, level);
  const LcSegment seg = segment(previous_state, level);
  const LightWeights w = weights(t0, t1, seg.tau_s);
  return w.level * seg.drive + w.previous * previous_state;
}

LcMotion PanelLight::end_state(const LcMotion& previous_state, double level) const {
  if (second_order_) return second_order_->end_of_frame(previous_state, drive(previous_state, level));
  return {end_state(previous_state.level, level), 0.0};
}

double PanelLight::end_state(double previous_state, double level) const {
  if (second_order_) {
    throw std::logic_error("PanelLight::end_state: the second-order LC's state has a rate; pass an LcMotion");
  }
  const double driven = drive(previous_state, level);
  if (response_) return response_->advance(previous_state, driven, period_);
  return driven + (previous_state - driven) * decay_;
}

PanelLight panel_light(const Panel& panel, double refresh_hz, const PanelLightOptions& options) {
  panel.validate("panel_light: ");
  PanelLightConfig config;
  config.refresh_hz = refresh_hz;
  config.scan_out = options.scan_out;
  if (panel.kind == PanelKind::Oled) {
    config.duty = panel.oled.duty;
    config.window_start = 0.0;
    config.lc_tau_s = 0.0;
  } else {
    config.duty = options.strobe_duty;
    if (!(options.strobe_duty > 0.0 && options.strobe_duty <= 1.0)) {
      reject("panel_light", "strobe_duty", "must be in (0, 1], got " + number_text(options.strobe_duty));
    }
    config.window_start = options.strobe_start < 0.0 ? 1.0 - options.strobe_duty : options.strobe_start;
    config.lc_tau_s = 0.0;
    config.overdrive = panel.lcd.overdrive;
    if (panel.lcd.lc_second_order) {
      config.lc_second_order = panel.lcd.lc_second_order;
    } else {
      config.lc_response = panel.lcd.lc_response;
    }
  }
  return PanelLight(config);
}

double steady_level(const Panel& panel, double v, int channel) { return panel.linear_from_drive(v, channel); }

cv::Mat steady_levels(const Panel& panel, int output_bits, const cv::Mat& drive_codes) {
  if (drive_codes.type() != CV_16UC3) reject("steady_levels", "drive_codes", "must be CV_16UC3 drive codes");
  const double top = std::ldexp(1.0, output_bits) - 1.0;
  cv::Mat levels(drive_codes.size(), CV_64FC3);
  for (int y = 0; y < drive_codes.rows; ++y) {
    const auto* code = drive_codes.ptr<cv::Vec3w>(y);
    auto* out = levels.ptr<cv::Vec3d>(y);
    for (int x = 0; x < drive_codes.cols; ++x) {
      for (int c = 0; c < 3; ++c) out[x][c] = steady_level(panel, code[x][c] / top, c);
    }
  }
  return levels;
}

}  // namespace trm
