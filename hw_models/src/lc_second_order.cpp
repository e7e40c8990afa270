// The liquid crystal as a damped second-order system, integrated by its matrix exponential.
#include "trm/lc_second_order.hpp"

#include <Eigen/Core>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>

#include "perception_checks.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;

constexpr const char* kLcSecondOrderName = "LcSecondOrder";

// e^{−800} is below the smallest subnormal double (4.9e-324, e^{−744}) even times the critical mode's factor u:
// past 800 / (slowest decay rate) natural times the state has reached the drive exactly in double precision, so
// longer spans are cut there and the exponential never sees arguments beyond about 1e3 · ζ.
constexpr double kDecayedExponent = 800.0;

Eigen::Matrix2d system_matrix(double damping_ratio) {
  Eigen::Matrix2d b;
  b << 0.0, 1.0, -1.0, -2.0 * damping_ratio;
  return b;
}

// ∫₀^{u} e^{Bs} ds: the upper-right block of exp([[B, I], [0, 0]] u).
Eigen::Matrix2d integral_of_exponential(const Eigen::Matrix2d& b, double u) {
  Eigen::Matrix4d augmented = Eigen::Matrix4d::Zero();
  augmented.topLeftCorner<2, 2>() = b * u;
  augmented.topRightCorner<2, 2>() = Eigen::Matrix2d::Identity() * u;
  const Eigen::Matrix4d exponential = augmented.exp();
  return exponential.topRightCorner<2, 2>();
}

}  // namespace

LcSecondOrder::LcSecondOrder(const LcSecondOrderParams& params, double frame_period_s) : params_(params) {
  perception_detail::require_positive(kLcSecondOrderName, "tau_s", params.tau_s);
  perception_detail::require_positive(kLcSecondOrderName, "damping_ratio", params.damping_ratio);
  perception_detail::require_positive(kLcSecondOrderName, "frame_period_s", frame_period_s);
  const double zeta = params.damping_ratio;
  // The slowest mode decays at ζ (ζ < 1) or ζ − √(ζ² − 1) = 1 / (ζ + √(ζ² − 1)) (ζ >= 1) per natural time.
  const double slowest = zeta < 1.0 ? zeta : 1.0 / (zeta + std::sqrt((zeta - 1.0) * (zeta + 1.0)));
  horizon_u_ = kDecayedExponent / slowest;
  const Eigen::Matrix2d frame =
      (system_matrix(zeta) * std::min(frame_period_s / params.tau_s, horizon_u_)).exp();
  Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> stored(frame_);
  stored = frame;
}

LcMotion LcSecondOrder::advance(const LcMotion& start, double drive, double seconds) const {
  if (!(seconds >= 0.0)) reject("LcSecondOrder::advance", "seconds", "must be >= 0, got " + number_text(seconds));
  const double u = std::min(seconds / params_.tau_s, horizon_u_);
  const Eigen::Matrix2d e = (system_matrix(params_.damping_ratio) * u).exp();
  const Eigen::Vector2d z = e * Eigen::Vector2d(start.level - drive, params_.tau_s * start.rate_per_s);
  return {drive + z(0), z(1) / params_.tau_s};
}

LcMotion LcSecondOrder::end_of_frame(const LcMotion& start, double drive) const {
  const double z0 = start.level - drive;
  const double z1 = params_.tau_s * start.rate_per_s;
  return {drive + frame_[0] * z0 + frame_[1] * z1, (frame_[2] * z0 + frame_[3] * z1) / params_.tau_s};
}

double LcSecondOrder::overdrive(const LcMotion& start, double level) const {
  const double gain = 1.0 - frame_[0];
  const double rest = frame_[0] * start.level + frame_[1] * params_.tau_s * start.rate_per_s;
  // A crystal so slow that one frame's drive moves nothing (gain rounds to 0): no drive does better than the level.
  if (!(gain > 0.0)) return level;
  return std::clamp((level - rest) / gain, 0.0, 1.0);
}

LcMotionWeights LcSecondOrder::weights(double t0, double t1) const {
  constexpr const char* kWeights = "LcSecondOrder::weights";
  if (!(std::isfinite(t0) && t0 >= 0.0)) reject(kWeights, "t0", "must be finite and >= 0, got " + number_text(t0));
  if (!(std::isfinite(t1) && t1 >= t0)) reject(kWeights, "t1", "must be finite and >= t0, got " + number_text(t1));
  const double tau = params_.tau_s;
  const Eigen::Matrix2d b = system_matrix(params_.damping_ratio);
  const Eigen::Matrix2d at_start = (b * std::min(t0 / tau, horizon_u_)).exp();
  const Eigen::Matrix2d span = at_start * integral_of_exponential(b, std::min((t1 - t0) / tau, horizon_u_));
  // ∫ (x − p) dt = τ (span₀₀ (x0 − p) + span₀₁ τ x0').
  const double previous = tau * span(0, 0);
  return {(t1 - t0) - previous, previous, tau * tau * span(0, 1)};
}

double LcSecondOrder::integral(const LcMotion& start, double drive, double t0, double t1) const {
  const LcMotionWeights w = weights(t0, t1);
  return w.level * drive + w.previous * start.level + w.previous_rate * start.rate_per_s;
}

}  // namespace trm
