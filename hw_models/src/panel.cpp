// Panel models (DESIGN §4 "Panel drive", paper Sec. 4.4) in double precision.
#include "trm/panel.hpp"

#include "trm/vector_pow.hpp"

#include "perception_checks.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

namespace trm {

namespace {

using perception_detail::number_text;  // shortest round-trip text of a number, for messages

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
std::string in_quotes(std::string_view text) {
  std::string out("'");
  out.append(text);
  out.push_back('\'');
  return out;
}


std::string accepted_forms() {
  const std::string gammas = "within [" + number_text(kMinPanelGamma) + ", " + number_text(kMaxPanelGamma) + "]";
  return "accepted panel specs: 'vive', 'rift', 'generic', 'gamma:G', 'gamma:GR,GG,GB' (gammas " + gammas +
         "), 'lcd', 'lcd:FILE.json' (a panel preset, as trm calibrate writes it), 'lcd:p1,p2,p3,p4,gamma' (finite parameters within [-" + number_text(kMaxLcdCoefficient) + ", " +
         number_text(kMaxLcdCoefficient) + "], M increasing in the drive, gamma " + gammas + ")";
}

[[noreturn]] void reject(const std::string& spec, const std::string& why) {
  std::string message("invalid panel ");
  message.append(in_quotes(spec)).append(": ").append(why).append("; ").append(accepted_forms());
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
      reject(spec, in_quotes(item) + " is not a number");
    }
    if (!std::isfinite(value)) reject(spec, "parameters must be finite (got " + in_quotes(item) + ")");
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

namespace lcd_detail {

// M(v, v_prev) = m as a v^2 + b v + c = 0 (Eq. 7), for LcdPanel::solve and its vector loop alike.
struct Quadratic {
  double a;
  double b;
  double c;
};
inline Quadratic quadratic(double p1, double p2, double p3, double p4, double m, double v_prev) {
  return {p1, p2 * v_prev + p3, p1 * v_prev * v_prev + p3 * v_prev + p4 - m};
}

// A root the solve takes: within [0, 1] up to kRangeTolerance (& rather than &&: no branch, for the vector loop).
inline bool in_drive_range(double v) { return (v >= -kRangeTolerance) & (v <= 1.0 + kRangeTolerance); }

// The pair's average, clamped at 0: what LcdPanel::target raises to 1/gamma.
inline double pair_average(double x_t, double x_prev) { return std::max(0.5 * (x_t + x_prev), 0.0); }

// LcdPanel::solve's common case (a root of M(v, v_prev) = m in range, taken as solve takes it) for a run of samples,
// every expression as solve writes it, as selects instead of branches so that the compiler vectorises the run; GCC's
// function multi-versioning compiles it for AVX2 too (four doubles a vector, no FMA: the same doubles). v is NaN
// where the sample needs solve itself (no root in range, the far root, q = 0).
[[gnu::target_clones("avx2", "default")]] void solve_in_range(double p1, double p2, double p3, double p4,
                                                              const double* m, const double* v_prev, double* v,
                                                              std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) {
    const auto [a, b, c] = quadratic(p1, p2, p3, p4, m[k], v_prev[k]);
    const bool linear = std::abs(a) <= kNegligibleQuadratic * std::abs(b);
    const double linear_root = -c / b;
    const double disc = b * b - 4.0 * a * c;
    const double sign_b = b < 0.0 ? -1.0 : 1.0;
    const double q = -0.5 * (b + sign_b * std::sqrt(disc));
    const double continuous_root = c / q;
    const double root = linear ? linear_root : continuous_root;
    const bool taken = in_drive_range(root) & (linear | ((disc >= 0.0) & (q != 0.0)));
    const double above_zero = root < 0.0 ? 0.0 : root;
    const double clamped = (1.0 < above_zero ? 1.0 : above_zero) + 0.0;
    v[k] = taken ? clamped : std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace lcd_detail

double LcdPanel::merge(double v_t, double v_prev) const {
  // Eq. 7
  return p1 * (v_t * v_t + v_prev * v_prev) + p2 * v_t * v_prev + p3 * (v_t + v_prev) + p4;
}

LcdPanel::Solution LcdPanel::solve(double m, double v_prev) const {
  const auto [a, b, c] = lcd_detail::quadratic(p1, p2, p3, p4, m, v_prev);
  const auto in_range = [](double v) { return lcd_detail::in_drive_range(v); };
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

double LcdPanel::luminance(double merged) const { return std::pow(std::max(merged, 0.0), gamma); }

double LcdPanel::target(double x_t, double x_prev) const {
  return std::pow(lcd_detail::pair_average(x_t, x_prev), 1.0 / gamma);
}

// The pair (v_{t-1}, v_t) is seen as the merged value M(v_t, v_{t-1}) with luminance M^gamma, the time average of the
// two frames. To add x_t after a frame that contributed x_{t-1}, the pair must merge to m; v_{t-1} is the drive
// actually shown. Where m is unreachable v_t is clamped to the closest attainable merge, and the pair then averages
// to M(v_t, v_{t-1})^gamma: frame t effectively contributed x_t_eff = 2 M(v_t, v_{t-1})^gamma - x_{t-1}.
PanelDriveSample LcdPanel::drive(double x_t, double x_prev, double v_prev) const {
  return drive_to(target(x_t, x_prev), x_t, x_prev, v_prev);
}

PanelDriveSample LcdPanel::drive_to(double m, double x_t, double x_prev, double v_prev) const {
  PanelDriveSample out;
  out.target = m;
  const Solution solution = solve(m, v_prev);
  out.v = solution.v;
  out.reachable = solution.reachable;
  out.contributed = solution.reachable ? x_t : 2.0 * emitted(solution.v, v_prev) - x_prev;
  return out;
}

void LcdPanel::drive(std::span<const double> x_t, std::span<const double> x_prev, std::span<const double> v_prev,
                     std::span<PanelDriveSample> out) const {
  if (x_prev.size() != x_t.size() || v_prev.size() != x_t.size() || out.size() != x_t.size()) {
    throw std::invalid_argument("LcdPanel::drive: x_t, x_prev, v_prev and out differ in size");
  }
  constexpr std::size_t kChunk = 256;
  std::array<double, kChunk> m;  // target() of each sample
  std::array<double, kChunk> solved;
  for (std::size_t start = 0; start < x_t.size(); start += kChunk) {
    const std::size_t count = std::min(kChunk, x_t.size() - start);
    for (std::size_t k = 0; k < count; ++k) m[k] = lcd_detail::pair_average(x_t[start + k], x_prev[start + k]);
    pow_elements(std::span<const double>(m.data(), count), 1.0 / gamma, std::span<double>(m.data(), count));
    lcd_detail::solve_in_range(p1, p2, p3, p4, m.data(), v_prev.data() + start, solved.data(), count);
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t i = start + k;
      if (std::isnan(solved[k])) {
        out[i] = drive_to(m[k], x_t[i], x_prev[i], v_prev[i]);
      } else {
        out[i] = PanelDriveSample{.v = solved[k], .target = m[k], .reachable = true, .contributed = x_t[i]};
      }
    }
  }
}

LcdPanel LcdPanel::held() const {
  LcdPanel out;
  out.p1 = 2.0 * p1 + p2;
  out.p2 = 0.0;
  out.p3 = 2.0 * p3;
  out.p4 = p4;
  out.gamma = gamma;
  return out;
}

cv::Mat LcdPanel::merged_of_emission(const cv::Mat& emitted) const {
  cv::Mat merged;
  cv::pow(emitted, 1.0 / gamma, merged);
  return merged;
}

double OledPanel::emitted(double v, int channel) const {
  return std::pow(v, gamma.at(static_cast<std::size_t>(channel)));
}

double OledPanel::drive(double x, int channel) const {
  return std::pow(std::clamp(x, 0.0, 1.0), 1.0 / gamma.at(static_cast<std::size_t>(channel)));
}

void OledPanel::drive(std::span<const double> x, std::span<double> v) const {
  if (x.size() != v.size()) throw std::invalid_argument("OledPanel::drive: x and v differ in size");
  // A chunk of whole pixels, so its exponents start at red.
  constexpr std::size_t kChunk = 255;
  std::array<double, kChunk> exponent;
  for (std::size_t k = 0; k < kChunk; ++k) exponent[k] = 1.0 / gamma.at(k % 3);
  std::array<double, kChunk> base;
  for (std::size_t start = 0; start < x.size(); start += kChunk) {
    const std::size_t count = std::min(kChunk, x.size() - start);
    for (std::size_t k = 0; k < count; ++k) base[k] = std::clamp(x[start + k], 0.0, 1.0);
    pow_elements(std::span<const double>(base.data(), count), std::span<const double>(exponent.data(), count),
                 v.subspan(start, count));
  }
}

std::array<double, 3> Panel::channel_gammas() const {
  return kind == PanelKind::Oled ? oled.gamma : std::array<double, 3>{lcd.gamma, lcd.gamma, lcd.gamma};
}

PanelDriveSample Panel::drive(double x_t, double x_prev, double v_prev, int channel) const {
  if (kind == PanelKind::Lcd) return lcd.drive(x_t, x_prev, v_prev);
  PanelDriveSample out;
  out.v = oled.drive(x_t, channel);
  out.target = out.v;
  out.contributed = x_t;
  return out;
}

double Panel::emitted(double v, double v_prev, int channel) const {
  return kind == PanelKind::Lcd ? lcd.emitted(v, v_prev) : oled.emitted(v, channel);
}

double Panel::linear_from_drive(double v, int channel) const {
  return kind == PanelKind::Lcd ? lcd.emitted(v, v) : oled.emitted(v, channel);
}

double Panel::drive_from_linear(double x, int channel) const {
  if (kind == PanelKind::Oled) return oled.drive(x, channel);
  // Held LCD pixel: solve M(v, v) = x^(1/gamma). With the default parameters M(v, v) = v and this is
  // v = x^(1/gamma).
  return lcd.held().solve(std::pow(std::clamp(x, 0.0, 1.0), 1.0 / lcd.gamma), 0.0).v;
}

bool operator==(const Panel& a, const Panel& b) {
  if (a.kind != b.kind || a.name != b.name) return false;
  return a.kind == PanelKind::Oled ? a.oled == b.oled : a.lcd == b.lcd;
}

PanelEmission::PanelEmission(const Panel& panel, int output_bits)
    : codes_(static_cast<std::size_t>(1) << output_bits), history_(panel.has_history()) {
  const int top = (1 << output_bits) - 1;
  if (history_) {
    // Both drives are codes (v_{t-1} = code / (2^out - 1) exactly), so M(v_t, v_{t-1})^gamma takes only (2^out)^2
    // values.
    table_.resize(codes_ * codes_);
    for (std::size_t code = 0; code < codes_; ++code) {
      for (std::size_t previous = 0; previous < codes_; ++previous) {
        table_[code * codes_ + previous] =
            panel.emitted(static_cast<double>(code) / top, static_cast<double>(previous) / top, 0);
      }
    }
    return;
  }
  table_.resize(3 * codes_);
  for (int ch = 0; ch < 3; ++ch) {
    for (std::size_t code = 0; code < codes_; ++code) {
      table_[static_cast<std::size_t>(ch) * codes_ + code] = panel.emitted(static_cast<double>(code) / top, 0.0, ch);
    }
  }
}

void PanelEmission::row(std::span<const std::uint16_t> codes, std::span<double> out) const {
  if (history_) throw std::logic_error("PanelEmission::row: the panel has history; the light needs the previous codes");
  if (codes.size() != out.size()) throw std::invalid_argument("PanelEmission::row: codes and out differ in size");
  const std::array<const double*, 3> channel{table_.data(), table_.data() + codes_, table_.data() + 2 * codes_};
  for (std::size_t k = 0; k < codes.size(); ++k) out[k] = channel[k % 3][codes[k]];
}

namespace {

void check_gamma(double gamma, const char* name, const std::string& what) {
  if (!(gamma > 0.0) || !std::isfinite(gamma)) throw std::invalid_argument(what + name + " must be > 0 and finite");
  if (gamma < kMinPanelGamma || gamma > kMaxPanelGamma) {
    throw std::invalid_argument(what + name + " " + number_text(gamma) + " is outside [" +
                                number_text(kMinPanelGamma) + ", " + number_text(kMaxPanelGamma) +
                                "], the display gammas trm models");
  }
}

}  // namespace

void OledPanel::validate(const std::string& what) const {
  for (double g : gamma) check_gamma(g, "OLED gamma", what);
  if (!(duty > 0.0 && duty <= 1.0)) throw std::invalid_argument(what + "OLED duty must be in (0, 1]");
}

void LcdPanel::validate(const std::string& what) const {
  const auto fail = [&](const std::string& why) { throw std::invalid_argument(what + why); };
  for (double p : {p1, p2, p3, p4}) {
    if (!std::isfinite(p)) fail("LCD parameters p1..p4 must be finite");
    if (std::abs(p) > kMaxLcdCoefficient) {
      fail("LCD merge coefficients p1..p4 must be within [-" + number_text(kMaxLcdCoefficient) + ", " +
           number_text(kMaxLcdCoefficient) + "]");
    }
  }
  check_gamma(gamma, "LCD gamma", what);
  // dM/dv_t = 2 p1 v_t + p2 v_prev + p3 is linear in both: positive at the four corners means positive on [0, 1]^2.
  for (double v : {0.0, 1.0}) {
    for (double vp : {0.0, 1.0}) {
      if (!(2.0 * p1 * v + p2 * vp + p3 > 0.0)) {
        fail("the LCD merge M(v_t, v_prev) must be increasing in v_t on [0, 1] (dM/dv_t = 2 p1 v_t + p2 v_prev + p3 "
             "> 0), or the drive has no unique inverse");
      }
    }
    if (!(2.0 * (2.0 * p1 + p2) * v + 2.0 * p3 > 0.0)) fail("the held LCD merge M(v, v) must be increasing on [0, 1]");
  }
  try {
    LcResponse(lc_response, 1.0);  // the model's own ranges, named
  } catch (const std::invalid_argument& e) {
    fail(std::string("LCD lc_response: ") + e.what());
  }
  if (lc_second_order && lc_response != LcResponseParams{}) {
    fail("LCD lc_response (the first-order LC) cannot be set together with lc_second_order: the panel has one LC "
         "model");
  }
  if (lc_second_order) {
    try {
      LcSecondOrder(*lc_second_order, 1.0);  // the model's own ranges, named
    } catch (const std::invalid_argument& e) {
      fail(std::string("LCD lc_second_order: ") + e.what());
    }
    if (!(lc_second_order->damping_ratio >= kMinPanelDampingRatio)) {
      fail("LCD lc_second_order damping_ratio " + number_text(lc_second_order->damping_ratio) + " must be >= " +
           number_text(kMinPanelDampingRatio) + ": an underdamped crystal overshoots, and a panel's light cannot go "
           "below black");
    }
  }
}

void Panel::validate(const std::string& what) const {
  if (kind == PanelKind::Oled) oled.validate(what); else lcd.validate(what);
}

void validate_panel(const Panel& panel, const std::string& what) { panel.validate(what); }

Panel parse_panel(const std::string& spec) {
  Panel panel = parse_panel_spec(spec);
  try {
    panel.validate("");
  } catch (const std::invalid_argument& e) {
    reject(spec, e.what());
  }
  return panel;
}

namespace {

// The OLED forms: the measured presets and gamma:G | gamma:GR,GG,GB. False when `spec` is none of them.
bool parse_oled_spec(const std::string& spec, Panel& out) {
  const std::string_view view(spec);
  if (spec == "vive" || spec == "rift" || spec == "generic") {
    out = oled_panel(spec, spec == "vive"   ? kViveGamma
                           : spec == "rift" ? kRiftGamma
                                            : std::array<double, 3>{kGenericGamma, kGenericGamma, kGenericGamma});
    return true;
  }
  if (!view.starts_with("gamma:")) return false;
  const std::vector<double> g = parse_numbers(spec, view.substr(6));
  if (g.size() != 1 && g.size() != 3) reject(spec, "gamma: takes 1 or 3 values");
  for (double value : g) {
    if (!(value > 0.0)) reject(spec, "gammas must be > 0");
  }
  out = oled_panel(spec, g.size() == 1 ? std::array<double, 3>{g[0], g[0], g[0]}
                                       : std::array<double, 3>{g[0], g[1], g[2]});
  return true;
}

// lcd:FILE.json: the panel JSON of to_json (what `trm calibrate` writes), which must be an LCD.
Panel read_lcd_preset(const std::string& spec, const std::string& path) {
  // A preset is a small regular file: a directory, a device or a FIFO named *.json is refused before it is opened
  // (reading one would fail part-way or never end), and so is a name with a NUL, which no file has.
  if (path.find('\0') != std::string::npos) reject(spec, "the preset file name contains a NUL character");
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) reject(spec, "cannot open the preset file " + in_quotes(path));
  if (!std::filesystem::is_regular_file(status)) reject(spec, "the preset file " + in_quotes(path) + " is not a file");
  constexpr std::uintmax_t kMaxPresetBytes = 1 << 20;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error || bytes > kMaxPresetBytes) {
    reject(spec, "the preset file " + in_quotes(path) + " is not a panel preset (larger than 1 MiB or unreadable)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) reject(spec, "cannot open the preset file " + in_quotes(path));
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    reject(spec, "the preset file " + in_quotes(path) + " is not JSON (" + e.what() + ")");
  } catch (const std::exception& e) {  // a read error of the stream itself
    reject(spec, "cannot read the preset file " + in_quotes(path) + " (" + e.what() + ")");
  }
  Panel panel;
  try {
    from_json(json, panel);
  } catch (const std::invalid_argument& e) {
    reject(spec, "the preset file " + in_quotes(path) + ": " + e.what());
  }
  if (panel.kind != PanelKind::Lcd) reject(spec, "the preset file " + in_quotes(path) + " is not an LCD panel");
  return panel;
}

// The LCD forms: lcd (the default merge) | lcd:FILE.json | lcd:p1,p2,p3,p4,gamma. False when `spec` is none.
bool parse_lcd_spec(const std::string& spec, Panel& out) {
  const std::string_view view(spec);
  if (spec != "lcd" && !view.starts_with("lcd:")) return false;
  // A list of numbers never ends in ".json": the suffix alone tells a preset file from parameters.
  if (view.ends_with(".json")) {
    out = read_lcd_preset(spec, spec.substr(4));
    return true;
  }
  out = Panel();
  out.kind = PanelKind::Lcd;
  out.name = spec;
  if (spec == "lcd") return true;
  const std::vector<double> p = parse_numbers(spec, view.substr(4));
  if (p.size() != 5) reject(spec, "lcd: takes 5 values p1,p2,p3,p4,gamma");
  if (!(p[4] > 0.0)) reject(spec, "the LCD gamma must be > 0");
  out.lcd.p1 = p[0];
  out.lcd.p2 = p[1];
  out.lcd.p3 = p[2];
  out.lcd.p4 = p[3];
  out.lcd.gamma = p[4];
  return true;
}

// Each panel kind parses its own forms; a new kind adds its parser here.
Panel parse_panel_spec(const std::string& spec) {
  Panel panel;
  if (parse_oled_spec(spec, panel) || parse_lcd_spec(spec, panel)) return panel;
  reject(spec, "unknown panel");
}

}  // namespace

namespace {

template <typename Json>
void write_panel(Json& out, const Panel& panel) {
  if (panel.kind == PanelKind::Oled) {
    out = {{"kind", "oled"}, {"name", panel.name}, {"gamma", panel.oled.gamma}, {"duty", panel.oled.duty}};
    return;
  }
  const LcdPanel& lcd = panel.lcd;
  out = {{"kind", "lcd"}, {"name", panel.name}, {"p1", lcd.p1}, {"p2", lcd.p2},
         {"p3", lcd.p3},  {"p4", lcd.p4},       {"gamma", lcd.gamma}};
  if (lcd.lc_response != LcResponseParams{}) {
    out["lc_response"] = {{"tau_off_s", lcd.lc_response.tau_off_s},
                          {"drive_ratio", lcd.lc_response.drive_ratio},
                          {"drive_gamma", lcd.lc_response.drive_gamma}};
  }
  if (lcd.lc_second_order) {
    out["lc_second_order"] = {{"tau_s", lcd.lc_second_order->tau_s},
                              {"damping_ratio", lcd.lc_second_order->damping_ratio}};
  }
  if (lcd.overdrive) out["overdrive"] = true;
}

[[noreturn]] void reject_json(const std::string& why) { throw std::invalid_argument("panel JSON: " + why); }

template <typename Json>
const Json& field(const Json& in, const char* key) {
  const auto found = in.find(key);
  if (found == in.end()) reject_json(std::string("missing \"") + key + "\"");
  return *found;
}

template <typename Json>
double number_field(const Json& in, const char* key) {
  const Json& value = field(in, key);
  if (!value.is_number()) reject_json(std::string("\"") + key + "\" must be a number, got " + value.dump());
  return value.template get<double>();
}

// Every field of `in` is one of `known` (what `where` takes): a misspelt field must not fall back to a default.
template <typename Json>
void reject_unknown_fields(const Json& in, const std::vector<std::string_view>& known, const std::string& where) {
  for (const auto& item : in.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    std::string takes;
    for (std::string_view k : known) takes.append(takes.empty() ? "" : ", ").append(k);
    reject_json(where + " has an unknown field \"" + item.key() + "\" (it takes " + takes + ")");
  }
}

// The object `key` of `in` with exactly the number fields `names`, or nullopt when `in` has no `key`.
template <typename Json>
std::optional<std::vector<double>> number_object(const Json& in, const char* key,
                                                 const std::vector<std::string_view>& names) {
  const auto found = in.find(key);
  if (found == in.end()) return std::nullopt;
  std::string takes;
  for (std::string_view name : names) takes.append(takes.empty() ? "" : ", ").append(name);
  if (!found->is_object()) {
    reject_json(std::string("\"") + key + "\" must be an object, got " + found->dump() + " (it takes " + takes + ")");
  }
  reject_unknown_fields(*found, names, std::string("\"") + key + "\"");
  std::vector<double> values;
  for (std::string_view name : names) values.push_back(number_field(*found, std::string(name).c_str()));
  return values;
}

template <typename Json>
void read_panel(const Json& in, Panel& panel) {
  if (!in.is_object()) reject_json("expected an object, got " + in.dump());
  const Json& kind = field(in, "kind");
  const Json& name = field(in, "name");
  if (!name.is_string()) reject_json("\"name\" must be a string, got " + name.dump());
  Panel out;
  out.name = name.template get<std::string>();
  if (kind == "oled") {
    reject_unknown_fields(in, {"kind", "name", "gamma", "duty"}, "an OLED panel");
    out.kind = PanelKind::Oled;
    const Json& gamma = field(in, "gamma");
    if (!gamma.is_array() || gamma.size() != 3) reject_json("\"gamma\" of an OLED panel must be 3 numbers (R, G, B)");
    for (std::size_t c = 0; c < 3; ++c) {
      if (!gamma[c].is_number()) reject_json("\"gamma\" of an OLED panel must be 3 numbers (R, G, B)");
      out.oled.gamma[c] = gamma[c].template get<double>();
    }
    out.oled.duty = number_field(in, "duty");
  } else if (kind == "lcd") {
    reject_unknown_fields(
        in, {"kind", "name", "p1", "p2", "p3", "p4", "gamma", "lc_response", "lc_second_order", "overdrive"},
        "an LCD panel");
    out.kind = PanelKind::Lcd;
    out.lcd.p1 = number_field(in, "p1");
    out.lcd.p2 = number_field(in, "p2");
    out.lcd.p3 = number_field(in, "p3");
    out.lcd.p4 = number_field(in, "p4");
    out.lcd.gamma = number_field(in, "gamma");
    if (const auto lc = number_object(in, "lc_response", {"tau_off_s", "drive_ratio", "drive_gamma"})) {
      out.lcd.lc_response = LcResponseParams{(*lc)[0], (*lc)[1], (*lc)[2]};
    }
    if (const auto lc = number_object(in, "lc_second_order", {"tau_s", "damping_ratio"})) {
      out.lcd.lc_second_order = LcSecondOrderParams{(*lc)[0], (*lc)[1]};
    }
    if (const auto overdrive = in.find("overdrive"); overdrive != in.end()) {
      if (!overdrive->is_boolean()) {
        reject_json("\"overdrive\" must be true or false (the panel overdrives its liquid crystal), got " +
                    overdrive->dump());
      }
      out.lcd.overdrive = overdrive->template get<bool>();
    }
  } else {
    reject_json("\"kind\" must be \"oled\" or \"lcd\", got " + kind.dump());
  }
  out.validate("panel JSON: ");
  panel = std::move(out);
}

}  // namespace

void to_json(nlohmann::json& out, const Panel& panel) { write_panel(out, panel); }
void to_json(nlohmann::ordered_json& out, const Panel& panel) { write_panel(out, panel); }
void from_json(const nlohmann::json& in, Panel& panel) { read_panel(in, panel); }
void from_json(const nlohmann::ordered_json& in, Panel& panel) { read_panel(in, panel); }

}  // namespace trm
