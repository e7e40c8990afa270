// Panel models (DESIGN §4 "Panel drive", paper Sec. 4.4): OLED per-channel gamma and the LCD temporal
// merge model (Eq. 7) with its numerically stable inverse. Double precision (reference).
//
// Each panel kind owns its parameters, their parsing and validation, the drive (inverse: linear light -> drive value,
// given the panel's history) and the emission (forward: drive value -> linear light, given the history), and the
// sample functions the fixed-point ROMs tabulate. Panel is the model every decoder, report and tool asks: a closed
// variant over the two kinds rather than a virtual interface, because configurations hold it by value (they are
// copied per decoder and sweep point, compared, and written to JSON) and the fixed-point decoder builds different
// ROMs and frame stores per kind at construction, so a new kind needs new hardware anyway, not just a new subclass.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "trm/lc_response.hpp"
#include "trm/lc_second_order.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm {

// What a panel drive of one channel sample gives (Panel::drive).
struct PanelDriveSample {
  double v = 0.0;            // the drive value in [0, 1], before output quantisation
  double target = 0.0;       // LCD: the merged value m the pair must reach; OLED: v
  bool reachable = true;     // LCD: M(v, v_prev) = m had a root in [0, 1]; OLED: always
  double contributed = 0.0;  // what this frame adds to the pair in linear light: x_t, or where unreachable
                             // x_t_eff = 2 M(v, v_prev)^gamma - x_{t-1}
};

struct OledPanel {
  std::array<double, 3> gamma{2.2, 2.2, 2.2};  // R, G, B: I = v^gamma
  double duty = 0.2;                           // persistence: fraction of the frame the pixel emits

  // I = v^gamma_c.
  double emitted(double v, int channel) const;
  // v = clamp(x, 0, 1)^(1/gamma_c).
  double drive(double x, int channel) const;
  // The same doubles for interleaved RGB samples (channel = index % 3; v may be x, the sizes must match), the pows a
  // vector at a time (trm/vector_pow.hpp).
  void drive(std::span<const double> x, std::span<double> v) const;
  // Throws std::invalid_argument with `what` and the broken rule (see validate_panel).
  void validate(const std::string& what) const;
  friend bool operator==(const OledPanel&, const OledPanel&) = default;
};

// LCD merge (Eq. 7): M(vt, vp) = p1 (vt^2 + vp^2) + p2 vt vp + p3 (vt + vp) + p4, luminance M^gamma.
struct LcdPanel {
  double p1 = -0.1, p2 = 0.2, p3 = 0.5, p4 = 0.0;  // defaults satisfy M(v, v) = v (p4 = 0, p3 = 1/2, p2 = -2 p1)
  double gamma = 2.2;
  // The liquid crystal of the eye model's light (panel_light.hpp): the level-dependent first-order response with
  // lc_response's parameters, or, when lc_second_order is set, the second-order system (damping_ratio >=
  // kMinPanelDampingRatio; lc_response then stays at its defaults: one LC model). The drive (Eq. 7) depends on
  // neither.
  LcResponseParams lc_response;
  std::optional<LcSecondOrderParams> lc_second_order;
  // The panel overdrives its liquid crystal (panel_light.hpp, PanelLightConfig::overdrive): the eye model's light
  // reaches each frame's level within the frame where the drive range allows. The drive (Eq. 7) does not depend on it.
  bool overdrive = false;

  double merge(double v_t, double v_prev) const;
  // Solves M(v, v_prev) = m for v in [0, 1] with the stable quadratic root form (linear solve when
  // |p1| is negligible). If no real root lies in [0, 1], returns the clamped v whose M is closest to m
  // and sets reachable = false.
  struct Solution {
    double v = 0.0;
    bool reachable = true;
  };
  Solution solve(double m, double v_prev) const;

  // The light of a merged value: max(M, 0)^gamma (negative merged values emit no light).
  double luminance(double merged) const;
  // Emission of drive v_t after v_prev: the pair's merged light M(v_t, v_prev)^gamma, which is already the time
  // average of the two frames.
  double emitted(double v_t, double v_prev) const { return luminance(merge(v_t, v_prev)); }
  // The pair target m = ((x_t + x_{t-1}) / 2)^(1/gamma), the average clamped at 0.
  double target(double x_t, double x_prev) const;
  // The drive of x_t after a frame that contributed x_prev and was driven at v_prev (DESIGN §4 inverse).
  PanelDriveSample drive(double x_t, double x_prev, double v_prev) const;
  // drive() of every sample of a run (all four spans of one length, else std::invalid_argument): the same doubles,
  // the pair targets' pows a vector at a time.
  void drive(std::span<const double> x_t, std::span<const double> x_prev, std::span<const double> v_prev,
             std::span<PanelDriveSample> out) const;
  // The merge of a pixel held at one drive, M(v, v), as a merge in v_t alone: p1' = 2 p1 + p2, p2' = 0,
  // p3' = 2 p3, p4' = p4 at v_prev = 0 (so the stable solver applies to it).
  LcdPanel held() const;
  // The merged values M of emitted light M^gamma (undoes luminance() where M >= 0).
  cv::Mat merged_of_emission(const cv::Mat& emitted) const;
  // Throws std::invalid_argument with `what` and the broken rule (see validate_panel).
  void validate(const std::string& what) const;
  friend bool operator==(const LcdPanel&, const LcdPanel&) = default;

