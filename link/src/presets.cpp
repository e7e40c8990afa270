#include "trm/presets.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace trm::link {

namespace {

// Channel-coding efficiencies (docs/link.md, "Link presets").
constexpr double k8b10b = 8.0 / 10.0;       // DP 1.x, HDMI 2.0 TMDS, USB 3.2 Gen 1
constexpr double k128b132b = 128.0 / 132.0;  // USB 3.2 Gen 2
constexpr double k16b18b = 16.0 / 18.0;     // HDMI 2.1 FRL
// DP 2.x UHBR: 128b/132b plus the link-layer control, FEC and PHY sync symbols the link inserts
// (DP 2.1 §3.5.2.18): 96.71 % of the line rate carries data, as VESA's 77.37 Gbit/s for UHBR20 states.
constexpr double kUhbrEfficiency = 0.9671;
// 802.11ad single-carrier MCS 12 PHY rate; what reaches an application is about half (MAC, framing,
// retransmissions), so the default practical throughput is 55 % of it (2.54 Gbit/s); `wigig:GBPS` sets it.
constexpr double kWigigPhyGbps = 4.62;
constexpr double kWigigPracticalShare = 0.55;

std::vector<LinkPreset> make_builtin() {
  std::vector<LinkPreset> p = {
      {"dp1.2", "DisplayPort 1.2 HBR2 x4 (4 x 5.4 Gbit/s), 8b/10b", 4 * 5.4, k8b10b},
      {"dp1.4", "DisplayPort 1.4 HBR3 x4 (4 x 8.1 Gbit/s), 8b/10b", 4 * 8.1, k8b10b},
      {"dp2.1-uhbr10", "DisplayPort 2.1 UHBR10 x4 (4 x 10 Gbit/s), 128b/132b + FEC", 4 * 10.0, kUhbrEfficiency},
      {"dp2.1-uhbr13.5", "DisplayPort 2.1 UHBR13.5 x4 (4 x 13.5 Gbit/s), 128b/132b + FEC", 4 * 13.5, kUhbrEfficiency},
      {"dp2.1-uhbr20", "DisplayPort 2.1 UHBR20 x4 (4 x 20 Gbit/s), 128b/132b + FEC", 4 * 20.0, kUhbrEfficiency},
      {"hdmi2.0", "HDMI 2.0 TMDS (3 x 6 Gbit/s), 8b/10b", 3 * 6.0, k8b10b},
      {"hdmi2.1", "HDMI 2.1 FRL (4 x 12 Gbit/s), 16b/18b", 4 * 12.0, k16b18b},
      {"wigig", "802.11ad (MCS 12 PHY 4.62 Gbit/s), practical throughput 55 %", kWigigPhyGbps, kWigigPracticalShare},
      {"usb3-gen1", "USB 3.2 Gen 1 (5 Gbit/s), 8b/10b", 5.0, k8b10b},
      {"usb3-gen2", "USB 3.2 Gen 2 (10 Gbit/s), 128b/132b", 10.0, k128b132b},
  };
  std::stable_sort(p.begin(), p.end(), [](const LinkPreset& a, const LinkPreset& b) { return a.data_gbps() < b.data_gbps(); });
  return p;
}

// Parses a whole string as a finite double; anything else is an error naming `what`.
double parse_number(const std::string& text, const std::string& what, const std::string& preset) {
  errno = 0;
  char* end = nullptr;
  const double v = text.empty() ? 0.0 : std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    throw std::invalid_argument("link preset '" + preset + "': " + what + " '" + text + "' is not a number");
  return v;
}

// A user-given rate in Gbit/s: above 0 and at most kMaxLinkGbps, so that every per-frame budget is finite.
void require_rate(double gbps, const std::string& what, const std::string& preset) {
  if (!(gbps > 0.0 && gbps <= kMaxLinkGbps)) {
    throw std::invalid_argument("link preset '" + preset + "': " + what + " must be > 0 and <= " +
                                std::to_string(static_cast<int>(kMaxLinkGbps)) + " Gbit/s");
  }
}

}  // namespace

