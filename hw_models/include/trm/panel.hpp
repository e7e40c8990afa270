// Panel models (DESIGN §4 "Panel drive", paper Sec. 4.4): OLED per-channel gamma and the LCD temporal
// merge model (Eq. 7) with its numerically stable inverse. Double precision (reference).
#pragma once

#include <array>
#include <string>

namespace trm {

struct OledPanel {
  std::array<double, 3> gamma{2.2, 2.2, 2.2};  // R, G, B: I = v^gamma
  double duty = 0.2;                           // persistence: fraction of the frame the pixel emits
};

// LCD merge (Eq. 7): M(vt, vp) = p1 (vt^2 + vp^2) + p2 vt vp + p3 (vt + vp) + p4, luminance M^gamma.
struct LcdPanel {
  double p1 = -0.1, p2 = 0.2, p3 = 0.5, p4 = 0.0;  // defaults satisfy M(v, v) = v (p4 = 0, p3 = 1/2, p2 = -2 p1)
  double gamma = 2.2;

  double merge(double v_t, double v_prev) const;
  // Solves M(v, v_prev) = m for v in [0, 1] with the stable quadratic root form (linear solve when
  // |p1| is negligible). If no real root lies in [0, 1], returns the clamped v whose M is closest to m
  // and sets reachable = false.
  struct Solution {
    double v = 0.0;
    bool reachable = true;
  };
  Solution solve(double m, double v_prev) const;
};

enum class PanelKind { Oled, Lcd };

struct Panel {
  PanelKind kind = PanelKind::Oled;
  std::string name = "vive";
  OledPanel oled;
  LcdPanel lcd;

  // OLED: I = v^gamma_c. LCD (one frame held, as if v_prev = v): M(v, v)^gamma = v^gamma.
  double linear_from_drive(double v, int channel) const;
  double drive_from_linear(double x, int channel) const;
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
// increasing on [0, 1] (otherwise several drives give one light and the inverse is not defined). Throws
// std::invalid_argument with `what` and the rule.
void validate_panel(const Panel& panel, const std::string& what);

// "vive" | "rift" | "generic" | "gamma:G" | "gamma:GR,GG,GB" | "lcd" | "lcd:p1,p2,p3,p4,gamma".
// Throws std::invalid_argument with the list of accepted forms, for a malformed spec and for a panel that breaks
// validate_panel's rules.
Panel parse_panel(const std::string& spec);

}  // namespace trm
