// Display-link presets (data rate after line coding) and CVT-RB v2 video timing (docs/link.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace trm::link {

// The fastest link any preset may claim (Gbit/s): a hundred times DP 2.1 UHBR20, so per-frame budgets and their
// plots stay finite numbers.
inline constexpr double kMaxLinkGbps = 10000.0;

struct LinkPreset {
  std::string name;         // as on the command line: dp1.2, hdmi2.1, custom:RATE_GBPS:EFFICIENCY, ...
  std::string description;  // e.g. "DisplayPort 1.2 HBR2 x4, 8b/10b"
  double raw_gbps = 0.0;    // aggregate line rate over all lanes, Gbit/s
  double efficiency = 1.0;  // fraction of the line rate left for data after channel coding, (0, 1]
  double data_gbps() const { return raw_gbps * efficiency; }
  double data_bits_per_second() const { return data_gbps() * 1e9; }
};

// The built-in presets (every name of the list below but custom), ordered by data rate, slowest first.
const std::vector<LinkPreset>& builtin_link_presets();

// Parses a preset name: dp1.2, dp1.4, dp2.1-uhbr10, dp2.1-uhbr13.5, dp2.1-uhbr20, hdmi2.0, hdmi2.1,
// wigig (or wigig:PRACTICAL_GBPS), usb3-gen1, usb3-gen2, custom:RATE_GBPS:EFFICIENCY.
// Throws std::invalid_argument with a clear message (listing the valid names for an unknown one;
// naming the bad number for a rate <= 0, an efficiency outside (0, 1], or trailing garbage).
LinkPreset parse_link_preset(const std::string& text);

// One line of help text listing the preset names.
std::string link_preset_names();

// A video timing: active and total raster, and the pixel clock that runs it at the refresh rate.
struct VideoTiming {
  int h_active = 0, v_active = 0;
  int h_total = 0, v_total = 0;
  double refresh_hz = 0.0;
  double pixel_clock_hz = 0.0;
  // Fraction of the frame period that carries active pixels; the rest is blanking, during which a
  // display link sends no pixel data.
  double active_fraction() const;
};

// VESA Coordinated Video Timings 1.2, reduced blanking version 2 (CVT-RB v2): 80-pixel horizontal
// blanking, at least 460 us of vertical blanking (and at least 1 + 8 + 6 lines: front porch, sync,
// back porch), pixel clock a multiple of 1 kHz. Throws std::invalid_argument for sizes < 1 or a
// refresh rate <= 0, or a refresh so high that the 460 us vertical blanking leaves no time for lines.
VideoTiming cvt_rb_v2_timing(int h_active, int v_active, double refresh_hz);

}  // namespace trm::link