const std::vector<LinkPreset>& builtin_link_presets() {
  static const std::vector<LinkPreset> presets = make_builtin();
  return presets;
}

std::string link_preset_names() {
  return "dp1.2, dp1.4, dp2.1-uhbr10, dp2.1-uhbr13.5, dp2.1-uhbr20, hdmi2.0, hdmi2.1, wigig[:GBPS], "
         "usb3-gen1, usb3-gen2, custom:RATE_GBPS:EFFICIENCY";
}

LinkPreset parse_link_preset(const std::string& text) {
  for (const LinkPreset& p : builtin_link_presets())
    if (p.name == text) return p;

  if (text.rfind("wigig:", 0) == 0) {
    const double gbps = parse_number(text.substr(6), "practical throughput", text);
    require_rate(gbps, "practical throughput", text);
    return {text, "802.11ad, practical throughput " + text.substr(6) + " Gbit/s", gbps, 1.0};
  }
  if (text.rfind("custom:", 0) == 0) {
    const std::string rest = text.substr(7);
    const std::size_t colon = rest.find(':');
    if (colon == std::string::npos)
      throw std::invalid_argument("link preset '" + text + "': expected custom:RATE_GBPS:EFFICIENCY, e.g. custom:10:0.8");
    const double rate = parse_number(rest.substr(0, colon), "rate", text);
    const double efficiency = parse_number(rest.substr(colon + 1), "efficiency", text);
    require_rate(rate, "rate", text);
    if (!(efficiency > 0.0 && efficiency <= 1.0))
      throw std::invalid_argument("link preset '" + text + "': coding efficiency must be in (0, 1]");
    return {text, "custom link", rate, efficiency};
  }
  throw std::invalid_argument("unknown link preset '" + text + "' (expected one of: " + link_preset_names() + ")");
}

double VideoTiming::active_fraction() const {
  if (h_total <= 0 || v_total <= 0) return 1.0;
  return (static_cast<double>(h_active) * v_active) / (static_cast<double>(h_total) * v_total);
}

VideoTiming cvt_rb_v2_timing(int h_active, int v_active, double refresh_hz) {
  if (h_active < 1 || v_active < 1) throw std::invalid_argument("CVT-RB v2: active size must be at least 1x1");
  if (!(refresh_hz > 0.0) || !std::isfinite(refresh_hz))
    throw std::invalid_argument("CVT-RB v2: refresh rate must be > 0 Hz");
  // VESA CVT 1.2, reduced blanking v2 constants.
  constexpr int kHBlank = 80;            // pixels
  constexpr double kMinVBlankUs = 460.0;
  constexpr int kVFrontPorch = 1, kVSync = 8, kMinVBackPorch = 6;
  constexpr double kClockStepHz = 1000.0;  // RB v2: pixel clock in 0.001 MHz steps

  const double frame_us = 1e6 / refresh_hz;
  if (frame_us <= kMinVBlankUs)
    throw std::invalid_argument("CVT-RB v2: at this refresh rate the 460 us vertical blanking fills the whole frame");
  const double h_period_estimate_us = (frame_us - kMinVBlankUs) / v_active;
  const int vbi_lines = static_cast<int>(std::floor(kMinVBlankUs / h_period_estimate_us)) + 1;
  const int min_vbi_lines = kVFrontPorch + kVSync + kMinVBackPorch;

  VideoTiming t;
  t.h_active = h_active;
  t.v_active = v_active;
  t.h_total = h_active + kHBlank;
  t.v_total = v_active + std::max(vbi_lines, min_vbi_lines);
  t.refresh_hz = refresh_hz;
  t.pixel_clock_hz =
      kClockStepHz * std::floor(refresh_hz * static_cast<double>(t.v_total) * t.h_total / kClockStepHz);
  return t;
}

}  // namespace trm::link
