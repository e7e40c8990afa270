// Smooth pursuit of a moving target (supplement Eq. 3, after Daly 1998, "Engineering observations from
// spatiovelocity and spatiotemporal visual models", SPIE 3299): the eye follows with a gain below one, never
// holds still (drift), and saturates. What is left, the retinal velocity v_r, is what the stCSF sees.
#pragma once

namespace trm {

inline constexpr double kPursuitGain = 0.82;         // g_sp
inline constexpr double kPursuitMinVelocity = 0.15;  // v_min, deg/s: the eye's drift when tracking nothing
inline constexpr double kPursuitMaxVelocity = 80.0;  // v_max, deg/s: fastest smooth pursuit

// The target speed at which pursuit saturates: g_sp v + v_min = v_max.
inline constexpr double kPursuitSaturationVelocity = (kPursuitMaxVelocity - kPursuitMinVelocity) / kPursuitGain;

// Eq. 3: v_eye = min(g_sp v + v_min, v_max) for a target moving at v >= 0 deg/s. A target moving the other way
// mirrors it (v_eye(-v) = -v_eye(v)), so the sign of v is the direction and both signs lag alike; v = 0 takes the
// positive branch, leaving the drift v_min as the only eye motion. Throws std::invalid_argument naming
// `target_velocity_deg_s` if it is not finite.
double eye_velocity_deg_s(double target_velocity_deg_s);

// Eq. 3: v_r = v - v_eye, the velocity of the target over the retina (positive: the target runs ahead of the eye
// in the direction of +v). Same domain as eye_velocity_deg_s.
double retinal_velocity_deg_s(double target_velocity_deg_s);

}  // namespace trm
