// Kelly-Daly spatio-velocity CSF.
#include "trm/csf.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "perception_checks.hpp"

namespace trm {

namespace {

// Both arguments are magnitudes, rho > 0 and velocity >= kCsfDriftVelocity.
double kelly_daly(double rho, double velocity) {
  const double scaled_velocity = kDalyC2 * velocity;
  const double log_term = std::abs(std::log10(scaled_velocity / 3.0));
  const double k = kKellyS1 + kKellyS2 * log_term * log_term * log_term;
  const double rho_max = kKellyP1 / (scaled_velocity + 2.0);
  const double alpha = kDalyC1 * 2.0 * std::numbers::pi * rho;
  // The band-pass shape first: where it underflows to 0 a huge velocity must not turn 0 into inf * 0.
  const double shape = alpha * alpha * std::exp(-2.0 * alpha / rho_max);
  if (shape == 0.0) return 0.0;
  return k * kDalyC0 * kDalyC2 * velocity * shape;
}

}  // namespace

double csf_spatiovelocity(double rho_cpd, double velocity_deg_s) {
  perception_detail::require_finite("csf_spatiovelocity", "rho_cpd", rho_cpd);
  perception_detail::require_finite("csf_spatiovelocity", "velocity_deg_s", velocity_deg_s);
  const double rho = std::abs(rho_cpd);
  if (rho == 0.0) return 0.0;
  return kelly_daly(rho, std::max(std::abs(velocity_deg_s), kCsfDriftVelocity));
}

double csf_spatiotemporal(double rho_cpd, double nu_hz) {
  perception_detail::require_finite("csf_spatiotemporal", "rho_cpd", rho_cpd);
  perception_detail::require_finite("csf_spatiotemporal", "nu_hz", nu_hz);
  const double rho = std::abs(rho_cpd);
  if (rho == 0.0) return 0.0;
  const double velocity = std::abs(nu_hz) / rho;
  // ν / ρ overflows only for ρ within a few ulps of 0 at finite ν, where the limit S → 0 holds.
  if (!std::isfinite(velocity)) return 0.0;
  return kelly_daly(rho, std::max(velocity, kCsfDriftVelocity));
}

}  // namespace trm
