// The liquid crystal's level-dependent response (DESIGN §7 "LC response", paper Sec. 2.2 and 4.4): how fast a pixel's
// optical state x follows the level p the panel drives, and the overdrive LUT the panel applies before the LC.
//
//   dx/dt = (p − x) / τ(x, p),   τ = τ_on(p) while rising (p > x), τ_off while falling (p <= x)
//
//   τ_off    = γ₁ d² / (K π²)                   relaxation by the elastic torque alone: the same for every level
//   τ_on(p)  = τ_off / ((V(p) / V_th)² − 1)     the field's torque helps: faster at higher drive voltage V
//   V(p)/V_th = 1 + (V_max / V_th − 1) · p^(1/γ_d)   the voltage linear in the drive code p^(1/γ_d) of the level
//
// (γ₁ rotational viscosity, d cell gap, K elastic constant, V_th the Fréedericksz threshold: E. Jakeman and
// E. P. Raynes, "Electro-optic response times in liquid crystals", Phys. Lett. A 39, 69 (1972); S.-T. Wu and D.-K.
// Yang, "Fundamentals of Liquid Crystal Devices", Wiley 2006, Sec. 5.3.) Within one frame the drive is constant, so
// each frame is one exponential segment toward p with the segment's τ: the state update is the exact solution,
// stable for any τ and step (no time-stepping of the ODE). τ_on grows without bound as p → 0 (V → V_th): rising to a
// dark grey is the slowest transition, as on real panels, while its amplitude goes to 0 with it.
//
// Overdrive: the panel looks up, for the state x the last frame left and the wanted level L, the drive p that ends
// the frame at L (one exponential segment of period T), tabulated on an N × N grid over [0, 1]² and interpolated
// bilinearly. Where even p = 1 (or 0) cannot reach L within a frame the entry is clamped to the drive range.
#pragma once

#include <vector>

namespace trm {

// Defaults of a fast-switching VR LCD (a few ms): τ_off = 2 ms falls 90 % → 10 % in τ ln 9 ≈ 4.4 ms, the order of
// the 4 ms grey-to-grey ratings of fast IPS panels such as the paper's ASUS ROG Swift (Sec. 4.4; a rating, not a
// measured curve); V_max / V_th = 3 puts full-drive rise at τ_off / 8 = 0.25 ms and mid-code (p^(1/γ_d) = ½) at
// τ_off / 3, the "rise much faster than decay at full drive" of nematic cells (Wu and Yang, Sec. 5.3).
struct LcResponseParams {
  double tau_off_s = 0.002;         // > 0 and finite: falling (elastic) time constant
  double drive_ratio = 3.0;         // V_max / V_th, > 1 and finite
  double drive_gamma = 2.2;         // γ_d: level p ↔ drive code p^(1/γ_d), in [0.5, 4]
  int overdrive_grid = 0;           // N of the N × N overdrive LUT; 0: no overdrive, else >= 2 and <= 4096
};

// One frame's segment of the ODE: the level the LC relaxes toward and its time constant.
struct LcSegment {
  double drive = 0.0;  // p: the wanted level, or the overdriven one
  double tau_s = 0.0;  // τ(x, p) of this segment
};

class LcResponse {
 public:
  // Throws std::invalid_argument naming the field and its range (see LcResponseParams) or `frame_period_s`
  // (finite and > 0: the overdrive LUT solves for one frame).
  LcResponse(const LcResponseParams& params, double frame_period_s);

  const LcResponseParams& params() const { return params_; }
  // τ_on(p) for p in (0, 1]; τ_off for p <= 0 never rises.
  double rise_tau_s(double drive) const;
  // τ of the segment from state x toward drive p.
  double tau_s(double state, double drive) const { return drive > state ? rise_tau_s(drive) : params_.tau_off_s; }
  // x after holding drive p for `seconds` from x: p + (x − p) e^{−t/τ(x, p)}, exact for constant drive.
  double advance(double state, double drive, double seconds) const;
  // The drive the panel applies for wanted level L after state x (the LUT, or L without overdrive).
  double drive_for(double state, double level) const;
  LcSegment segment(double state, double level) const;
  // The drive that ends one frame at L from x, solved (bisection, to 1e-15) without the LUT: what the LUT tabulates.
  double exact_overdrive(double state, double level) const;

 private:
  LcResponseParams params_;
  double period_ = 0.0;
  std::vector<double> lut_;  // [state index][level index], N × N
};

}  // namespace trm
