// The liquid crystal's level-dependent first-order response and the panel's overdrive LUT.
#include "trm/lc_response.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "perception_checks.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;

constexpr const char* kWhere = "LcResponse";
constexpr int kMaxOverdriveGrid = 4096;
constexpr double kNeverRisesTauS = 1e30;

}  // namespace

LcResponse::LcResponse(const LcResponseParams& params, double frame_period_s) : params_(params) {
  perception_detail::require_positive(kWhere, "tau_off_s", params.tau_off_s);
  if (!(std::isfinite(params.drive_ratio) && params.drive_ratio > 1.0)) {
    reject(kWhere, "drive_ratio", "(V_max / V_th) must be finite and > 1, got " + number_text(params.drive_ratio));
  }
  if (!(params.drive_gamma >= 0.5 && params.drive_gamma <= 4.0)) {
    reject(kWhere, "drive_gamma", "must be in [0.5, 4], got " + number_text(params.drive_gamma));
  }
  if (params.overdrive_grid != 0 && (params.overdrive_grid < 2 || params.overdrive_grid > kMaxOverdriveGrid)) {
    reject(kWhere, "overdrive_grid",
           "must be 0 (no overdrive) or in [2, " + std::to_string(kMaxOverdriveGrid) + "], got " +
               std::to_string(params.overdrive_grid));
  }
  perception_detail::require_positive(kWhere, "frame_period_s", frame_period_s);
  period_ = frame_period_s;
  const int n = params.overdrive_grid;
  lut_.resize(static_cast<std::size_t>(n) * n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      lut_[static_cast<std::size_t>(i) * n + j] = exact_overdrive(double(i) / (n - 1), double(j) / (n - 1));
    }
  }
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

double LcResponse::exact_overdrive(double state, double level) const {
  // The frame's end state is increasing in the drive (τ_on falls as the drive rises, and a falling segment is linear
  // in it), continuous at drive = state, so bisection on [0, 1] finds the one drive, clamped where none reaches.
  const auto end = [&](double drive) { return advance(state, drive, period_); };
  if (end(1.0) <= level) return 1.0;
  if (end(0.0) >= level) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (hi - lo > 1e-15) {
    const double mid = 0.5 * (lo + hi);
    (end(mid) < level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double LcResponse::drive_for(double state, double level) const {
  const int n = params_.overdrive_grid;
  if (n == 0 || !(state >= 0.0 && state <= 1.0 && level >= 0.0 && level <= 1.0)) return level;
  const double u = state * (n - 1), w = level * (n - 1);
  const int i = std::min(static_cast<int>(u), n - 2), j = std::min(static_cast<int>(w), n - 2);
  const double fu = u - i, fw = w - j;
  const auto at = [&](int a, int b) { return lut_[static_cast<std::size_t>(a) * n + b]; };
  const double low = at(i, j) + (at(i, j + 1) - at(i, j)) * fw;
  const double high = at(i + 1, j) + (at(i + 1, j + 1) - at(i + 1, j)) * fw;
  return std::clamp(low + (high - low) * fu, 0.0, 1.0);
}

LcSegment LcResponse::segment(double state, double level) const {
  const double drive = drive_for(state, level);
  return {drive, tau_s(state, drive)};
}

}  // namespace trm
