// The liquid crystal as a damped second-order system (DESIGN §7 "LC response"), the optional alternative to the
// first-order response of lc_response.hpp: the director has inertia as well as viscosity, so the optical state x
// answers a drive step with a delayed S-shaped rise (and, underdamped, with ringing) instead of a jump in slope.
//
//   m x'' + k x' + x = p,   m = τ², k = 2 ζ τ          (τ = 1/ω₀ the natural time, ζ the damping ratio)
//
// Written in the dimensionless time u = t/τ with z = (x − p, τ x'), the ODE is z' = B z with the constant matrix
// B = [[0, 1], [−1, −2ζ]]; within one frame the drive p is constant, so a frame is the exact solution
// z(u) = e^{Bu} z(0), and the light of a part of it is ∫ x dt = p Δt + τ [1 0] e^{B u₀} G(Δu) z(0) with
// G(Δu) = ∫₀^{Δu} e^{Bs} ds, both read from one 4 × 4 matrix exponential exp([[B, I], [0, 0]] Δu) (C. F. Van
// Loan, "Computing integrals involving the matrix exponential", IEEE Trans. Autom. Control 23(3), 1978), computed
// by Eigen's scaling-and-squaring Padé exponential (unsupported/Eigen/MatrixFunctions). No time-stepping: exact
// and stable for any τ and step, stiff (τ far below the frame) or not. B does not depend on the level, so every
// pixel of a frame shares the propagator and only the state differs.
//
// ζ < 1 rings: x overshoots p by e^{−πζ/√(1−ζ²)} of the step. ζ >= 1 never overshoots from rest, and more: its
// impulse response is non-negative with unit area, so x is a weighted average of the past drive and stays within
// the drive's range (kMinPanelDampingRatio).
#pragma once

namespace trm {

struct LcSecondOrderParams {
  double tau_s = 0.002;         // τ = √m, finite and > 0: the natural time (ω₀ = 1/τ)
  double damping_ratio = 1.0;   // ζ = k / (2√m), finite and > 0: 1 critical, < 1 rings, > 1 overdamped
  friend bool operator==(const LcSecondOrderParams&, const LcSecondOrderParams&) = default;
};

// A panel's light must not go negative nor beyond the drive range, which needs a non-negative impulse response:
// ζ >= 1 (the panel preset's rule; the model itself accepts any ζ > 0).
inline constexpr double kMinPanelDampingRatio = 1.0;

// The liquid crystal's state: its optical level and how fast it changes (1/s).
struct LcMotion {
  double level = 0.0;
  double rate_per_s = 0.0;
  friend bool operator==(const LcMotion&, const LcMotion&) = default;
};

// ∫_{t0}^{t1} x dt for a constant drive p from state (x0, x0') at t = 0:
// p · level + x0 · previous + x0' · previous_rate (seconds, seconds and seconds²).
struct LcMotionWeights {
  double level = 0.0;
  double previous = 0.0;
  double previous_rate = 0.0;
};

class LcSecondOrder {
 public:
  // Throws std::invalid_argument naming `tau_s`, `damping_ratio` (finite and > 0) or `frame_period_s` (finite and
  // > 0: the frame's propagator is computed once).
  LcSecondOrder(const LcSecondOrderParams& params, double frame_period_s);

  const LcSecondOrderParams& params() const { return params_; }
  // The state after holding drive p for `seconds` (>= 0) from `start`.
  LcMotion advance(const LcMotion& start, double drive, double seconds) const;
  // advance() over one frame period, from the propagator computed at construction.
  LcMotion end_of_frame(const LcMotion& start, double drive) const;
  // The overdrive: the drive in [0, 1] whose frame from `start` ends at `level`, or the clamped one nearest it. The
  // end level p (1 − Φ₀₀) + Φ₀₀ x0 + Φ₀₁ τ x0' (Φ = e^{BT/τ}) is affine in p with slope 1 − Φ₀₀ > 0, so the inverse
  // is closed form and the clamp is the best the drive range allows.
  double overdrive(const LcMotion& start, double level) const;
  // The weights of ∫_{t0}^{t1} x dt, 0 <= t0 <= t1 (throws std::invalid_argument naming `t0` or `t1`).
  LcMotionWeights weights(double t0, double t1) const;
  double integral(const LcMotion& start, double drive, double t0, double t1) const;

 private:
  LcSecondOrderParams params_;
  double horizon_u_ = 0.0;   // beyond this many τ every mode has decayed below the smallest double
  double frame_[4] = {};     // e^{B T/τ}, row-major
};

}  // namespace trm
