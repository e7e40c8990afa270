// The spatio-temporal contrast sensitivity the supplement's visual difference model uses (its Eq. 2, "stCSF
// from [2]"): Kelly's stabilised spatio-temporal threshold surface (D. H. Kelly, "Motion and vision II.
// Stabilized spatio-temporal threshold surface", JOSA 69(10):1340, 1979) in the spatio-velocity form Daly fitted
// to unstabilised viewing (S. J. Daly, "Engineering observations from spatiovelocity and spatiotemporal visual
// models", SPIE 3299:180, 1998; the formula as corrected in K. Myszkowski, P. Rokita, T. Tawara, IEEE TVCG
// 6(4):360, 2000; the same constants and form are in the public reference implementation gfxdisp/ALSaRR,
// utils/csf_spatiovel_daly.m, its Daly 1998 branch):
//
//   S(ρ, v) = k · c0 · c2 · v · (c1 · 2πρ)² · exp(−c1 · 4πρ / ρ_max)
//   k       = s1 + s2 · |log10(c2 · v / 3)|³
//   ρ_max   = p1 / (c2 · v + 2)
//
// ρ in cycles/deg, v the retinal velocity in deg/s. With c0 = c1 = c2 = 1 this is Kelly's surface written with
// α = 2πρ: k · v · α² · exp(−2α / α_max), α_max = 45.9 / (v + 2) rad/deg being the peak of each constant-velocity
// curve. Daly's c1 and c2 rescale frequency and velocity, so the peak of S over ρ lies at
// ρ_peak = ρ_max / (2π c1), where S = k c0 c2 v ρ_max² e⁻².
//
// The spatio-temporal form is S(ρ, ν) = S(ρ, v = ν / ρ) with ν in Hz (a grating of ρ moving at v flickers at ρv).
#pragma once

#include "trm/pursuit.hpp"

namespace trm {

// Kelly 1979's surface constants.
inline constexpr double kKellyS1 = 6.1;
inline constexpr double kKellyS2 = 7.3;
inline constexpr double kKellyP1 = 45.9;
// Daly 1998's fit to unstabilised viewing.
inline constexpr double kDalyC0 = 1.14;
inline constexpr double kDalyC1 = 0.67;
inline constexpr double kDalyC2 = 1.7;

// Kelly's surface falls to zero as the retinal velocity does (a stabilised image fades), but the eye is never
// still: its drift keeps every image moving at about Daly's 0.15 deg/s, the v_min of Eq. 3, and at drift
// velocities Kelly's stabilised curve matches the ordinary unstabilised static CSF (Kelly 1979). Slower retinal
// velocities, v = 0 included, are therefore evaluated at this drift velocity; this also defines the ν = 0 line
// of the spatio-temporal form as the static CSF S(ρ, 0.15 deg/s), whose peak is about 245 at 4.8 cpd.
inline constexpr double kCsfDriftVelocity = kPursuitMinVelocity;

// S(ρ, v) above, for |ρ| cycles/deg and |v| deg/s (a grating's sensitivity does not depend on its direction),
// with |v| below kCsfDriftVelocity raised to it. S(0, v) = 0: every constant-velocity curve is band-pass,
// S ∝ ρ² near ρ = 0. Throws std::invalid_argument naming the argument if ρ or v is not finite.
double csf_spatiovelocity(double rho_cpd, double velocity_deg_s);

// S(ρ, ν) = S(ρ, ν / ρ) for |ρ| cycles/deg and |ν| Hz. ν = 0 is the static CSF at the drift velocity (see
// kCsfDriftVelocity). ρ = 0 is 0 for every ν: at fixed ν, S ∝ ρ · log³(1/ρ) → 0 as ρ → 0 (a uniform field has
// no contrast to detect). Throws std::invalid_argument naming the argument if ρ or ν is not finite.
double csf_spatiotemporal(double rho_cpd, double nu_hz);

}  // namespace trm
