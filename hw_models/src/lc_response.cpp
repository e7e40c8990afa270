// The liquid crystal's level-dependent first-order response and the panel's overdrive LUT.
#include "trm/lc_response.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "perception_checks.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;

constexpr const char* kLcResponseName = "LcResponse";
constexpr double kNeverRisesTauS = 1e30;
constexpr int kMostNewtonSteps = 100;

}  // namespace

LcResponse::LcResponse(const LcResponseParams& params, double frame_period_s) : params_(params) {
  perception_detail::require_positive(kLcResponseName, "tau_off_s", params.tau_off_s);
  if (!(std::isfinite(params.drive_ratio) && params.drive_ratio > 1.0)) {
    reject(kLcResponseName, "drive_ratio", "(V_max / V_th) must be finite and > 1, got " + number_text(params.drive_ratio));
  }
  if (!(params.drive_gamma >= 0.5 && params.drive_gamma <= 4.0)) {
    reject(kLcResponseName, "drive_gamma", "must be in [0.5, 4], got " + number_text(params.drive_gamma));
  }
  perception_detail::require_positive(kLcResponseName, "frame_period_s", frame_period_s);
  period_ = frame_period_s;
  fall_reach_ = -std::expm1(-period_ / params.tau_off_s);
}

double LcResponse::rise_tau_s(double drive) const {
  if (!(drive > 0.0)) return params_.tau_off_s;
  const double voltage = 1.0 + (params_.drive_ratio - 1.0) * std::pow(drive, 1.0 / params_.drive_gamma);
  // (V/V_th)² − 1 = (V/V_th − 1)(V/V_th + 1): no cancellation as V → V_th. A drive so small that the voltage rounds
  // to V_th never rises in any simulated time; the cap keeps τ finite so that the segment's weights stay numbers.
  return std::min(params_.tau_off_s / ((voltage - 1.0) * (voltage + 1.0)), kNeverRisesTauS);
}

double LcResponse::advance(double state, double drive, double seconds) const {
  return drive + (state - drive) * std::exp(-seconds / tau_s(state, drive));
}

double LcResponse::overdrive(double state, double level) const {
  if (level == state) return level;
  if (level < state) {
    // A falling segment's τ is τ_off whatever the drive: the end state x + (p − x) reach is linear in p.
    return fall_reach_ > 0.0 ? std::max(0.0, state + (level - state) / fall_reach_) : 0.0;
  }
  // Rising: h(p) = (p − x) reach(p) − (L − x), reach(p) = 1 − e^{−T/τ_on(p)}, increasing in p on (x, 1] (a larger step
  // that also rises faster).
  const double gap = level - state;
  const double ratio = params_.drive_ratio - 1.0, exponent = 1.0 / params_.drive_gamma;
  const auto reach = [&](double drive) { return -std::expm1(-period_ / rise_tau_s(drive)); };
  const auto excess = [&](double drive) { return (drive - state) * reach(drive) - gap; };
  if (excess(1.0) <= 0.0) return 1.0;
  // τ_on(L) >= τ_on(p*), so the drive that would reach L at τ_on(L) is at or above the root: the upper bracket.
  double lo = level, hi = std::min(1.0, state + gap / reach(level));
  double drive = hi;
  for (int step = 0; step < kMostNewtonSteps; ++step) {
    const double value = excess(drive);
    if (value == 0.0) return drive;
    (value < 0.0 ? lo : hi) = drive;
    // h'(p) = reach + (p − x) e^{−T/τ} (T/τ) 2V V' / (V² − 1), V' = (V_max/V_th − 1) p^{1/γ_d − 1} / γ_d.
    const double tau = rise_tau_s(drive);
    const double voltage = 1.0 + ratio * std::pow(drive, exponent);
    const double slope_v = ratio * exponent * std::pow(drive, exponent - 1.0);
    const double slope = reach(drive) + (drive - state) * std::exp(-period_ / tau) * (period_ / tau) * 2.0 *
                                            voltage * slope_v / ((voltage - 1.0) * (voltage + 1.0));
    double next = drive - value / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - drive) <= 4.0 * std::numeric_limits<double>::epsilon() * drive) return next;
    drive = next;
  }
  return drive;
}

}  // namespace trm
