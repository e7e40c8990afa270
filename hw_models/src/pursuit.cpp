// Smooth pursuit (supplement Eq. 3).
#include "trm/pursuit.hpp"

#include <algorithm>
#include <cmath>

#include "perception_checks.hpp"

namespace trm {

double eye_velocity_deg_s(double target_velocity_deg_s) {
  perception_detail::require_finite("eye_velocity_deg_s", "target_velocity_deg_s", target_velocity_deg_s);
  const double speed = std::abs(target_velocity_deg_s);
  const double eye_speed = std::min(kPursuitGain * speed + kPursuitMinVelocity, kPursuitMaxVelocity);
  return target_velocity_deg_s < 0.0 ? -eye_speed : eye_speed;
}

double retinal_velocity_deg_s(double target_velocity_deg_s) {
  perception_detail::require_finite("retinal_velocity_deg_s", "target_velocity_deg_s", target_velocity_deg_s);
  return target_velocity_deg_s - eye_velocity_deg_s(target_velocity_deg_s);
}

}  // namespace trm
