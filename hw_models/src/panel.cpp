// Panel models (DESIGN §4 "Panel drive", paper Sec. 4.4) in double precision.
#include "trm/panel.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace trm {

namespace {

// Measured per-primary gammas (paper Sec. 4.4, Specbos 1211 measurements).
constexpr std::array<double, 3> kViveGamma{2.2912, 2.2520, 2.1940};
constexpr std::array<double, 3> kRiftGamma{2.1526, 2.0910, 2.0590};
constexpr double kGenericGamma = 2.2;

// Low persistence: the Vive and Rift CV1 OLEDs emit for about 2 ms of an 11.1 ms frame (DESIGN §8,
// "≈ 20 % duty on the Vive"). The same value is used for every OLED preset; it only matters to the eye
// model, never to the drive values.
constexpr double kOledDuty = 0.2;

// A root computed a few ulps outside [0, 1] (e.g. m = M(1, v_prev) exactly) is still the root.
constexpr double kRangeTolerance = 1e-12;

// |M(v) - m| this small at the closest clamped v is a root lost to rounding (a tangent, disc ≈ 0).
constexpr double kReachedTolerance = 1e-14;

// Below this ratio |a| / |b| the quadratic term a v^2 is under 2^-80 of the linear term for every
// v in [0, 1]: the linear root is the quadratic root to full double precision.
constexpr double kNegligibleQuadratic = 0x1p-80;

// 'text' (built by appending: GCC 12 misreports "literal" + std::string&& under -Wrestrict).
std::string quoted(std::string_view text) {
  std::string out("'");
  out.append(text);
  out.push_back('\'');
  return out;
}

// Shortest round-trip text of a number, for messages.
std::string number_text(double value) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
  return ec == std::errc() ? std::string(text, end) : std::string("?");
}

std::string accepted_forms() {
  const std::string gammas = "within [" + number_text(kMinPanelGamma) + ", " + number_text(kMaxPanelGamma) + "]";
  return "accepted panel specs: 'vive', 'rift', 'generic', 'gamma:G', 'gamma:GR,GG,GB' (gammas " + gammas +
         "), 'lcd', 'lcd:p1,p2,p3,p4,gamma' (finite parameters within [-" + number_text(kMaxLcdCoefficient) + ", " +
         number_text(kMaxLcdCoefficient) + "], M increasing in the drive, gamma " + gammas + ")";
}

[[noreturn]] void reject(const std::string& spec, const std::string& why) {
  std::string message("invalid panel ");
  message.append(quoted(spec)).append(": ").append(why).append("; ").append(accepted_forms());
  throw std::invalid_argument(message);
}

// Comma-separated finite doubles, every character consumed.
std::vector<double> parse_numbers(const std::string& spec, std::string_view list) {
  std::vector<double> values;
  while (true) {
    const std::size_t comma = list.find(',');
    const std::string_view item = list.substr(0, comma);
    double value = 0.0;
    const char* end = item.data() + item.size();
    const auto [ptr, ec] = std::from_chars(item.data(), end, value);
    if (item.empty() || ec != std::errc() || ptr != end) {
      reject(spec, quoted(item) + " is not a number");
    }
    if (!std::isfinite(value)) reject(spec, "parameters must be finite (got " + quoted(item) + ")");
    values.push_back(value);
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  return values;
}

Panel parse_panel_spec(const std::string& spec);

Panel oled_panel(const std::string& name, const std::array<double, 3>& gamma) {
  Panel panel;
  panel.kind = PanelKind::Oled;
  panel.name = name;
  panel.oled.gamma = gamma;
  panel.oled.duty = kOledDuty;
  return panel;
}

}  // namespace

double LcdPanel::merge(double v_t, double v_prev) const {
  // Eq. 7
  return p1 * (v_t * v_t + v_prev * v_prev) + p2 * v_t * v_prev + p3 * (v_t + v_prev) + p4;
}

