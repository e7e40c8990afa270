// The light a panel pixel emits within a frame (DESIGN §8; paper Sec. 2.2 and 3, hold-type blur), beside the drive
// model of panel.hpp: the drive model says how much light a frame gives on average, this says when within the frame
// it is given, which is what an eye moving over the panel integrates.
//
// One model covers both panel kinds. A frame of period T = 1 / refresh drives a steady level L (linear light, the
// level the pixel would settle at if the frame were held for ever). Within the frame, at time t in [0, T) after the
// frame starts for that pixel's row,
//
//   light(t) = g(t) · s(t),
//   s(t)     = L + (s0 − L) e^{−t/τ}                  optical state: first-order liquid-crystal response from s0,
//                                                     the state the previous frame left (τ = 0: instant, as OLED)
//   g(t)     = 1 / duty  for t in [a, a + duty·T),    emission window (OLED persistence, or the strobed backlight)
//              0         elsewhere                    of `duty` of the frame starting at a = window_start · T.
//
// Normalisation: the window emits at 1 / duty, so a settled pixel (s0 = L) averages exactly L over the frame for any
// duty. A frame's time average is then the level it drives, as the decoders' emitted_linear reports it (Talbot-
// Plateau), and the persistence changes only when within the frame the light comes, never how much: peak luminance
// losses (BFI, interlace) come from their black frames and rows, which are levels 0 through the same model.
//
// The liquid crystal relaxes toward L for the whole frame, lit or not, and a frame ends at end_state(s0, L), where
// the next frame starts. τ is either one constant (lc_tau_s) or, for LCD panels, the level-dependent response of
// lc_response.hpp (rise τ_on(p) faster at higher drive, fall τ_off): then each frame's segment relaxes toward the
// drive p the panel applies with τ(s0, p), per pixel. Or the LC is
// the second-order system of lc_second_order.hpp (an LCD preset's "lc_second_order"): its state is the level and
// its rate (LcMotion), and the light of a part of a frame is linear in L, s0 and the rate s0' with weights shared by
// every pixel. Every value is the closed form (the exponential or matrix-exponential update, not a time step of the
// ODE), so it is exact and stable for any τ >= 0: τ far below T reaches L without overshoot, τ far above T barely
// moves.
//
// Overdrive (an LCD preset's "overdrive": true): the panel drives, instead of L, the level p = drive(s0, L) whose
// frame ends at L, the inverse of its own LC model's exact one-frame response (constant τ and the falling first-order
// segment: s0 + (L − s0) / (1 − e^{−T/τ}); the rising one: lc_response.hpp; second order: lc_second_order.hpp, from
// the level and the rate), clamped to the drive range [0, 1] where no drive reaches L within the frame. The panel
// knows its LC's state because it computes it from the drives it applied (a frame memory of the previous level, as
// panels keep for their overdrive LUT). Every function below that takes the wanted level L applies it.
//
// Rolling scan-out: row y of H starts its frames y / H · T after row 0 (the scan reaches it then); global scan-out
// starts every row together. Times passed to level_at and integral are since the row's own frame start.
#pragma once

#include "trm/lc_response.hpp"
#include "trm/lc_second_order.hpp"
#include "trm/panel.hpp"

#include <optional>
#include <string>
#include <utility>

namespace trm {

enum class ScanOut { Global, Rolling };

struct PanelLightConfig {
  double refresh_hz = 90.0;
  double duty = 1.0;          // fraction of the frame the window emits, in (0, 1]; 1: sample-and-hold
  double window_start = 0.0;  // start of the window as a fraction of the frame, in [0, 1 − duty]
  double lc_tau_s = 0.0;      // τ of the liquid-crystal response, >= 0 s; 0: instant (OLED)
  ScanOut scan_out = ScanOut::Global;
  // The level-dependent LC response; set, it replaces lc_tau_s (which must then be 0).
  std::optional<LcResponseParams> lc_response = std::nullopt;
  // The second-order LC; set, it replaces both (lc_tau_s must be 0 and lc_response unset).
  std::optional<LcSecondOrderParams> lc_second_order = std::nullopt;
  // The panel overdrives its LC (drive()); needs an LC with state (lc_tau_s > 0, lc_response or lc_second_order).
  bool overdrive = false;
};

// Low persistence on the Vive (paper Sec. 2.2, Fig. 2c, measured with a 9 kHz sensor: "the display remains black for
// 80% of a frame"): 20 % of an 11.1 ms frame, 2.2 ms. Consistent with the 2-3 ms per frame generally given for
// consumer low-persistence headsets (https://xinreality.com/wiki/Low_persistence: "3ms or lower";
// https://explorations360.com/en/glossary/persistence: "2-3 ms per frame"). Panel presets carry it as oled.duty
// (panel.hpp uses it for every OLED preset; no per-model measurement of the Rift CV1 was found).
inline constexpr double kViveOledDuty = 0.2;

// The constant τ of a first-order response with one time constant for every transition: 2 ms, the falling τ_off of
// LcResponseParams. LCD panels use the level-dependent response (their preset's LcdPanel::lc_response) instead.
inline constexpr double kDefaultLcdTauS = 0.002;

// Options for the light of a Panel (panel_light): what the drive model does not know.
struct PanelLightOptions {
  ScanOut scan_out = ScanOut::Global;
  double strobe_duty = 1.0;           // LCD only: backlight window (1: always on)
  // LCD only: strobe window start as a fraction of the frame; negative means at the end of the frame (1 − duty),
  // where the liquid crystal has settled most, as strobed backlights place it.
  double strobe_start = -1.0;
};

// ∫ light dt over an interval = level · L + previous · s0 + previous_rate · s0' (seconds × light; s0' the
// second-order LC's rate, whose weight is 0 for the first-order models).
struct LightWeights {
  double level = 0.0;
  double previous = 0.0;
  double previous_rate = 0.0;
};

class PanelLight {
 public:
  // Throws std::invalid_argument naming the field: refresh_hz finite and > 0, duty in (0, 1], window_start in
  // [0, 1 − duty], lc_tau_s finite and >= 0 (0 with lc_response or lc_second_order), lc_response's fields
  // (LcResponse), lc_second_order's (LcSecondOrder; not with lc_response).
  explicit PanelLight(const PanelLightConfig& config);

