// libFuzzer target for the --panel parser (parse_panel). The input is the option text. The parser must
// throw std::invalid_argument or return a panel of the kind the text names with finite parameters; the
// returned panel's drive inverse must then give drive values in [0, 1] for any light level (the decoder
// turns them into integer codes), and the LCD solver must stay in [0, 1] for any target and history.
#include "fuzz_support.hpp"
#include "trm/panel.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

using trm::fuzz::check;

namespace {

bool in_unit(double v) { return v >= 0.0 && v <= 1.0; }  // false for NaN

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  trm::Panel panel;
  try {
    panel = trm::parse_panel(text);
  } catch (const std::invalid_argument& e) {
    check(std::string(e.what()).find("invalid panel") != std::string::npos, "message does not name the panel");
    return 0;
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_panel");
  }
  check(panel.name == text, "panel name differs from the text");
  const bool lcd = text == "lcd" || text.rfind("lcd:", 0) == 0;
  check((panel.kind == trm::PanelKind::Lcd) == lcd, "panel kind differs from the text");
  if (panel.kind == trm::PanelKind::Oled) {
    for (double g : panel.oled.gamma) check(std::isfinite(g) && g > 0.0, "OLED gamma not finite and > 0");
  } else {
    const trm::LcdPanel& l = panel.lcd;
    check(std::isfinite(l.p1) && std::isfinite(l.p2) && std::isfinite(l.p3) && std::isfinite(l.p4),
          "LCD parameter not finite");
    check(std::isfinite(l.gamma) && l.gamma > 0.0, "LCD gamma not finite and > 0");
  }
  for (double x : {0.0, 1e-6, 0.25, 0.5, 0.999, 1.0, -1.0, 2.0}) {
    for (int channel = 0; channel < 3; ++channel) {
      const double v = panel.drive_from_linear(x, channel);
      check(in_unit(v), "drive_from_linear outside [0, 1]");
      (void)panel.linear_from_drive(v, channel);
    }
    if (panel.kind == trm::PanelKind::Lcd) {
      for (double prev : {0.0, 0.5, 1.0}) check(in_unit(panel.lcd.solve(x, prev).v), "LcdPanel::solve outside [0, 1]");
    }
  }
  return 0;
}