LcdPanel::Solution LcdPanel::solve(double m, double v_prev) const {
  // M(v, v_prev) = m as a v^2 + b v + c = 0.
  const double a = p1;
  const double b = p2 * v_prev + p3;
  const double c = p1 * v_prev * v_prev + p3 * v_prev + p4 - m;

  const auto in_range = [](double v) { return v >= -kRangeTolerance && v <= 1.0 + kRangeTolerance; };
  // Clamps the few-ulp overshoot allowed by in_range; "+ 0.0" turns -0 (from -c / b with c = 0) into +0.
  const auto reachable = [](double v) { return Solution{std::clamp(v, 0.0, 1.0) + 0.0, true}; };

  if (std::abs(a) <= kNegligibleQuadratic * std::abs(b)) {
    // p1 -> 0: the linear solve, the limit of the stable root c / q below.
    const double v = -c / b;
    if (in_range(v)) return reachable(v);
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      // Stable root form: q = -(b + sign(b) sqrt(disc)) / 2 never subtracts nearly equal numbers.
      // c / q is the branch that tends to the linear root -c / b as a -> 0, so it is preferred when both
      // roots lie in [0, 1]; q / a is the root that escapes to infinity in that limit.
      const double sign_b = b < 0.0 ? -1.0 : 1.0;
      const double q = -0.5 * (b + sign_b * std::sqrt(disc));
      if (q == 0.0) {
        // b = 0 and disc = 0, so c = 0: the double root v = 0.
        return reachable(0.0);
      }
      const double continuous_root = c / q;
      if (in_range(continuous_root)) return reachable(continuous_root);
      const double far_root = q / a;
      if (in_range(far_root)) return reachable(far_root);
    }
  }

  // No real root in [0, 1]. M - m keeps one sign on [0, 1], so |M - m| is smallest at an extremum of M:
  // an end of the range or the vertex of the parabola.
  std::array<double, 3> candidates{0.0, 1.0, 0.0};
  std::size_t count = 2;
  if (a != 0.0) {
    const double vertex = -b / (2.0 * a);
    if (vertex > 0.0 && vertex < 1.0) candidates[count++] = vertex;
  }
  Solution best{candidates[0], false};
  double best_error = std::abs(merge(candidates[0], v_prev) - m);
  for (std::size_t k = 1; k < count; ++k) {
    const double error = std::abs(merge(candidates[k], v_prev) - m);
    if (error < best_error) {
      best_error = error;
      best.v = candidates[k];
    }
  }
  // A tangent root (disc rounded just below 0) or a flat M equal to m: the closest value hits m.
  if (best_error <= kReachedTolerance) best.reachable = true;
  return best;
}

double Panel::linear_from_drive(double v, int channel) const {
  if (kind == PanelKind::Oled) return std::pow(v, oled.gamma.at(static_cast<std::size_t>(channel)));
  // A held LCD pixel: the merge of the frame with itself. Negative merged values emit no light.
  return std::pow(std::max(lcd.merge(v, v), 0.0), lcd.gamma);
}

double Panel::drive_from_linear(double x, int channel) const {
  const double clamped = std::clamp(x, 0.0, 1.0);
  if (kind == PanelKind::Oled) return std::pow(clamped, 1.0 / oled.gamma.at(static_cast<std::size_t>(channel)));
  // Held LCD pixel: solve M(v, v) = x^(1/gamma), i.e. (2 p1 + p2) v^2 + 2 p3 v + p4 = m. With the default
  // parameters M(v, v) = v and this is v = x^(1/gamma). M(v, v) is the merge with p1' = 2 p1 + p2, p2' = 0,
  // p3' = 2 p3, p4' = p4 evaluated at v_prev = 0, which reuses the stable solver.
  LcdPanel held;
  held.p1 = 2.0 * lcd.p1 + lcd.p2;
  held.p2 = 0.0;
  held.p3 = 2.0 * lcd.p3;
  held.p4 = lcd.p4;
  held.gamma = lcd.gamma;
  return held.solve(std::pow(clamped, 1.0 / lcd.gamma), 0.0).v;
}

