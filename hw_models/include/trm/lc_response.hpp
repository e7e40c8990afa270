// The liquid crystal's level-dependent response (DESIGN §7 "LC response", paper Sec. 2.2 and 4.4): how fast a pixel's
// optical state x follows the level p the panel drives, and the overdrive that inverts it.
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
// Overdrive (PanelLightConfig::overdrive): for the state x the last frame left and the wanted level L, the panel
// drives the p that ends the frame at L, the inverse of one exponential segment of period T. Falling (L <= x) has
// τ_off whatever p is, so p = x + (L − x) / (1 − e^{−T/τ_off}) in closed form; rising, τ_on depends on p and the end
// state p + (x − p) e^{−T/τ_on(p)} (increasing in p) is solved by safeguarded Newton to a few ulps. Where even p = 1
// (or 0) cannot reach L within a frame, p is clamped to the drive range, the end state nearest L. This is the ideal
// panel LUT (previous level, target level) → drive, exact at every entry: a real panel's 17 × 17 or 33 × 33 table
// interpolates it.
#pragma once

namespace trm {

// Defaults of a fast-switching VR LCD (a few ms): τ_off = 2 ms falls 90 % → 10 % in τ ln 9 ≈ 4.4 ms, the order of
// the 4 ms grey-to-grey ratings of fast IPS panels such as the paper's ASUS ROG Swift (Sec. 4.4; a rating, not a
// measured curve); V_max / V_th = 3 puts full-drive rise at τ_off / 8 = 0.25 ms and mid-code (p^(1/γ_d) = ½) at
// τ_off / 3, the "rise much faster than decay at full drive" of nematic cells (Wu and Yang, Sec. 5.3).
struct LcResponseParams {
  double tau_off_s = 0.002;         // > 0 and finite: falling (elastic) time constant
  double drive_ratio = 3.0;         // V_max / V_th, > 1 and finite
  double drive_gamma = 2.2;         // γ_d: level p ↔ drive code p^(1/γ_d), in [0.5, 4]
  friend bool operator==(const LcResponseParams&, const LcResponseParams&) = default;
};

// One frame's segment of the ODE: the level the LC relaxes toward and its time constant.
struct LcSegment {
  double drive = 0.0;  // p: the wanted level, or the overdriven one
  double tau_s = 0.0;  // τ(x, p) of this segment
};

class LcResponse {
 public:
  // Throws std::invalid_argument naming the field and its range (see LcResponseParams) or `frame_period_s`
  // (finite and > 0: the overdrive solves for one frame).
  LcResponse(const LcResponseParams& params, double frame_period_s);

  const LcResponseParams& params() const { return params_; }
  // τ_on(p) for p in (0, 1]; τ_off for p <= 0 never rises.
  double rise_tau_s(double drive) const;
  // τ of the segment from state x toward drive p.
  double tau_s(double state, double drive) const { return drive > state ? rise_tau_s(drive) : params_.tau_off_s; }
  // x after holding drive p for `seconds` from x: p + (x − p) e^{−t/τ(x, p)}, exact for constant drive.
  double advance(double state, double drive, double seconds) const;
  // The segment that drives p from x.
  LcSegment segment(double state, double drive) const { return {drive, tau_s(state, drive)}; }
  // The overdrive: the drive in [0, 1] whose frame from x ends at L, or the clamped one nearest L (x, L in [0, 1]).
  double overdrive(double state, double level) const;

 private:
  LcResponseParams params_;
  double period_ = 0.0;
  double fall_reach_ = 0.0;  // 1 − e^{−T/τ_off}: the share of a falling step one frame delivers
};

}  // namespace trm