  const PanelLightConfig& config() const { return config_; }
  double frame_period_s() const { return period_; }
  // The lit part of each frame, [window_begin_s, window_end_s) since the row's frame start.
  double window_begin_s() const { return window_begin_; }
  double window_end_s() const { return window_end_; }
  // When row y of `rows` starts its frames after row 0: y / rows · T for rolling scan-out, 0 for global. Throws
  // std::invalid_argument naming `rows` (< 1) or `y` (outside [0, rows)).
  double row_delay_s(int y, int rows) const;
  // The LC response: its state depends on the previous frame (lc_tau_s > 0 or lc_response), and whether its τ
  // depends on the transition (lc_response: the weights differ per pixel, take them from segment()).
  bool has_lc_state() const { return config_.lc_tau_s > 0.0 || response_.has_value() || second_order_.has_value(); }
  const std::optional<LcResponse>& lc_response() const { return response_; }
  // The second-order LC: the state is an LcMotion, and the LcMotion overloads below are the ones to use (the scalar
  // ones take the state at rest, and end_state(double, double) throws std::logic_error, as it would drop the rate).
  const std::optional<LcSecondOrder>& lc_second_order() const { return second_order_; }
  // The level the panel drives for wanted level L after state s0: L, or with overdrive the one that ends the frame at
  // L where [0, 1] allows (levels outside [0, 1] are driven as they are). The scalar form takes s0 at rest.
  double drive(const LcMotion& previous_state, double level) const;
  double drive(double previous_state, double level) const { return drive(LcMotion{previous_state, 0.0}, level); }
  // The frame's segment from state s0 for wanted level L: the drive the LC relaxes toward and τ (constant τ: τ).
  LcSegment segment(double previous_state, double level) const;

  // light(t) for t in [0, T] since the frame start, after state s0 (`previous_state`), for wanted level `level` (the
  // LC relaxes toward drive(s0, level)).
  double level_at(double t, double previous_state, double level) const;
  double level_at(double t, const LcMotion& previous_state, double level) const;
  // ∫_{t0}^{t1} light dt in closed form, 0 <= t0 <= t1 <= T (throws std::invalid_argument naming `t0` or `t1`):
  // previous = τ e^{−u0/τ} (1 − e^{−Δ/τ}) / duty and level = Δ / duty − previous over the lit part [u0, u0 + Δ] of
  // [t0, t1], each evaluated without cancellation (expm1 and a series for Δ ≪ τ), to a few ulps.
  // With the constant τ (or the second-order LC's weights); the second form for one segment's τ (tau_s >= 0).
  LightWeights weights(double t0, double t1) const;
  LightWeights weights(double t0, double t1, double tau_s) const;
  double integral(double t0, double t1, double previous_state, double level) const;
  double integral(double t0, double t1, const LcMotion& previous_state, double level) const;
  // s(T): the state the frame leaves for the next one (the level itself when τ = 0).
  double end_state(double previous_state, double level) const;
  // With the rate: the second-order LC's state after the frame (first-order models: their level, at rate 0).
  LcMotion end_state(const LcMotion& previous_state, double level) const;

 private:
  PanelLightConfig config_;
  double period_ = 0.0;
  double window_begin_ = 0.0;
  double window_end_ = 0.0;
  double decay_ = 0.0;  // e^{−T/τ}
  double reach_ = 0.0;  // 1 − e^{−T/τ}
  std::optional<LcResponse> response_;
  std::optional<LcSecondOrder> second_order_;

  // [t0, t1] (checked: within [0, T]) cut to the lit window.
  std::pair<double, double> lit_part(double t0, double t1) const;
};

// The light of `panel` at `refresh_hz`: an OLED emits for panel.oled.duty of the frame from its start with no LC
// response; an LCD holds (or strobes) with its preset's LC: the level-dependent response panel.lcd.lc_response, or
// the second-order LC when the preset has one (panel.lcd.lc_second_order), overdriven when the preset says so
// (panel.lcd.overdrive). Throws std::invalid_argument naming the argument.
PanelLight panel_light(const Panel& panel, double refresh_hz, const PanelLightOptions& options = {});

// The steady level drive v holds on `panel` (channel c): OLED v^gamma_c, LCD M(v, v)^gamma. What a frame's drive
// gives this model as L; for an OLED it is also the frame's emitted_linear (the LCD's emitted_linear already averages
// the LC transition of the merge model, so it must not be fed again through τ).
double steady_level(const Panel& panel, double v, int channel);
// steady_level of every sample of drive codes (CV_16UC3 at `output_bits`, code / (2^bits − 1)): CV_64FC3, the levels
// L a decoded frame gives this model. Throws std::invalid_argument naming `drive_codes` for another type.
cv::Mat steady_levels(const Panel& panel, int output_bits, const cv::Mat& drive_codes);

}  // namespace trm