 private:
  // drive() with the pair target m already computed.
  PanelDriveSample drive_to(double m, double x_t, double x_prev, double v_prev) const;
};

enum class PanelKind { Oled, Lcd };

struct Panel {
  PanelKind kind = PanelKind::Oled;
  std::string name = "vive";
  OledPanel oled;
  LcdPanel lcd;

  // The emission depends on the previous frame's drive (LCD): the decoder keeps v_{t-1} and x_{t-1} frame stores.
  bool has_history() const { return kind == PanelKind::Lcd; }
  // The exponent of each channel's emission (OLED gamma_c; LCD one gamma for all): what the fixed-point drive
  // thresholds and inverse-gamma LUTs tabulate.
  std::array<double, 3> channel_gammas() const;

  // The drive of x_t (channel sample) given the history: x_prev, what the previous frame contributed, and v_prev,
  // its drive value. Panels without history ignore both.
  PanelDriveSample drive(double x_t, double x_prev, double v_prev, int channel) const;
  // The light drive v emits after drive v_prev (ignored without history).
  double emitted(double v, double v_prev, int channel) const;
  // A pixel held at one drive (no history, or the same frame before): OLED v^gamma_c, LCD M(v, v)^gamma.
  double linear_from_drive(double v, int channel) const;
  // Its inverse: the drive that holds x (clamped to [0, 1]).
  double drive_from_linear(double x, int channel) const;

  // Throws std::invalid_argument with `what` and the broken rule (see validate_panel).
  void validate(const std::string& what) const;
  // Same kind, name and parameters of that kind (the other kind's parameters are not part of the panel).
  friend bool operator==(const Panel& a, const Panel& b);
};

// The light of every drive code after every previous code at one output depth (previous codes only for a panel with
// history): the emission both decoders report for their quantised drive, tabulated once instead of a pow per sample
// (the same doubles as Panel::emitted of code / (2^bits - 1)).
class PanelEmission {
 public:
  PanelEmission(const Panel& panel, int output_bits);
  double operator()(std::uint16_t code, std::uint16_t previous_code, int channel) const {
    return history_ ? table_[code * codes_ + previous_code] : table_[static_cast<std::size_t>(channel) * codes_ + code];
  }
  // The light of a run of interleaved RGB codes (starting at red) without history, as operator() per sample.
  void row(std::span<const std::uint16_t> codes, std::span<double> out) const;

 private:
  std::size_t codes_ = 0;
  bool history_ = false;
  std::vector<double> table_;  // with history [code][previous] (one for every channel); else [channel][code]
};

// The panels every decoder accepts. Display gammas are measured near 2.2 (1.8 to 2.6); [0.5, 4] leaves room for
// experiments while every drive code still emits distinct light in double precision.
inline constexpr double kMinPanelGamma = 0.5;
inline constexpr double kMaxPanelGamma = 4.0;
// LCD merge coefficients beyond this are no panel (M(v, v) = v needs |p| <= 1); the fixed-point decoder holds
// them in sQ7.f.
inline constexpr double kMaxLcdCoefficient = 16.0;

// The physical rules a panel must meet for its drive to be an inverse (one validation for every decoder): OLED gammas
// and LCD gamma within [kMinPanelGamma, kMaxPanelGamma], OLED duty in (0, 1], LCD coefficients finite and within
// kMaxLcdCoefficient, M(v_t, v_prev) strictly increasing in v_t on [0, 1]^2 and the held merge M(v, v) strictly
// increasing on [0, 1] (otherwise several drives give one light and the inverse is not defined); and for the eye
// model's light, the LCD's LC parameters within their models' ranges (LcResponse, LcSecondOrder; damping_ratio >=
// kMinPanelDampingRatio) with one LC model set. Throws std::invalid_argument with `what` and the rule.
void validate_panel(const Panel& panel, const std::string& what);

// "vive" | "rift" | "generic" | "gamma:G" | "gamma:GR,GG,GB" | "lcd" | "lcd:p1,p2,p3,p4,gamma" | "lcd:FILE.json"
// (an LCD panel's JSON as to_json writes it, e.g. the preset of `trm calibrate`). Throws std::invalid_argument with
// the list of accepted forms, for a malformed spec, an unreadable or malformed preset file and for a panel that
// breaks validate_panel's rules.
Panel parse_panel(const std::string& spec);

// The panel as JSON, every parameter of its kind: {"kind": "oled", "name", "gamma": [R, G, B], "duty"} or
// {"kind": "lcd", "name", "p1", "p2", "p3", "p4", "gamma"}, and with first-order LC parameters other than the
// defaults "lc_response": {"tau_off_s", "drive_ratio", "drive_gamma"} (absent at the defaults), with a second-order
// liquid crystal "lc_second_order": {"tau_s", "damping_ratio"} (absent without one), with overdrive "overdrive": true
// (absent without). The one writer and the one reader of a panel, for both JSON flavours the reports use (one body
// each).
void to_json(nlohmann::json& out, const Panel& panel);
void to_json(nlohmann::ordered_json& out, const Panel& panel);
// Throws std::invalid_argument "panel JSON: ..." for a missing or mistyped field (an "overdrive" that is not a
// boolean), a field the kind does not take (named, with the ones it takes: a misspelt field is an error, not a
// default), an unknown kind or a panel that breaks validate_panel's rules.
void from_json(const nlohmann::json& in, Panel& panel);
void from_json(const nlohmann::ordered_json& in, Panel& panel);

}  // namespace trm