void validate_panel(const Panel& panel, const std::string& what) {
  const auto fail = [&](const std::string& why) { throw std::invalid_argument(what + why); };
  const auto check_gamma = [&](double gamma, const char* name) {
    if (!(gamma > 0.0) || !std::isfinite(gamma)) fail(std::string(name) + " must be > 0 and finite");
    if (gamma < kMinPanelGamma || gamma > kMaxPanelGamma) {
      fail(std::string(name) + " " + number_text(gamma) + " is outside [" + number_text(kMinPanelGamma) + ", " +
           number_text(kMaxPanelGamma) + "], the display gammas trm models");
    }
  };
  if (panel.kind == PanelKind::Oled) {
    for (double gamma : panel.oled.gamma) check_gamma(gamma, "OLED gamma");
    if (!(panel.oled.duty > 0.0 && panel.oled.duty <= 1.0)) fail("OLED duty must be in (0, 1]");
    return;
  }
  const LcdPanel& lcd = panel.lcd;
  for (double p : {lcd.p1, lcd.p2, lcd.p3, lcd.p4}) {
    if (!std::isfinite(p)) fail("LCD parameters p1..p4 must be finite");
    if (std::abs(p) > kMaxLcdCoefficient) {
      fail("LCD merge coefficients p1..p4 must be within [-" + number_text(kMaxLcdCoefficient) + ", " +
           number_text(kMaxLcdCoefficient) + "]");
    }
  }
  check_gamma(lcd.gamma, "LCD gamma");
  // dM/dv_t = 2 p1 v_t + p2 v_prev + p3 is linear in both: positive at the four corners means positive on [0, 1]^2.
  for (double v : {0.0, 1.0}) {
    for (double vp : {0.0, 1.0}) {
      if (!(2.0 * lcd.p1 * v + lcd.p2 * vp + lcd.p3 > 0.0)) {
        fail("the LCD merge M(v_t, v_prev) must be increasing in v_t on [0, 1] (dM/dv_t = 2 p1 v_t + p2 v_prev + p3 "
             "> 0), or the drive has no unique inverse");
      }
    }
    if (!(2.0 * (2.0 * lcd.p1 + lcd.p2) * v + 2.0 * lcd.p3 > 0.0)) {
      fail("the held LCD merge M(v, v) must be increasing on [0, 1]");
    }
  }
}

Panel parse_panel(const std::string& spec) {
  Panel panel = parse_panel_spec(spec);
  try {
    validate_panel(panel, "");
  } catch (const std::invalid_argument& e) {
    reject(spec, e.what());
  }
  return panel;
}

namespace {

Panel parse_panel_spec(const std::string& spec) {
  if (spec == "vive") return oled_panel(spec, kViveGamma);
  if (spec == "rift") return oled_panel(spec, kRiftGamma);
  if (spec == "generic") return oled_panel(spec, {kGenericGamma, kGenericGamma, kGenericGamma});

  const std::string_view view(spec);
  if (view.starts_with("gamma:")) {
    const std::vector<double> g = parse_numbers(spec, view.substr(6));
    if (g.size() != 1 && g.size() != 3) reject(spec, "gamma: takes 1 or 3 values");
    for (double value : g) {
      if (!(value > 0.0)) reject(spec, "gammas must be > 0");
    }
    return oled_panel(spec, g.size() == 1 ? std::array<double, 3>{g[0], g[0], g[0]}
                                          : std::array<double, 3>{g[0], g[1], g[2]});
  }

  Panel panel;
  panel.kind = PanelKind::Lcd;
  panel.name = spec;
  if (spec == "lcd") return panel;
  if (view.starts_with("lcd:")) {
    const std::vector<double> p = parse_numbers(spec, view.substr(4));
    if (p.size() != 5) reject(spec, "lcd: takes 5 values p1,p2,p3,p4,gamma");
    if (!(p[4] > 0.0)) reject(spec, "the LCD gamma must be > 0");
    panel.lcd.p1 = p[0];
    panel.lcd.p2 = p[1];
    panel.lcd.p3 = p[2];
    panel.lcd.p4 = p[3];
    panel.lcd.gamma = p[4];
    return panel;
  }
  reject(spec, "unknown panel");
}

}  // namespace

}  // namespace trm
